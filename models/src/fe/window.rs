//! Windowed solution of a crack growing along one interface: only the nodes around the crack
//! front are solved for; the cracked part behind it and the intact part ahead of it are linear
//! and enter exactly through their condensed stiffness.
//!
//! **The regions.** Nodes are split into a left region `L` (the loaded end: the cracked arms, whose
//! interface points have failed and carry no traction in opening), a window `W` (the process
//! zone and its neighbourhood, solved by Newton) and a right region `R` (the intact interface,
//! whose points are still elastic: traction `K₀ g`). With small rotations the beams are linear, so
//! `L` and `R` are linear elastic substructures with no load but at their boundary with `W` (and
//! the prescribed control unknown in `L`). Every matrix of this engine couples neighbouring nodes
//! only, so eliminating a region node by node (block tridiagonal elimination) leaves a node-sized
//! stiffness on the window's end node: `q_{j+1} = T_{j+1} q_j` in `R` and
//! `q_{j−1} = T_{j−1} q_j + t_{j−1} c` in `L` (`c` the control unknown). Newton then works on the
//! window's unknowns only, and the result is the solution of the whole problem — exactly, not an
//! approximation — as long as the points of `L` and `R` are what their region assumes.
//!
//! **A control ahead of the crack.** A specimen loaded away from its cracked end (a mixed-mode
//! bending test: supports at both ends, the lever's saddle at mid-span, ahead of the front) has
//! the control unknown coupled to one node of the interface, and supports inside the regions.
//! Supports only leave their nodes with fewer unknowns. The control's column is carried by
//! whichever region holds its node: in `R` the elimination gives `q_{j+1} = T_{j+1} q_j +
//! t_{j+1} c` and the control's force from `R` as `a·q_{i1} + s c` on the window's last node, in
//! the window it is a term of the residual, and in `L` it is eliminated as the DCB's. The cracked
//! faces' contact points behind the interface belong to `L`, where open faces carry nothing;
//! that they stay open is checked like the failed points'.
//!
//! **Checks.** That is verified, not assumed: the law's response is checked to be `K₀ g` over a box
//! of gaps containing the origin (its corners, the elastic domain being convex) and zero for failed
//! material in opening; after every step the unknowns of `R` and `L` are recovered over
//! [`CHECK_DECAYS`] decay lengths `(4EI/k_f)^{1/4}` of the beam on its elastic interface from the
//! window and their gaps checked; at the end of the run every point is checked. A step whose
//! check fails is repeated with a wider window; a run whose final check fails (or that does not
//! fit the assumptions) is repeated on the whole mesh by [`super::path`]. A run
//! that gives up part way, where the path turns back (a specimen splitting), the window reaches
//! the far end or it spans three quarters of the interface (a process zone as long as the
//! specimen, where it saves little), hands its last committed state to the whole mesh, which goes
//! on from there (`Resume`) instead of starting again from rest.
//!
//! **Cost.** The right region is eliminated once per run (from the far end: the elimination up to
//! any node is a prefix of the same sweep), the left one incrementally as points fail and leave the
//! window; a Newton iteration costs law evaluations and a block tridiagonal solve over the window,
//! independent of the specimen's length.
//!
//! **Energies** of `L` and `R` follow from Clapeyron's theorem: a linear substructure loaded only
//! at its boundary stores half the work of the boundary forces on the boundary displacements (the
//! control among them, with each region's share of its force).

use std::any::Any;
use std::cell::RefCell;
use std::rc::Rc;

use czid_core::{CohesiveLaw, Gap, LawEval, LawState, Tangent, Traction};

use super::assembly::FeProblem;
use super::beam;
use super::crack::CrackMeasures;
use super::energy::path_work;
use super::interface::{self, PointKind, POINT_DOFS};
use super::mesh::NONE;
use super::newton::{CHORD_BELOW, CHORD_CONTRACTION};
use super::pool::{self, Pooled};
use super::run_types::{FrontTrack, PathSettings, Resume, RunStats, StepRow};
use super::segment::{self, End, ModeOne, Segment};

/// Largest number of unknowns per node the window handles.
const MD: usize = 8;
/// Decay lengths of the condensed regions checked after every step. The intact region ahead of
/// the window is a beam on an elastic foundation loaded at the window's end only, so its gaps
/// decay within an envelope `e^{−x/λ}` set by that end's displacement and rotation: four decay
/// lengths on they are below 2 % of it, and a point there leaving the elastic box would need the
/// window's end fifty times beyond it (that end is itself checked). Every point is checked again
/// at the end of the run. Ten decay lengths cost 6 % more instructions on the paper's DCB; the
/// records of the paper's and Hartlen's DCB populations are the same with one, four or ten.
const CHECK_DECAYS: f64 = 4.0;
/// A node leaves the window for a step when the predictor opens its point to this many times the
/// law's failure opening ([`Solver::condense_failing`])...
const CONDENSE_OPENING: f64 = 1.5;
/// ... and it lies this many nodes behind the last such node.
const CONDENSE_MARGIN: usize = 4;
// Chord steps ([`CHORD_BELOW`], the residual relative to the interface forces here): they spare
// the tangent's assembly and the block elimination; on the paper's DCB the step that takes the
// residual from about 10⁻⁸ to the tolerance is such a step, and a run factorises 222 times
// instead of 289.
/// Node blocks: every node carries `D` unknowns, nodes with fewer padded with unknowns of unit
/// stiffness coupled to nothing (they stay zero).
type Blk<const D: usize> = [[f64; D]; D];
type Vct<const D: usize> = [f64; D];

/// Why the window cannot run a problem (the caller then solves the whole mesh).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Unfit {
    /// The problem does not have the structure the window needs.
    Structure(&'static str),
    /// A step or the final check failed.
    Run(&'static str),
}

impl Unfit {
    /// What went wrong, for the run's statistics.
    pub(crate) fn reason(self) -> &'static str {
        match self {
            Unfit::Structure(r) | Unfit::Run(r) => r,
        }
    }
}

/// Unknowns of one node (global indices) other than fixed ones and the control unknown.
#[derive(Clone, Copy, Debug)]
struct NodeDofs {
    dofs: [usize; MD],
    d: usize,
}

/// A cohesive point of the interface chain, by node.
#[derive(Clone, Copy, Debug)]
struct ChainPoint<const D: usize> {
    /// Index into the problem's points.
    point: usize,
    /// Gap gradient in the node's unknowns (`[g_n, g_t]` rows).
    grad: [[f64; D]; 2],
    /// Area × energy share (nodal rule), for the point-wise work and dissipation.
    weight: f64,
}

/// The law's linear domains.
#[derive(Clone, Copy, Debug)]
struct Linear {
    /// Tangent of the virgin law inside its elastic domain.
    k0: Tangent,
    /// Gaps with `lo ≤ g ≤ hi` (per component) are elastic.
    lo: [f64; 2],
    hi: [f64; 2],
}

impl Linear {
    fn contains(&self, g: &Gap) -> bool {
        (0..2).all(|c| g[c] >= self.lo[c] && g[c] <= self.hi[c])
    }
    /// Largest fraction of the box's extent reached by `g`.
    fn usage(&self, g: &Gap) -> f64 {
        (0..2).fold(0.0f64, |m, c| m.max(if g[c] >= 0.0 { g[c] / self.hi[c] } else { g[c] / self.lo[c] }))
    }
}

fn zb<const D: usize>() -> Blk<D> {
    [[0.0; D]; D]
}

#[inline(always)]
fn blk_mul<const D: usize>(a: &Blk<D>, b: &Blk<D>) -> Blk<D> {
    let mut o = zb::<D>();
    for i in 0..D {
        for l in 0..D {
            let v = a[i][l];
            for j in 0..D {
                o[i][j] += v * b[l][j];
            }
        }
    }
    o
}

#[inline(always)]
fn blk_vec<const D: usize>(a: &Blk<D>, v: &Vct<D>) -> Vct<D> {
    let mut o = [0.0; D];
    for i in 0..D {
        let mut s = 0.0;
        for j in 0..D {
            s += a[i][j] * v[j];
        }
        o[i] = s;
    }
    o
}

/// Weights of the cubic through the abscissae `x` evaluated at `t`. The translated field is
/// smooth across the process zone (the arms' deflection is that of a beam on its cohesive
/// foundation), so a cubic places it closer than a line: on the paper's DCB the residual after two
/// Newton corrections falls from about 10⁻⁶ to 10⁻⁸ of the interface forces, and one step in five
/// converges a correction earlier.
fn cubic_weights(x: &[f64; 4], t: f64) -> [f64; 4] {
    let d = [t - x[0], t - x[1], t - x[2], t - x[3]];
    let den = |m: usize| (0..4).filter(|&l| l != m).fold(1.0, |p, l| p * (x[m] - x[l]));
    [d[1] * d[2] * d[3] / den(0), d[0] * d[2] * d[3] / den(1), d[0] * d[1] * d[3] / den(2), d[0] * d[1] * d[2] / den(3)]
}

/// LU factors of a node block with partial pivoting.
#[derive(Clone, Copy)]
struct Lu<const D: usize> {
    m: Blk<D>,
    perm: [usize; D],
}

impl<const D: usize> Lu<D> {
    fn new(a: &Blk<D>) -> Option<Lu<D>> {
        let mut m = *a;
        let mut perm = [0; D];
        for (i, p) in perm.iter_mut().enumerate() {
            *p = i;
        }
        let scale = (0..D).fold(0.0f64, |s, i| s.max(m[i][i].abs())).max(1e-300);
        for k in 0..D {
            let mut piv = k;
            for i in k + 1..D {
                if m[i][k].abs() > m[piv][k].abs() {
                    piv = i;
                }
            }
            if m[piv][k].abs() <= 1e-14 * scale || !m[piv][k].is_finite() {
                return None;
            }
            m.swap(k, piv);
            perm.swap(k, piv);
            let inv = 1.0 / m[k][k];
            for i in k + 1..D {
                let l = m[i][k] * inv;
                m[i][k] = l;
                for j in k + 1..D {
                    m[i][j] -= l * m[k][j];
                }
            }
            m[k][k] = inv;
        }
        Some(Lu { m, perm })
    }

    #[inline(always)]
    fn solve(&self, b: &Vct<D>) -> Vct<D> {
        let mut x = [0.0; D];
        for i in 0..D {
            x[i] = b[self.perm[i]];
        }
        for i in 0..D {
            for j in 0..i {
                x[i] -= self.m[i][j] * x[j];
            }
        }
        for i in (0..D).rev() {
            for j in i + 1..D {
                x[i] -= self.m[i][j] * x[j];
            }
            x[i] *= self.m[i][i];
        }
        x
    }

