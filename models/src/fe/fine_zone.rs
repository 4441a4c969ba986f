//! Under large rotations: a beam mesh that is fine only around the crack front, coarse in the free
//! arm behind it and in the intact part ahead, moving with the front.
//!
//! **Why.** Co-rotational arms are not linear, so a large-rotation run is solved on the whole mesh
//! (the small-rotation window condenses linear regions, which these are not). The model meshes
//! the whole bonded length finely, four beam elements per interface element, because the process
//! zone needs it wherever it will be (`mesh.interface_subdivision`). Everywhere else that is
//! waste, and every Newton iteration assembles and factorises it:
//!
//! * behind the front the interface has failed and is open, so it carries nothing, and the arm is
//!   an elastica loaded at its end whose curvature varies smoothly along it, as along the
//!   pre-crack arm;
//! * ahead of it the arm lies on its intact, elastic interface, and its deflection decays over
//!   `λ = (4 EI / (K₀ b))^{1/4}`, which elements of `λ / 2` follow.
//!
//! **What.** The run's problem keeps a subset of the model's nodes (the *base* mesh): every node in
//! the fine zone, from [`FREE_ARM_MARGIN`] coarse elements behind the first interface point that
//! still carries a traction or a stiffness to [`AHEAD_DECAY_LENGTHS`] `λ` ahead of the onset front;
//! behind it every node that starts an element as long as the base mesh's longest (a DCB's
//! pre-crack arm's); ahead of it every node that starts an element of about `λ / 2`. Coarse nodes
//! sit at fixed multiples from the first interior node, so the zone's moves only remove nodes
//! behind and add nodes ahead.
//!
//! * **Behind**, at a committed step, the nodes whose points are spent (damage 1, no traction, no
//!   stiffness, open) are removed with their points. The points carry nothing and would add no
//!   work, so the energy ledger's totals keep what was done on them; the debonded length still
//!   counts the stretch (its longer segments have failed at both ends).
//! * **Ahead**, the zone reaches [`AHEAD_BATCH_DECAY_LENGTHS`] `λ` further once the onset front
//!   comes within [`AHEAD_DECAY_LENGTHS`] `λ` of its end. The inserted nodes take the displacements
//!   of the coarse element they split (cubic in the deflection, with the rotations as slopes;
//!   linear axially), and their points the law's state at their gap from the virgin state (they
//!   have been loaded monotonically and elastically there); the next step's Newton iterations
//!   bring them to equilibrium.
//!
//! The kept points' areas follow their tributary lengths. The result differs from the fine mesh's
//! by how well the longer elements represent the arm where nothing happens.

use czid_core::{CohesiveLaw, Gap, LawEval, LawState};

use super::assembly::FeProblem;
use super::interface::{InterfacePoint, PointKind};
use super::mesh::{Layer, Mesh, NONE};

/// Coarse elements kept fine between the free arm's coarse part and the first point that still
/// carries something (the free arm's curvature is largest next to the front).
pub const FREE_ARM_MARGIN: f64 = 5.0;

/// Decay lengths `λ` kept fine ahead of the onset front.
pub const AHEAD_DECAY_LENGTHS: f64 = 8.0;

/// Decay lengths by which the fine zone reaches further when the front comes too close to its end.
pub const AHEAD_BATCH_DECAY_LENGTHS: f64 = 2.0;

/// Coarse elements behind the fine zone that must be freed at once before the free arm is
/// coarsened (the problem is rebuilt each time).
const BEHIND_BATCH: usize = 2;

/// The fine zone of a run and the base problem's nodes and points it keeps.
pub(crate) struct FineZone {
    /// First base node of the interior interface (a cohesive point at it and at both neighbours).
    anchor: usize,
    /// Base nodes per coarse element behind and ahead of the zone.
    k_behind: usize,
    k_ahead: usize,
    /// Fine length kept ahead of the onset front, and how far a refinement reaches beyond it (mm).
    ahead: f64,
    batch_ahead: f64,
    /// Fine length kept behind the first point that carries something, and the length freed
    /// behind the zone before it moves (mm).
    behind: f64,
    batch_behind: f64,
    /// The zone: every base node with `from <= x <= to` is kept (mm).
    from: f64,
    to: f64,
    /// Base nodes of the current problem.
    pub kept: Vec<usize>,
    /// Base point of each of the current problem's points.
    pub point_base: Vec<usize>,
}

