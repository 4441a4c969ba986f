//! The windowed solver: its state, its set-up and the path it follows step by step. The rest of
//! its work is in the submodules: Newton's iterations over the window ([`newton`]), the condensed
//! regions and their checks ([`regions`]), the step's predictor ([`predictor`]) and what a step
//! commits and records ([`records`]).

mod newton;
mod predictor;
mod records;
mod regions;

use std::rc::Rc;

use czid_core::{CohesiveLaw, Gap, LawEval, LawState, Tangent, Traction};

use self::records::PointRecord;
use self::regions::Verdict;
use crate::fe::assembly::FeProblem;
use crate::fe::crack::CrackMeasures;
use crate::fe::newton::CHORD_BELOW;
use crate::fe::pool::{self, Pooled};
use crate::fe::run_types::{FrontTrack, PathSettings, Resume, RunStats, StepRow};
use crate::fe::segment::ModeOne;
use crate::fe::window::blocks::{add, addv, blk_mul, blk_vec, dot, neg, zb, Blk, Lu, Vct};
use crate::fe::window::layout::{Layout, Linear};
use crate::fe::window::{Unfit, CONDENSE_OPENING};

/// Where a windowed run stands along its path (for [`Resume`]).
pub(super) struct Cursor {
    pos: f64,
    h: f64,
    k_out: usize,
    external: f64,
    front: FrontTrack,
}

pub(super) struct Solver<'a, const D: usize> {
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
    pub(super) condense_opening: f64,
    /// See [`CHORD_BELOW`].
    pub(super) chord_below: f64,
    /// Set when the run gives up with a state the whole mesh can go on from.
    pub(super) resume: Option<Box<Resume>>,
    /// Energy dissipated up to the last commit, and by the last step that dissipated (N·mm).
    dissipated_committed: f64,
    step_dissipation: f64,
}

impl<'a, const D: usize> Solver<'a, D> {
    pub(super) fn new(
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

    pub(super) fn seg_len(&self) -> f64 {
        self.lay.segs[0].len
    }

    pub(super) fn run(&mut self) -> Result<(Vec<StepRow>, RunStats), Unfit> {
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
