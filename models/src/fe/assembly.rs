//! The discrete problem and the assembly of internal forces and tangent.
//!
//! With small rotations the beams and springs are linear: their stiffness is assembled once per
//! mesh into [`Assembler::linear`] and a Newton iteration only copies it and adds the interface
//! items (points, segments) — and, where its tangent holds the last one, only in the rows of the
//! items whose stiffness changed (`fe::changed_rows`; the rows are the same sums, in the same
//! order, as a whole assembly's). With large rotations the co-rotational beams are re-assembled
//! each iteration. No allocation happens per iteration: every buffer lives in the [`Assembler`].
//!
//! The interface is integrated by the nodal rule ([`InterfaceRule::Nodal`]: each point with its
//! tributary area) or, between neighbouring cohesive points, by [`super::segment`]'s exact
//! integration over a traction field with its kinks at the damage fronts
//! ([`InterfaceRule::Segments`]).

use czid_core::{CohesiveLaw, Gap, LawEval, LawState, Tangent, Traction};

use super::banded::{BandMatrix, RowSparse};
use super::beam;
use super::changed_rows::ChangedRows;
use super::corotational;
use super::interface::{self, GapKinematics, InterfacePoint, PointKind, POINT_DOFS, SIDE};
use super::mesh::{Mesh, NONE};
use super::segment::{self, End, ModeOne, Segment};

/// A linear spring of stiffness `k` (N/mm) between unknowns `i` and `j` (`j` = [`NONE`]: ground).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    /// First unknown.
    pub i: usize,
    /// Second unknown, or [`NONE`].
    pub j: usize,
    /// Stiffness.
    pub k: f64,
    /// Coefficient of `i` in the spring's elongation `c_i q_i − q_j` (e.g. 2 for a half model
    /// whose load point moves half the opening).
    pub ci: f64,
}

impl Spring {
    /// Its elongation `c_i q_i − q_j` (mm).
    fn elongation(&self, q: &[f64]) -> f64 {
        self.ci * q[self.i] - get(q, self.j)
    }

    /// Adds its stiffness to `k`.
    fn stiffness_into(&self, k: &mut BandMatrix) {
        k.add(self.i, self.i, self.k * self.ci * self.ci);
        if self.j != NONE {
            k.add(self.j, self.j, self.k);
            k.add(self.i, self.j, -self.k * self.ci);
            k.add(self.j, self.i, -self.k * self.ci);
        }
    }
}

/// Everything the solver needs to know about a discretised test.
#[derive(Clone, Debug, PartialEq)]
pub struct FeProblem {
    /// Nodes, layers, unknowns.
    pub mesh: Mesh,
    /// Interface integration points.
    pub points: Vec<InterfacePoint>,
    /// Linear springs (machine compliance, supports).
    pub springs: Vec<Spring>,
    /// Unknowns held at zero.
    pub fixed: Vec<usize>,
    /// The loaded unknown: prescribed under displacement control, carrying the load factor under
    /// dissipation control. Its reaction is the generalised load.
    pub control: usize,
    /// Co-rotational (large-rotation) kinematics for beams and interfaces.
    pub large_rotation: bool,
    /// Normal penalty of contact-only points (MPa/mm), also the stiffness of their stick spring
    /// when they carry friction.
    pub contact_stiffness: f64,
    /// Coulomb friction coefficient of contact-only points (dimensionless); 0: frictionless
    /// ([`interface::contact`]), else [`interface::frictional_contact`].
    pub contact_friction: f64,
}

struct Element {
    layer: usize,
    /// Its left node.
    node: usize,
    dofs: [usize; 6],
    x1: f64,
    x2: f64,
}

/// How the cohesive interface is integrated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum InterfaceRule {
    /// Each point carries its tributary area (trapezoidal rule).
    #[default]
    Nodal,
    /// Neighbouring cohesive points form segments integrated exactly over a piecewise linear
    /// traction field with kinks at the onset and failure fronts ([`super::segment`]).
    Segments,
}

/// Per-point data of the last assembly kept for the segment rule.
#[derive(Clone, Copy, Debug, Default)]
struct PointData {
    kin: GapKinematics,
    d: Tangent,
    /// The unknowns are among `kin.dofs[first..]`: [`SIDE`] on a symmetry plane (no lower side),
    /// else 0.
    first: usize,
}