/// A move of the fine zone: the new problem and how to carry a state over to it.
pub(crate) struct Move {
    /// The problem on the new node set.
    pub problem: FeProblem,
    /// For each point of the new problem, the point of the old one it was (`None`: inserted).
    pub point_of: Vec<Option<usize>>,
    old_kept: Vec<usize>,
    old_x: Vec<f64>,
    old_dofs: Vec<[usize; 3]>,
    layers: usize,
    extra: usize,
}

impl Move {
    /// The new index of the old problem's node `node` or, if it is gone, of the first kept node
    /// after it.
    pub fn node(&self, kept: &[usize], node: usize) -> usize {
        match self.old_kept.get(node) {
            Some(&j) => kept.partition_point(|&b| b < j),
            None => kept.len(),
        }
    }
}

impl FineZone {
    /// The zone for `base` under `law`, its end [`AHEAD_DECAY_LENGTHS`] + [`AHEAD_BATCH_DECAY_LENGTHS`]
    /// `λ` ahead of `origin`, with its first problem; `None` when `base` does not have the
    /// structure this needs (large rotations, one cohesive point per node from near the loaded end
    /// to the far end, the held, loaded and spring unknowns before it, layers spanning it).
    pub fn of(base: &FeProblem, law: &dyn CohesiveLaw, origin: f64) -> Option<(FineZone, FeProblem)> {
        let mesh = &base.mesh;
        let nn = mesh.x.len();
        if !base.large_rotation || nn < 4 {
            return None;
        }
        let mut point_at = vec![usize::MAX; nn];
        for (i, pt) in base.points.iter().enumerate() {
            if pt.kind != PointKind::Cohesive || point_at[pt.node] != usize::MAX {
                return None;
            }
            point_at[pt.node] = i;
        }
        let anchor = (1..nn - 1).find(|&j| point_at[j - 1] != usize::MAX && point_at[j] != usize::MAX)?;
        if point_at[anchor - 1..].contains(&usize::MAX) {
            return None;
        }
        let node_of_dof = node_of_dof(mesh);
        let special =
            base.fixed.iter().copied().chain([base.control]).chain(base.springs.iter().flat_map(|s| [s.i, s.j]));
        for d in special {
            // (Unknowns of no node, such as an actuator behind a machine spring, do not count.)
            if d != NONE && node_of_dof.get(d).is_some_and(|&j| j != usize::MAX && j >= anchor) {
                return None;
            }
        }
        if mesh.layers.iter().any(|l| l.first + 1 > anchor || l.last + 1 != nn) {
            return None;
        }
        let h = mesh.x[anchor + 1] - mesh.x[anchor];
        let longest = mesh.x.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        let k0 = law.initial_stiffness()[0];
        let lambda =
            mesh.layers.iter().map(|l| (4.0 * l.section.ei() / (k0 * l.section.b)).powf(0.25)).fold(0.0f64, f64::max);
        if !(h > 0.0 && k0 > 0.0 && lambda.is_finite() && lambda > 0.0) {
            return None;
        }
        let k_behind = ((longest / h).round() as usize).max(1);
        let k_ahead = ((0.5 * lambda / h).round() as usize).max(1);
        let mut zone = FineZone {
            anchor,
            k_behind,
            k_ahead,
            ahead: AHEAD_DECAY_LENGTHS * lambda,
            batch_ahead: AHEAD_BATCH_DECAY_LENGTHS * lambda,
            behind: FREE_ARM_MARGIN * k_behind as f64 * h,
            batch_behind: BEHIND_BATCH as f64 * k_behind as f64 * h,
            from: f64::NEG_INFINITY,
            to: origin + (AHEAD_DECAY_LENGTHS + AHEAD_BATCH_DECAY_LENGTHS) * lambda,
            kept: (0..nn).collect(),
            point_base: (0..base.points.len()).collect(),
        };
        let m = zone.relocate(base, zone.from, zone.to)?;
        Some((zone, m.problem))
    }

