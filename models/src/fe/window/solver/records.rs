//! What a step commits and records: the points' work and dissipation, the energies of the
//! condensed regions, the crack measures, the rows, and the state the whole mesh can resume from.

use czid_core::{CohesiveLaw, Gap, LawEval, LawState, Traction};

use super::{Cursor, Solver};
use crate::fe::crack::CrackMeasures;
use crate::fe::energy::path_work;
use crate::fe::run_types::{Resume, StepRow};
use crate::fe::segment::ModeOne;
use crate::fe::window::blocks::{add, addv, blk_vec, dot, sub, Vct};
use crate::fe::window::layout::node_dofs;

/// Per-point bookkeeping of the interface.
#[derive(Clone, Copy, Debug)]
pub(super) struct PointRecord {
    pub(super) state: LawState,
    /// Work per unit area done on the point so far, last traction and gap.
    pub(super) work: f64,
    pub(super) t: Traction,
    pub(super) g: Gap,
}

impl PointRecord {
    /// Moves the point to the gap `g1` and the law's evaluation `ev` there, from the committed
    /// state `before`: the work over the step is integrated along the gap path by the law where
    /// the state changed (as [`crate::fe::energy::Ledger::commit_along`]), by the trapezoidal rule
    /// where it did not.
    pub(super) fn commit(
        &mut self,
        law: &dyn CohesiveLaw,
        mode_one: &ModeOne,
        before: &LawState,
        g1: Gap,
        ev: &LawEval,
    ) {
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
    pub(super) fn dissipated(&self, law: &dyn CohesiveLaw) -> f64 {
        self.work - law.stored_energy(&self.g, &self.state)
    }
}

impl<'a, const D: usize> Solver<'a, D> {
    /// Total energy of the beams, springs and interface (N·mm), by Clapeyron for the condensed
    /// regions.
    pub(super) fn elastic_energy(&self) -> f64 {
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

    pub(super) fn crack(&self) -> CrackMeasures {
        let lay = &self.lay;
        let (i0, i1) = (self.i0, self.i1);
        let (k0, k1) = (i0 - lay.first, i1 - lay.first);
        let point = |i: usize| (self.pts[i].g, &self.pts[i].state);
        let (segs, fronts) = (&lay.segs[k0..k1], &self.fronts[k0..k1]);
        let mut m =
            crate::fe::crack::from_segments(segs, fronts, self.law, point, self.s.crack_origin, self.s.debonded());
        // The left region has failed all along.
        let failed_left = self.p.mesh.x[i0] - self.p.mesh.x[lay.first];
        if failed_left > 0.0 {
            m.debonded += failed_left;
            m.tip = m.tip.max(self.p.mesh.x[i0]);
        }
        m
    }

    pub(super) fn reaction_committed(&self) -> f64 {
        self.committed_reaction
    }

    /// Commits the window's points: states, and the work done on them over the step (integrated
    /// along each point's gap path by the law, as [`crate::fe::energy::Ledger::commit_along`]).
    pub(super) fn commit_points(&mut self, before: &[LawState]) {
        for j in self.i0..=self.i1 {
            let pi = self.lay.cp(j).point;
            self.pts[pi].commit(self.law, &self.mode_one, &before[pi], self.gaps[pi], &self.ev[pi]);
        }
    }

    /// Energy the interface has dissipated (N·mm): the points that left the window, and the
    /// window's.
    pub(super) fn dissipated(&self) -> f64 {
        let mut dissipated = self.frozen;
        for j in self.i0..=self.i1 {
            let cp = self.lay.cp(j);
            dissipated += cp.weight * self.pts[cp.point].dissipated(self.law);
        }
        dissipated
    }

    /// The committed state's row, with `dissipated` from [`Solver::dissipated`].
    pub(super) fn row(&self, external: f64, dissipated: f64) -> StepRow {
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

    /// The last committed state as the whole mesh numbers it ([`Resume`]): every unknown, the
    /// condensed regions' recovered from the window's ends; every point's state (the right
    /// region's points at their recovered gaps, elastic); the energies and the path's position.
    /// `None` if the problem cannot be numbered again (it always can: it was at the start).
    pub(super) fn resume_state(
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
}