    /// `A⁻¹ B`.
    fn solve_blk(&self, b: &Blk<D>) -> Blk<D> {
        let mut o = zb::<D>();
        for j in 0..D {
            let mut col = [0.0; D];
            for i in 0..D {
                col[i] = b[i][j];
            }
            let x = self.solve(&col);
            for i in 0..D {
                o[i][j] = x[i];
            }
        }
        o
    }
}

/// The static structure of a problem the window can solve.
struct Layout<const D: usize> {
    /// First and last node of the interface chain.
    first: usize,
    last: usize,
    /// Chain point of each node from `first` to `last`.
    chain: Vec<ChainPoint<D>>,
    /// Segment between node `first + k` and the next.
    segs: Vec<Segment>,
    /// Diagonal blocks of the linear stiffness (beams, springs) per node (padded unknowns: 1).
    kd: Vec<Blk<D>>,
    /// Blocks coupling node j to j + 1 (row j) and j + 1 to j (row j + 1).
    ku: Vec<Blk<D>>,
    kl: Vec<Blk<D>>,
    /// The diagonal contributions of element (j, j + 1) to node j (`ed0`) and to node j + 1 (`ed1`).
    ed0: Vec<Blk<D>>,
    ed1: Vec<Blk<D>>,
    /// Coupling of each node's unknowns to the control unknown, and its own diagonal.
    kc: Vec<Vct<D>>,
    kcc: f64,
    /// The nodes the control unknown couples to where they are not behind the interface's first
    /// node (the load point of a beam on two supports, ahead of the crack), first and last: the
    /// condensed right region and the window then carry the control's column too.
    control_nodes: Option<(usize, usize)>,
    /// Contact points of the cracked faces before the interface chain (node, gap gradient): open
    /// faces carry nothing, so they belong to the left region while they stay open.
    contacts: Vec<(usize, ChainPoint<D>)>,
}

/// Each node's unknowns, each unknown's (node, position in the node), and which are fixed.
type Numbering = (Vec<NodeDofs>, Vec<(usize, usize)>, Vec<bool>);

/// Checks the problem's structure and numbers each node's unknowns (at most [`MD`]).
fn node_dofs(p: &FeProblem) -> Result<Numbering, Unfit> {
    let mesh = &p.mesh;
    if p.large_rotation {
        return Err(Unfit::Structure("large rotations (the beams are not linear)"));
    }
    if p.contact_friction != 0.0 && p.points.iter().any(|pt| pt.kind != PointKind::Cohesive) {
        return Err(Unfit::Structure("frictional contact points"));
    }
    let nn = mesh.x.len();
    let mut fixed = vec![false; mesh.n_dofs()];
    for &f in &p.fixed {
        fixed[f] = true;
    }
    let c = p.control;
    if mesh.extra > 1 || (mesh.extra == 1 && c != 0) {
        return Err(Unfit::Structure("extra unknowns other than the control"));
    }
    let mut nodes = Vec::with_capacity(nn);
    let mut owner = vec![(usize::MAX, 0usize); mesh.n_dofs()];
    for i in 0..nn {
        let mut nd = NodeDofs { dofs: [NONE; MD], d: 0 };
        for l in 0..mesh.layers.len() {
            for g in mesh.dofs(l, i) {
                if g == NONE || g == c || fixed[g] {
                    continue;
                }
                if nd.d == MD {
                    return Err(Unfit::Structure("too many unknowns per node"));
                }
                owner[g] = (i, nd.d);
                nd.dofs[nd.d] = g;
                nd.d += 1;
            }
        }
        nodes.push(nd);
    }
    // Supports anywhere leave their nodes with fewer unknowns; where the control unknown may sit
    // is checked on the stiffness ([`Layout::new`]).
    Ok((nodes, owner, fixed))
}

impl<const D: usize> Layout<D> {
    fn new(p: &FeProblem, nodes: &[NodeDofs], owner: &[(usize, usize)], fixed: &[bool]) -> Result<Self, Unfit> {
        let mesh = &p.mesh;
        let nn = mesh.x.len();
        let c = p.control;
        // One chain of segments over consecutive nodes.
        let (segs, _) = segment::segments(mesh, &p.points);
        let cohesive = p.points.iter().filter(|pt| pt.kind == PointKind::Cohesive).count();
        if segs.is_empty() || segs.len() + 1 != cohesive {
            return Err(Unfit::Structure("the cohesive points do not form one chain of segments"));
        }
        let first = p.points[segs[0].a].node;
        for (k, s) in segs.iter().enumerate() {
            if p.points[s.a].node != first + k || p.points[s.b].node != first + k + 1 {
                return Err(Unfit::Structure("segments out of node order"));
            }
            if k > 0 && segs[k - 1].b != s.a {
                return Err(Unfit::Structure("segments out of node order"));
            }
        }
        let last = first + segs.len();
        if first < 2 || last != nn - 1 {
            return Err(Unfit::Structure("the interface must run from beyond the loaded end to the far end"));
        }
        let mut hess = [[[0.0; POINT_DOFS]; POINT_DOFS]; 2];
        let zero = vec![0.0; mesh.n_dofs()];
        let mut chain_point = |pi: usize| -> Result<ChainPoint<D>, Unfit> {
            let pt = &p.points[pi];
            let kin = interface::kinematics(mesh, pt, &zero, false, &mut hess);
            let mut grad = [[0.0; D]; 2];
            for (j, &g) in kin.dofs.iter().enumerate() {
                if g == NONE || fixed[g] || g == c {
                    continue;
                }
                let (node, local) = owner[g];
                if node != pt.node {
                    return Err(Unfit::Structure("a gap depends on another node's unknowns"));
                }
                for r in 0..2 {
                    grad[r][local] = kin.grad[r][j];
                }
            }
            Ok(ChainPoint { point: pi, grad, weight: pt.area * pt.factor })
        };
        let mut chain = Vec::with_capacity(segs.len() + 1);
        for k in 0..=segs.len() {
            chain.push(chain_point(if k < segs.len() { segs[k].a } else { segs[k - 1].b })?);
        }
        let mut contacts = Vec::new();
        for (pi, pt) in p.points.iter().enumerate() {
            if pt.kind == PointKind::Contact {
                if pt.node > first {
                    return Err(Unfit::Structure("contact points ahead of the interface's first node"));
                }
                contacts.push((pt.node, chain_point(pi)?));
            }
        }
        contacts.sort_by_key(|(node, _)| *node);
        // Linear stiffness blocks: beams and springs, scattered by node. Only the rows of node
        // unknowns are kept for the control unknown's coupling (the matrix is symmetric).
        let mut lay = Layout {
            first,
            last,
            chain,
            segs,
            kd: vec![zb::<D>(); nn],
            ku: vec![zb::<D>(); nn],
            kl: vec![zb::<D>(); nn],
            ed0: vec![zb::<D>(); nn],
            ed1: vec![zb::<D>(); nn],
            kc: vec![[0.0; D]; nn],
            kcc: 0.0,
            control_nodes: None,
            contacts,
        };
        for (i, nd) in nodes.iter().enumerate() {
            for a in nd.d..D {
                lay.kd[i][a][a] = 1.0;
            }
        }
        let put = |lay: &mut Layout<D>, gr: usize, gs: usize, v: f64, element: Option<usize>| -> Result<(), Unfit> {
            if gr == NONE || gs == NONE || fixed[gr] || fixed[gs] || v == 0.0 {
                return Ok(());
            }
            if gr == c {
                if gs == c {
                    lay.kcc += v;
                }
                return Ok(());
            }
            let (nr, lr) = owner[gr];
            if gs == c {
                lay.kc[nr][lr] += v;
                return Ok(());
            }
            let (ns, ls) = owner[gs];
            if nr == ns {
                lay.kd[nr][lr][ls] += v;
                if let Some(e) = element {
                    if nr == e {
                        lay.ed0[e][lr][ls] += v;
                    } else {
                        lay.ed1[e][lr][ls] += v;
                    }
                }
            } else if ns == nr + 1 {
                lay.ku[nr][lr][ls] += v;
            } else if nr == ns + 1 {
                lay.kl[ns][lr][ls] += v;
            } else {
                return Err(Unfit::Structure("stiffness couples non-neighbouring nodes"));
            }
            Ok(())
        };
        // Elements of equal length and section share their stiffness.
        let mut cache: Vec<(usize, u64, [[f64; 6]; 6])> = Vec::new();
        for (l, layer) in mesh.layers.iter().enumerate() {
            for i in layer.first..layer.last {
                let len = mesh.x[i + 1] - mesh.x[i];
                let ke = match cache.iter().find(|e| e.0 == l && e.1 == len.to_bits()) {
                    Some(e) => e.2,
                    None => {
                        let ke = beam::stiffness(&layer.section, len);
                        if cache.len() == 8 {
                            cache.remove(0);
                        }
                        cache.push((l, len.to_bits(), ke));
                        ke
                    }
                };
                let (da, db) = (mesh.dofs(l, i), mesh.dofs(l, i + 1));
                let ed = [da[0], da[1], da[2], db[0], db[1], db[2]];
                if ed.iter().any(|&g| g != NONE && (g == c || fixed[g])) {
                    // Near the loaded end: route entries of the control and fixed unknowns.
                    for r in 0..6 {
                        for s in 0..6 {
                            put(&mut lay, ed[r], ed[s], ke[r][s], Some(i))?;
                        }
                    }
                    continue;
                }
                // Elsewhere the element's unknowns are the two nodes' own: add its blocks.
                let local: [Option<usize>; 6] = std::array::from_fn(|r| (ed[r] != NONE).then(|| owner[ed[r]].1));
                for r in 0..6 {
                    let Some(lr) = local[r] else { continue };
                    for s in 0..6 {
                        let Some(ls) = local[s] else { continue };
                        let v = ke[r][s];
                        match (r < 3, s < 3) {
                            (true, true) => {
                                lay.kd[i][lr][ls] += v;
                                lay.ed0[i][lr][ls] += v;
                            }
                            (false, false) => {
                                lay.kd[i + 1][lr][ls] += v;
                                lay.ed1[i][lr][ls] += v;
                            }
                            (true, false) => lay.ku[i][lr][ls] += v,
                            (false, true) => lay.kl[i][lr][ls] += v,
                        }
                    }
                }
            }
        }
        for sp in &p.springs {
            put(&mut lay, sp.i, sp.i, sp.k * sp.ci * sp.ci, None)?;
            if sp.j != NONE {
                put(&mut lay, sp.j, sp.j, sp.k, None)?;
                put(&mut lay, sp.i, sp.j, -sp.k * sp.ci, None)?;
                put(&mut lay, sp.j, sp.i, -sp.k * sp.ci, None)?;
            }
        }
        // The control couples to nodes behind the interface (a DCB's loaded end: the left region
        // holds them all run long), or to nodes along it (each carried by whichever region holds
        // it).
        let coupled = |j: &usize| lay.kc[*j].iter().any(|x| *x != 0.0);
        if let (Some(a), Some(b)) = ((first..nn).find(coupled), (first..nn).rev().find(coupled)) {
            lay.control_nodes = Some((a, b));
        }
        Ok(lay)
    }

