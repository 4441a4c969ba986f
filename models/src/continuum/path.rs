//! Path following of a continuum problem: Newton under displacement control, switching to
//! crack-front opening control where a displacement step fails or dissipates more than a crack
//! advance of a few elements, so the path passes through the snap-backs of an unstable crack (the
//! applied displacement then falls).
//!
//! Opening control (a local arc length, de Borst 1987; the crack-tip control of the beam engine
//! in spirit, written anew here) prescribes the effective opening `√(⟨g_n⟩² + g_t²)` of the most
//! opened point that has not failed, the one just ahead of the crack, and solves for the applied
//! displacement with the unknowns: a bordered Newton system solved with one factorisation and two
//! right-hand sides. That opening grows monotonically through a snap-back, where both the load and
//! the applied displacement fall.
//!
//! Energies are integrated where they arise: the external work by the trapezoidal rule on the
//! load–displacement path, the interface's work at every cohesive point by the trapezoidal rule on
//! its traction–gap path, and the arms' strain energy from their state. The dissipated energy is
//! the interface's work less the energy its points still store, so the balance `W = U + D` is a
//! check on the solution, not an identity.

use czid_core::{CohesiveLaw, CzError, LawState};
use nalgebra::Vector4;

use super::measures::{measure, CrackMeasures};
use super::problem::{Assembled, ContinuumProblem, Elements};
use super::solver::System;
use crate::fe::newton::ROUND_OFF_FLOOR;

/// Settings of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct PathSettings {
    /// Final value of the controlled unknowns (mm).
    pub target: f64,
    /// Equally spaced displacements recorded (the output grid).
    pub outputs: usize,
    /// Largest energy a displacement-controlled step may dissipate before the path switches to
    /// opening control (N·mm, in the mesh's share).
    pub max_dissipation: f64,
    /// Largest opening increment of an opening-controlled step (mm).
    pub max_opening_step: f64,
    /// Newton iterations before a step is cut.
    pub max_iterations: usize,
    /// Relative residual tolerance.
    pub tolerance: f64,
    /// Damage from which a point counts as debonded.
    pub damage_threshold: f64,
    /// Where the crack starts (mm).
    pub crack_origin: f64,
    /// Stop once the crack tip passes this position (mm).
    pub stop_tip: f64,
}

/// One recorded state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Row {
    /// Value of the controlled unknowns (mm).
    pub control: f64,
    /// Their summed reaction (N).
    pub reaction: f64,
    /// Crack measures.
    pub crack: CrackMeasures,
    /// External work (N·mm).
    pub external_work: f64,
    /// Strain energy of the arms plus energy stored in the interface (N·mm).
    pub elastic_energy: f64,
    /// Energy dissipated at the cohesive points (N·mm).
    pub dissipated_energy: f64,
}

/// Statistics of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Converged steps.
    pub steps: usize,
    /// Factorisations.
    pub factorisations: usize,
    /// Unknowns.
    pub unknowns: usize,
    /// Stored matrix entries (band or sparse pattern).
    pub stored: usize,
    /// Seconds spent factorising and solving.
    pub solver_seconds: f64,
    /// Steps accepted at the residual's round-off floor rather than at the tolerance: where no
    /// step converges however short, a step whose relative residual has stayed within ten times
    /// the tolerance for five iterations without halving. 0 unless the path would otherwise have
    /// stopped.
    pub floor_steps: usize,
}

/// A run that stopped early: why, and the rows before.
#[derive(Debug)]
pub struct Failure {
    /// Why.
    pub error: CzError,
    /// Converged rows.
    pub rows: Vec<Row>,
}

/// The committed state of the path.
#[derive(Clone)]
struct State {
    u: Vec<f64>,
    delta: f64,
    reaction: f64,
    laws: Vec<LawState>,
    gaps: Vec<czid_core::Gap>,
    tractions: Vec<nalgebra::Vector2<f64>>,
    work: Vec<f64>,
    bubbles: Vec<Vector4<f64>>,
    external: f64,
    /// The step that led here, the predictor of the next one of the same control.
    last: Option<LastStep>,
}