impl PointData {
    fn new(kin: GapKinematics, d: Tangent) -> Self {
        let first = if kin.dofs[..SIDE].iter().all(|&d| d == NONE) { SIDE } else { 0 };
        PointData { kin, d, first }
    }
}

/// Assembly workspace for one [`FeProblem`].
pub struct Assembler {
    elements: Vec<Element>,
    /// Constant part of the tangent (small-rotation beams and springs); empty band otherwise.
    pub linear: BandMatrix,
    /// Its non-zero entries, for the forces: a row of a beam mesh's band holds a few times more
    /// zeros than entries.
    linear_entries: RowSparse,
    /// Trial law results of the last assembly, one per interface point.
    pub trial: Vec<LawEval>,
    /// Gaps of the last assembly.
    pub gaps: Vec<Gap>,
    /// Segments of the interface (empty with the nodal rule).
    pub segments: Vec<Segment>,
    /// Fronts found in each segment by the last assembly (fractions from the segment's left end:
    /// onset, failure).
    pub fronts: Vec<[Option<f64>; 2]>,
    /// Recoverable energy `∫ ½ T·g` of each segment at the last assembly (N·mm).
    pub segment_stored: Vec<f64>,
    covered: Vec<bool>,
    mode_one: Option<ModeOne>,
    data: Vec<PointData>,
    hessians: Vec<interface::Hessian>,
    /// Under small rotations, each point's gap kinematics at rest: its gradient holds at every
    /// `q`, so an assembly only takes the gap. Empty under large rotations.
    at_rest: Vec<GapKinematics>,
    n: usize,
    strength: [f64; 2],
    hess: Box<interface::Hessian>,
    /// Nodes from this one on are left out (at rest, their unknowns not solved for, see
    /// [`super::newton::Newton::active`]): only the elements, points and segments of the nodes
    /// before it are assembled, the structure cut there. `usize::MAX`: none.
    pub frozen_from_node: usize,
    /// What the interface scattered into the tangent, for the rows that can have changed since
    /// the last factorisation (small rotations only).
    pub(crate) changed: ChangedRows,
    /// Whether the last tangent was rebuilt only where it changed ([`Assembler::assemble_reusing`]).
    pub(crate) tangent_reused: bool,
}

/// Relative margin within which a cohesive point iterates with its loading-branch tangent.
pub const LOADING_BIAS: f64 = 1e-3;

#[inline]
fn get(q: &[f64], d: usize) -> f64 {
    if d == NONE {
        0.0
    } else {
        q[d]
    }
}

impl Assembler {
    /// Prepares element lists and the constant part of the tangent (nodal interface rule).
    pub fn new(p: &FeProblem, law: &dyn CohesiveLaw) -> Self {
        Self::with_rule(p, law, InterfaceRule::Nodal)
    }

