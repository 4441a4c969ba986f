//! The condensed regions on both sides of the window: their elimination as nodes leave or join
//! the window, the forces they exert, and the checks that they hold what they assume.

use czid_core::LawState;

use super::Solver;
use crate::fe::window::blocks::{add, blk_mul, blk_vec, dot, neg, Lu, Vct};
use crate::fe::window::layout::gap_at;
use crate::fe::window::{Unfit, CHECK_DECAYS, CONDENSE_MARGIN};

/// The outcome of checking the condensed regions after a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Verdict {
    /// Both regions hold what they assume.
    Fits,
    /// A point of the right region left the elastic box: the window must reach further.
    Right,
    /// A failed point of the left region closed (or the window's first point is not failed).
    Left,
}

impl<'a, const D: usize> Solver<'a, D> {
    /// Moves nodes `i0..new_i0` from the window to the left region.
    pub(super) fn advance_left(&mut self, new_i0: usize) -> Result<(), Unfit> {
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
    pub(super) fn left_value(&self, j: usize, next: &Vct<D>) -> Vct<D> {
        let mut v = blk_vec(&self.tl[j], next);
        for a in 0..D {
            v[a] += self.tlc[j][a] * self.c;
        }
        v
    }

    /// Unknowns of the right region's node `j` (`j > i1`) from those of node `j − 1`.
    pub(super) fn right_value(&self, j: usize, prev: &Vct<D>) -> Vct<D> {
        let mut v = blk_vec(&self.tr[j], prev);
        self.add_control_column(j, &mut v);
        v
    }

    /// Adds the control's part `trc[j] c` to the right region's node `j` recovered from its
    /// neighbour (nothing where the control couples to no node of the interface).
    #[inline(always)]
    pub(super) fn add_control_column(&self, j: usize, v: &mut Vct<D>) {
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
    pub(super) fn control_forces(&self) -> [f64; 3] {
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

    /// After convergence: whether the regions' points are what they are assumed to be, within
    /// the check zones; also returns how far (node) the window must reach on the right for the
    /// next step, and the first node that may leave it on the left.
    pub(super) fn check(&self) -> (Verdict, usize, usize) {
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

    /// Adds node `i1 + 1` to the window (its unknowns recovered from the right region; its point
    /// is elastic, so the work done on it is its stored energy).
    pub(super) fn grow_right(&mut self) {
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
    pub(super) fn shrink_left(&mut self, new_i0: usize) -> Result<(), Unfit> {
        for j in self.i0..new_i0 {
            let cp = self.lay.cp(j);
            self.frozen += cp.weight * self.pts[cp.point].dissipated(self.law);
        }
        self.advance_left(new_i0)
    }

    /// Moves the window's leading nodes whose predicted opening is well beyond the law's failure
    /// opening ([`CONDENSE_OPENING`](crate::fe::window::CONDENSE_OPENING) times it, and [`CONDENSE_MARGIN`] nodes behind the last such
    /// node) to the left region for this step: they fail during it, and Newton then works on the
    /// process zone and the intact part only. Whether they did fail is checked after
    /// convergence ([`Solver::settle_condensed`]); if not, the step is repeated without this.
    pub(super) fn condense_failing(&mut self) -> Result<(), Unfit> {
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
    pub(super) fn restore_left(&mut self, (i0, sigma, rho): (usize, f64, Vct<D>)) {
        self.i0 = i0;
        self.sigma = sigma;
        self.rho = rho;
    }

    /// After a converged step whose nodes `from..i0` left the window: their unknowns recovered
    /// from the left region, their points evaluated from the committed `states`; if every one has
    /// failed, open, their points are committed (state, work along the gap path, the dissipation
    /// frozen as [`Solver::shrink_left`] does) and `true` returned; else nothing changes.
    pub(super) fn settle_condensed(&mut self, from: usize, states: &[LawState]) -> bool {
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

    /// Recovers the condensed regions' unknowns from the window's ends and visits each node with
    /// them: the right region's from the window outwards, then the left region's down to node
    /// `left_to`; stops at the first visit that returns `false` (and returns `false`).
    pub(super) fn walk_condensed(&self, left_to: usize, mut visit: impl FnMut(usize, &Vct<D>) -> bool) -> bool {
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
    pub(super) fn final_check(&self) -> bool {
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
}