/// A converged step's change of the unknowns and of the applied displacement, per unit of its
/// control's increment (the applied displacement's, or the front opening's).
#[derive(Clone)]
struct LastStep {
    by_opening: bool,
    du: Vec<f64>,
    dd: f64,
}

struct Evaluation {
    assembled: Assembled,
    reaction: f64,
    norm: f64,
    constraint: f64,
}

#[derive(Clone, Copy)]
enum Control {
    /// The controlled unknowns at this value (mm).
    Displacement(f64),
    /// The effective opening of cohesive point `point` at `target` (mm).
    Opening { point: usize, target: f64 },
}

struct Solver<'a> {
    p: &'a ContinuumProblem,
    law: &'a dyn CohesiveLaw,
    elements: Elements,
    system: System,
    held: Vec<bool>,
    stats: Stats,
    settings: &'a PathSettings,
    /// Accept a step whose residual has settled at the round-off floor (see [`FLOOR_ITERATIONS`]).
    /// Switched on only where the path would otherwise stop, so runs that converge are untouched.
    accept_floor: bool,
}

/// Where no step converges however short, a step whose residual stays within
/// [`ROUND_OFF_FLOOR`] times the tolerance for this many iterations without falling has reached
/// the floor the arithmetic of its states allows, as the beam engine's dissipation-controlled
/// steps do.
///
/// On long total-Lagrangian runs (large rotations of a stiff arm, a crack far along) the
/// residual of a converged step settles at 1.0–1.3 times a 10⁻⁸ tolerance and stays there while
/// the applied displacement no longer moves: cutting the step does not lower it, and the path
/// would stop with the state found. Accepting such a step is accepting what the arithmetic gives.
const FLOOR_ITERATIONS: usize = 5;

