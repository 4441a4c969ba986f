//! Path following: adaptive displacement control that lands exactly on an output grid, with a
//! dissipation-controlled detour through snap-backs.
//!
//! * **Displacement control.** The control unknown advances towards the next output abscissa in
//!   steps that double after fast convergence and halve after a failure. The predictor
//!   extrapolates the last increment; with the segment rule ([`RunOptions::interface`]) it also
//!   translates the solution near the crack front by the front's extrapolated advance
//!   (`shift_predictor`: a cohesive zone travels with its shape, which no linear extrapolation of
//!   the unknowns represents), so Newton starts within its quadratic basin even when the front
//!   crosses dozens of points in a step. Every output abscissa is hit exactly, so a response read
//!   at those abscissae is an equilibrium state, not an interpolation between adaptively placed
//!   steps: this keeps responses smooth in the parameters (finite-difference Jacobians).
//! * **Snap-back.** When displacement control cannot proceed even at the smallest step, the
//!   equilibrium path turns back in the control displacement. With the nodal rule a cohesive
//!   crack does this once per point; with segments only a genuinely unstable structure does. The
//!   solver then switches to the dissipation constraint (released energy per step prescribed,
//!   Gutiérrez 2004; Verhoosel, Remmers & Gutiérrez 2009), which follows snap-backs because
//!   dissipation only increases, with the released energy adapted to give control increments of
//!   about half an output spacing. With the nodal rule it stays there while the crack runs; with
//!   segments it returns to displacement control after every forward step. It ends on the target
//!   under displacement control; if the target lies inside an unstable stretch, or dissipation
//!   control itself stalls, it jumps over the stretch under displacement control (the recorded
//!   states are still equilibria).
//! * **Window.** With [`RunOptions::window`] a problem that fits is solved by `fe::window`
//!   (displacement control on the unknowns around the crack front only); anything else, and any
//!   run the window gives up on, by the whole-mesh solver here.
//! * A run that still fails returns the error and every row that converged.

use czid_core::{CohesiveLaw, CzError, LawState};

use super::assembly::{FeProblem, InterfaceRule};
use super::crack::{self, CrackMeasures};
use super::energy::{self, Ledger};
use super::interface::PointKind;
use super::newton::{Newton, NewtonSettings, StepFailure};

/// How far and how finely to follow the path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSettings {
    /// Final value of the control unknown (either sign).
    pub target: f64,
    /// Number of equally spaced output abscissae between 0 and `target` (all are hit exactly).
    pub outputs: usize,
    /// Smallest displacement step, as a fraction of the output spacing, before switching to
    /// dissipation control.
    pub min_step_fraction: f64,
    /// Damage at or above which a point counts as fully debonded.
    pub damage_threshold: f64,
    /// Position of the initial crack front (reported as the tip until something debonds).
    pub crack_origin: f64,
    /// Newton settings.
    pub newton: NewtonSettings,
}

/// One converged state, in the units of the simulated part (not yet scaled by symmetry).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepRow {
    /// Control unknown.
    pub control: f64,
    /// Its reaction (work-conjugate generalised force).
    pub reaction: f64,
    /// Work of the reaction so far.
    pub external_work: f64,
    /// Strain energy of beams, springs and the interface's recoverable part.
    pub elastic_energy: f64,
    /// Energy dissipated by the interface so far.
    pub dissipated_energy: f64,
    /// Debonded length, process zone and tip along the cohesive points.
    pub crack: CrackMeasures,
}

/// Statistics of a run, for profiling and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunStats {
    /// Converged steps.
    pub steps: usize,
    /// Assemblies (Newton iterations including the final residual check).
    pub assemblies: usize,
    /// LU factorisations.
    pub factorizations: usize,
    /// Steps that had to be cut.
    pub cuts: usize,
    /// Dissipation-controlled steps.
    pub dissipation_steps: usize,
    /// Whether the run was solved on a window around the crack front ([`RunOptions::window`]).
    pub windowed: bool,
    /// Why a run asked to use the window was solved on the whole mesh instead.
    pub window_fallback: Option<&'static str>,
}

/// A failed run: the error and the converged rows.
#[derive(Clone, Debug)]
pub struct PathFailure {
    /// What went wrong.
    pub error: CzError,
    /// Rows that converged before it.
    pub rows: Vec<StepRow>,
}