    fn cp(&self, node: usize) -> &ChainPoint<D> {
        &self.chain[node - self.first]
    }

    /// Whether the contact points at `node` (if any) are open at its unknowns `q`.
    fn contacts_open(&self, node: usize, q: &Vct<D>) -> bool {
        let from = self.contacts.partition_point(|(n, _)| *n < node);
        self.contacts[from..].iter().take_while(|(n, _)| *n == node).all(|(_, cp)| gap_at(cp, q)[0] >= 0.0)
    }
}

/// The virgin law's linear domain: its tangent at half the mode I elastic limit, and a box of gaps
/// whose corners respond as `K₀ g` without damage (the elastic domain of every bundled law, and of
/// damage laws in general, is convex, so the whole box is elastic).
fn linear_domain(law: &dyn CohesiveLaw, m: &ModeOne) -> Option<Linear> {
    let init = law.initial_state();
    let k0 = law.evaluate(&Gap::new(0.5 * m.onset, 0.0), &init).tangent;
    // Mode II elastic limit by bisection on the virgin law.
    let dmg = |g: Gap| law.evaluate(&g, &init).state.damage;
    let mut hi = m.onset;
    let mut n = 0;
    while dmg(Gap::new(0.0, hi)) <= 0.0 {
        hi *= 2.0;
        n += 1;
        if n > 80 {
            return None;
        }
    }
    let mut lo = 0.0;
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        // Converged to round-off: further halvings would not move either end.
        if mid <= lo || mid >= hi {
            break;
        }
        if dmg(Gap::new(0.0, mid)) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let (gn, gt) = (0.9 * m.onset, 0.9 * lo);
    let mut lin = Linear { k0, lo: [-10.0 * m.onset, -gt], hi: [gn, gt] };
    // Shrink the shear extent until the corners are elastic (mixed-mode criteria cut the box's
    // corners off the axes' limits).
    for _ in 0..40 {
        let corners = [
            Gap::new(lin.hi[0], lin.hi[1]),
            Gap::new(lin.hi[0], lin.lo[1]),
            Gap::new(lin.lo[0], lin.hi[1]),
            Gap::new(lin.lo[0], lin.lo[1]),
        ];
        let ok = corners.iter().all(|g| {
            let e = law.evaluate(g, &init);
            let t = k0 * g;
            e.state.damage <= 0.0 && (e.traction - t).norm() <= 1e-9 * t.norm().max(1e-300) && e.tangent == k0
        });
        if ok {
            return (lin.hi[1] > 0.0).then_some(lin);
        }
        lin.hi[1] *= 0.5;
        lin.lo[1] *= 0.5;
        lin.hi[0] *= 0.9;
    }
    None
}

/// The outcome of checking the condensed regions after a step.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Verdict {
    /// Both regions hold what they assume.
    Fits,
    /// A point of the right region left the elastic box: the window must reach further.
    Right,
    /// A failed point of the left region closed (or the window's first point is not failed).
    Left,
}

/// Where a windowed run stands along its path (for [`Resume`]).
struct Cursor {
    pos: f64,
    h: f64,
    k_out: usize,
    external: f64,
    front: FrontTrack,
}

/// Per-point bookkeeping of the interface.
#[derive(Clone, Copy, Debug)]
struct PointRecord {
    state: LawState,
    /// Work per unit area done on the point so far, last traction and gap.
    work: f64,
    t: Traction,
    g: Gap,
}

impl PointRecord {
    /// Moves the point to the gap `g1` and the law's evaluation `ev` there, from the committed
    /// state `before`: the work over the step is integrated along the gap path by the law where
    /// the state changed (as [`super::energy::Ledger::commit_along`]), by the trapezoidal rule
    /// where it did not.
    fn commit(&mut self, law: &dyn CohesiveLaw, mode_one: &ModeOne, before: &LawState, g1: Gap, ev: &LawEval) {
        self.work += if ev.state != *before {
            path_work(law, before, (self.g, self.t), (g1, ev.traction), &ev.state, Some(mode_one))
        } else {
            0.5 * (self.t + ev.traction).dot(&(g1 - self.g))
        };
        self.t = ev.traction;
        self.g = g1;
        self.state = ev.state;
    }

    /// Energy per unit area the point has dissipated: the work done on it less what it stores.
    fn dissipated(&self, law: &dyn CohesiveLaw) -> f64 {
        self.work - law.stored_energy(&self.g, &self.state)
    }
}

/// Why a windowed run gave up, and the state it reached when the whole mesh can go on from it.
pub(crate) type GaveUp = (Unfit, Option<Box<Resume>>);

/// Solves `p` along `s` with the window; the rows at the output abscissae. A run that gives up
/// where the path turns back or the window reaches the far end also returns its last committed
/// state, for the whole mesh to go on from.
pub(crate) fn run(p: &FeProblem, law: &dyn CohesiveLaw, s: &PathSettings) -> Result<(Vec<StepRow>, RunStats), GaveUp> {
    run_tuned(p, law, s, CONDENSE_OPENING, CHORD_BELOW)
}

/// [`run`] with the opening (times the failure opening) beyond which a predicted point leaves the
/// window for its step, and the residual below which Newton reuses its last factorisation.
fn run_tuned(
    p: &FeProblem,
    law: &dyn CohesiveLaw,
    s: &PathSettings,
    condense_opening: f64,
    chord_below: f64,
) -> Result<(Vec<StepRow>, RunStats), GaveUp> {
    let unfit = |why: Unfit| (why, None);
    let (d, layout) = prepared(p).map_err(unfit)?;
    let mode_one =
        ModeOne::of(law).ok_or(Unfit::Structure("the law has no elastic domain in mode I")).map_err(unfit)?;
    let lin = linear_domain(law, &mode_one)
        .ok_or(Unfit::Structure("the law is not linear near the origin"))
        .map_err(unfit)?;
    macro_rules! with {
        ($d:literal) => {{
            let lay = layout
                .downcast::<Layout<$d>>()
                .map_err(|_| Unfit::Structure("layout of another node size"))
                .map_err(unfit)?;
            let mut solver = Solver::new(p, law, s, lay, lin, mode_one).map_err(unfit)?;
            solver.condense_opening = condense_opening;
            solver.chord_below = chord_below;
            solver.run().map_err(|why| (why, solver.resume.take()))
        }};
    }
    match d {
        2 => with!(2),
        3 => with!(3),
        4 => with!(4),
        6 => with!(6),
        7 => with!(7),
        _ => with!(8),
    }
}

/// How many problems' layouts a thread keeps.
const LAYOUTS_KEPT: usize = 4;

/// A problem, its node block size and its layout (a `Layout<D>` of that size).
struct Prepared {
    problem: FeProblem,
    d: usize,
    layout: Rc<dyn Any>,
}

thread_local! {
    /// Layouts of the last problems run on this thread, most recent last. A layout does not depend
    /// on the law, so the runs of an identification (one problem per experiment, thousands of
    /// laws) build it once.
    static LAYOUTS: RefCell<Vec<Prepared>> = const { RefCell::new(Vec::new()) };
}

/// The node block size and layout of `p`, from this thread's cache or built.
fn prepared(p: &FeProblem) -> Result<(usize, Rc<dyn Any>), Unfit> {
    let hit = LAYOUTS.with(|c| c.borrow().iter().rev().find(|e| e.problem == *p).map(|e| (e.d, e.layout.clone())));
    if let Some(hit) = hit {
        return Ok(hit);
    }
    let (nodes, owner, fixed) = node_dofs(p)?;
    let d = match nodes.iter().map(|n| n.d).max().unwrap_or(0) {
        0..=2 => 2,
        3 => 3,
        4 => 4,
        5 | 6 => 6,
        7 => 7,
        _ => 8,
    };
    let layout: Rc<dyn Any> = match d {
        2 => Rc::new(Layout::<2>::new(p, &nodes, &owner, &fixed)?),
        3 => Rc::new(Layout::<3>::new(p, &nodes, &owner, &fixed)?),
        4 => Rc::new(Layout::<4>::new(p, &nodes, &owner, &fixed)?),
        6 => Rc::new(Layout::<6>::new(p, &nodes, &owner, &fixed)?),
        7 => Rc::new(Layout::<7>::new(p, &nodes, &owner, &fixed)?),
        _ => Rc::new(Layout::<8>::new(p, &nodes, &owner, &fixed)?),
    };
    LAYOUTS.with(|c| {
        let mut c = c.borrow_mut();
        if c.len() == LAYOUTS_KEPT {
            c.remove(0);
        }
        c.push(Prepared { problem: p.clone(), d, layout: layout.clone() });
    });
    Ok((d, layout))
}

