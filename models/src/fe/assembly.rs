//! The discrete problem and the assembly of internal forces and tangent.
//!
//! With small rotations the beams and springs are linear: their stiffness is assembled once per
//! mesh into [`Assembler::linear`] and every Newton iteration only copies it and adds the interface
//! points (one 2×2 law tangent each, at the nodes). With large rotations the co-rotational beams are
//! re-assembled each iteration. No allocation happens per iteration: every buffer lives in the
//! [`Assembler`].

use czid_core::{CohesiveLaw, Gap, LawEval, LawState, Tangent};

use super::banded::BandMatrix;
use super::beam;
use super::corotational;
use super::interface::{self, InterfacePoint, PointKind};
use super::mesh::{Mesh, NONE};

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

/// Everything the solver needs to know about a discretised test.
#[derive(Clone, Debug)]
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
    /// Normal penalty of contact-only points (MPa/mm).
    pub contact_stiffness: f64,
}

struct Element {
    layer: usize,
    dofs: [usize; 6],
    x1: f64,
    x2: f64,
}

/// Assembly workspace for one [`FeProblem`].
pub struct Assembler {
    elements: Vec<Element>,
    /// Constant part of the tangent (small-rotation beams and springs); empty band otherwise.
    pub linear: BandMatrix,
    /// Trial law results of the last assembly, one per interface point.
    pub trial: Vec<LawEval>,
    /// Gaps of the last assembly.
    pub gaps: Vec<Gap>,
    n: usize,
    strength: [f64; 2],
    hess: Box<interface::Hessian>,
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
    /// Prepares element lists and the constant part of the tangent.
    pub fn new(p: &FeProblem, law: &dyn CohesiveLaw) -> Self {
        let mesh = &p.mesh;
        let mut elements = Vec::new();
        for (k, layer) in mesh.layers.iter().enumerate() {
            for i in layer.first..layer.last {
                let a = mesh.dofs(k, i);
                let b = mesh.dofs(k, i + 1);
                elements.push(Element {
                    layer: k,
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
            linear.add(s.i, s.i, s.k * s.ci * s.ci);
            if s.j != NONE {
                linear.add(s.j, s.j, s.k);
                linear.add(s.i, s.j, -s.k * s.ci);
                linear.add(s.j, s.i, -s.k * s.ci);
            }
        }
        let np = p.points.len();
        let zero = LawEval { traction: Default::default(), tangent: Default::default(), state: LawState::default() };
        let st = law.strength();
        let strength = [st[0].abs().max(1e-300), st[1].abs().max(1e-300)];
        Assembler {
            elements,
            linear,
            trial: vec![zero; np],
            gaps: vec![Gap::zeros(); np],
            n,
            strength,
            hess: Box::new([[[0.0; 8]; 8]; 2]),
        }
    }

    /// Internal forces `f` and tangent `k` at `q`, laws evaluated from the committed `states`.
    /// Returns `false` if a law returned a non-finite value.
    #[allow(clippy::too_many_arguments)]
    pub fn assemble(
        &mut self,
        p: &FeProblem,
        law: &dyn CohesiveLaw,
        states: &[LawState],
        q: &[f64],
        k: &mut BandMatrix,
        f: &mut [f64],
        secant: bool,
    ) -> bool {
        k.copy_from(&self.linear);
        self.linear.mul_vec(q, f);
        if p.large_rotation {
            for e in &self.elements {
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
                scatter(k, &e.dofs, &cr.tangent);
            }
        }
        let mut ok = true;
        for (ip, pt) in p.points.iter().enumerate() {
            let kin = interface::kinematics(&p.mesh, pt, q, p.large_rotation, &mut self.hess);
            let gap = Gap::new(kin.gap[0], kin.gap[1]);
            let (ev, d) = match pt.kind {
                PointKind::Cohesive => {
                    let ev = law.evaluate(&gap, &states[ip]);
                    let d = if secant {
                        secant_tangent(&gap, &ev)
                    } else {
                        self.loading_tangent(law, &gap, &states[ip], &ev)
                    };
                    (ev, d)
                }
                PointKind::Contact => {
                    let ev = interface::contact(&gap, p.contact_stiffness);
                    (ev, ev.tangent)
                }
            };
            let t = ev.traction;
            if !(t[0].is_finite() && t[1].is_finite() && d.iter().all(|v| v.is_finite())) {
                ok = false;
            }
            self.trial[ip] = ev;
            self.gaps[ip] = gap;
            let w = pt.area * pt.factor;
            // f += w Gᵀ T ; K += w (Gᵀ D G + T_n H_n + T_t H_t)
            let g = &kin.grad;
            for a in 0..8 {
                let da = kin.dofs[a];
                if da == NONE || (g[0][a] == 0.0 && g[1][a] == 0.0 && !kin.nonlinear) {
                    continue;
                }
                f[da] += w * (g[0][a] * t[0] + g[1][a] * t[1]);
                // Row a of Gᵀ D: (g0a D00 + g1a D10, g0a D01 + g1a D11)
                let ra0 = g[0][a] * d[(0, 0)] + g[1][a] * d[(1, 0)];
                let ra1 = g[0][a] * d[(0, 1)] + g[1][a] * d[(1, 1)];
                for b in 0..8 {
                    let db = kin.dofs[b];
                    if db == NONE {
                        continue;
                    }
                    let mut v = ra0 * g[0][b] + ra1 * g[1][b];
                    if kin.nonlinear {
                        v += t[0] * self.hess[0][a][b] + t[1] * self.hess[1][a][b];
                    }
                    if v != 0.0 {
                        k.add(da, db, w * v);
                    }
                }
            }
        }
        ok
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
        if ev.state.damage > state.damage || ev.state.damage >= 1.0 {
            return ev.tangent; // already loading, or nothing left to damage
        }
        // Far from the surface (low traction, no damage) the secant is the tangent.
        let s = &self.strength;
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
            let d = s.ci * q[s.i] - get(q, s.j);
            e += 0.5 * s.k * d * d;
        }
        e
    }

    /// Number of unknowns.
    pub fn n(&self) -> usize {
        self.n
    }
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
    for (a, &da) in dofs.iter().enumerate() {
        if da == NONE {
            continue;
        }
        for (b, &db) in dofs.iter().enumerate() {
            if db == NONE || ke[a][b] == 0.0 {
                continue;
            }
            k.add(da, db, ke[a][b]);
        }
    }
}