/// Choices of a run beyond the path itself.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunOptions {
    /// How the interface is integrated. With [`InterfaceRule::Segments`] the crack measures come
    /// from the segments' fronts and each point's work is integrated along its gap path by the law
    /// ([`Ledger::commit_along`]).
    pub interface: InterfaceRule,
    /// Record only the output abscissae (and the states followed under the dissipation constraint,
    /// where the output grid cannot be followed) instead of every converged step. Then the rows'
    /// abscissae do not depend on the parameters, so a response interpolated between them is as
    /// smooth in the parameters as the states themselves.
    pub outputs_only: bool,
    /// Solve only a window around the crack front, the linear regions behind and ahead of it
    /// condensed exactly (`fe::window`), when the problem fits (small rotations, segments,
    /// one interface from near the loaded end to the far end, a law linear near the origin); any
    /// other problem, or a run whose checks fail, is solved on the whole mesh. Records the output
    /// abscissae only.
    pub window: bool,
}

struct State {
    q: Vec<f64>,
    states: Vec<LawState>,
    reaction: f64,
}

/// Runs problem `p` with `law` along the path described by `s` (nodal interface rule, every
/// converged step recorded).
pub fn run(p: &FeProblem, law: &dyn CohesiveLaw, s: &PathSettings) -> Result<(Vec<StepRow>, RunStats), PathFailure> {
    run_with(p, law, s, &RunOptions::default())
}

