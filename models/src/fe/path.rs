//! Path following: adaptive displacement control that lands exactly on an output grid, with a
//! dissipation-controlled detour through snap-backs.
//!
//! * **Displacement control.** The control unknown advances towards the next output abscissa in
//!   steps that double after fast convergence (≤ 3 iterations) and halve after a failure. The
//!   predictor extrapolates the last increment, so on a smooth branch Newton starts within its
//!   quadratic basin. Every output abscissa is hit exactly, so a response read at those
//!   abscissae is an equilibrium state, not an interpolation between adaptively placed steps: this
//!   keeps responses smooth in the parameters (finite-difference Jacobians).
//! * **Snap-back.** When displacement control cannot proceed even at the smallest step, the
//!   equilibrium path turns back in the control displacement (a cohesive crack advancing node by
//!   node does this once per node). The solver then switches to the dissipation constraint
//!   (released energy per step prescribed, Gutiérrez 2004; Verhoosel, Remmers & Gutiérrez 2009),
//!   which follows snap-backs because dissipation only increases, with the released energy
//!   adapted to give control increments of about half an output spacing. It stays there while the
//!   crack runs and returns to displacement control to end on the target; if the target lies
//!   inside an unstable stretch, or dissipation control itself stalls, it jumps over the stretch
//!   under displacement control (the recorded states are still equilibria).
//! * A run that still fails returns the error and every row that converged.

use czid_core::{CohesiveLaw, CzError, LawState};

use super::assembly::FeProblem;
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
}

/// A failed run: the error and the converged rows.
#[derive(Clone, Debug)]
pub struct PathFailure {
    /// What went wrong.
    pub error: CzError,
    /// Rows that converged before it.
    pub rows: Vec<StepRow>,
}

struct State {
    q: Vec<f64>,
    states: Vec<LawState>,
    reaction: f64,
}

/// Runs problem `p` with `law` along the path described by `s`.
pub fn run(p: &FeProblem, law: &dyn CohesiveLaw, s: &PathSettings) -> Result<(Vec<StepRow>, RunStats), PathFailure> {
    let mut nw = Newton::new(p, law, s.newton);
    let n = nw.asm.n();
    let np = p.points.len();
    let cohesive: Vec<usize> = (0..np).filter(|&i| p.points[i].kind == PointKind::Cohesive).collect();
    let xs: Vec<f64> = cohesive.iter().map(|&i| p.mesh.x[p.points[i].node]).collect();
    let mut dmg = vec![0.0; cohesive.len()];
    let mut scratch = vec![0.0; cohesive.len()];
    let init = law.initial_state();
    let mut cur = State { q: vec![0.0; n], states: vec![init; np], reaction: 0.0 };
    let mut prev_q = vec![0.0; n];
    let mut trial = vec![0.0; n];
    let mut ledger = Ledger::new(np);
    let mut stats = RunStats::default();
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

    macro_rules! commit {
        ($lambda:expr) => {{
            let c_old = cur.q[ic];
            let r_old = cur.reaction;
            prev_q.copy_from_slice(&cur.q);
            cur.q.copy_from_slice(&trial);
            let reaction = $lambda;
            for (st, ev) in cur.states.iter_mut().zip(&nw.asm.trial) {
                *st = ev.state;
            }
            cur.reaction = reaction;
            ledger.commit(&p.points, &nw.asm.trial, &nw.asm.gaps, cur.q[ic] - c_old, r_old, reaction);
            let stored = energy::interface_stored(&p.points, law, &cur.states, &nw.asm.trial, &nw.asm.gaps);
            let structural = nw.asm.structural_energy(p, &cur.q);
            for (d, &i) in dmg.iter_mut().zip(&cohesive) {
                *d = cur.states[i].damage;
            }
            let crack = crack::measure(&xs, &dmg, s.damage_threshold, s.crack_origin, &mut scratch);
            let dissipated = ledger.interface_work - stored;
            let last_diss = rows.last().map_or(0.0, |r| r.dissipated_energy);
            if dissipated - last_diss > 0.0 {
                tau_hint = dissipated - last_diss;
            }
            stats.steps += 1;
            rows.push(StepRow {
                control: cur.q[ic],
                reaction,
                external_work: ledger.external_work,
                elastic_energy: structural + stored,
                dissipated_energy: dissipated,
                crack,
            });
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
            trial[ic] = dir * (pos + dh);
            match nw.solve_displacement(p, law, &cur.states, &mut trial) {
                Ok(it) => {
                    let reaction = nw.f[ic];
                    commit!(reaction);
                    pos = if (next - (pos + dh)).abs() <= eps { next } else { pos + dh };
                    h_prev = dh;
                    quick_fallback = false;
                    if it <= 3 {
                        h = (2.0 * h).min(spacing);
                    } else if it >= 7 {
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
                    commit!(lam);
                    stats.dissipation_steps += 1;
                    last = Some((lam - l0, tau_try));
                    let dc = (cur.q[ic] - c0).abs();
                    dc_last = dc * tau_ratio_guard(dir * (cur.q[ic] - c0));
                    pos = dir * cur.q[ic];
                    // Aim at steps of about half the output spacing in the control.
                    if it <= 4 && dc > 0.0 {
                        tau *= (0.5 * spacing / dc).clamp(0.5, 2.0);
                    } else if it >= 7 {
                        tau *= 0.6;
                    }
                    // Stay on dissipation control while the crack runs (each node that fails is a
                    // small snap-back for displacement control); return to displacement control to
                    // end exactly at the target, or when nothing dissipates any more.
                    let near_end = pos + spacing >= target;
                    if dir * (cur.q[ic] - c0) > 0.0 && (near_end || it == usize::MAX) {
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
                                commit!(reaction);
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