    /// Base nodes kept for the zone `[from, to]`.
    fn kept_for(&self, base: &FeProblem, from: f64, to: f64) -> Vec<usize> {
        let xs = &base.mesh.x;
        let nn = xs.len();
        (0..nn)
            .filter(|&j| {
                let x = xs[j];
                j < self.anchor
                    || j + 1 == nn
                    || (from..=to).contains(&x)
                    || (x < from && (j - self.anchor) % self.k_behind == 0)
                    || (x > to && (j - self.anchor) % self.k_ahead == 0)
            })
            .collect()
    }

    /// Where the zone should be after a commit of `current` (the problem on [`FineZone::kept`])
    /// with its points' `states`, law results and `gaps`, the onset front at `onset` (mm); the
    /// move there when it differs from where it is.
    pub fn follow(
        &mut self,
        base: &FeProblem,
        current: &FeProblem,
        states: &[LawState],
        evals: &[LawEval],
        gaps: &[Gap],
        onset: f64,
    ) -> Option<Move> {
        // The first point, in node order, that still carries something.
        let trail = current
            .points
            .iter()
            .enumerate()
            .filter(|(i, _)| !spent(&current.points[*i], &evals[*i], &states[*i], &gaps[*i]))
            .map(|(_, pt)| current.mesh.x[pt.node])
            .fold(f64::INFINITY, f64::min);
        let mut from = self.from;
        if trail.is_finite() {
            let x_anchor = base.mesh.x[self.anchor];
            let candidate = trail - self.behind;
            if candidate - from.max(x_anchor) >= self.batch_behind {
                from = candidate;
            }
        }
        let mut to = self.to;
        if onset.is_finite() && onset + self.ahead > to {
            to = onset + self.ahead + self.batch_ahead;
        }
        if from == self.from && to == self.to {
            return None;
        }
        self.relocate(base, from, to)
    }

    /// Moves the zone to `[from, to]`: the problem on its nodes, and the map from the current one.
    fn relocate(&mut self, base: &FeProblem, from: f64, to: f64) -> Option<Move> {
        let kept = self.kept_for(base, from, to);
        let (problem, point_base) = restrict(base, &kept)?;
        let mut old_point = vec![usize::MAX; base.points.len()];
        for (i, &b) in self.point_base.iter().enumerate() {
            old_point[b] = i;
        }
        let point_of = point_base.iter().map(|&b| (old_point[b] != usize::MAX).then_some(old_point[b])).collect();
        let old_mesh_x: Vec<f64> = self.kept.iter().map(|&j| base.mesh.x[j]).collect();
        let layers = base.mesh.layers.len();
        // The old problem's unknowns, node by node (its numbering follows from the kept nodes).
        let old_layers: Vec<Layer> = base
            .mesh
            .layers
            .iter()
            .map(|l| {
                Some(Layer { first: index_of(&self.kept, l.first)?, last: index_of(&self.kept, l.last)?, ..l.clone() })
            })
            .collect::<Option<_>>()?;
        let old_mesh = Mesh::new(old_mesh_x.clone(), old_layers, base.mesh.extra).ok()?;
        let old_dofs = (0..self.kept.len())
            .flat_map(|k| (0..layers).map(move |l| (k, l)))
            .map(|(k, l)| old_mesh.dofs(l, k))
            .collect();
        let m = Move {
            problem,
            point_of,
            old_kept: std::mem::replace(&mut self.kept, kept),
            old_x: old_mesh_x,
            old_dofs,
            layers,
            extra: base.mesh.extra,
        };
        self.point_base = point_base;
        self.from = from;
        self.to = to;
        Some(m)
    }
}

