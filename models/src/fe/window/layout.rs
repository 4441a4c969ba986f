//! The static structure of a problem the window can solve: each node's unknowns, the interface
//! chain's points and segments, the linear stiffness by node blocks, and the law's linear domain.

use czid_core::{CohesiveLaw, Gap, Tangent};

use super::blocks::{zb, Blk, Vct};
use super::Unfit;
use crate::fe::assembly::FeProblem;
use crate::fe::beam;
use crate::fe::interface::{self, PointKind, POINT_DOFS};
use crate::fe::mesh::NONE;
use crate::fe::segment::{self, ModeOne, Segment};

/// Largest number of unknowns per node the window handles.
pub(super) const MD: usize = 8;

/// Unknowns of one node (global indices) other than fixed ones and the control unknown.
#[derive(Clone, Copy, Debug)]
pub(super) struct NodeDofs {
    pub(super) dofs: [usize; MD],
    pub(super) d: usize,
}

/// A cohesive point of the interface chain, by node.
#[derive(Clone, Copy, Debug)]
pub(super) struct ChainPoint<const D: usize> {
    /// Index into the problem's points.
    pub(super) point: usize,
    /// Gap gradient in the node's unknowns (`[g_n, g_t]` rows).
    pub(super) grad: [[f64; D]; 2],
    /// Area × energy share (nodal rule), for the point-wise work and dissipation.
    pub(super) weight: f64,
}

/// The law's linear domains.
#[derive(Clone, Copy, Debug)]
pub(super) struct Linear {
    /// Tangent of the virgin law inside its elastic domain.
    pub(super) k0: Tangent,
    /// Gaps with `lo ≤ g ≤ hi` (per component) are elastic.
    pub(super) lo: [f64; 2],
    pub(super) hi: [f64; 2],
}

impl Linear {
    pub(super) fn contains(&self, g: &Gap) -> bool {
        (0..2).all(|c| g[c] >= self.lo[c] && g[c] <= self.hi[c])
    }
    /// Largest fraction of the box's extent reached by `g`.
    pub(super) fn usage(&self, g: &Gap) -> f64 {
        (0..2).fold(0.0f64, |m, c| m.max(if g[c] >= 0.0 { g[c] / self.hi[c] } else { g[c] / self.lo[c] }))
    }
}

/// The static structure of a problem the window can solve.
pub(super) struct Layout<const D: usize> {
    /// First and last node of the interface chain.
    pub(super) first: usize,
    pub(super) last: usize,
    /// Chain point of each node from `first` to `last`.
    pub(super) chain: Vec<ChainPoint<D>>,
    /// Segment between node `first + k` and the next.
    pub(super) segs: Vec<Segment>,
    /// Diagonal blocks of the linear stiffness (beams, springs) per node (padded unknowns: 1).
    pub(super) kd: Vec<Blk<D>>,
    /// Blocks coupling node j to j + 1 (row j) and j + 1 to j (row j + 1).
    pub(super) ku: Vec<Blk<D>>,
    pub(super) kl: Vec<Blk<D>>,
    /// The diagonal contributions of element (j, j + 1) to node j (`ed0`) and to node j + 1 (`ed1`).
    pub(super) ed0: Vec<Blk<D>>,
    pub(super) ed1: Vec<Blk<D>>,
    /// Coupling of each node's unknowns to the control unknown, and its own diagonal.
    pub(super) kc: Vec<Vct<D>>,
    pub(super) kcc: f64,
    /// The nodes the control unknown couples to where they are not behind the interface's first
    /// node (the load point of a beam on two supports, ahead of the crack), first and last: the
    /// condensed right region and the window then carry the control's column too.
    pub(super) control_nodes: Option<(usize, usize)>,
    /// Contact points of the cracked faces before the interface chain (node, gap gradient): open
    /// faces carry nothing, so they belong to the left region while they stay open.
    pub(super) contacts: Vec<(usize, ChainPoint<D>)>,
}

/// Each node's unknowns, each unknown's (node, position in the node), and which are fixed.
pub(super) type Numbering = (Vec<NodeDofs>, Vec<(usize, usize)>, Vec<bool>);

/// Checks the problem's structure and numbers each node's unknowns (at most [`MD`]).
pub(super) fn node_dofs(p: &FeProblem) -> Result<Numbering, Unfit> {
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
    pub(super) fn new(
        p: &FeProblem,
        nodes: &[NodeDofs],
        owner: &[(usize, usize)],
        fixed: &[bool],
    ) -> Result<Self, Unfit> {
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

    pub(super) fn cp(&self, node: usize) -> &ChainPoint<D> {
        &self.chain[node - self.first]
    }

    /// Whether the contact points at `node` (if any) are open at its unknowns `q`.
    pub(super) fn contacts_open(&self, node: usize, q: &Vct<D>) -> bool {
        let from = self.contacts.partition_point(|(n, _)| *n < node);
        self.contacts[from..].iter().take_while(|(n, _)| *n == node).all(|(_, cp)| gap_at(cp, q)[0] >= 0.0)
    }
}

/// The virgin law's linear domain: its tangent at half the mode I elastic limit, and a box of gaps
/// whose corners respond as `K₀ g` without damage (the elastic domain of every bundled law, and of
/// damage laws in general, is convex, so the whole box is elastic).
pub(super) fn linear_domain(law: &dyn CohesiveLaw, m: &ModeOne) -> Option<Linear> {
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

/// The gap at a chain point from its node's unknowns.
pub(super) fn gap_at<const D: usize>(cp: &ChainPoint<D>, q: &Vct<D>) -> Gap {
    let mut g = Gap::zeros();
    for r in 0..2 {
        for a in 0..D {
            g[r] += cp.grad[r][a] * q[a];
        }
    }
    g
}