    /// [`Assembler::new`] with the interface integrated by `rule`.
    pub fn with_rule(p: &FeProblem, law: &dyn CohesiveLaw, rule: InterfaceRule) -> Self {
        let mesh = &p.mesh;
        let mut elements = Vec::new();
        for (k, layer) in mesh.layers.iter().enumerate() {
            for i in layer.first..layer.last {
                let a = mesh.dofs(k, i);
                let b = mesh.dofs(k, i + 1);
                elements.push(Element {
                    layer: k,
                    node: i,
                    dofs: [a[0], a[1], a[2], b[0], b[1], b[2]],
                    x1: mesh.x[i],
                    x2: mesh.x[i + 1],
                });
            }
        }
        let n = mesh.n_dofs();
        let mut linear = BandMatrix::zeros(n, mesh.bandwidth());
        if !p.large_rotation {
            for e in &elements {
                let ke = beam::stiffness(&mesh.layers[e.layer].section, e.x2 - e.x1);
                scatter(&mut linear, &e.dofs, &ke);
            }
        }
        for s in &p.springs {
            s.stiffness_into(&mut linear);
        }
        let np = p.points.len();
        let zero = LawEval { traction: Default::default(), tangent: Default::default(), state: LawState::default() };
        let strength = strengths(law);
        let (segments, covered) = match rule {
            InterfaceRule::Nodal => (Vec::new(), vec![false; np]),
            InterfaceRule::Segments => segment::segments(mesh, &p.points),
        };
        let mode_one = if segments.is_empty() { None } else { ModeOne::of(law) };
        let large = p.large_rotation && !segments.is_empty();
        let at_rest: Vec<GapKinematics> = if p.large_rotation {
            Vec::new()
        } else {
            let (zero, mut hess) = (vec![0.0; n], [[[0.0; POINT_DOFS]; POINT_DOFS]; 2]);
            p.points.iter().map(|pt| interface::kinematics(mesh, pt, &zero, false, &mut hess)).collect()
        };
        // The rows each interface item writes: its points' unknowns.
        let rows_of = |ips: &[usize]| {
            let dofs = ips.iter().flat_map(|&ip| at_rest[ip].dofs).filter(|&d| d != NONE);
            dofs.fold(None, |r: Option<(usize, usize)>, d| Some(r.map_or((d, d), |(lo, hi)| (lo.min(d), hi.max(d)))))
        };
        let changed = if p.large_rotation {
            ChangedRows::default()
        } else {
            ChangedRows::new(
                (0..np).map(|ip| if covered[ip] { None } else { rows_of(&[ip]) }).collect(),
                segments.iter().map(|sg| rows_of(&[sg.a, sg.b])).collect(),
            )
        };
        Assembler {
            elements,
            // (Under large rotations the band is empty: the springs are added directly.)
            linear_entries: if p.large_rotation { RowSparse::default() } else { RowSparse::from_band(&linear) },
            linear,
            trial: vec![zero; np],
            gaps: vec![Gap::zeros(); np],
            fronts: vec![[None; 2]; segments.len()],
            segment_stored: vec![0.0; segments.len()],
            segments,
            covered,
            mode_one,
            data: vec![PointData::default(); np],
            hessians: if large { vec![[[[0.0; POINT_DOFS]; POINT_DOFS]; 2]; np] } else { Vec::new() },
            at_rest,
            n,
            strength,
            hess: Box::new([[[0.0; POINT_DOFS]; POINT_DOFS]; 2]),
            frozen_from_node: usize::MAX,
            changed,
            tangent_reused: false,
        }
    }

    /// Internal forces `f` and tangent `k` at `q`, laws evaluated from the committed `states`;
    /// with `k` `None`, the forces only (and the law results), `k` left as it is (a chord step
    /// reuses its factors). Returns `false` if a law returned a non-finite value.
    #[allow(clippy::too_many_arguments)]
    pub fn assemble(
        &mut self,
        p: &FeProblem,
        law: &dyn CohesiveLaw,
        states: &[LawState],
        q: &[f64],
        k: Option<&mut BandMatrix>,
        f: &mut [f64],
        secant: bool,
    ) -> bool {
        self.assemble_reusing(p, law, states, q, k, f, secant, false)
    }