struct Solver<'a, const D: usize> {
    p: &'a FeProblem,
    law: &'a dyn CohesiveLaw,
    s: &'a PathSettings,
    lay: Rc<Layout<D>>,
    lin: Linear,
    mode_one: ModeOne,
    /// Elastic segment blocks (segment k between nodes first + k and first + k + 1).
    es_aa: Pooled<Blk<D>>,
    es_ab: Pooled<Blk<D>>,
    /// Right region: `q_{j} = tr[j] q_{j−1} + trc[j] c` for j > i1, and the control's force from
    /// nodes `j` on, `ra[j]·q_{j−1} + rs[j] c` (`trc`, `ra`, `rs` zero unless the control couples
    /// to nodes of the interface, [`Layout::control_nodes`]; `ra`, `rs` have a zero entry past the
    /// last node).
    tr: Pooled<Blk<D>>,
    trc: Pooled<Vct<D>>,
    ra: Pooled<Vct<D>>,
    rs: Pooled<f64>,
    /// Left region: `q_j = tl[j] q_{j+1} + tlc[j] c` for j < i0, and the eliminated state.
    tl: Pooled<Blk<D>>,
    tlc: Pooled<Vct<D>>,
    rho: Vct<D>,
    sigma: f64,
    /// Window.
    i0: usize,
    i1: usize,
    /// Unknowns per node (valid inside the window) and their values one step back.
    q: Pooled<Vct<D>>,
    q_prev: Pooled<Vct<D>>,
    c: f64,
    pts: Pooled<PointRecord>,
    /// Dissipation of the points that left the window (failed; N·mm).
    frozen: f64,
    /// Decay length of the beam on its elastic interface (mm), for the check zones.
    decay: f64,
    // Newton workspace.
    ev: Pooled<LawEval>,
    dt: Pooled<Tangent>,
    gaps: Pooled<Gap>,
    fronts: Pooled<[Option<f64>; 2]>,
    seg_stored: Pooled<f64>,
    jd: Pooled<Blk<D>>,
    ju: Pooled<Blk<D>>,
    jl: Pooled<Blk<D>>,
    res: Pooled<Vct<D>>,
    lus: Pooled<Lu<D>>,
    rhs: Pooled<Vct<D>>,
    reaction: f64,
    committed_reaction: f64,
    stats: RunStats,
    /// See [`CONDENSE_OPENING`].
    condense_opening: f64,
    /// See [`CHORD_BELOW`].
    chord_below: f64,
    /// Set when the run gives up with a state the whole mesh can go on from.
    resume: Option<Box<Resume>>,
    /// Energy dissipated up to the last commit, and by the last step that dissipated (N·mm).
    dissipated_committed: f64,
    step_dissipation: f64,
}

impl<'a, const D: usize> Solver<'a, D> {
    fn new(
        p: &'a FeProblem,
        law: &'a dyn CohesiveLaw,
        s: &'a PathSettings,
        lay: Rc<Layout<D>>,
        lin: Linear,
        mode_one: ModeOne,
    ) -> Result<Self, Unfit> {
        let nn = lay.kd.len();
        let ns = lay.segs.len();
        let (mut es_aa, mut es_ab, mut es_ba, mut es_bb) = (
            pool::take(ns, zb::<D>()),
            pool::take(ns, zb::<D>()),
            pool::take(ns, zb::<D>()),
            pool::take(ns, zb::<D>()),
        );
        for (k, sg) in lay.segs.iter().enumerate() {
            let (ga, gb) = (&lay.chain[k].grad, &lay.chain[k + 1].grad);
            let kk = lin.k0;
            let w = sg.weight;
            // f_a = w/6 (2 K g_a + K g_b), f_b = w/6 (K g_a + 2 K g_b)
            let put = |out: &mut Blk<D>, gr: &[[f64; D]; 2], gc: &[[f64; D]; 2], f: f64| {
                for r in 0..D {
                    for c in 0..D {
                        let mut v = 0.0;
                        for x in 0..2 {
                            for y in 0..2 {
                                v += gr[x][r] * kk[(x, y)] * gc[y][c];
                            }
                        }
                        out[r][c] += f * w * v;
                    }
                }
            };
            put(&mut es_aa[k], ga, ga, 1.0 / 3.0);
            put(&mut es_ab[k], ga, gb, 1.0 / 6.0);
            put(&mut es_ba[k], gb, ga, 1.0 / 6.0);
            put(&mut es_bb[k], gb, gb, 1.0 / 3.0);
        }
        // Right region, eliminated from the far end: q_j = tr[j] q_{j−1} (+ trc[j] c).
        let mut tr = pool::take(nn, zb::<D>());
        let with_control = lay.control_nodes.is_some();
        let mut trc = pool::take(if with_control { nn } else { 0 }, [0.0; D]);
        let mut ra = pool::take(if with_control { nn + 1 } else { 0 }, [0.0; D]);
        let mut rs = pool::take(if with_control { nn + 1 } else { 0 }, 0.0);
        let mut next: Option<Blk<D>> = None; // E_{j,j+1} tr[j+1]
        let mut next_c = [0.0; D]; // E_{j,j+1} trc[j+1]
        for j in (lay.first + 1..=lay.last).rev() {
            let mut dd = lay.kd[j];
            let k = j - lay.first; // segment k − 1 ends at j, segment k starts at j
            add(&mut dd, &es_bb[k - 1]);
            if k < ns {
                add(&mut dd, &es_aa[k]);
            }
            if let Some(nx) = next {
                add(&mut dd, &nx);
            }
            let lu = Lu::new(&dd).ok_or(Unfit::Structure("singular elastic region"))?;
            // E_{j,j−1} = kl[j−1] + es_ba[k−1]
            let mut ejm = lay.kl[j - 1];
            add(&mut ejm, &es_ba[k - 1]);
            let t = lu.solve_blk(&ejm);
            tr[j] = neg(&t);
            // For node j − 1: E_{j−1,j} tr[j]
            let mut e_up = lay.ku[j - 1];
            add(&mut e_up, &es_ab[k - 1]);
            next = Some(blk_mul(&e_up, &tr[j]));
            if with_control {
                // trc[j] = −M⁻¹ (k_c,j + E_{j,j+1} trc[j+1]); the control's force from nodes j on,
                // k_c,j·q_j + ra[j+1]·q_j + rs[j+1] c, with q_j substituted.
                let mut e = lay.kc[j];
                addv(&mut e, &next_c);
                let tc = lu.solve(&e);
                for a in 0..D {
                    trc[j][a] = -tc[a];
                }
                next_c = blk_vec(&e_up, &trc[j]);
                let mut f = lay.kc[j];
                addv(&mut f, &ra[j + 1]);
                let mut r = [0.0; D];
                for b in 0..D {
                    for a in 0..D {
                        r[b] += f[a] * tr[j][a][b];
                    }
                }
                ra[j] = r;
                rs[j] = rs[j + 1] + dot(&f, &trc[j]);
            }
        }
        // Decay length: the upper layer's EI against the normal interface stiffness per unit
        // length of a typical segment.
        let decay = {
            let k = ns / 2;
            let sg = &lay.segs[k];
            let up = p.points[sg.a].upper;
            let ei = p.mesh.layers[up].section.ei();
            let g = &lay.chain[k].grad[0];
            let gw = g.iter().map(|v| v * v).fold(0.0, f64::max);
            let kf = (sg.weight / sg.len) * lin.k0[(0, 0)].abs() * gw;
            if kf > 0.0 {
                (4.0 * ei / kf).powf(0.25)
            } else {
                f64::INFINITY
            }
        };
        let np = p.points.len();
        let init = law.initial_state();
        let pts = pool::take(np, PointRecord { state: init, work: 0.0, t: Traction::zeros(), g: Gap::zeros() });
        let first = lay.first;
        let mut w = Solver {
            p,
            law,
            s,
            lin,
            mode_one,
            es_aa,
            es_ab,
            tr,
            trc,
            ra,
            rs,
            tl: pool::take(nn, zb::<D>()),
            tlc: pool::take(nn, [0.0; D]),
            rho: [0.0; D],
            sigma: lay.kcc,
            i0: 0,
            i1: first,
            q: pool::take(nn, [0.0; D]),
            q_prev: pool::take(nn, [0.0; D]),
            c: 0.0,
            pts,
            frozen: 0.0,
            decay,
            ev: pool::take(np, LawEval { traction: Traction::zeros(), tangent: Tangent::zeros(), state: init }),
            dt: pool::take(np, Tangent::zeros()),
            gaps: pool::take(np, Gap::zeros()),
            fronts: pool::take(ns, [None; 2]),
            seg_stored: pool::take(ns, 0.0),
            jd: pool::take(nn, zb::<D>()),
            ju: pool::take(nn, zb::<D>()),
            jl: pool::take(nn, zb::<D>()),
            res: pool::take(nn, [0.0; D]),
            lus: pool::take(0, Lu { m: zb::<D>(), perm: [0; D] }),
            rhs: pool::take(0, [0.0; D]),
            reaction: 0.0,
            committed_reaction: 0.0,
            stats: RunStats::default(),
            condense_opening: CONDENSE_OPENING,
            chord_below: CHORD_BELOW,
            resume: None,
            dissipated_committed: 0.0,
            step_dissipation: 0.0,
            lay,
        };
        w.rho = w.lay.kc[0];
        // The arms up to the interface are always linear: eliminate them.
        w.advance_left(first)?;
        // Start with a window of a few decay lengths (grown as needed).
        let span = ((2.0 * w.decay / w.seg_len()).ceil() as usize).max(4);
        w.i1 = (first + span).min(w.lay.last);
        Ok(w)
    }

    fn seg_len(&self) -> f64 {
        self.lay.segs[0].len
    }

    /// Moves nodes `i0..new_i0` from the window to the left region.
    fn advance_left(&mut self, new_i0: usize) -> Result<(), Unfit> {
        let lay = &self.lay;
        for j in self.i0..new_i0 {
            let mut dd = lay.kd[j];
            let mut e = lay.kc[j];
            if j > 0 {
                let s = blk_mul(&lay.kl[j - 1], &self.tl[j - 1]);
                add(&mut dd, &s);
                let v = blk_vec(&lay.kl[j - 1], &self.tlc[j - 1]);
                for a in 0..D {
                    e[a] += v[a];
                }
            }
            let lu = Lu::new(&dd).ok_or(Unfit::Structure("singular cracked region"))?;
            let t = lu.solve_blk(&lay.ku[j]);
            self.tl[j] = neg(&t);
            let tc = lu.solve(&e);
            for a in 0..D {
                self.tlc[j][a] = -tc[a];
            }
            // R_c = σ c + ρ·q_j  →  with q_j = T_j q_{j+1} + t_j c
            let mut sig = self.sigma;
            for a in 0..D {
                sig += self.rho[a] * self.tlc[j][a];
            }
            let mut rho = lay.kc[j + 1];
            for b in 0..D {
                for a in 0..D {
                    rho[b] += self.rho[a] * self.tl[j][a][b];
                }
            }
            self.sigma = sig;
            self.rho = rho;
        }
        self.i0 = new_i0;
        Ok(())
    }

    /// Unknowns of the left region's node `j` (`j < i0`) from those of node `j + 1`.
    fn left_value(&self, j: usize, next: &Vct<D>) -> Vct<D> {
        let mut v = blk_vec(&self.tl[j], next);
        for a in 0..D {
            v[a] += self.tlc[j][a] * self.c;
        }
        v
    }

