//! Under large rotations: the free arm behind a crack front merged into longer beam elements as
//! the crack grows.
//!
//! **Why.** Co-rotational arms are not linear, so a large-rotation run is solved on the whole mesh
//! (the small-rotation window condenses linear regions, which these are not). The mesh is fine
//! where the crack will grow, four beam elements per interface element, because the process zone
//! needs it there (`mesh.interface_subdivision`). Once the zone has passed, that stretch is free
//! arm: its interface points have failed and are open, so they carry nothing, and the arm is an
//! elastica loaded at its end, whose curvature varies smoothly along it, as it does along the
//! pre-crack arm. By the end of a run on Hartlen's DCB-01 that stretch holds most of the unknowns,
//! and every Newton iteration assembles and factorises it.
//!
//! **What.** At a committed step, the stretch of nodes whose points have all failed (damage 1,
//! no traction, no stiffness, open) and that lie at least [`FREE_ARM_MARGIN`] coarse elements
//! behind the first point that still carries something is thinned to nodes as far apart as the
//! mesh's longest elements (a DCB's pre-crack arm's): the nodes in between, their unknowns and
//! their interface points are removed. The kept nodes keep their unknowns' values; the removed points'
//! work stays in the energy ledger's totals (they carry no traction, so they would add none), and
//! the kept points' areas follow their new tributary lengths. The problem is rebuilt and the run
//! continues on it. Nothing else changes: the result differs from the fine mesh's only by how
//! well the longer co-rotational elements represent the free arm.

use super::assembly::FeProblem;
use super::interface::{InterfacePoint, PointKind};
use super::mesh::{Layer, Mesh, NONE};
use czid_core::{Gap, LawEval, LawState};

/// Coarse elements kept fine between the stretch thinned and the first point that still carries
/// something (the free arm's curvature is largest next to the front).
pub const FREE_ARM_MARGIN: f64 = 5.0;

/// Nodes a coarsening must remove at least: the problem is rebuilt each time, so it waits until
/// that pays.
const MIN_REMOVED: usize = 32;

/// A coarsened problem and where its parts came from in the problem before.
pub(crate) struct Coarsened {
    /// The problem with the free arm thinned.
    pub problem: FeProblem,
    /// For each unknown, the unknown it was before.
    pub dof_of: Vec<usize>,
    /// For each interface point, the point it was before.
    pub point_of: Vec<usize>,
    /// For each node, the node it was before.
    pub node_of: Vec<usize>,
}

/// Whether a point carries nothing and cannot (failed, open, no traction or stiffness).
fn spent(pt: &InterfacePoint, ev: &LawEval, state: &LawState, gap: &Gap) -> bool {
    pt.kind == PointKind::Cohesive
        && state.damage >= 1.0
        && gap[0] > 0.0
        && ev.traction.iter().all(|&t| t == 0.0)
        && ev.tangent.iter().all(|&t| t == 0.0)
}