    /// [`Assembler::assemble`]; with `reuse`, a tangent `k` that holds this assembler's last one
    /// (the caller's word that it changed since only in the identity rows and columns of
    /// prescribed unknowns, set again before any factorisation) is rebuilt only in the rows of the
    /// interface items that changed ([`Assembler::tangent_reused`] says whether it was).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn assemble_reusing(
        &mut self,
        p: &FeProblem,
        law: &dyn CohesiveLaw,
        states: &[LawState],
        q: &[f64],
        mut k: Option<&mut BandMatrix>,
        f: &mut [f64],
        secant: bool,
        reuse: bool,
    ) -> bool {
        if p.large_rotation {
            // The constant part is the springs alone: added directly rather than by copying and
            // multiplying a band that is empty elsewhere.
            if let Some(k) = k.as_deref_mut() {
                k.clear();
            }
            f.fill(0.0);
            for s in &p.springs {
                let e = s.elongation(q);
                f[s.i] += s.k * s.ci * e;
                if s.j != NONE {
                    f[s.j] -= s.k * e;
                }
                if let Some(k) = k.as_deref_mut() {
                    s.stiffness_into(k);
                }
            }
        } else {
            if k.is_some() {
                self.changed.start(self.frozen_from_node);
            }
            self.linear_entries.mul_vec(q, f);
        }
        if p.large_rotation {
            for e in self.elements.iter().filter(|e| e.node + 1 < self.frozen_from_node) {
                let mut qe = [0.0; 6];
                for (v, &d) in qe.iter_mut().zip(&e.dofs) {
                    *v = get(q, d);
                }
                let cr = corotational::element(&p.mesh.layers[e.layer].section, e.x1, e.x2, &qe);
                for (a, &da) in e.dofs.iter().enumerate() {
                    if da == NONE {
                        continue;
                    }
                    f[da] += cr.force[a];
                }
                if let Some(k) = k.as_deref_mut() {
                    scatter(k, &e.dofs, &cr.tangent);
                }
            }
        }
        let mut ok = true;
        for (ip, pt) in p.points.iter().enumerate() {
            if pt.node >= self.frozen_from_node {
                // At rest beyond the solved part, with its results at rest.
                continue;
            }
            // A point integrated through its segments keeps its Hessians for them; the others
            // use them at once.
            let hess =
                if self.covered[ip] && !self.hessians.is_empty() { &mut self.hessians[ip] } else { &mut *self.hess };
            let kin = match self.at_rest.get(ip) {
                Some(rest) => GapKinematics { gap: interface::small_gap(&p.mesh, pt, q), ..*rest },
                None => interface::kinematics(&p.mesh, pt, q, p.large_rotation, hess),
            };
            let gap = Gap::new(kin.gap[0], kin.gap[1]);
            let (ev, d) = match pt.kind {
                PointKind::Cohesive => {
                    let ev = law.evaluate(&gap, &states[ip]);
                    let d = if secant {
                        secant_tangent(&gap, &ev)
                    } else if self.covered[ip] {
                        // Segments: forces are continuous at the elastic limit, so the law's own
                        // tangent is the consistent Jacobian (see `fe::window`).
                        ev.tangent
                    } else {
                        self.loading_tangent(law, &gap, &states[ip], &ev)
                    };
                    (ev, d)
                }
                PointKind::Contact => {
                    let ev = if p.contact_friction == 0.0 {
                        interface::contact(&gap, p.contact_stiffness)
                    } else {
                        interface::frictional_contact(&gap, &states[ip], p.contact_stiffness, p.contact_friction)
                    };
                    (ev, ev.tangent)
                }
            };
            let t = ev.traction;
            if !(t[0].is_finite() && t[1].is_finite() && d.iter().all(|v| v.is_finite())) {
                ok = false;
            }
            self.trial[ip] = ev;
            self.gaps[ip] = gap;
            if self.covered[ip] {
                // Integrated through its segments below.
                self.data[ip] = PointData::new(kin, d);
                continue;
            }
            let w = pt.area * pt.factor;
            // f += w Gᵀ T
            let g = &kin.grad;
            for a in 0..POINT_DOFS {
                let da = kin.dofs[a];
                if da == NONE || (g[0][a] == 0.0 && g[1][a] == 0.0 && !kin.nonlinear) {
                    continue;
                }
                f[da] += w * (g[0][a] * t[0] + g[1][a] * t[1]);
            }
            // K += w (Gᵀ D G + T_n H_n + T_t H_t): at once under large rotations (the Hessian is
            // this point's until the next), once the whole interface is known otherwise.
            if let Some(k) = k.as_deref_mut() {
                if p.large_rotation {
                    scatter_point(k, &kin, &d, w, Some((&*self.hess, t)), (0, usize::MAX));
                } else {
                    self.changed.point(ip, &d);
                }
            }
        }
        for (is, sg) in self.segments.iter().enumerate() {
            if p.points[sg.b].node >= self.frozen_from_node {
                continue;
            }
            let end = |i: usize| End {
                gap: self.gaps[i],
                t: self.trial[i].traction,
                d: self.data[i].d,
                trial: &self.trial[i].state,
                state: &states[i],
            };
            let sf = segment::integrate(sg, &end(sg.a), &end(sg.b), law, self.mode_one.as_ref());
            self.fronts[is] = sf.fronts;
            self.segment_stored[is] = sf.stored;
            let pts = [&self.data[sg.a], &self.data[sg.b]];
            // Both points on a symmetry plane (a half DCB): only their upper sides have unknowns.
            let half = on_symmetry_plane(pts);
            if half {
                segment_forces::<SIDE>(f, pts, &sf.f);
            } else {
                segment_forces::<0>(f, pts, &sf.f);
            }
            if let Some(k) = k.as_deref_mut() {
                if p.large_rotation {
                    let hess = [self.hessians.get(sg.a), self.hessians.get(sg.b)];
                    let all = (0, usize::MAX);
                    if half {
                        scatter_segment::<SIDE>(k, pts, hess, &sf.jac, &sf.f, all);
                    } else {
                        scatter_segment::<0>(k, pts, hess, &sf.jac, &sf.f, all);
                    }
                } else {
                    self.changed.segment(is, &sf.jac);
                }
            }
        }
        if let Some(k) = k {
            if !p.large_rotation {
                self.scatter_interface(p, k, reuse);
            }
        }
        ok
    }

    /// The small-rotation tangent from the interface items' stiffnesses of this assembly: the
    /// linear part and every item's share, in the order of a whole assembly (points, then
    /// segments). With `reuse`, where `k` holds this assembler's last tangent (the same buffer,
    /// the same frozen node; the identity rows of prescribed unknowns the Newton iteration set in
    /// it being set again before its factorisation), only the rows of the items that changed since
    /// are rebuilt, from the items that write them: each row is the same sum, in the same order,
    /// as a whole assembly's, and the others are as they were.
    fn scatter_interface(&mut self, p: &FeProblem, k: &mut BandMatrix, reuse: bool) {
        let same_buffer = self.changed.last_buffer(k.address(), self.frozen_from_node);
        self.tangent_reused = reuse && same_buffer;
        let rows = if self.tangent_reused { self.changed.rows_since_last_assembly() } else { Some((0, self.n - 1)) };
        if let Some(rows) = rows {
            self.rebuild_rows(p, k, rows);
        }
    }

    /// Rows `lo..=hi` of the small-rotation tangent of the last assembly, built in `k`: the
    /// linear part and the shares of the interface items that write them, in their order.
    pub(crate) fn rebuild_rows(&self, p: &FeProblem, k: &mut BandMatrix, (lo, hi): (usize, usize)) {
        k.copy_rows_from(&self.linear, lo, hi);
        let touches = |r: Option<(usize, usize)>| r.is_some_and(|(a, b)| a <= hi && b >= lo);
        for (ip, pt) in p.points.iter().enumerate() {
            if pt.node >= self.frozen_from_node || self.covered[ip] || !touches(self.changed.point_rows(ip)) {
                continue;
            }
            let d = self.changed.assembled_point(ip);
            scatter_point(k, &self.at_rest[ip], &d, pt.area * pt.factor, None, (lo, hi));
        }
        for (is, sg) in self.segments.iter().enumerate() {
            if p.points[sg.b].node >= self.frozen_from_node || !touches(self.changed.segment_rows(is)) {
                continue;
            }
            let pts = [&self.data[sg.a], &self.data[sg.b]];
            let (jac, none) = (self.changed.assembled_segment(is), &[Traction::zeros(); 2]);
            if on_symmetry_plane(pts) {
                scatter_segment::<SIDE>(k, pts, [None, None], jac, none, (lo, hi));
            } else {
                scatter_segment::<0>(k, pts, [None, None], jac, none, (lo, hi));
            }
        }
    }

    /// Tangent for the iteration matrix of a cohesive point.
    ///
    /// A point sitting on (or just inside) its damage surface has two one-sided tangents: the
    /// secant one if it unloads and the softening one if it loads. The law returns the secant one
    /// unless the trial gap is strictly beyond the committed surface, so a whole process zone can
    /// flip between the two from one iteration to the next and Newton cycles (and the bordered
    /// dissipation-controlled system becomes singular at a converged state, where every damaging
    /// point is exactly on its surface). Points within a relative [`LOADING_BIAS`] of their surface
    /// therefore iterate with the loading-branch tangent, obtained from the law at a gap enlarged
    /// by that margin. Only the iteration matrix changes; tractions, hence converged solutions,
    /// are the law's own.
    fn loading_tangent(&self, law: &dyn CohesiveLaw, gap: &Gap, state: &LawState, ev: &LawEval) -> Tangent {
        loading_tangent(law, &self.strength, gap, state, ev)
    }

    /// Strain energy of the beams and springs (N·mm) at `q`.
    pub fn structural_energy(&self, p: &FeProblem, q: &[f64]) -> f64 {
        let mut e = 0.0;
        for el in &self.elements {
            let mut qe = [0.0; 6];
            for (v, &d) in qe.iter_mut().zip(&el.dofs) {
                *v = get(q, d);
            }
            let s = &p.mesh.layers[el.layer].section;
            e += if p.large_rotation {
                corotational::element(s, el.x1, el.x2, &qe).energy
            } else {
                beam::energy(s, el.x2 - el.x1, &qe)
            };
        }
        for s in &p.springs {
            let d = s.elongation(q);
            e += 0.5 * s.k * d * d;
        }
        e
    }

    /// Recoverable energy of the interface integrated as the forces are: the segments' `∫ ½ T·g`
    /// and the nodal rule for the points outside segments (N·mm). `stored` holds each point's
    /// own recoverable energy per unit area.
    pub fn interface_stored(&self, p: &FeProblem, stored: &[f64]) -> f64 {
        let mut e: f64 = self.segment_stored.iter().sum();
        for (i, pt) in p.points.iter().enumerate() {
            if !self.covered[i] {
                e += pt.area * pt.factor * stored[i];
            }
        }
        e
    }

    /// Number of unknowns.
    pub fn n(&self) -> usize {
        self.n
    }
}