    /// Unknowns of the right region's node `j` (`j > i1`) from those of node `j − 1`.
    fn right_value(&self, j: usize, prev: &Vct<D>) -> Vct<D> {
        let mut v = blk_vec(&self.tr[j], prev);
        self.add_control_column(j, &mut v);
        v
    }

    /// Adds the control's part `trc[j] c` to the right region's node `j` recovered from its
    /// neighbour (nothing where the control couples to no node of the interface).
    #[inline(always)]
    fn add_control_column(&self, j: usize, v: &mut Vct<D>) {
        if let Some(tc) = self.trc.get(j) {
            for a in 0..D {
                v[a] += tc[a] * self.c;
            }
        }
    }

    /// The control's force from each region at the current unknowns: the left region's
    /// `σ c + ρ·q_{i0}` (with the control's own stiffness and its coupling to node `i0`), the
    /// window's nodes after `i0`, and the right region's `ra·q_{i1} + rs c`. Their sum is the
    /// reaction; the energies take each region's share.
    fn control_forces(&self) -> [f64; 3] {
        let (i0, i1) = (self.i0, self.i1);
        let mut left = self.sigma * self.c;
        for a in 0..D {
            left += self.rho[a] * self.q[i0][a];
        }
        let (mut window, mut right) = (0.0, 0.0);
        if let Some((a, b)) = self.lay.control_nodes {
            for j in a.max(i0 + 1)..=b.min(i1) {
                window += dot(&self.lay.kc[j], &self.q[j]);
            }
            if let (Some(ra), Some(rs)) = (self.ra.get(i1 + 1), self.rs.get(i1 + 1)) {
                right = dot(ra, &self.q[i1]) + rs * self.c;
            }
        }
        [left, window, right]
    }

    fn gap(&self, node: usize, q: &Vct<D>) -> Gap {
        gap_at(self.lay.cp(node), q)
    }

    /// Assembles the window's residual (into `res`) and Jacobian blocks at the current `q`, `c`;
    /// returns the residual's largest entry and the scale of the internal forces.
    fn assemble(&mut self, states: &[LawState], tangent: bool) -> Result<(f64, f64), ()> {
        let (i0, i1) = (self.i0, self.i1);
        let lay = &self.lay;
        self.stats.assemblies += 1;
        // Linear parts.
        for j in i0..=i1 {
            let mut a = lay.kd[j];
            // The control's column at node j: its own coupling, or the right region's through it.
            let mut ctl = None;
            if j == i1 && j < lay.last {
                let k = j - lay.first;
                add(&mut a, &self.es_aa[k]);
                let mut e_up = lay.ku[j];
                add(&mut e_up, &self.es_ab[k]);
                let s = blk_mul(&e_up, &self.tr[j + 1]);
                add(&mut a, &s);
                if let Some(tc) = self.trc.get(j + 1) {
                    ctl = Some(blk_vec(&e_up, tc));
                }
            }
            if j > i0 && lay.control_nodes.is_some_and(|(a, b)| a <= j && j <= b) {
                let mut v = ctl.unwrap_or([0.0; D]);
                addv(&mut v, &lay.kc[j]);
                ctl = Some(v);
            }
            if j == i0 {
                let s = blk_mul(&lay.kl[j - 1], &self.tl[j - 1]);
                add(&mut a, &s);
            }
            let mut r = blk_vec(&a, &self.q[j]);
            if tangent {
                self.jd[j] = a;
            }
            if j > i0 {
                let v = blk_vec(&lay.kl[j - 1], &self.q[j - 1]);
                addv(&mut r, &v);
            }
            if j < i1 {
                let v = blk_vec(&lay.ku[j], &self.q[j + 1]);
                addv(&mut r, &v);
                if tangent {
                    self.ju[j] = lay.ku[j];
                    self.jl[j] = lay.kl[j];
                }
            }
            if j == i0 {
                let v = blk_vec(&lay.kl[j - 1], &self.tlc[j - 1]);
                for a in 0..D {
                    r[a] += (v[a] + lay.kc[j][a]) * self.c;
                }
            }
            if let Some(v) = ctl {
                for a in 0..D {
                    r[a] += v[a] * self.c;
                }
            }
            self.res[j] = r;
        }
        // Interface: law at the window's points, segments between them.
        let mut ok = true;
        for j in i0..=i1 {
            let pi = lay.cp(j).point;
            let g = self.gap(j, &self.q[j]);
            let ev = self.law.evaluate(&g, &states[pi]);
            // The law's own tangent: with segments the forces are continuous at a point's elastic
            // limit, and Newton converges there with the one-sided tangent, while the nodal rule's
            // loading-branch bias would be an inconsistent Jacobian (linear convergence, or
            // divergence, for a point converging just inside its limit).
            let d = ev.tangent;
            if !(ev.traction.iter().all(|v| v.is_finite()) && d.iter().all(|v| v.is_finite())) {
                ok = false;
            }
            self.gaps[pi] = g;
            self.ev[pi] = ev;
            self.dt[pi] = d;
        }
        if !ok {
            return Err(());
        }
        for j in i0..i1 {
            let k = j - lay.first;
            let sg = &lay.segs[k];
            let end = |i: usize| End {
                gap: self.gaps[i],
                t: self.ev[i].traction,
                d: self.dt[i],
                trial: &self.ev[i].state,
                state: &states[i],
            };
            let sf = segment::integrate(sg, &end(sg.a), &end(sg.b), self.law, Some(&self.mode_one));
            self.fronts[k] = sf.fronts;
            self.seg_stored[k] = sf.stored;
            let nodes = [j, j + 1];
            for (x, &nx) in nodes.iter().enumerate() {
                let gx = &lay.cp(nx).grad;
                for a in 0..D {
                    self.res[nx][a] += gx[0][a] * sf.f[x][0] + gx[1][a] * sf.f[x][1];
                }
                if !tangent {
                    continue;
                }
                for (y, &ny) in nodes.iter().enumerate() {
                    let gy = &lay.cp(ny).grad;
                    let jac = &sf.jac[x][y];
                    let blk = match (x, y) {
                        (0, 0) | (1, 1) => &mut self.jd[nx],
                        (0, 1) => &mut self.ju[j],
                        _ => &mut self.jl[j],
                    };
                    for a in 0..D {
                        let r0 = gx[0][a] * jac[(0, 0)] + gx[1][a] * jac[(1, 0)];
                        let r1 = gx[0][a] * jac[(0, 1)] + gx[1][a] * jac[(1, 1)];
                        if r0 == 0.0 && r1 == 0.0 {
                            continue;
                        }
                        for b in 0..D {
                            blk[a][b] += r0 * gy[0][b] + r1 * gy[1][b];
                        }
                    }
                }
            }
        }
        // Reaction at the control unknown.
        let [left, window, right] = self.control_forces();
        // Only the left region's where the control couples to no node of the interface (a DCB).
        let react = if lay.control_nodes.is_some() { left + window + right } else { left };
        self.reaction = react;
        let mut rmax = 0.0f64;
        let mut fmax = react.abs();
        for j in i0..=i1 {
            for a in 0..D {
                rmax = rmax.max(self.res[j][a].abs());
            }
            // Interface forces give the scale of the internal forces in the window.
            let pi = lay.cp(j).point;
            fmax = fmax.max(self.ev[pi].traction.norm() * lay.cp(j).weight);
        }
        Ok((rmax, fmax))
    }

    /// Solves the block tridiagonal system `J Δq = −res` over the window and adds `Δq` to `q`;
    /// returns the largest correction relative to the largest unknown.
    fn correct(&mut self) -> Result<f64, ()> {
        self.stats.factorizations += 1;
        let mut lus = std::mem::take(&mut self.lus);
        let mut rhs = std::mem::take(&mut self.rhs);
        lus.clear();
        rhs.resize(self.i1 - self.i0 + 1, [0.0; D]);
        let out = self.eliminate(&mut lus, &mut rhs);
        self.lus = lus;
        self.rhs = rhs;
        out
    }

    /// A chord correction: [`Solver::correct`] with the block factors of its last call, for the
    /// residual of the current unknowns.
    fn correct_chord(&mut self) -> f64 {
        let lus = std::mem::take(&mut self.lus);
        let mut rhs = std::mem::take(&mut self.rhs);
        for j in self.i0..=self.i1 {
            rhs[j - self.i0] = self.forward_row(&lus, &rhs, j);
        }
        let out = self.substitute(&lus, &rhs);
        self.lus = lus;
        self.rhs = rhs;
        out
    }

    /// Block elimination of the window's tangent, `D_j = J_jj − J_{j,j−1} D_{j−1}⁻¹ J_{j−1,j}`
    /// (the LU factors of each `D_j` into `lus`), with the residual's forward elimination in the
    /// same pass; then [`Solver::substitute`].
    fn eliminate(&mut self, lus: &mut Vec<Lu<D>>, rhs: &mut [Vct<D>]) -> Result<f64, ()> {
        let i0 = self.i0;
        for j in i0..=self.i1 {
            let mut dd = self.jd[j];
            if j > i0 {
                let x = lus[j - 1 - i0].solve_blk(&self.ju[j - 1]);
                let s = blk_mul(&self.jl[j - 1], &x);
                sub(&mut dd, &s);
            }
            rhs[j - i0] = self.forward_row(lus, rhs, j);
            lus.push(Lu::new(&dd).ok_or(())?);
        }
        Ok(self.substitute(lus, rhs))
    }

    /// Node `j`'s row of the forward elimination of `−res`, from the rows before it. (Inlined:
    /// it runs per node of every correction; as a call it cost a run 1 % more instructions.)
    #[inline(always)]
    fn forward_row(&self, lus: &[Lu<D>], rhs: &[Vct<D>], j: usize) -> Vct<D> {
        let i0 = self.i0;
        let mut r = self.res[j];
        for a in 0..D {
            r[a] = -r[a];
        }
        if j > i0 {
            let y = lus[j - 1 - i0].solve(&rhs[j - 1 - i0]);
            let v = blk_vec(&self.jl[j - 1], &y);
            for a in 0..D {
                r[a] -= v[a];
            }
        }
        r
    }

    /// Back substitution of the eliminated system: adds `Δq` to `q` and returns the largest
    /// correction relative to the largest unknown.
    fn substitute(&mut self, lus: &[Lu<D>], rhs: &[Vct<D>]) -> f64 {
        let (i0, i1) = (self.i0, self.i1);
        let (mut dmax, mut qmax) = (0.0f64, 0.0f64);
        let mut next = [0.0; D];
        for j in (i0..=i1).rev() {
            let mut r = rhs[j - i0];
            if j < i1 {
                let v = blk_vec(&self.ju[j], &next);
                for a in 0..D {
                    r[a] -= v[a];
                }
            }
            let x = lus[j - i0].solve(&r);
            for a in 0..D {
                self.q[j][a] += x[a];
                dmax = dmax.max(x[a].abs());
                qmax = qmax.max(self.q[j][a].abs());
            }
            next = x;
        }
        dmax / qmax.max(1e-300)
    }