impl Move {
    /// A vector of the old problem's unknowns on the new one's: kept nodes keep their values,
    /// inserted ones take the coarse element's interpolation (cubic in the deflection with the
    /// rotations as slopes, linear in the rotation's derivative and axially).
    pub fn carry(&self, kept: &[usize], base_x: &[f64], old: &[f64]) -> Vec<f64> {
        let mesh = &self.problem.mesh;
        let mut new = vec![0.0; mesh.n_dofs()];
        new[..self.extra].copy_from_slice(&old[..self.extra]);
        let get = |d: usize| if d == NONE { 0.0 } else { old[d] };
        for (k, &j) in kept.iter().enumerate() {
            let at = self.old_kept.partition_point(|&o| o < j);
            let same = at < self.old_kept.len() && self.old_kept[at] == j;
            for l in 0..self.layers {
                let d = mesh.dofs(l, k);
                if same {
                    let o = self.old_dofs[at * self.layers + l];
                    for c in 0..3 {
                        if d[c] != NONE {
                            new[d[c]] = get(o[c]);
                        }
                    }
                    continue;
                }
                // Between old nodes at - 1 and at.
                let (a, b) = (self.old_dofs[(at - 1) * self.layers + l], self.old_dofs[at * self.layers + l]);
                let (xa, xb) = (self.old_x[at - 1], self.old_x[at]);
                let len = xb - xa;
                let s = (base_x[j] - xa) / len;
                let (h1, h2, h3, h4) = (
                    1.0 - 3.0 * s * s + 2.0 * s * s * s,
                    s - 2.0 * s * s + s * s * s,
                    3.0 * s * s - 2.0 * s * s * s,
                    -s * s + s * s * s,
                );
                let (d1, d2, d3, d4) = (
                    -6.0 * s + 6.0 * s * s,
                    1.0 - 4.0 * s + 3.0 * s * s,
                    6.0 * s - 6.0 * s * s,
                    -2.0 * s + 3.0 * s * s,
                );
                let (wa, ta, wb, tb) = (get(a[1]), get(a[2]), get(b[1]), get(b[2]));
                if d[0] != NONE {
                    new[d[0]] = (1.0 - s) * get(a[0]) + s * get(b[0]);
                }
                if d[1] != NONE {
                    new[d[1]] = h1 * wa + h2 * len * ta + h3 * wb + h4 * len * tb;
                }
                if d[2] != NONE {
                    new[d[2]] = (d1 * wa + d3 * wb) / len + d2 * ta + d4 * tb;
                }
            }
        }
        new
    }
}

/// Whether a point carries nothing and cannot (failed, open, no traction or stiffness).
fn spent(pt: &InterfacePoint, ev: &LawEval, state: &LawState, gap: &Gap) -> bool {
    pt.kind == PointKind::Cohesive
        && state.damage >= 1.0
        && gap[0] > 0.0
        && ev.traction.iter().all(|&t| t == 0.0)
        && ev.tangent.iter().all(|&t| t == 0.0)
}

fn index_of(kept: &[usize], j: usize) -> Option<usize> {
    kept.binary_search(&j).ok()
}

fn node_of_dof(mesh: &Mesh) -> Vec<usize> {
    let mut node_of = vec![usize::MAX; mesh.n_dofs()];
    for j in 0..mesh.x.len() {
        for l in 0..mesh.layers.len() {
            for d in mesh.dofs(l, j) {
                if d != NONE {
                    node_of[d] = j;
                }
            }
        }
    }
    node_of
}