/// Whether both points of a segment lie on a symmetry plane (a half DCB: only their upper sides
/// have unknowns).
fn on_symmetry_plane(pts: [&PointData; 2]) -> bool {
    pts[0].first == SIDE && pts[1].first == SIDE
}

/// Adds a segment's forces `fs` (on its two points' gaps) to `f`; the points' unknowns are among
/// `kin.dofs[FIRST..]` (a constant, so the loops unroll).
fn segment_forces<const FIRST: usize>(f: &mut [f64], pts: [&PointData; 2], fs: &[Traction; 2]) {
    for (pi, fi) in pts.iter().zip(fs) {
        let ki = &pi.kin;
        for r in FIRST..POINT_DOFS {
            let dr = ki.dofs[r];
            if dr == NONE {
                continue;
            }
            let (g0, g1) = (ki.grad[0][r], ki.grad[1][r]);
            if g0 == 0.0 && g1 == 0.0 && !ki.nonlinear {
                continue;
            }
            f[dr] += g0 * fi[0] + g1 * fi[1];
        }
    }
}

/// Adds a segment's tangent `G_iᵀ J_ij G_j` (and, under large rotations, `f_i·H_i`) to the rows
/// `rows.0..=rows.1` of `k`; the points' unknowns are among `kin.dofs[FIRST..]`.
fn scatter_segment<const FIRST: usize>(
    k: &mut BandMatrix,
    pts: [&PointData; 2],
    hess: [Option<&interface::Hessian>; 2],
    jac: &[[Tangent; 2]; 2],
    fs: &[Traction; 2],
    (lo, hi): (usize, usize),
) {
    for (i, pi) in pts.iter().enumerate() {
        let ki = &pi.kin;
        let fi = fs[i];
        for r in FIRST..POINT_DOFS {
            let dr = ki.dofs[r];
            if dr == NONE || dr < lo || dr > hi {
                continue;
            }
            let (g0, g1) = (ki.grad[0][r], ki.grad[1][r]);
            if g0 == 0.0 && g1 == 0.0 && !ki.nonlinear {
                continue;
            }
            // Row r of G_iᵀ J_ij, times G_j.
            for (j, pj) in pts.iter().enumerate() {
                let kj = &pj.kin;
                let jac = &jac[i][j];
                let ra0 = g0 * jac[(0, 0)] + g1 * jac[(1, 0)];
                let ra1 = g0 * jac[(0, 1)] + g1 * jac[(1, 1)];
                let h = if i == j && ki.nonlinear { hess[i] } else { None };
                for c in FIRST..POINT_DOFS {
                    let dc = kj.dofs[c];
                    if dc == NONE {
                        continue;
                    }
                    let mut v = ra0 * kj.grad[0][c] + ra1 * kj.grad[1][c];
                    if let Some(h) = h {
                        v += fi[0] * h[0][r][c] + fi[1] * h[1][r][c];
                    }
                    if v != 0.0 {
                        k.add(dr, dc, v);
                    }
                }
            }
        }
    }
}