    /// Newton iterations at the control value `self.c` from the predictor in `q`.
    fn solve(&mut self, states: &[LawState]) -> Result<usize, ()> {
        let max_it = self.s.newton.max_iterations;
        let mut stalled = false;
        // Whether the next correction reuses the last factorisation (a chord step), and the
        // residual of the last one that did.
        let mut chord = false;
        let mut chord_from = f64::INFINITY;
        for it in 0..=max_it {
            let (rmax, fmax) = self.assemble(states, !chord)?;
            let tol = self.s.newton.tolerance * fmax.max(1e-300);
            if !rmax.is_finite() {
                return Err(());
            }
            if rmax <= tol || (stalled && rmax <= 1e4 * tol) {
                return Ok(it);
            }
            if it == max_it {
                break;
            }
            let rel = rmax / fmax.max(1e-300);
            if chord && rel > CHORD_CONTRACTION * chord_from {
                // The chord does not contract: a full Newton step from here (the tangent was not
                // assembled, so assemble again).
                chord = false;
                chord_from = f64::INFINITY;
                self.assemble(states, true)?;
            }
            stalled = if chord {
                chord_from = rel;
                self.correct_chord()
            } else {
                self.correct()?
            } <= 1e-12;
            chord = rel <= self.chord_below;
        }
        Err(())
    }

    /// After convergence: whether the regions' points are what they are assumed to be, within
    /// the check zones; also returns how far (node) the window must reach on the right for the
    /// next step, and the first node that may leave it on the left.
    fn check(&self) -> (Verdict, usize, usize) {
        let lay = &self.lay;
        let (i0, i1) = (self.i0, self.i1);
        let zone = (CHECK_DECAYS * self.decay).max(20.0 * self.seg_len());
        let xs = &self.p.mesh.x;
        // Right: recover outwards.
        let mut ok = Verdict::Fits;
        let mut need = i1;
        let mut prev = self.q[i1];
        // The window's own points near its right end count too.
        for j in i0..=i1 {
            let pi = lay.cp(j).point;
            if self.ev[pi].state.damage > 0.0 || self.lin.usage(&self.gaps[pi]) > 0.25 {
                need = j;
            }
        }
        let pi1 = lay.cp(i1).point;
        if self.ev[pi1].state.damage > 0.0 || !self.lin.contains(&self.gaps[pi1]) {
            ok = Verdict::Right;
        }
        // The zone's nodes (in order along the interface), walked over slices of equal length: no
        // index checks in the loop.
        let end = i1 + 1 + xs[i1 + 1..=lay.last].partition_point(|&x| x - xs[i1] <= zone);
        let (tr, chain) = (&self.tr[i1 + 1..end], &lay.chain[i1 + 1 - lay.first..end - lay.first]);
        for (j, (t, cp)) in (i1 + 1..end).zip(tr.iter().zip(chain)) {
            let mut v = blk_vec(t, &prev);
            self.add_control_column(j, &mut v);
            let g = gap_at(cp, &v);
            if !self.lin.contains(&g) {
                ok = Verdict::Right;
            }
            if self.lin.usage(&g) > 0.25 {
                need = j;
            }
            prev = v;
        }
        // Left: recover inwards from the window; failed points must stay open.
        let mut next = self.q[i0];
        let mut j = i0;
        if !lay.contacts_open(i0, &next) {
            ok = Verdict::Left;
        }
        // Behind the interface's first node only the contact points of the cracked faces.
        let bottom = if lay.contacts.is_empty() { lay.first } else { 0 };
        while j > bottom && xs[i0] - xs[j - 1] <= zone {
            j -= 1;
            let v = self.left_value(j, &next);
            if j >= lay.first && self.gap(j, &v)[0] < 0.0 || !lay.contacts_open(j, &v) {
                ok = Verdict::Left;
            }
            next = v;
        }
        let pi0 = lay.cp(i0).point;
        if i0 > lay.first && (self.ev[pi0].state.damage < 1.0 || self.gaps[pi0][0] < 0.0) {
            ok = Verdict::Left;
        }
        // Nodes that can leave: failed, open, with their right neighbour failed too, a few
        // segments behind the failure front.
        let mut leave = i0;
        for j in i0..i1 {
            let (pa, pb) = (lay.cp(j).point, lay.cp(j + 1).point);
            if self.ev[pa].state.damage >= 1.0 && self.ev[pb].state.damage >= 1.0 && self.gaps[pa][0] > 0.0 {
                leave = j;
            } else {
                break;
            }
        }
        let leave = leave.saturating_sub(2).max(i0);
        (ok, need, leave)
    }

    /// Total energy of the beams, springs and interface (N·mm), by Clapeyron for the condensed
    /// regions.
    fn elastic_energy(&self) -> f64 {
        let lay = &self.lay;
        let (i0, i1) = (self.i0, self.i1);
        let mut e = 0.0;
        let control = self.control_forces();
        // Left: ½ (P_L c + f·q_{i0}) with f the force of element (i0 − 1, i0) on node i0 and P_L
        // the control's force from the left region (the whole reaction unless the control couples
        // to a node of the interface).
        {
            let qp = self.left_value(i0 - 1, &self.q[i0]);
            let mut f = blk_vec(&lay.kl[i0 - 1], &qp);
            addv(&mut f, &blk_vec(&lay.ed1[i0 - 1], &self.q[i0]));
            let kc = &lay.kc[i0];
            for a in 0..D {
                f[a] += kc[a] * self.c;
            }
            e += 0.5 * (control[0] * self.c + dot(&f, &self.q[i0]));
        }
        if lay.control_nodes.is_some() {
            // The control's coupling to nodes of the window, and the right region's share.
            e += self.c * control[1] + 0.5 * control[2] * self.c;
        }
        // Right: ½ f·q_{i1}, f the force of element (i1, i1 + 1) and its elastic segment on node i1.
        if i1 < lay.last {
            let k = i1 - lay.first;
            let qn = self.right_value(i1 + 1, &self.q[i1]);
            let mut diag = lay.ed0[i1];
            add(&mut diag, &self.es_aa[k]);
            let mut up = lay.ku[i1];
            add(&mut up, &self.es_ab[k]);
            let mut f = blk_vec(&diag, &self.q[i1]);
            addv(&mut f, &blk_vec(&up, &qn));
            e += 0.5 * dot(&f, &self.q[i1]);
        }
        // Window: elements and springs inside it, and its segments.
        for j in i0..=i1 {
            // Node j's own diagonal minus the parts of the elements leaving the window.
            let mut diag = lay.kd[j];
            if j == i0 {
                sub(&mut diag, &lay.ed1[j - 1]);
            }
            if j == i1 && j < lay.last {
                sub(&mut diag, &lay.ed0[j]);
            }
            e += 0.5 * dot(&blk_vec(&diag, &self.q[j]), &self.q[j]);
            if j < i1 {
                e += dot(&blk_vec(&lay.ku[j], &self.q[j + 1]), &self.q[j]);
            }
        }
        e + self.seg_stored[i0 - lay.first..i1 - lay.first].iter().sum::<f64>()
    }

    fn crack(&self) -> CrackMeasures {
        let lay = &self.lay;
        let (i0, i1) = (self.i0, self.i1);
        let (k0, k1) = (i0 - lay.first, i1 - lay.first);
        let point = |i: usize| (self.pts[i].g, &self.pts[i].state);
        let (segs, fronts) = (&lay.segs[k0..k1], &self.fronts[k0..k1]);
        let mut m = super::crack::from_segments(segs, fronts, self.law, point, self.s.crack_origin, self.s.debonded());
        // The left region has failed all along.
        let failed_left = self.p.mesh.x[i0] - self.p.mesh.x[lay.first];
        if failed_left > 0.0 {
            m.debonded += failed_left;
            m.tip = m.tip.max(self.p.mesh.x[i0]);
        }
        m
    }

    fn reaction_committed(&self) -> f64 {
        self.committed_reaction
    }

    /// Adds node `i1 + 1` to the window (its unknowns recovered from the right region; its point
    /// is elastic, so the work done on it is its stored energy).
    fn grow_right(&mut self) {
        let j = self.i1 + 1;
        let v = self.right_value(j, &self.q[self.i1]);
        self.q[j] = v;
        self.q_prev[j] = v;
        let g = self.gap(j, &v);
        let pi = self.lay.cp(j).point;
        let ev = self.law.evaluate(&g, &self.pts[pi].state);
        let r = &mut self.pts[pi];
        r.work = 0.5 * ev.traction.dot(&g);
        r.t = ev.traction;
        r.g = g;
        self.i1 = j;
    }

    /// Moves the window's nodes before `new_i0` (failed, open) to the left region, freezing the
    /// energy their points dissipated.
    fn shrink_left(&mut self, new_i0: usize) -> Result<(), Unfit> {
        for j in self.i0..new_i0 {
            let cp = self.lay.cp(j);
            self.frozen += cp.weight * self.pts[cp.point].dissipated(self.law);
        }
        self.advance_left(new_i0)
    }

    /// Commits the window's points: states, and the work done on them over the step (integrated
    /// along each point's gap path by the law, as [`super::energy::Ledger::commit_along`]).
    fn commit_points(&mut self, before: &[LawState]) {
        for j in self.i0..=self.i1 {
            let pi = self.lay.cp(j).point;
            self.pts[pi].commit(self.law, &self.mode_one, &before[pi], self.gaps[pi], &self.ev[pi]);
        }
    }

    /// Energy the interface has dissipated (N·mm): the points that left the window, and the
    /// window's.
    fn dissipated(&self) -> f64 {
        let mut dissipated = self.frozen;
        for j in self.i0..=self.i1 {
            let cp = self.lay.cp(j);
            dissipated += cp.weight * self.pts[cp.point].dissipated(self.law);
        }
        dissipated
    }

    /// The committed state's row, with `dissipated` from [`Solver::dissipated`].
    fn row(&self, external: f64, dissipated: f64) -> StepRow {
        StepRow {
            control: self.c,
            reaction: self.reaction,
            external_work: external,
            elastic_energy: self.elastic_energy(),
            dissipated_energy: dissipated,
            crack: self.crack(),
            shear_work: None,
        }
    }