/// The free arm of `p` thinned to elements about as long as its longest, from the committed
/// states, law results and gaps of its points; `None` when there is not enough to remove yet or the
/// problem does not have the structure this needs (one point set per node, the held, loaded and
/// spring unknowns outside the stretch).
pub(crate) fn free_arm(p: &FeProblem, states: &[LawState], evals: &[LawEval], gaps: &[Gap]) -> Option<Coarsened> {
    let mesh = &p.mesh;
    let nn = mesh.x.len();
    let element = mesh.x.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    if !(element > 0.0 && element.is_finite()) || states.len() != p.points.len() {
        return None;
    }
    // Per node: no points (None), or whether all of them are spent.
    let mut node_spent: Vec<Option<bool>> = vec![None; nn];
    for (i, pt) in p.points.iter().enumerate() {
        let s = spent(pt, &evals[i], &states[i], &gaps[i]);
        let v = &mut node_spent[pt.node];
        *v = Some(v.unwrap_or(true) && s);
    }
    // Nodes whose unknowns the problem holds, loads or ties with a spring stay.
    let mut pinned = vec![false; nn];
    let dofs_of = |j: usize| (0..mesh.layers.len()).flat_map(move |l| mesh.dofs(l, j)).filter(|&d| d != NONE);
    let mut node_of_dof = vec![usize::MAX; mesh.n_dofs()];
    for j in 0..nn {
        for d in dofs_of(j) {
            node_of_dof[d] = j;
        }
    }
    let special = p.fixed.iter().copied().chain([p.control]).chain(p.springs.iter().flat_map(|s| [s.i, s.j]));
    for d in special {
        if let Some(&j) = node_of_dof.get(d) {
            if j != usize::MAX {
                pinned[j] = true;
            }
        }
    }
    let fine = |j: usize| j + 1 < nn && mesh.x[j + 1] - mesh.x[j] < 0.75 * element;
    // The stretch starts at the first spent node after another followed by a fine element (so
    // that points on both sides make its area a whole tributary length)...
    let start =
        (1..nn).find(|&j| node_spent[j - 1] == Some(true) && node_spent[j] == Some(true) && !pinned[j] && fine(j))?;
    // ...and ends where the nodes stop being spent, less the margin.
    let stop = (start..nn).find(|&j| node_spent[j] != Some(true) || pinned[j]).unwrap_or(nn);
    if stop >= nn {
        return None;
    }
    let limit = mesh.x[stop] - FREE_ARM_MARGIN * element;
    // Nodes about `element` apart from the start on; the rest of the stretch goes.
    let mut keep = vec![true; nn];
    let mut end = start;
    for j in start + 1..stop {
        if mesh.x[j] > limit {
            break;
        }
        if mesh.x[j] - mesh.x[end] >= element * (1.0 - 1e-9) {
            for k in &mut keep[end + 1..j] {
                *k = false;
            }
            end = j;
        }
    }
    // Every layer must pass through the stretch, so that no layer begins or ends in it.
    if mesh.layers.iter().any(|l| l.first > start || l.last < end) {
        return None;
    }
    let removed = keep.iter().filter(|k| !**k).count();
    if removed < MIN_REMOVED {
        return None;
    }
    let node_of: Vec<usize> = (0..nn).filter(|&j| keep[j]).collect();
    let mut new_index = vec![usize::MAX; nn];
    for (k, &j) in node_of.iter().enumerate() {
        new_index[j] = k;
    }
    let layers: Vec<Layer> =
        mesh.layers.iter().map(|l| Layer { first: new_index[l.first], last: new_index[l.last], ..l.clone() }).collect();
    let x: Vec<f64> = node_of.iter().map(|&j| mesh.x[j]).collect();
    let new_mesh = Mesh::new(x, layers, mesh.extra).ok()?;
    let mut dof_of = vec![usize::MAX; new_mesh.n_dofs()];
    for d in 0..mesh.extra {
        dof_of[d] = d;
    }
    let mut new_dof = vec![NONE; mesh.n_dofs()];
    for d in 0..mesh.extra {
        new_dof[d] = d;
    }
    for (k, &j) in node_of.iter().enumerate() {
        for l in 0..mesh.layers.len() {
            let (a, b) = (new_mesh.dofs(l, k), mesh.dofs(l, j));
            for c in 0..3 {
                if a[c] != NONE && b[c] != NONE {
                    dof_of[a[c]] = b[c];
                    new_dof[b[c]] = a[c];
                }
            }
        }
    }
    if dof_of.contains(&usize::MAX) {
        return None;
    }
    let tributary = |xs: &[f64], j: usize| {
        let left = if j > 0 { xs[j] - xs[j - 1] } else { 0.0 };
        let right = if j + 1 < xs.len() { xs[j + 1] - xs[j] } else { 0.0 };
        0.5 * (left + right)
    };
    let mut points = Vec::with_capacity(p.points.len() - removed);
    let mut point_of = Vec::with_capacity(p.points.len() - removed);
    for (i, pt) in p.points.iter().enumerate() {
        if !keep[pt.node] {
            continue;
        }
        let k = new_index[pt.node];
        // The stretch's points are spent and have points on both sides: their areas follow the
        // new tributary lengths (they carry nothing unless they close again).
        let area = if (start..=end).contains(&pt.node) {
            let (before, after) = (tributary(&mesh.x, pt.node), tributary(&new_mesh.x, k));
            if before > 0.0 {
                pt.area * after / before
            } else {
                pt.area
            }
        } else {
            pt.area
        };
        points.push(InterfacePoint { node: k, area, ..*pt });
        point_of.push(i);
    }
    let map = |d: usize| if d == NONE { NONE } else { new_dof[d] };
    let problem = FeProblem {
        mesh: new_mesh,
        points,
        springs: p.springs.iter().map(|s| super::Spring { i: map(s.i), j: map(s.j), ..*s }).collect(),
        fixed: p.fixed.iter().map(|&d| map(d)).collect(),
        control: map(p.control),
        large_rotation: p.large_rotation,
        contact_stiffness: p.contact_stiffness,
        contact_friction: p.contact_friction,
    };
    Some(Coarsened { problem, dof_of, point_of, node_of })
}