/// Adds a point's tangent `w (Gᵀ D G + T_n H_n + T_t H_t)` (the Hessian terms with `hess` =
/// `Some((H, T))`, large rotations) to the rows `rows.0..=rows.1` of `k`.
fn scatter_point(
    k: &mut BandMatrix,
    kin: &GapKinematics,
    d: &Tangent,
    w: f64,
    hess: Option<(&interface::Hessian, Traction)>,
    (lo, hi): (usize, usize),
) {
    let g = &kin.grad;
    for a in 0..POINT_DOFS {
        let da = kin.dofs[a];
        if da == NONE || da < lo || da > hi || (g[0][a] == 0.0 && g[1][a] == 0.0 && !kin.nonlinear) {
            continue;
        }
        // Row a of Gᵀ D: (g0a D00 + g1a D10, g0a D01 + g1a D11)
        let ra0 = g[0][a] * d[(0, 0)] + g[1][a] * d[(1, 0)];
        let ra1 = g[0][a] * d[(0, 1)] + g[1][a] * d[(1, 1)];
        for b in 0..POINT_DOFS {
            let db = kin.dofs[b];
            if db == NONE {
                continue;
            }
            let mut v = ra0 * g[0][b] + ra1 * g[1][b];
            if kin.nonlinear {
                if let Some((h, t)) = hess {
                    v += t[0] * h[0][a][b] + t[1] * h[1][a][b];
                }
            }
            if v != 0.0 {
                k.add(da, db, w * v);
            }
        }
    }
}