    /// Translates the window's unknowns within `zone` of the front at `x` by `da` (see
    /// [`super::path`]'s shift predictor; here interpolated by cubics, [`cubic_weights`]), from
    /// the committed values `from` at control `c_from` (behind the window they are recovered from
    /// the left region).
    fn shift(&mut self, from: &[Vct<D>], c_from: f64, x: f64, da: f64, zone: f64) {
        let xs = &self.p.mesh.x;
        let (i0, i1) = (self.i0, self.i1);
        // Sources behind the window: recovered down to the farthest one needed.
        let lowest = xs[i0..=i1].partition_point(|v| *v < x - zone) + i0;
        let need = xs.partition_point(|v| *v < xs[lowest] - da.abs()).saturating_sub(1).max(self.lay.first);
        let mut behind = vec![[0.0; D]; i0 - need.min(i0)];
        let mut next = from[i0];
        for j in (need..i0).rev() {
            let mut v = blk_vec(&self.tl[j], &next);
            for a in 0..D {
                v[a] += self.tlc[j][a] * c_from;
            }
            behind[j - need] = v;
            next = v;
        }
        let value = |j: usize| if j >= i0 { from[j] } else { behind[j - need] };
        // The targets move right with `i`, so the interval holding each is found by walking on.
        let mut j = need;
        for i in i0..=i1 {
            if (xs[i] - x).abs() > zone {
                continue;
            }
            let xt = xs[i] - da;
            if xt < xs[need] || xt > xs[i1] {
                continue;
            }
            while j + 1 < i1 && xs[j + 1] <= xt {
                j += 1;
            }
            // A cubic through the four nearest nodes where there are four, else a line.
            if j > need && j + 2 <= i1 {
                let w = cubic_weights(&[xs[j - 1], xs[j], xs[j + 1], xs[j + 2]], xt);
                let v = [value(j - 1), value(j), value(j + 1), value(j + 2)];
                for a in 0..D {
                    self.q[i][a] = w[0] * v[0][a] + w[1] * v[1][a] + w[2] * v[2][a] + w[3] * v[3][a];
                }
            } else {
                let t = ((xt - xs[j]) / (xs[j + 1] - xs[j])).clamp(0.0, 1.0);
                let (va, vb) = (value(j), value(j + 1));
                for a in 0..D {
                    self.q[i][a] = (1.0 - t) * va[a] + t * vb[a];
                }
            }
        }
    }

    /// Moves the window's leading nodes whose predicted opening is well beyond the law's failure
    /// opening ([`CONDENSE_OPENING`] times it, and [`CONDENSE_MARGIN`] nodes behind the last such
    /// node) to the left region for this step: they fail during it, and Newton then works on the
    /// process zone and the intact part only. Whether they did fail is checked after
    /// convergence ([`Solver::settle_condensed`]); if not, the step is repeated without this.
    fn condense_failing(&mut self) -> Result<(), Unfit> {
        let Some(fail) = self.mode_one.failure else { return Ok(()) };
        let (i0, i1) = (self.i0, self.i1);
        let mut k = i0;
        while k < i1 && self.gap(k, &self.q[k])[0] > self.condense_opening * fail {
            k += 1;
        }
        let new_i0 = k.saturating_sub(CONDENSE_MARGIN);
        if new_i0 > i0 + 1 && new_i0 + 2 * CONDENSE_MARGIN < i1 {
            self.advance_left(new_i0)?;
        }
        Ok(())
    }

    /// Undoes [`Solver::condense_failing`]: the left region as it was (its transfer blocks beyond
    /// the restored end are recomputed when it advances again).
    fn restore_left(&mut self, (i0, sigma, rho): (usize, f64, Vct<D>)) {
        self.i0 = i0;
        self.sigma = sigma;
        self.rho = rho;
    }

    /// After a converged step whose nodes `from..i0` left the window: their unknowns recovered
    /// from the left region, their points evaluated from the committed `states`; if every one has
    /// failed, open, their points are committed (state, work along the gap path, the dissipation
    /// frozen as [`Solver::shrink_left`] does) and `true` returned; else nothing changes.
    fn settle_condensed(&mut self, from: usize, states: &[LawState]) -> bool {
        let mut settled = Vec::with_capacity(self.i0 - from);
        let mut next = self.q[self.i0];
        for j in (from..self.i0).rev() {
            let v = self.left_value(j, &next);
            next = v;
            let g = self.gap(j, &v);
            let pi = self.lay.cp(j).point;
            let ev = self.law.evaluate(&g, &states[pi]);
            if g[0] <= 0.0 || ev.state.damage < 1.0 {
                return false;
            }
            settled.push((j, g, ev));
        }
        for (j, g1, ev) in settled {
            let cp = self.lay.cp(j);
            let r = &mut self.pts[cp.point];
            r.commit(self.law, &self.mode_one, &states[cp.point], g1, &ev);
            self.frozen += cp.weight * r.dissipated(self.law);
        }
        true
    }

    /// The last committed state as the whole mesh numbers it ([`Resume`]): every unknown, the
    /// condensed regions' recovered from the window's ends; every point's state (the right
    /// region's points at their recovered gaps, elastic); the energies and the path's position.
    /// `None` if the problem cannot be numbered again (it always can: it was at the start).
    fn resume_state(
        &self,
        reason: &'static str,
        snap_back: bool,
        rows: Vec<StepRow>,
        at: Cursor,
        states: &[LawState],
    ) -> Option<Box<Resume>> {
        let (nodes, _, _) = node_dofs(self.p).ok()?;
        let lay = &self.lay;
        let mut q = vec![0.0; self.p.mesh.n_dofs()];
        q[self.p.control] = self.c;
        let mut put = |j: usize, v: &Vct<D>| {
            let nd = &nodes[j];
            for (a, &g) in nd.dofs[..nd.d].iter().enumerate() {
                q[g] = v[a];
            }
        };
        let mut states = states.to_vec();
        for j in self.i0..=self.i1 {
            put(j, &self.q[j]);
        }
        self.walk_condensed(0, |j, v| {
            put(j, v);
            if j > self.i1 {
                let pi = lay.cp(j).point;
                states[pi] = self.law.evaluate(&self.gap(j, v), &states[pi]).state;
            }
            true
        });
        let dissipated = self.dissipated();
        Some(Box::new(Resume {
            reason,
            snap_back,
            q,
            states,
            reaction: self.committed_reaction,
            external_work: at.external,
            dissipated,
            dissipation_hint: self.step_dissipation,
            rows,
            stats: self.stats,
            pos: at.pos,
            h: at.h,
            k_out: at.k_out,
            front: at.front,
        }))
    }

    /// Recovers the condensed regions' unknowns from the window's ends and visits each node with
    /// them: the right region's from the window outwards, then the left region's down to node
    /// `left_to`; stops at the first visit that returns `false` (and returns `false`).
    fn walk_condensed(&self, left_to: usize, mut visit: impl FnMut(usize, &Vct<D>) -> bool) -> bool {
        let mut prev = self.q[self.i1];
        for j in self.i1 + 1..=self.lay.last {
            let v = self.right_value(j, &prev);
            if !visit(j, &v) {
                return false;
            }
            prev = v;
        }
        let mut next = self.q[self.i0];
        for j in (left_to..self.i0).rev() {
            let v = self.left_value(j, &next);
            if !visit(j, &v) {
                return false;
            }
            next = v;
        }
        true
    }

    /// Every point of both regions, recovered from the window: elastic on the right, failed and
    /// open on the left.
    fn final_check(&self) -> bool {
        let lay = &self.lay;
        let left_to = if lay.contacts.is_empty() { lay.first } else { 0 };
        lay.contacts_open(self.i0, &self.q[self.i0])
            && self.walk_condensed(left_to, |j, v| {
                if j > self.i1 {
                    self.lin.contains(&self.gap(j, v))
                } else {
                    lay.contacts_open(j, v)
                        && (j < lay.first || self.gap(j, v)[0] >= 0.0 && self.pts[lay.cp(j).point].state.damage >= 1.0)
                }
            })
    }