/// Follows the path of `p` with `law` to `settings.target`.
pub fn run(p: &ContinuumProblem, law: &dyn CohesiveLaw, settings: &PathSettings) -> Result<(Vec<Row>, Stats), Failure> {
    let n = p.unknowns();
    let mut held = vec![false; n];
    for &d in p.fixed.iter().chain(p.control.iter().map(|(d, _)| d)) {
        held[d] = true;
    }
    let system = p.system();
    let stats = Stats { unknowns: n, stored: system.stored(), ..Default::default() };
    let mut s = Solver { p, law, elements: p.elements(), system, held, stats, settings, accept_floor: false };
    let m = p.cohesive.len();
    let ne = p.grid.elements().len();
    let mut state = State {
        u: vec![0.0; n],
        delta: 0.0,
        reaction: 0.0,
        laws: vec![law.initial_state(); m],
        gaps: vec![czid_core::Gap::zeros(); m],
        tractions: vec![nalgebra::Vector2::zeros(); m],
        work: vec![0.0; m],
        bubbles: vec![Vector4::zeros(); if p.large { ne } else { 0 }],
        external: 0.0,
        last: None,
    };
    let mut rows = vec![s.row(&state)];
    let grid = settings.target / settings.outputs as f64;
    let min_step = grid * 1e-4;
    let mut step = grid;
    let mut opening_step = settings.max_opening_step;
    let mut by_opening = false;
    let fail = |rows: Vec<Row>, why: String| Failure { error: CzError::Simulation(why), rows };
    while state.delta < settings.target * (1.0 - 1e-12) {
        if rows.last().is_some_and(|r| r.crack.tip >= settings.stop_tip) {
            break;
        }
        if !by_opening {
            // The next point of the output grid, or a cut step towards it.
            let next_grid = ((state.delta / grid + 1e-9).floor() + 1.0) * grid;
            let to = (state.delta + step).min(next_grid).min(settings.target);
            match s.step(&state, Control::Displacement(to)) {
                Ok(next) => {
                    let released = s.row(&next).dissipated_energy - rows.last().map_or(0.0, |r| r.dissipated_energy);
                    if released > settings.max_dissipation {
                        by_opening = true;
                        opening_step = 0.05 * settings.max_opening_step;
                        continue;
                    }
                    state = next;
                    rows.push(s.row(&state));
                    step = (step * 2.0).min(grid);
                }
                // Two cuts without convergence: the load point cannot lead (a snap-back, or a
                // point cycling on its law's kink), the crack front can.
                Err(_) if step > grid / 20.0 && step > min_step => step *= 0.25,
                Err(_) => {
                    by_opening = true;
                    // Small first steps: the path may still be near its peak.
                    opening_step = 0.05 * settings.max_opening_step;
                }
            }
        } else {
            let Some((point, now)) = s.front_point(&state) else {
                break;
            };
            let control = Control::Opening { point, target: now + opening_step };
            let result = s.step(&state, control).and_then(|next| {
                // A converged state far from the last one (another branch) is not the path.
                if (next.delta - state.delta).abs() > 10.0 * grid || next.reaction * state.reaction < 0.0 {
                    Err(format!("the step jumped from {} to {} mm", state.delta, next.delta))
                } else {
                    Ok(next)
                }
            });
            match result {
                Ok(next) => {
                    // Grow the step while it converges, but keep the recorded rows about one
                    // output spacing apart in the applied displacement: the record is read
                    // between its rows.
                    let moved = (next.delta - state.delta).abs();
                    let growth = if moved > 0.0 { (grid / moved).clamp(0.25, 1.5) } else { 1.5 };
                    state = next;
                    rows.push(s.row(&state));
                    opening_step = (opening_step * growth).min(settings.max_opening_step);
                }
                Err(why) => {
                    opening_step *= 0.25;
                    if opening_step < settings.max_opening_step * 1e-4 && !s.accept_floor {
                        // The last resort before stopping: from here on, a step whose residual
                        // has settled just above the tolerance is taken as converged.
                        s.accept_floor = true;
                        opening_step = 0.05 * settings.max_opening_step;
                    } else if opening_step < settings.max_opening_step * 1e-4 {
                        return Err(fail(
                            rows,
                            format!("the path could not be followed past {:.4} mm: {why}", state.delta),
                        ));
                    }
                }
            }
        }
    }
    Ok((rows, s.stats))
}