/// The iteration tangent of a cohesive point (see [`Assembler`]'s `loading_tangent`), for a law
/// whose pure-mode strengths are `strength` (absolute values, positive).
pub(crate) fn loading_tangent(
    law: &dyn CohesiveLaw,
    strength: &[f64; 2],
    gap: &Gap,
    state: &LawState,
    ev: &LawEval,
) -> Tangent {
    if ev.state.damage > state.damage || ev.state.damage >= 1.0 {
        return ev.tangent; // already loading, or nothing left to damage
    }
    // Far from the surface (low traction, no damage) the secant is the tangent.
    let s = strength;
    let ratio = (ev.traction[0].max(0.0) / s[0]).powi(2) + (ev.traction[1] / s[1]).powi(2);
    if state.damage <= 0.0 && ratio < 0.8 {
        return ev.tangent;
    }
    let probe = law.evaluate(&(gap * (1.0 + LOADING_BIAS)), state);
    if probe.state.damage > state.damage && probe.tangent.iter().all(|v| v.is_finite()) {
        probe.tangent
    } else {
        ev.tangent
    }
}

/// Pure-mode strengths of `law` as positive numbers (a zero strength is replaced by a tiny one).
pub(crate) fn strengths(law: &dyn CohesiveLaw) -> [f64; 2] {
    let st = law.strength();
    [st[0].abs().max(1e-300), st[1].abs().max(1e-300)]
}

/// Secant stiffness `diag(T_n/g_n, T_t/g_t)` of a damage law (whose tractions are proportional to
/// the gap components), falling back to the tangent's diagonal at a zero gap component. Always
/// non-negative for such laws, so iterations with it cannot cycle between branches.
fn secant_tangent(gap: &Gap, ev: &LawEval) -> Tangent {
    let mut d = Tangent::zeros();
    for i in 0..2 {
        d[(i, i)] = if gap[i].abs() > 1e-14 { ev.traction[i] / gap[i] } else { ev.tangent[(i, i)].max(0.0) };
        d[(i, i)] = d[(i, i)].max(0.0);
    }
    d
}

fn scatter(k: &mut BandMatrix, dofs: &[usize; 6], ke: &[[f64; 6]; 6]) {
    // An element whose unknowns are numbered consecutively (the nodes of one layer without fixed
    // unknowns) adds whole rows.
    let d0 = dofs[0];
    if d0 != NONE && dofs.iter().enumerate().all(|(a, &d)| d == d0 + a) {
        for (a, row) in ke.iter().enumerate() {
            k.row_mut(d0 + a).add_run(d0, row);
        }
        return;
    }
    for (a, &da) in dofs.iter().enumerate() {
        if da == NONE {
            continue;
        }
        let mut row = k.row_mut(da);
        for (&db, &v) in dofs.iter().zip(&ke[a]) {
            if db != NONE && v != 0.0 {
                row.add(db, v);
            }
        }
    }
}