/// [`run`] with the choices of `o`.
pub fn run_with(
    p: &FeProblem,
    law: &dyn CohesiveLaw,
    s: &PathSettings,
    o: &RunOptions,
) -> Result<(Vec<StepRow>, RunStats), PathFailure> {
    let mut fallback = None;
    if o.window && o.interface == InterfaceRule::Segments {
        match super::window::run(p, law, s) {
            Ok((rows, mut stats)) => {
                stats.windowed = true;
                return Ok((rows, stats));
            }
            Err(why) => fallback = Some(why.reason()),
        }
    }
    let mut nw = Newton::with_rule(p, law, s.newton, o.interface);
    // With segments, forces are continuous and a good predictor leaves Newton in its basin: the
    // branch-cycling safeguard of the nodal rule only slows it down.
    nw.safeguard = o.interface == InterfaceRule::Nodal;
    let segments = o.interface == InterfaceRule::Segments;
    // Steps double after convergence in at most this many iterations. With segments a crack front
    // crossing many points per step is normal work for Newton (typically 4-5 quadratically
    // converging iterations), not a sign that the step is too long.
    let (grow_below, shrink_above) = if segments { (5, 9) } else { (3, 7) };
    let mode_one = if segments { super::segment::ModeOne::of(law) } else { None };
    let mut before = Vec::new();
    let n = nw.asm.n();
    let np = p.points.len();
    let cohesive: Vec<usize> = (0..np).filter(|&i| p.points[i].kind == PointKind::Cohesive).collect();
    let xs: Vec<f64> = cohesive.iter().map(|&i| p.mesh.x[p.points[i].node]).collect();
    let mut dmg = vec![0.0; cohesive.len()];
    let mut all_damage = vec![0.0; np];
    let mut point_stored = vec![0.0; np];
    let mut scratch = vec![0.0; cohesive.len()];
    let init = law.initial_state();
    let mut cur = State { q: vec![0.0; n], states: vec![init; np], reaction: 0.0 };
    let mut prev_q = vec![0.0; n];

    let mut trial = vec![0.0; n];
    let mut ledger = Ledger::new(np);
    let mut stats = RunStats { window_fallback: fallback, ..Default::default() };
    let mut rows =
        vec![StepRow { crack: CrackMeasures { tip: s.crack_origin, ..Default::default() }, ..Default::default() }];

    let fail = |rows: Vec<StepRow>, msg: String| PathFailure { error: CzError::Simulation(msg), rows };
    if !(s.target.is_finite() && s.target != 0.0 && s.outputs > 0) {
        return Err(fail(rows, "the path needs a finite, non-zero target and at least one output".into()));
    }
    let dir = s.target.signum();
    let spacing = s.target.abs() / s.outputs as f64;
    let h_min = spacing * s.min_step_fraction;
    let ic = p.control;
    // Signed progress along the control unknown.
    let mut pos = 0.0f64;
    let mut h = spacing;
    let mut h_prev = 0.0f64;
    let mut k_out = 1usize;
    let mut tau_hint = 0.0f64;
    let mut front = FrontTrack::default();

    let mut last_diss = 0.0f64;
    macro_rules! commit {
        ($lambda:expr, $record:expr) => {{
            let c_old = cur.q[ic];
            let r_old = cur.reaction;
            prev_q.copy_from_slice(&cur.q);
            cur.q.copy_from_slice(&trial);
            let reaction = $lambda;
            if segments {
                before.clone_from(&cur.states);
            }
            for (st, ev) in cur.states.iter_mut().zip(&nw.asm.trial) {
                *st = ev.state;
            }
            cur.reaction = reaction;
            if segments {
                let dc = cur.q[ic] - c_old;
                let (t, g) = (&nw.asm.trial, &nw.asm.gaps);
                ledger.commit_along(&p.points, law, &before, t, g, dc, r_old, reaction, mode_one.as_ref());
            } else {
                ledger.commit(&p.points, &nw.asm.trial, &nw.asm.gaps, cur.q[ic] - c_old, r_old, reaction);
            }
            let stored = energy::interface_stored(&p.points, law, &cur.states, &nw.asm.trial, &nw.asm.gaps);
            let dissipated = ledger.interface_work - stored;
            // With segments the recoverable energy is integrated like the forces (the dissipation
            // stays point by point, where the work is integrated).
            let stored = if segments {
                for (i, v) in point_stored.iter_mut().enumerate() {
                    let g = &nw.asm.gaps[i];
                    *v = match p.points[i].kind {
                        PointKind::Cohesive => law.stored_energy(g, &cur.states[i]),
                        PointKind::Contact => 0.5 * nw.asm.trial[i].traction.dot(g),
                    };
                }
                nw.asm.interface_stored(p, &point_stored)
            } else {
                stored
            };
            if dissipated - last_diss > 0.0 {
                tau_hint = dissipated - last_diss;
            }
            last_diss = dissipated;
            stats.steps += 1;
            if segments {
                front.commit(cur.q[ic], &nw.asm.segments, &nw.asm.fronts);
            }
            if $record {
                let structural = nw.asm.structural_energy(p, &cur.q);
                let crack = if segments {
                    for (d, st) in all_damage.iter_mut().zip(&cur.states) {
                        *d = st.damage;
                    }
                    {
                        let (segs, gaps, st) = (&nw.asm.segments, &nw.asm.gaps, &cur.states);
                        let level = |k: usize| {
                            let sg = &segs[k];
                            super::segment::level_front(
                                law,
                                gaps[sg.a],
                                gaps[sg.b],
                                &st[sg.a],
                                &st[sg.b],
                                s.damage_threshold,
                            )
                        };
                        crack::from_segments(
                            segs,
                            &nw.asm.fronts,
                            |i| all_damage[i],
                            s.crack_origin,
                            s.damage_threshold,
                            level,
                        )
                    }
                } else {
                    for (d, &i) in dmg.iter_mut().zip(&cohesive) {
                        *d = cur.states[i].damage;
                    }
                    crack::measure(&xs, &dmg, s.damage_threshold, s.crack_origin, &mut scratch)
                };
                rows.push(StepRow {
                    control: cur.q[ic],
                    reaction,
                    external_work: ledger.external_work,
                    elastic_energy: structural + stored,
                    dissipated_energy: dissipated,
                    crack,
                });
            }
        }};
    }

    let target = s.target.abs();
    let eps = 1e-12 * spacing;
    let mut dissipating = false;
    // After a detour through dissipation control, one failed displacement step sends the path
    // straight back (no step halving): the snap-backs of a propagating crack come one per node.
    let mut quick_fallback = false;
    let mut tau = 0.0f64;
    let mut last: Option<(f64, f64)> = None;
    // Control increment of the last dissipation step that moved forward (0: none).
    let mut dc_last = 0.0f64;
    let mut overshoots = 0usize;
    let max_steps = 200 * s.outputs + 20_000;
    while pos < target - eps {
        if stats.steps > max_steps {
            return Err(fail(rows, format!("gave up after {} steps at control {:.6}", stats.steps, dir * pos)));
        }
        if !dissipating {
            while k_out < s.outputs && spacing * k_out as f64 <= pos + eps {
                k_out += 1;
            }
            let next = if k_out >= s.outputs { target } else { spacing * k_out as f64 };
            let dh = h.min(next - pos);
            // Predictor: extrapolate the last increment.
            let alpha = if h_prev > 0.0 { dh / h_prev } else { 0.0 };
            for i in 0..n {
                trial[i] = cur.q[i] + alpha * (cur.q[i] - prev_q[i]);
            }
            if let Some(da) = front.advance(dir * dh) {
                shift_predictor(p, &cur.q, &mut trial, front.x, da, front.zone());
            }
            trial[ic] = dir * (pos + dh);
            match nw.solve_displacement(p, law, &cur.states, &mut trial) {
                Ok(it) => {
                    let reaction = nw.f[ic];
                    let lands = (next - (pos + dh)).abs() <= eps;
                    commit!(reaction, !o.outputs_only || lands);
                    pos = if (next - (pos + dh)).abs() <= eps { next } else { pos + dh };
                    h_prev = dh;
                    quick_fallback = false;
                    if it <= grow_below {
                        h = (2.0 * h).min(spacing);
                    } else if it >= shrink_above {
                        h *= 0.5;
                    }
                }
                Err(e) => {
                    stats.cuts += 1;
                    h = 0.5 * dh;
                    if h >= h_min && !quick_fallback {
                        continue;
                    }
                    // Snap-back (or a genuinely hard step): follow the path by dissipation. That
                    // needs a loaded, dissipating state; without one no snap-back is possible and
                    // the failure is genuine.
                    if !(tau_hint > 0.0 && cur.reaction != 0.0 && cur.q[ic] != 0.0) {
                        let msg = format!(
                            "no convergence at control {:.6} ({e:?}) even with steps of {:.3e}, and nothing has \
                             dissipated yet, so no snap-back to follow",
                            dir * (pos + dh),
                            dh
                        );
                        return Err(fail(rows, msg));
                    }
                    dissipating = true;
                    if tau <= 0.0 || !quick_fallback {
                        tau = tau_hint;
                    }
                    last = None;
                }
            }
        } else {
            let c0 = cur.q[ic];
            let l0 = cur.reaction;
            // Do not jump past the target: the run must end exactly on it.
            let tau_try = if dc_last > 0.0 && pos + dc_last * 1.5 > target {
                tau * (0.5 * (target - pos) / dc_last).clamp(0.05, 1.0)
            } else {
                tau
            };
            let mut lam = l0;
            trial.copy_from_slice(&cur.q);
            if let Some((dl_prev, tau_prev)) = last {
                let beta = tau_try / tau_prev;
                for i in 0..n {
                    trial[i] += beta * (cur.q[i] - prev_q[i]);
                }
                lam += beta * dl_prev;
            }
            match nw.solve_dissipation(p, law, &cur.states, &mut trial, &mut lam, c0, l0, tau_try) {
                Ok(_) if dir * trial[ic] > target + eps && overshoots < 3 => {
                    // Would end beyond the target: retry with a smaller increment so the run ends
                    // on the target under displacement control. If the target lies inside a
                    // snap-back no forward step can stop there; the run then ends just beyond it.
                    tau *= 0.25;
                    last = None;
                    overshoots += 1;
                    stats.cuts += 1;
                }
                Ok(it) => {
                    commit!(lam, true);
                    stats.dissipation_steps += 1;
                    last = Some((lam - l0, tau_try));
                    let dc = (cur.q[ic] - c0).abs();
                    dc_last = dc * tau_ratio_guard(dir * (cur.q[ic] - c0));
                    pos = dir * cur.q[ic];
                    // Aim at steps of about half the output spacing in the control.
                    if it <= 4 && dc > 0.0 {
                        tau *= (0.5 * spacing / dc).clamp(0.5, 2.0);
                    } else if it >= shrink_above {
                        tau *= 0.6;
                    }
                    // Stay on dissipation control while the crack runs (each node that fails is a
                    // small snap-back for displacement control); return to displacement control to
                    // end exactly at the target, or when nothing dissipates any more.
                    // With segments a snap-back is genuine, not one per point: go back to
                    // displacement control after every forward step.
                    let near_end = pos + spacing >= target;
                    if dir * (cur.q[ic] - c0) > 0.0 && (near_end || segments) {
                        dissipating = false;
                        quick_fallback = true;
                        h = (0.5 * spacing).max(h_min);
                        h_prev = 0.0;
                    }
                }
                Err(_) => {
                    stats.cuts += 1;
                    tau *= 0.5;
                    last = None;
                    if tau < 1e-12 * ledger.external_work.abs().max(1e-300) {
                        // Last resort: jump over the unstable stretch under displacement control
                        // (the states recorded are still equilibria; the skipped part is not).
                        let mut jumped = false;
                        for k in 1..=4 {
                            // (may end beyond the target when it lies inside the unstable stretch)
                            let dh = 0.5 * spacing * k as f64;
                            trial.copy_from_slice(&cur.q);
                            trial[ic] = dir * (pos + dh);
                            if nw.solve_displacement(p, law, &cur.states, &mut trial).is_ok() {
                                let reaction = nw.f[ic];
                                commit!(reaction, true);
                                pos += dh;
                                jumped = true;
                                break;
                            }
                        }
                        if jumped {
                            dissipating = false;
                            quick_fallback = true;
                            h = (0.5 * spacing).max(h_min);
                            h_prev = 0.0;
                            tau = tau_hint.max(tau);
                            continue;
                        }
                        let msg = format!(
                            "no convergence at control {:.6}: displacement control failed and the dissipation \
                             constraint could not be met with increments down to {tau:.3e} N·mm",
                            dir * pos
                        );
                        return Err(fail(rows, msg));
                    }
                }
            }
        }
    }
    stats.assemblies = nw.counters.0;
    stats.factorizations = nw.counters.1;
    Ok((rows, stats))
}