/// `base` on its nodes `kept` (increasing), with the base point of each point kept. A point whose
/// neighbours are both kept keeps its area; the others' follow their tributary lengths.
fn restrict(base: &FeProblem, kept: &[usize]) -> Option<(FeProblem, Vec<usize>)> {
    let mesh = &base.mesh;
    let nn = mesh.x.len();
    let layers: Vec<Layer> = mesh
        .layers
        .iter()
        .map(|l| Some(Layer { first: index_of(kept, l.first)?, last: index_of(kept, l.last)?, ..l.clone() }))
        .collect::<Option<_>>()?;
    let x: Vec<f64> = kept.iter().map(|&j| mesh.x[j]).collect();
    let new_mesh = Mesh::new(x, layers, mesh.extra).ok()?;
    let mut new_dof = vec![NONE; mesh.n_dofs()];
    for (d, v) in new_dof.iter_mut().enumerate().take(mesh.extra) {
        *v = d;
    }
    for (k, &j) in kept.iter().enumerate() {
        for l in 0..mesh.layers.len() {
            let (a, b) = (new_mesh.dofs(l, k), mesh.dofs(l, j));
            for c in 0..3 {
                if b[c] != NONE {
                    new_dof[b[c]] = a[c];
                }
            }
        }
    }
    let tributary = |xs: &[f64], j: usize| {
        let left = if j > 0 { xs[j] - xs[j - 1] } else { 0.0 };
        let right = if j + 1 < xs.len() { xs[j + 1] - xs[j] } else { 0.0 };
        0.5 * (left + right)
    };
    let mut points = Vec::new();
    let mut point_base = Vec::new();
    for (i, pt) in base.points.iter().enumerate() {
        let Some(k) = index_of(kept, pt.node) else { continue };
        let j = pt.node;
        let neighbours_kept =
            (j == 0 || index_of(kept, j - 1).is_some()) && (j + 1 == nn || index_of(kept, j + 1).is_some());
        let area = if neighbours_kept { pt.area } else { pt.area * tributary(&new_mesh.x, k) / tributary(&mesh.x, j) };
        points.push(InterfacePoint { node: k, area, ..*pt });
        point_base.push(i);
    }
    let map = |d: usize| if d == NONE { NONE } else { new_dof[d] };
    let problem = FeProblem {
        mesh: new_mesh,
        points,
        springs: base.springs.iter().map(|s| super::Spring { i: map(s.i), j: map(s.j), ..*s }).collect(),
        fixed: base.fixed.iter().map(|&d| map(d)).collect(),
        control: map(base.control),
        large_rotation: base.large_rotation,
        contact_stiffness: base.contact_stiffness,
        contact_friction: base.contact_friction,
    };
    Some((problem, point_base))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::Bilinear;
    use czid_core::{Tangent, Traction};

    fn hartlen() -> (FeProblem, Bilinear, f64) {
        let mut d = crate::dcb::Dcb::hartlen_dcb01();
        d.effects.large_rotation = true;
        let (p, _) = d.problem().unwrap();
        (p, Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap(), d.a0)
    }

    fn area(q: &FeProblem) -> f64 {
        q.points.iter().map(|pt| pt.area).sum()
    }

    #[test]
    fn the_first_problem_is_fine_near_the_front_only_and_keeps_the_interface_area() {
        let (base, law, a0) = hartlen();
        let (zone, p) = FineZone::of(&base, &law, a0).unwrap();
        let lambda = zone.ahead / AHEAD_DECAY_LENGTHS;
        // λ = (4 EI / (K₀ b))^{1/4} of Hartlen's arm: 19.3 GPa, 2.7 mm thick, 10⁵ MPa/mm.
        let ei = 19_300.0 * 25.0 * 2.7f64.powi(3) / 12.0;
        assert!((lambda - (4.0 * ei / (1e5 * 25.0)).powf(0.25)).abs() < 1e-12);
        let h = base.mesh.x[zone.anchor + 1] - base.mesh.x[zone.anchor];
        for w in p.mesh.x.windows(2) {
            let l = w[1] - w[0];
            if w[0] < a0 - 1e-9 {
                continue; // the pre-crack arm, as built
            }
            if w[1] <= zone.to {
                assert!((l - h).abs() < 1e-9, "fine element {l} at {}", w[0]);
            } else {
                assert!(l <= zone.k_ahead as f64 * h + 1e-9, "coarse element {l} at {}", w[0]);
            }
        }
        assert!(p.mesh.n_dofs() < base.mesh.n_dofs() / 2, "{} of {} unknowns", p.mesh.n_dofs(), base.mesh.n_dofs());
        assert!((area(&p) - area(&base)).abs() <= 1e-9 * area(&base));
        assert_eq!(p.control, base.control);
        assert_eq!(p.fixed, base.fixed);
    }

    #[test]
    fn inserted_nodes_take_a_cubic_deflection_exactly() {
        let (base, law, a0) = hartlen();
        let (mut zone, p) = FineZone::of(&base, &law, a0).unwrap();
        // w = c(x), θ = c'(x) (no shear), u linear, on the coarse problem.
        let c = |x: f64| 1e-3 * (x - 60.0).powi(3) - 0.02 * (x - 60.0).powi(2) + 0.1 * x - 2.0;
        let dc = |x: f64| 3e-3 * (x - 60.0).powi(2) - 0.04 * (x - 60.0) + 0.1;
        let u = |x: f64| 1e-4 * x - 0.3;
        let mut q = vec![0.0; p.mesh.n_dofs()];
        for (k, &x) in p.mesh.x.iter().enumerate() {
            let d = p.mesh.dofs(0, k);
            q[d[0]] = u(x);
            q[d[1]] = c(x);
            q[d[2]] = dc(x);
        }
        let n = p.points.len();
        let (states, gaps) = (vec![LawState::default(); n], vec![Gap::new(1e-4, 0.0); n]);
        let evals =
            vec![
                LawEval { traction: Traction::new(1.0, 0.0), tangent: Tangent::identity(), state: LawState::default() };
                n
            ];
        let before = zone.to;
        let m = zone.follow(&base, &p, &states, &evals, &gaps, before).expect("the front at the zone's end moves it");
        assert!(zone.to > before);
        let new = m.carry(&zone.kept, &base.mesh.x, &q);
        let mesh = &m.problem.mesh;
        assert!(mesh.x.len() > p.mesh.x.len());
        for (k, &x) in mesh.x.iter().enumerate() {
            let d = mesh.dofs(0, k);
            let scale = 1.0 + c(x).abs();
            assert!((new[d[1]] - c(x)).abs() <= 1e-12 * scale, "w at {x}: {} against {}", new[d[1]], c(x));
            assert!((new[d[2]] - dc(x)).abs() <= 1e-12 * scale, "θ at {x}");
            assert!((new[d[0]] - u(x)).abs() <= 1e-12, "u at {x}");
        }
        // Every old point is still there, and the new ones are the inserted nodes'.
        assert_eq!(m.point_of.iter().flatten().count(), n);
        assert!((area(&m.problem) - area(&base)).abs() <= 1e-9 * area(&base));
    }

    #[test]
    fn only_spent_points_leave_behind_the_front() {
        let (base, law, a0) = hartlen();
        let (mut zone, mut p) = FineZone::of(&base, &law, a0).unwrap();
        // Bring the zone's end past 80 mm first (front at 70 mm), nothing spent.
        let fill = |p: &FeProblem, spent_to: f64| {
            let n = p.points.len();
            let mut states = vec![LawState::default(); n];
            let mut evals = Vec::with_capacity(n);
            let mut gaps = vec![Gap::new(1e-4, 0.0); n];
            for (i, pt) in p.points.iter().enumerate() {
                let spent = p.mesh.x[pt.node] <= spent_to;
                if spent {
                    states[i].damage = 1.0;
                    gaps[i] = Gap::new(0.5, 0.0);
                }
                let (t, k) = if spent {
                    (Traction::zeros(), Tangent::zeros())
                } else {
                    (Traction::new(1.0, 0.0), Tangent::identity())
                };
                evals.push(LawEval { traction: t, tangent: k, state: states[i] });
            }
            (states, evals, gaps)
        };
        let (s, e, g) = fill(&p, 0.0);
        p = zone.follow(&base, &p, &s, &e, &g, 70.0).unwrap().problem;
        let (s, e, g) = fill(&p, 60.0);
        let m = zone.follow(&base, &p, &s, &e, &g, 70.0).expect("22 mm spent");
        for (i, pt) in p.points.iter().enumerate() {
            if !m.point_of.contains(&Some(i)) {
                assert!(p.mesh.x[pt.node] <= 60.0 - FREE_ARM_MARGIN + 1e-9, "point at {} removed", p.mesh.x[pt.node]);
            }
        }
        // The free arm in elements of the pre-crack arm's length (to a fine element), up to five of
        // them behind 60 mm.
        let xs = &m.problem.mesh.x;
        let h = base.mesh.x[zone.anchor + 1] - base.mesh.x[zone.anchor];
        let long: Vec<(f64, f64)> = xs
            .windows(2)
            .filter(|w| w[0] > a0 + 1e-9 && w[1] < 60.0)
            .map(|w| (w[0], w[1] - w[0]))
            .filter(|(_, l)| *l > 2.0 * h)
            .collect();
        assert!(long.len() >= 15, "{long:?}");
        // (The last one joins the fine zone's first node, and may be shorter.)
        let (last, whole) = long.split_last().unwrap();
        assert!(whole.iter().all(|(_, l)| (l - zone.k_behind as f64 * h).abs() < 1e-9), "{long:?}");
        assert!(last.1 <= zone.k_behind as f64 * h + 1e-9);
        assert!((area(&m.problem) - area(&base)).abs() <= 1e-9 * area(&base));
    }
}