    fn run(&mut self) -> Result<(Vec<StepRow>, RunStats), Unfit> {
        let s = self.s;
        let target = s.target.abs();
        let dir = s.target.signum();
        if !(s.target.is_finite() && s.target != 0.0 && s.outputs > 0) {
            return Err(Unfit::Run("invalid path settings"));
        }
        let spacing = target / s.outputs as f64;
        let eps = 1e-12 * spacing;
        let h_min = spacing * s.min_step_fraction;
        let mut rows =
            vec![StepRow { crack: CrackMeasures { tip: s.crack_origin, ..Default::default() }, ..Default::default() }];
        let mut pos = 0.0f64;
        let mut h = spacing;
        let mut h_prev = 0.0f64;
        let mut k_out = 1usize;
        let mut external = 0.0f64;
        let mut front = FrontTrack::default();
        let mut states = pool::take(self.pts.len(), LawState::default());
        for (st, r) in states.iter_mut().zip(self.pts.iter()) {
            *st = r.state;
        }
        let mut saved_q = pool::take(self.q.len(), [0.0; D]);
        // Last node with sizeable gaps at the last commit.
        let mut need_node = self.i1;
        // Whether this step may leave the points predicted failed out of the window.
        let mut condense = true;
        let max_steps = 200 * s.outputs + 20_000;
        while pos < target - eps {
            if self.stats.steps > max_steps {
                return Err(Unfit::Run("too many steps"));
            }
            if 4 * (self.i1 + 1 - self.i0) > 3 * (self.lay.last + 1 - self.lay.first) {
                // A process zone as long as the specimen (a weak shear branch in a mixed-mode
                // test): the window saves little and its Newton lacks the whole mesh's safeguards,
                // so the whole mesh goes on from here, under the same control.
                let why = "the window spans most of the interface";
                let at = Cursor { pos, h, k_out, external, front };
                self.resume = self.resume_state(why, false, std::mem::take(&mut rows), at, &states);
                return Err(Unfit::Run(why));
            }
            while k_out < s.outputs && spacing * k_out as f64 <= pos + eps {
                k_out += 1;
            }
            let next = if k_out >= s.outputs { target } else { spacing * k_out as f64 };
            let dh = h.min(next - pos);
            // Widen the window ahead of the front's predicted advance.
            let da = front.advance(dir * dh);
            if let Some(da) = da {
                // The region with sizeable gaps moves with the front.
                let reach = self.p.mesh.x[need_node] + da.abs() + 4.0 * self.seg_len();
                while self.i1 < self.lay.last && self.p.mesh.x[self.i1] < reach {
                    self.grow_right();
                }
            }
            // Predictor: extrapolate the last increment, and translate the front region.
            let (i0, i1) = (self.i0, self.i1);
            saved_q[i0..=i1].copy_from_slice(&self.q[i0..=i1]);
            let alpha = if h_prev > 0.0 { dh / h_prev } else { 0.0 };
            for j in i0..=i1 {
                for a in 0..D {
                    self.q[j][a] += alpha * (saved_q[j][a] - self.q_prev[j][a]);
                }
            }
            if let Some(da) = da {
                self.shift(&saved_q, self.c, front.x, da, front.zone());
            }
            let c_old = self.c;
            self.c = dir * (pos + dh);
            let left_before = (self.i0, self.sigma, self.rho);
            if condense && da.is_some() {
                self.condense_failing()?;
            }
            let outcome = self.solve(&states);
            let mut verdict = outcome.map(|it| (it, self.check()));
            if let Ok((it, (Verdict::Fits, need, leave))) = verdict {
                // The points that left the window for this step must have failed, open.
                if self.i0 > i0 && !self.settle_condensed(i0, &states) {
                    verdict = Ok((it, (Verdict::Left, need, leave)));
                }
            }
            match verdict {
                Ok((it, (Verdict::Fits, need, leave))) => {
                    // Commit.
                    condense = true;
                    let r_old = self.reaction_committed();
                    self.q_prev[i0..=i1].copy_from_slice(&saved_q[i0..=i1]);
                    external += 0.5 * (r_old + self.reaction) * (self.c - c_old);
                    self.commit_points(&states);
                    for j in i0..=i1 {
                        states[self.lay.cp(j).point] = self.pts[self.lay.cp(j).point].state;
                    }
                    self.committed_reaction = self.reaction;
                    // The energy the step dissipated: where the window gives up, the whole mesh's
                    // dissipation constraint starts from it (as it would from its own last step).
                    let dissipated = self.dissipated();
                    if dissipated > self.dissipated_committed {
                        self.step_dissipation = dissipated - self.dissipated_committed;
                    }
                    self.dissipated_committed = dissipated;
                    self.stats.steps += 1;
                    let lands = (next - (pos + dh)).abs() <= eps;
                    pos = if lands { next } else { pos + dh };
                    h_prev = dh;
                    if it <= 5 {
                        h = (2.0 * h).min(spacing);
                    } else if it >= 9 {
                        h *= 0.5;
                    }
                    let k0 = self.i0 - self.lay.first;
                    front.commit(
                        self.c,
                        &self.lay.segs[k0..i1 - self.lay.first],
                        &self.fronts[k0..i1 - self.lay.first],
                    );
                    if lands {
                        rows.push(self.row(external, dissipated));
                    }
                    // Window for the next step.
                    need_node = need;
                    let want = (need + 4).min(self.lay.last);
                    while self.i1 < want {
                        self.grow_right();
                    }
                    if leave > self.i0 && leave + 4 < self.i1 {
                        self.shrink_left(leave)?;
                    }
                }
                Ok((_, (Verdict::Left, _, _))) if self.i0 > i0 => {
                    // A point that left the window for this step did not fail: repeat the step
                    // with the whole window.
                    self.restore_left(left_before);
                    self.c = c_old;
                    self.q[i0..=i1].copy_from_slice(&saved_q[i0..=i1]);
                    condense = false;
                    self.stats.cuts += 1;
                }
                Ok((_, (Verdict::Left, _, _))) => {
                    return Err(Unfit::Run("a failed point behind the window closed"));
                }
                Ok((_, (Verdict::Right, need, _))) => {
                    // A point ahead of the window left the elastic box: widen the window and
                    // repeat the step.
                    self.restore_left(left_before);
                    self.c = c_old;
                    self.q[i0..=i1].copy_from_slice(&saved_q[i0..=i1]);
                    if self.i1 == self.lay.last && need >= self.i1 {
                        let why = "the window reached the far end";
                        let at = Cursor { pos, h: dh, k_out, external, front };
                        self.resume = self.resume_state(why, false, std::mem::take(&mut rows), at, &states);
                        return Err(Unfit::Run(why));
                    }
                    let want = (need.max(self.i1) + 8).min(self.lay.last);
                    while self.i1 < want {
                        self.grow_right();
                    }
                    self.stats.cuts += 1;
                    if self.stats.cuts > 50 * s.outputs + 1000 {
                        return Err(Unfit::Run("too many repeated steps"));
                    }
                }
                Err(()) => {
                    self.restore_left(left_before);
                    self.c = c_old;
                    self.q[i0..=i1].copy_from_slice(&saved_q[i0..=i1]);
                    self.stats.cuts += 1;
                    h = 0.5 * dh;
                    if h < h_min {
                        let why = "no convergence even with the smallest step";
                        let at = Cursor { pos, h: spacing, k_out, external, front };
                        self.resume = self.resume_state(why, true, std::mem::take(&mut rows), at, &states);
                        return Err(Unfit::Run(why));
                    }
                }
            }
        }
        if !self.final_check() {
            return Err(Unfit::Run("a point outside the window left its linear domain"));
        }
        Ok((rows, self.stats))
    }
}

/// The gap at a chain point from its node's unknowns.
fn gap_at<const D: usize>(cp: &ChainPoint<D>, q: &Vct<D>) -> Gap {
    let mut g = Gap::zeros();
    for r in 0..2 {
        for a in 0..D {
            g[r] += cp.grad[r][a] * q[a];
        }
    }
    g
}

fn add<const D: usize>(a: &mut Blk<D>, b: &Blk<D>) {
    for i in 0..D {
        for j in 0..D {
            a[i][j] += b[i][j];
        }
    }
}

fn sub<const D: usize>(a: &mut Blk<D>, b: &Blk<D>) {
    for i in 0..D {
        for j in 0..D {
            a[i][j] -= b[i][j];
        }
    }
}

fn neg<const D: usize>(a: &Blk<D>) -> Blk<D> {
    let mut o = *a;
    for row in o.iter_mut() {
        for v in row.iter_mut() {
            *v = -*v;
        }
    }
    o
}

fn addv<const D: usize>(a: &mut Vct<D>, b: &Vct<D>) {
    for i in 0..D {
        a[i] += b[i];
    }
}

fn dot<const D: usize>(a: &Vct<D>, b: &Vct<D>) -> f64 {
    (0..D).map(|i| a[i] * b[i]).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dcb::Dcb;
    use crate::laws::StCzm;

    #[test]
    fn points_that_leave_the_window_for_a_step_and_do_not_fail_repeat_it_with_the_whole_window() {
        // Condensing points predicted at a tenth of the failure opening takes out points that do
        // not fail in the step: each such step is repeated with the whole window, and the records
        // are those of the default run (a node the window leaves out for a step is the one it
        // would have solved, failed and open) and of a run that never condenses.
        let law = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
        let mut d = Dcb::paper();
        d.control.max_displacement = Some(6.0);
        let (p, _) = d.problem().unwrap();
        let path = PathSettings::new(3.0, 30, d.a0);
        let (default, s_default) = run_tuned(&p, &law, &path, CONDENSE_OPENING, CHORD_BELOW).unwrap();
        let (eager, s_eager) = run_tuned(&p, &law, &path, 0.1, CHORD_BELOW).unwrap();
        let (never, s_never) = run_tuned(&p, &law, &path, f64::INFINITY, CHORD_BELOW).unwrap();
        println!("default {s_default:?}\neager   {s_eager:?}\nnever   {s_never:?}");
        assert!(s_eager.cuts > s_default.cuts, "the eager condensation had to repeat steps");
        assert!(default.last().unwrap().crack.debonded > 5.0, "the crack ran");
        for other in [&eager, &never] {
            assert_eq!(other.len(), default.len());
            for (a, b) in default.iter().zip(other) {
                let w = a.external_work.abs().max(1e-9);
                assert!((a.reaction - b.reaction).abs() <= 1e-9 * a.reaction.abs().max(1e-9), "{a:?}\n{b:?}");
                assert!((a.dissipated_energy - b.dissipated_energy).abs() <= 1e-9 * w, "{a:?}\n{b:?}");
                assert!((a.elastic_energy - b.elastic_energy).abs() <= 1e-9 * w, "{a:?}\n{b:?}");
                assert!((a.crack.debonded - b.crack.debonded).abs() <= 1e-7, "{a:?}\n{b:?}");
            }
        }
    }

    #[test]
    fn chord_corrections_reach_the_states_of_full_newton_steps() {
        // Once the residual is small, Newton reuses its last factorisation: the states are
        // Newton's to its tolerance either way, and fewer factorisations are needed.
        let paper: Box<dyn CohesiveLaw> =
            Box::new(StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap());
        let hartlen: Box<dyn CohesiveLaw> =
            Box::new(crate::laws::Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap());
        for (d, law, end) in [(Dcb::paper(), paper, 6.0), (Dcb::hartlen_dcb01(), hartlen, 20.0)] {
            let (p, _) = d.problem().unwrap();
            let path = PathSettings::new(end, 50, d.a0);
            let (chord, s_chord) = run_tuned(&p, law.as_ref(), &path, CONDENSE_OPENING, CHORD_BELOW).unwrap();
            let (full, s_full) = run_tuned(&p, law.as_ref(), &path, CONDENSE_OPENING, 0.0).unwrap();
            println!("chord {s_chord:?}\nfull  {s_full:?}");
            assert!(s_chord.factorizations < s_full.factorizations, "the chord steps saved factorisations");
            assert!(full.last().unwrap().crack.debonded > 5.0, "the crack ran");
            assert_eq!(chord.len(), full.len());
            let peak = full.iter().fold(0.0f64, |m, r| m.max(r.reaction.abs()));
            for (a, b) in full.iter().zip(&chord) {
                let w = a.external_work.abs().max(1e-9);
                assert!((a.reaction - b.reaction).abs() <= 1e-9 * peak, "{a:?}\n{b:?}");
                assert!((a.dissipated_energy - b.dissipated_energy).abs() <= 1e-9 * w, "{a:?}\n{b:?}");
                assert!((a.elastic_energy - b.elastic_energy).abs() <= 1e-9 * w, "{a:?}\n{b:?}");
                assert!((a.crack.debonded - b.crack.debonded).abs() <= 1e-7, "{a:?}\n{b:?}");
            }
        }
    }
}