/// The most advanced onset front of the segment rule over the last two commits, for predicting
/// how far it moves in the next step.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct FrontTrack {
    /// Control and front position at the previous and the last commit (NaN: no front).
    hist: [(f64, f64); 2],
    /// Front position at the last commit.
    pub(crate) x: f64,
    /// Distance between the onset and the failure front (or the crack origin) at the last commit.
    zone_length: f64,
    /// Length of the segment holding the front.
    element: f64,
    known: usize,
}

impl FrontTrack {
    pub(crate) fn commit(&mut self, control: f64, segments: &[super::segment::Segment], fronts: &[[Option<f64>; 2]]) {
        let (mut onset, mut failure, mut element) = (f64::NAN, f64::NAN, 0.0);
        for (sg, fr) in segments.iter().zip(fronts) {
            if let Some(e) = fr[0] {
                onset = sg.x + e * sg.len;
                element = sg.len;
            }
            if let Some(e) = fr[1] {
                failure = sg.x + e * sg.len;
            }
        }
        self.hist = [self.hist[1], (control, onset)];
        self.known = if onset.is_finite() { (self.known + 1).min(2) } else { 0 };
        self.x = onset;
        self.element = element;
        self.zone_length = if failure.is_finite() { (onset - failure).abs() } else { 0.0 };
    }