#[cfg(test)]
mod tests {
    use super::*;
    use czid_core::{Tangent, Traction};

    /// Hartlen's DCB-01 under large rotations, its points spent up to `x_spent` (mm).
    fn spent_up_to(x_spent: f64) -> (FeProblem, Vec<LawState>, Vec<LawEval>, Vec<Gap>) {
        let mut d = crate::dcb::Dcb::hartlen_dcb01();
        d.effects.large_rotation = true;
        let (p, _) = d.problem().unwrap();
        let n = p.points.len();
        let (mut states, mut evals, mut gaps) =
            (vec![LawState::default(); n], Vec::with_capacity(n), vec![Gap::zeros(); n]);
        for (i, pt) in p.points.iter().enumerate() {
            let failed = p.mesh.x[pt.node] <= x_spent;
            if failed {
                states[i].damage = 1.0;
                gaps[i] = Gap::new(0.5, 0.0);
            }
            let traction = if failed { Traction::zeros() } else { Traction::new(1.0, 0.0) };
            let tangent = if failed { Tangent::zeros() } else { Tangent::identity() };
            evals.push(LawEval { traction, tangent, state: states[i] });
        }
        (p, states, evals, gaps)
    }

    #[test]
    fn thins_the_spent_stretch_and_keeps_everything_else() {
        let (p, states, evals, gaps) = spent_up_to(60.0);
        let c = free_arm(&p, &states, &evals, &gaps).expect("22 mm spent");
        let (old, new) = (&p.mesh, &c.problem.mesh);
        // The pre-crack arm's 0.99 mm elements (38 over 37.64 mm), then the stretch's from one
        // node after the front on, twenty of the 0.05 mm elements each, to five of them before
        // the first point that carries something.
        let coarse: Vec<f64> = new.x.windows(2).map(|w| w[1] - w[0]).filter(|l| *l > 0.5).collect();
        assert_eq!(coarse.len(), 38 + 17, "{coarse:?}");
        let fine = old.x[old.x.len() - 1] - old.x[old.x.len() - 2];
        assert!(coarse[38..].iter().all(|l| *l >= coarse[0] && *l < coarse[0] + fine), "{coarse:?}");
        let last_coarse = new.x.windows(2).rposition(|w| w[1] - w[0] > 0.5).unwrap() + 1;
        assert!(
            new.x[last_coarse] <= 60.0 - FREE_ARM_MARGIN + 0.05 && new.x[last_coarse] > 60.0 - FREE_ARM_MARGIN - 1.0
        );
        // Every kept node keeps its position and its unknowns' meaning; held and loaded unknowns
        // are the same ones.
        for (k, &j) in c.node_of.iter().enumerate() {
            assert_eq!(new.x[k], old.x[j]);
            for c3 in 0..3 {
                let (a, b) = (new.dofs(0, k)[c3], old.dofs(0, j)[c3]);
                assert_eq!(a == NONE, b == NONE);
                if a != NONE {
                    assert_eq!(c.dof_of[a], b);
                }
            }
        }
        assert_eq!(c.dof_of[c.problem.control], p.control);
        for (a, b) in c.problem.fixed.iter().zip(&p.fixed) {
            assert_eq!(c.dof_of[*a], *b);
        }
        // Only spent points go, and the interface keeps its area.
        for (i, pt) in p.points.iter().enumerate() {
            if !c.point_of.contains(&i) {
                assert!(old.x[pt.node] <= 60.0);
            }
        }
        let area = |q: &FeProblem| q.points.iter().map(|pt| pt.area).sum::<f64>();
        assert!((area(&c.problem) - area(&p)).abs() <= 1e-9 * area(&p));
        // Nothing to do when less than the minimum is spent beyond the margin.
        let (p, states, evals, gaps) = spent_up_to(37.64 + FREE_ARM_MARGIN + 0.5);
        assert!(free_arm(&p, &states, &evals, &gaps).is_none());
    }
}