impl Solver<'_> {
    /// The most opened cohesive point that has not failed, and its effective opening.
    fn front_point(&self, st: &State) -> Option<(usize, f64)> {
        st.laws
            .iter()
            .zip(&st.gaps)
            .enumerate()
            .filter(|(_, (l, _))| l.damage < self.settings.damage_threshold.min(1.0 - 1e-9))
            .map(|(i, (_, g))| (i, effective(g)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }

    fn row(&self, st: &State) -> Row {
        let stored: f64 = self
            .p
            .cohesive
            .iter()
            .zip(st.gaps.iter().zip(&st.laws))
            .map(|(pt, (g, l))| self.law.stored_energy(g, l) * pt.area * pt.factor())
            .sum();
        let work: f64 = st.work.iter().sum();
        let bulk = self.bulk_energy(st);
        let xs: Vec<f64> = self.p.cohesive.iter().map(|p| p.x).collect();
        let damage: Vec<f64> = st.laws.iter().map(|l| l.damage).collect();
        Row {
            control: st.delta,
            reaction: st.reaction,
            crack: measure(&xs, &damage, self.settings.damage_threshold, self.settings.crack_origin),
            external_work: st.external,
            elastic_energy: bulk + stored + self.p.contact_energy(&st.u),
            dissipated_energy: work - stored,
        }
    }

    fn bulk_energy(&self, st: &State) -> f64 {
        // Cheap next to a step: one assembly without the tangent.
        self.p.assemble(&self.elements, self.law, &st.u, &st.laws, &st.bubbles, None).bulk_energy
    }

    /// One step from `st` under `control`; the converged state, or why Newton failed.
    ///
    /// Newton with a backtracking line search on the residual: where a cohesive point sits on the
    /// kink of its law (the peak, the onset of damage), plain Newton can cycle between loading and
    /// unloading it; halving the update until the residual falls breaks the cycle. Where no
    /// halving lowers it (points crossing their kinks), the full update is taken: short ones
    /// left the crack-front points where they were, 10–19 iterations a step instead of about 6.
    fn step(&mut self, st: &State, control: Control) -> Result<State, String> {
        let n = self.p.unknowns();
        let mut u = st.u.clone();
        let mut delta = match control {
            Control::Displacement(to) => to,
            Control::Opening { .. } => st.delta,
        };
        // The control's increment, and under large displacements the state extrapolated along
        // the last step of the same control: the whole field moves, not the load point (or the
        // front) alone. From the last state alone, a front-opening step of the total Lagrangian
        // arms started with a residual ten times the load, which Newton's damped updates took 6
        // to 18 iterations to bring down (the book's "Beam or continuum?"). In small strain
        // Newton converges in a few iterations from the last state, and the runs are left as
        // they were.
        let (by_opening, increment) = match control {
            Control::Displacement(to) => (false, to - st.delta),
            Control::Opening { point, target } => (true, target - effective(&st.gaps[point])),
        };
        if let Some(last) = st.last.as_ref().filter(|l| self.p.large && l.by_opening == by_opening) {
            for (v, r) in u.iter_mut().zip(&last.du) {
                *v += r * increment;
            }
            if by_opening {
                delta += last.dd * increment;
            }
        }
        let p0 = st.reaction;
        let mut current = self.evaluate(&mut u, delta, st, &control, true);
        // Relative residuals of the iterations so far, for the floor test.
        let mut history: Vec<f64> = Vec::with_capacity(self.settings.max_iterations);
        for iteration in 0..self.settings.max_iterations {
            let Evaluation { assembled: a, reaction, norm, constraint } = current;
            // The load is the scale of the residual; the reaction of a displacement predictor
            // (the controlled unknowns moved alone) is not.
            let scale = p0.abs().max(reaction.abs()).max(1e-9);
            let relative = norm / scale;
            history.push(relative);
            let constrained = match control {
                Control::Displacement(_) => true,
                Control::Opening { .. } => constraint.abs() <= 1e-9 * self.settings.max_opening_step,
            };
            let converged = iteration > 0 && relative <= self.settings.tolerance && constrained;
            let floor = !converged && self.accept_floor && constrained && at_floor(&history, self.settings.tolerance);
            if converged || floor {
                self.stats.floor_steps += usize::from(floor);
                return Ok(self.commit(st, u, delta, reaction, a, (by_opening, increment)));
            }
            if !norm.is_finite() {
                return Err("the residual is not finite".into());
            }
            let (du, dd) = self.direction(&a, constraint, &control)?;
            // Backtracking: the full update first, then halves while the residual grows.
            // The opening's error weighs as the force that would close it over the step's size.
            let weight = scale / self.settings.max_opening_step;
            let merit = |e: &Evaluation| e.norm + e.constraint.abs() * weight;
            let start = norm + constraint.abs() * weight;
            let step = |alpha: f64| -> (Vec<f64>, f64) {
                let mut trial = u.clone();
                for i in 0..n {
                    trial[i] += alpha * du[i];
                }
                (trial, delta + alpha * dd)
            };
            let mut alpha = 1.0;
            // The full update's state and evaluation, kept while shorter ones are tried (their
            // evaluations leave the system holding the full update's tangent).
            let mut full_update = None;
            current = loop {
                let (mut trial, td) = step(alpha);
                // The full update usually stands: assemble its tangent with its residual.
                let full = alpha == 1.0;
                let e = self.evaluate(&mut trial, td, st, &control, full);
                if merit(&e) < start || iteration == 0 {
                    u = trial;
                    delta = td;
                    break if full { e } else { self.evaluate(&mut u, delta, st, &control, true) };
                }
                if full {
                    full_update = Some((trial, td, e));
                } else if alpha < 0.1 {
                    // No shorter update lowers the residual: the points crossing a kink of their
                    // law (onset, unloading) make it a poor guide there. A short update would keep
                    // them where they are for many iterations; the full one moves them to the
                    // side of the kink their law puts them on, and Newton converges from there.
                    let Some((t, d, e)) = full_update.take() else {
                        // Unreachable (the full update is tried first), but never a loop.
                        (u, delta) = (trial, td);
                        break self.evaluate(&mut u, delta, st, &control, true);
                    };
                    (u, delta) = (t, d);
                    break e;
                }
                alpha *= 0.5;
            };
        }
        Err(format!("Newton did not converge in {} iterations", self.settings.max_iterations))
    }

    /// Residual (and tangent, when `tangent`) at `u` with the controlled unknowns at `delta`.
    fn evaluate(&mut self, u: &mut [f64], delta: f64, st: &State, control: &Control, tangent: bool) -> Evaluation {
        for &(c, w) in &self.p.control {
            u[c] = w * delta;
        }
        let a = if tangent {
            self.p.assemble(&self.elements, self.law, u, &st.laws, &st.bubbles, Some(&mut self.system))
        } else {
            self.p.assemble(&self.elements, self.law, u, &st.laws, &st.bubbles, None)
        };
        let reaction: f64 = self.p.control.iter().map(|&(c, w)| w * a.force[c]).sum();
        let norm = (0..a.force.len()).filter(|&i| !self.held[i]).map(|i| a.force[i] * a.force[i]).sum::<f64>().sqrt();
        let constraint = match control {
            Control::Displacement(_) => 0.0,
            Control::Opening { point, target } => effective(&a.interface.gaps[*point]) - target,
        };
        Evaluation { assembled: a, reaction, norm, constraint }
    }

    /// The Newton update `(du, dδ)` from the assembled tangent.
    fn direction(&mut self, a: &Assembled, constraint: f64, control: &Control) -> Result<(Vec<f64>, f64), String> {
        let n = self.p.unknowns();
        // Column of the control (summed over the controlled unknowns with their factors), before the held
        // rows and columns are replaced by the identity.
        let mut col = vec![0.0; n];
        for &(c, w) in &self.p.control {
            for i in self.system.neighbours(c) {
                col[i] += w * self.system.get(i, c);
            }
        }
        for i in 0..n {
            if self.held[i] {
                self.system.set_identity(i);
                col[i] = 0.0;
            }
        }
        let t = std::time::Instant::now();
        self.system.factor()?;
        let mut ra: Vec<f64> = (0..n).map(|i| if self.held[i] { 0.0 } else { -a.force[i] }).collect();
        let mut rb: Vec<f64> = col.iter().map(|v| -v).collect();
        // Under displacement control the control's column plays no part (dδ = 0).
        match control {
            Control::Displacement(_) => self.system.solve(&mut ra),
            Control::Opening { .. } => self.system.solve2(&mut ra, &mut rb),
        }
        self.stats.factorisations += 1;
        self.stats.solver_seconds += t.elapsed().as_secs_f64();
        // Under displacement control the controlled unknowns already sit at their new value in
        // the residual, so the free ones follow from it alone.
        let dd = match control {
            Control::Displacement(_) => 0.0,
            Control::Opening { point, .. } => {
                // g(u) = |gap(u)| − target, linearised with du = a + b dδ (g does not depend on δ
                // directly: the controlled unknowns are not on the interface).
                let c = self.p.cohesive[*point].opening_gradient(&a.interface.gaps[*point]);
                let dot =
                    |v: &[f64]| -> f64 { c.iter().map(|&(i, w)| if self.held[i] { 0.0 } else { w * v[i] }).sum() };
                let denom = dot(&rb);
                if denom.abs() < 1e-300 {
                    return Err("the controlled opening does not respond to the load".into());
                }
                (-constraint - dot(&ra)) / denom
            }
        };
        let du = match control {
            Control::Displacement(_) => (0..n).map(|i| if self.held[i] { 0.0 } else { ra[i] }).collect(),
            Control::Opening { .. } => (0..n).map(|i| if self.held[i] { 0.0 } else { ra[i] + rb[i] * dd }).collect(),
        };
        Ok((du, dd))
    }

    fn commit(
        &mut self,
        st: &State,
        u: Vec<f64>,
        delta: f64,
        reaction: f64,
        a: Assembled,
        (by_opening, increment): (bool, f64),
    ) -> State {
        self.stats.steps += 1;
        let work: Vec<f64> = self
            .p
            .cohesive
            .iter()
            .enumerate()
            .map(|(i, pt)| {
                let dg = a.interface.gaps[i] - st.gaps[i];
                st.work[i] + 0.5 * (st.tractions[i] + a.interface.tractions[i]).dot(&dg) * pt.area * pt.factor()
            })
            .collect();
        let last = (self.p.large && increment.abs() > 0.0).then(|| LastStep {
            by_opening,
            du: u.iter().zip(&st.u).map(|(a, b)| (a - b) / increment).collect(),
            dd: (delta - st.delta) / increment,
        });
        State {
            external: st.external + 0.5 * (st.reaction + reaction) * (delta - st.delta),
            last,
            u,
            delta,
            reaction,
            laws: a.interface.states,
            gaps: a.interface.gaps,
            tractions: a.interface.tractions,
            work,
            bubbles: if self.p.large { a.bubbles } else { Vec::new() },
        }
    }
}

/// Whether the last [`FLOOR_ITERATIONS`] relative residuals all lie within [`ROUND_OFF_FLOOR`] times
/// `tolerance` and the last is no lower than half the first of them: Newton has stopped gaining,
/// at a level just above the tolerance.
fn at_floor(history: &[f64], tolerance: f64) -> bool {
    let Some(last) = history.len().checked_sub(FLOOR_ITERATIONS).map(|i| &history[i..]) else {
        return false;
    };
    last.iter().all(|&r| r <= ROUND_OFF_FLOOR * tolerance) && last[FLOOR_ITERATIONS - 1] >= 0.5 * last[0]
}

/// Effective opening `√(⟨g_n⟩² + g_t²)` (mm).
fn effective(g: &czid_core::Gap) -> f64 {
    (g[0].max(0.0).powi(2) + g[1] * g[1]).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_residual_settled_just_above_the_tolerance_is_at_the_floor() {
        // Case 9 of the large-rotation bench: three updates, then 1.0–1.3e-8 against 1e-8.
        let settled = [3e-2, 4e-5, 2e-8, 1.2e-8, 1.05e-8, 1.3e-8, 1.1e-8, 1.25e-8];
        assert!(at_floor(&settled, 1e-8));
    }

    #[test]
    fn a_residual_still_falling_or_far_above_the_tolerance_is_not_at_the_floor() {
        // Still converging (halving each iteration): Newton has not stopped gaining.
        assert!(!at_floor(&[8e-8, 4e-8, 2e-8, 1.5e-8, 1.1e-8, 3e-9], 1e-8));
        let falling = [9e-8, 6e-8, 4e-8, 3e-8, 2e-8];
        assert!(!at_floor(&falling, 1e-8));
        // Stalled, but a hundred times the tolerance: not converged, whatever the arithmetic.
        assert!(!at_floor(&[1e-6; 8], 1e-8));
        // Fewer iterations than the test needs.
        assert!(!at_floor(&[1.1e-8; 4], 1e-8));
        // One iteration of the window above the floor's ceiling.
        assert!(!at_floor(&[1.1e-8, 1.2e-7, 1.1e-8, 1.1e-8, 1.1e-8], 1e-8));
    }
}