    /// Front advance over a control increment `dc`, extrapolated from the last two commits.
    pub(crate) fn advance(&self, dc: f64) -> Option<f64> {
        let [(c0, x0), (c1, x1)] = self.hist;
        (self.known == 2 && c1 != c0).then(|| (x1 - x0) / (c1 - c0) * dc)
    }

    /// Half-width of the region that travels with the front: the process zone and the elastic
    /// region ahead of it where the gaps are still large (a few process zones), at least a few
    /// elements.
    pub(crate) fn zone(&self) -> f64 {
        (4.0 * self.zone_length).max(20.0 * self.element)
    }
}

/// Predictor for a propagating crack: near the front a cohesive zone travels along the interface
/// with its shape nearly unchanged, which extrapolating the unknowns linearly cannot represent (it
/// superposes two fronts). Unknowns of nodes within `zone` of the front at `x` are replaced by the
/// current solution translated by the predicted advance `da` (interpolated linearly between
/// nodes); Newton then only corrects the shape.
fn shift_predictor(p: &FeProblem, cur: &[f64], trial: &mut [f64], x: f64, da: f64, zone: f64) {
    use super::mesh::NONE;
    let xs = &p.mesh.x;
    let nn = xs.len();
    for i in 0..nn {
        if (xs[i] - x).abs() > zone {
            continue;
        }
        let xt = xs[i] - da;
        let j = xs.partition_point(|v| *v <= xt).clamp(1, nn - 1) - 1;
        let t = ((xt - xs[j]) / (xs[j + 1] - xs[j])).clamp(0.0, 1.0);
        for layer in 0..p.mesh.layers.len() {
            let (di, dj, dk) = (p.mesh.dofs(layer, i), p.mesh.dofs(layer, j), p.mesh.dofs(layer, j + 1));
            for c in 0..4 {
                if di[c] != NONE && dj[c] != NONE && dk[c] != NONE && di[c] != p.control {
                    trial[di[c]] = (1.0 - t) * cur[dj[c]] + t * cur[dk[c]];
                }
            }
        }
    }
}

/// A backward dissipation step (snap-back) says nothing about the forward reach of the next one.
fn tau_ratio_guard(forward: f64) -> f64 {
    if forward > 0.0 {
        1.0
    } else {
        0.0
    }
}

impl From<StepFailure> for CzError {
    fn from(e: StepFailure) -> Self {
        CzError::Simulation(format!("{e:?}"))
    }
}
