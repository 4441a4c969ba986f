//! Verification kit: the checks every bundled law passes, public so that a user-defined law can be
//! held to the same standard.
//!
//! * [`check_tangent`]: the law's tangent against central finite differences of its traction;
//! * [`follow_path`] / [`dissipated_energy`]: walk a gap history with committed states and
//!   integrate the work `∫ T·du`;
//! * [`pure_mode_energy`]: the energy to separate in a pure mode against
//!   [`CohesiveLaw::fracture_energy`];
//! * [`opening_path_nonlinearity`]: a law's claim that its opening path is linear between kinks
//!   ([`CohesiveLaw::opening_path_piecewise_linear`]) against its traction;
//! * [`audit`]: all of these (and irreversibility) on a standard set of paths scaled to the law.
//!
//! ```
//! use czid_models::laws::{verify, StCzm};
//! let law = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
//! let report = verify::audit(&law);
//! assert!(report.passed(1e-6), "{report:?}");
//! ```

use czid_core::{CohesiveLaw, Gap, LawState, Tangent, Traction};

/// A pure fracture mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Mode I: normal opening only.
    Normal,
    /// Mode II: tangential slip only.
    Shear,
}

impl Mode {
    /// Index of the mode in `[normal, shear]` arrays.
    pub fn index(self) -> usize {
        match self {
            Mode::Normal => 0,
            Mode::Shear => 1,
        }
    }

    /// The gap of this pure mode at `opening` (mm).
    pub fn gap(self, opening: f64) -> Gap {
        match self {
            Mode::Normal => Gap::new(opening, 0.0),
            Mode::Shear => Gap::new(0.0, opening),
        }
    }
}

/// The law's smallest elastic-limit opening `min_m σ_m / k_m` (mm): the length on which its
/// traction changes character, used to scale finite-difference steps and standard paths.
pub fn length_scale(law: &dyn CohesiveLaw) -> f64 {
    let (s, k) = (law.strength(), law.initial_stiffness());
    (s[0] / k[0]).min(s[1] / k[1])
}

/// `‖a − b‖_F / max(‖a‖_F, ‖b‖_F)` (0 when both vanish, infinite when either is not finite).
pub fn relative_error(a: &Tangent, b: &Tangent) -> f64 {
    let scale = a.norm().max(b.norm());
    let error = if scale == 0.0 { 0.0 } else { (a - b).norm() / scale };
    if error.is_nan() {
        f64::INFINITY
    } else {
        error
    }
}

/// Central finite-difference tangent `(T(u + h e_j) − T(u − h e_j)) / 2h` with `previous` held fixed.
pub fn finite_difference_tangent(law: &dyn CohesiveLaw, gap: &Gap, previous: &LawState, step: f64) -> Tangent {
    let mut tangent = Tangent::zeros();
    for j in 0..2 {
        let mut shift = Gap::zeros();
        shift[j] = step;
        let plus = law.evaluate(&(gap + shift), previous).traction;
        let minus = law.evaluate(&(gap - shift), previous).traction;
        tangent.set_column(j, &((plus - minus) / (2.0 * step)));
    }
    tangent
}

/// Outcome of a tangent check at one gap and state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentCheck {
    /// Where the check was made.
    pub gap: Gap,
    /// The law's tangent.
    pub analytic: Tangent,
    /// The central-difference tangent.
    pub finite_difference: Tangent,
    /// Finite-difference step (mm).
    pub step: f64,
    /// [`relative_error`] between the two.
    pub relative_error: f64,
    /// The finite differences with steps `h` and `2h` disagree: the traction has a kink within `2h`
    /// of the gap (onset of damage, reversal, closure, separation), where no tangent is defined.
    pub near_kink: bool,
}

/// [`check_tangent_with_step`] with the step `1e-6 · max(`[`length_scale`]`, |gap|)`: small
/// against the scale on which the traction curves, large enough that roundoff in the traction
/// (relative 1e-16) stays far below the tolerance.
pub fn check_tangent(law: &dyn CohesiveLaw, gap: &Gap, previous: &LawState) -> TangentCheck {
    check_tangent_with_step(law, gap, previous, 1e-6 * length_scale(law).max(gap.norm()))
}

/// Compares the law's tangent at `gap` (from the committed state `previous`) with central finite
/// differences of step `step`.
pub fn check_tangent_with_step(law: &dyn CohesiveLaw, gap: &Gap, previous: &LawState, step: f64) -> TangentCheck {
    let eval = law.evaluate(gap, previous);
    let (center, analytic) = (eval.traction, eval.tangent);
    let traction_at = |j: usize, h: f64| {
        let mut shift = Gap::zeros();
        shift[j] = h;
        law.evaluate(&(gap + shift), previous).traction
    };
    let mut finite_difference = Tangent::zeros();
    let mut coarse = Tangent::zeros();
    let mut forward = Tangent::zeros();
    let mut backward = Tangent::zeros();
    for j in 0..2 {
        let (plus, minus) = (traction_at(j, step), traction_at(j, -step));
        finite_difference.set_column(j, &((plus - minus) / (2.0 * step)));
        forward.set_column(j, &((plus - center) / step));
        backward.set_column(j, &((center - minus) / step));
        coarse.set_column(j, &((traction_at(j, 2.0 * step) - traction_at(j, -2.0 * step)) / (4.0 * step)));
    }
    // Smooth tractions: central differences with h and 2h differ by O(h²) (~1e-12 relative) and
    // one-sided ones by O(h) (~1e-6). A kink within 2h makes either O(1); a kink exactly at the
    // gap fools the central pair but not the one-sided one.
    let near_kink = relative_error(&finite_difference, &coarse) > 1e-6 || relative_error(&forward, &backward) > 1e-3;
    TangentCheck {
        gap: *gap,
        analytic,
        finite_difference,
        step,
        relative_error: relative_error(&analytic, &finite_difference),
        near_kink,
    }
}

/// One committed point of a gap history.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathPoint {
    /// Gap (mm).
    pub gap: Gap,
    /// Traction (MPa).
    pub traction: Traction,
    /// Committed state.
    pub state: LawState,
    /// Work `∫ T·du` done from the origin up to here (N/mm).
    pub work: f64,
}

/// Walks `path` from the origin in the law's initial state, committing the state at every point,
/// and integrates the work with the trapezoidal rule.
///
/// The trapezoidal rule is exact for tractions linear along a step, second order otherwise, and
/// keeps the sign of the dissipation: for a secant-damage law the trapezoidal work minus
/// `½ T·u` grows by `½ Σ_m ΔS_m u_m,k u_m,k+1` per step (`ΔS_m` the loss of secant stiffness), never
/// negative as long as no step straddles a sign change of a gap component (see [`polyline`]).
pub fn follow_path(law: &dyn CohesiveLaw, path: &[Gap]) -> Vec<PathPoint> {
    let mut points = Vec::with_capacity(path.len());
    let mut gap = Gap::zeros();
    let mut state = law.initial_state();
    let mut traction = law.evaluate(&gap, &state).traction;
    let mut work = 0.0;
    for next in path {
        let eval = law.evaluate(next, &state);
        work += 0.5 * (traction + eval.traction).dot(&(next - gap));
        gap = *next;
        state = eval.state;
        traction = eval.traction;
        points.push(PathPoint { gap, traction, state, work });
    }
    points
}

/// Work done minus the energy stored at the end of a walk (N/mm): what the law dissipated.
pub fn dissipated_energy(law: &dyn CohesiveLaw, points: &[PathPoint]) -> f64 {
    points.last().map_or(0.0, |p| p.work - law.stored_energy(&p.gap, &p.state))
}

/// `steps` points from `from` (excluded) to `to` (included), evenly spaced.
pub fn line(from: Gap, to: Gap, steps: usize) -> Vec<Gap> {
    (1..=steps).map(|i| from + (to - from) * (i as f64 / steps as f64)).collect()
}

/// A path from the origin through `vertices`, `steps` points per leg, plus every point where a gap
/// component changes sign (set exactly to zero), so that no step straddles the closure of the
/// interface or a reversal of slip.
pub fn polyline(vertices: &[Gap], steps: usize) -> Vec<Gap> {
    let mut path = Vec::with_capacity(vertices.len() * (steps + 2));
    let mut from = Gap::zeros();
    for &to in vertices {
        // Fractions of the leg where u_n or u_t crosses zero, in order.
        let crossing = |m: usize| (from[m] * to[m] < 0.0).then(|| from[m] / (from[m] - to[m]));
        let crossings = [crossing(0), crossing(1)];
        let mut cuts = [crossings[0].unwrap_or(1.0), crossings[1].unwrap_or(1.0), 1.0];
        cuts.sort_by(f64::total_cmp);
        let mut start = from;
        let mut done = 0.0;
        for fraction in cuts {
            if fraction <= done {
                continue;
            }
            let mut end = from + (to - from) * fraction;
            for m in 0..2 {
                if crossings[m] == Some(fraction) {
                    end[m] = 0.0;
                }
            }
            let piece_steps = ((steps as f64 * (fraction - done)).ceil() as usize).max(1);
            path.extend(line(start, end, piece_steps));
            if let Some(last) = path.last_mut() {
                *last = end;
            }
            start = end;
            done = fraction;
        }
        from = to;
    }
    path
}

/// `steps` openings from 0 (excluded) to `max_opening` in a pure mode, spaced quadratically
/// (`x_i = X (i/N)²`): fine near the origin, where the stiffest kinks (onset of damage) sit. The
/// trapezoidal error at a kink of slope jump `J` at `x` is about `J h²`, with `J ~ σ/x` and
/// `h ~ 2√(xX)/N`, hence `~ 4σX/N²` wherever the kink is.
pub fn graded_line(mode: Mode, max_opening: f64, steps: usize) -> Vec<Gap> {
    let n = steps.max(1) as f64;
    (1..=steps.max(1)).map(|i| mode.gap(max_opening * (i as f64 / n).powi(2))).collect()
}

/// Energy to separate in a pure mode, compared with the law's claim.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyCheck {
    /// `∫ T dΔ` along the monotonic path (N/mm).
    pub computed: f64,
    /// [`CohesiveLaw::fracture_energy`] of the mode (N/mm).
    pub expected: f64,
    /// `|computed − expected| / expected`.
    pub relative_error: f64,
    /// Damage at the end of the path (1 if the law separated).
    pub final_damage: f64,
}

/// Opens the interface monotonically in `mode` from 0 to `max_opening` in `steps` steps
/// ([`graded_line`]) and integrates the traction. `max_opening` must lie beyond separation for the
/// comparison to mean anything; [`separation_opening`] finds such an opening.
pub fn pure_mode_energy(law: &dyn CohesiveLaw, mode: Mode, max_opening: f64, steps: usize) -> EnergyCheck {
    let points = follow_path(law, &graded_line(mode, max_opening, steps));
    let last = points.last().copied();
    let computed = last.map_or(0.0, |p| p.work);
    let expected = law.fracture_energy()[mode.index()];
    EnergyCheck {
        computed,
        expected,
        relative_error: (computed - expected).abs() / expected.abs(),
        final_damage: last.map_or(0.0, |p| p.state.damage),
    }
}

/// An opening (mm) at which the law has separated (damage 1) in a monotonic pure-mode test:
/// doubles a trial opening from [`length_scale`] until damage reaches 1. `None` if it never does
/// within 2⁶⁰ length scales.
pub fn separation_opening(law: &dyn CohesiveLaw, mode: Mode) -> Option<f64> {
    let mut opening = length_scale(law);
    for _ in 0..60 {
        let points = follow_path(law, &line(Gap::zeros(), mode.gap(opening), 64));
        if points.last().is_some_and(|p| p.state.damage >= 1.0) {
            return Some(opening);
        }
        opening *= 2.0;
    }
    None
}

/// For a law that says its monotonic pure opening path is linear between kinks
/// ([`CohesiveLaw::opening_path_piecewise_linear`]): the largest second difference of the normal
/// traction over three evenly spaced openings of the same piece (elastic, softening between the
/// same inner kinks, failed), relative to the normal strength, on 3000 steps to 1.2 times the
/// separation opening. Zero to round-off (~10⁻¹⁵) when the claim holds; a curved softening
/// (exponential) gives 10⁻⁸ or more. `None` for a law that makes no such claim or never separates.
pub fn opening_path_nonlinearity(law: &dyn CohesiveLaw) -> Option<f64> {
    if !law.opening_path_piecewise_linear() {
        return None;
    }
    let sep = separation_opening(law, Mode::Normal)?;
    let points = follow_path(law, &line(Gap::zeros(), Mode::Normal.gap(1.2 * sep), 3000));
    let piece = |p: &PathPoint| {
        let kinks = (0..law.inner_kinks()).filter(|&k| law.beyond_inner_kink(&p.state, k)).count();
        (p.state.damage > 0.0, p.state.damage >= 1.0, kinks)
    };
    let strength = law.strength()[0];
    let worst = points
        .windows(3)
        .filter(|w| piece(&w[0]) == piece(&w[1]) && piece(&w[1]) == piece(&w[2]))
        .map(|w| (w[0].traction[0] - 2.0 * w[1].traction[0] + w[2].traction[0]).abs() / strength)
        .fold(0.0f64, f64::max);
    Some(worst)
}

/// The worst tangent check along a path (each point checked from the previous committed state),
/// and how many points were skipped because they sit on a kink.
pub fn worst_tangent_along(law: &dyn CohesiveLaw, path: &[Gap]) -> (Option<TangentCheck>, usize) {
    let mut state = law.initial_state();
    let mut worst: Option<TangentCheck> = None;
    let mut skipped = 0;
    for gap in path {
        let check = check_tangent(law, gap, &state);
        if check.near_kink {
            skipped += 1;
        } else if worst.is_none_or(|w| check.relative_error > w.relative_error) {
            worst = Some(check);
        }
        state = law.evaluate(gap, &state).state;
    }
    (worst, skipped)
}

/// Result of [`audit`].
#[derive(Clone, Debug, PartialEq)]
pub struct Audit {
    /// Largest tangent relative error over the standard paths (kinks skipped).
    pub tangent_error: f64,
    /// Where it occurred.
    pub worst_gap: Gap,
    /// Points skipped as kinks, and points checked in total.
    pub kinks_skipped: (usize, usize),
    /// Pure-mode energy checks `[mode I, mode II]` (`None` if the law never separated).
    pub energy: [Option<EnergyCheck>; 2],
    /// Damage stayed in [0, 1] and never decreased on every path.
    pub damage_admissible: bool,
    /// Smallest dissipated energy (work − stored, see [`follow_path`]) met at any point of any
    /// path, relative to the smaller pure-mode toughness; negative beyond roundoff means the law
    /// creates energy.
    pub min_dissipation: f64,
    /// Every traction was finite.
    pub finite: bool,
    /// [`opening_path_nonlinearity`] (`None`: the law makes no linearity claim).
    pub opening_nonlinearity: Option<f64>,
}

impl Audit {
    /// Whether tangent and energy errors are within `tolerance`, damage is admissible, no energy
    /// is created (beyond `tolerance`), fewer than 5 % of points were kinks, and a claimed
    /// piecewise-linear opening path is linear to round-off (10⁻¹⁰ of the strength).
    pub fn passed(&self, tolerance: f64) -> bool {
        let energy_ok = self.energy.iter().all(|e| e.is_some_and(|e| e.relative_error <= tolerance));
        self.opening_nonlinearity.is_none_or(|e| e <= 1e-10)
            && self.finite
            && self.damage_admissible
            && self.tangent_error <= tolerance
            && energy_ok
            && self.min_dissipation >= -tolerance
            && self.kinks_skipped.0 * 20 < self.kinks_skipped.1.max(1)
    }
}

/// Standard paths, scaled to the law: monotonic loading, unloading and reloading, in each pure mode
/// (shear under slight compression), at two mixities, and a non-proportional path through
/// compression.
pub fn standard_paths(law: &dyn CohesiveLaw) -> Vec<(&'static str, Vec<Gap>)> {
    let sep = |mode| separation_opening(law, mode).unwrap_or(1e3 * length_scale(law));
    let (n, t) = (sep(Mode::Normal), sep(Mode::Shear));
    let g = Gap::new;
    // Odd fractions keep path points off the law's break points.
    let steps = 97;
    vec![
        (
            "mode I load-unload-reload",
            polyline(&[g(0.37 * n, 0.0), g(0.11 * n, 0.0), g(0.71 * n, 0.0), g(1.13 * n, 0.0)], steps),
        ),
        (
            "mode II load-unload-reload",
            polyline(&[g(-0.013 * n, 0.41 * t), g(-0.013 * n, -0.23 * t), g(-0.013 * n, 1.17 * t)], steps),
        ),
        (
            "mixed, mostly normal",
            polyline(&[g(0.43 * n, 0.17 * t), g(0.05 * n, 0.02 * t), g(0.93 * n, 0.37 * t)], steps),
        ),
        ("mixed, mostly shear", polyline(&[g(0.13 * n, 0.52 * t), g(0.2 * n, -0.1 * t), g(0.31 * n, 1.09 * t)], steps)),
        (
            "non-proportional through compression",
            polyline(
                &[
                    g(0.29 * n, 0.0),
                    g(-0.07 * n, 0.19 * t),
                    g(0.33 * n, 0.47 * t),
                    g(0.61 * n, -0.29 * t),
                    g(1.21 * n, 0.3 * t),
                ],
                steps,
            ),
        ),
    ]
}

/// Runs every check of the kit on [`standard_paths`] and both pure modes.
pub fn audit(law: &dyn CohesiveLaw) -> Audit {
    let mut report = Audit {
        tangent_error: 0.0,
        worst_gap: Gap::zeros(),
        kinks_skipped: (0, 0),
        energy: [None, None],
        damage_admissible: true,
        min_dissipation: f64::INFINITY,
        finite: true,
        opening_nonlinearity: opening_path_nonlinearity(law),
    };
    let toughness = law.fracture_energy();
    let energy_scale = toughness[0].min(toughness[1]);
    for (_, path) in standard_paths(law) {
        let (worst, skipped) = worst_tangent_along(law, &path);
        report.kinks_skipped.0 += skipped;
        report.kinks_skipped.1 += path.len();
        if let Some(w) = worst.filter(|w| w.relative_error > report.tangent_error) {
            report.tangent_error = w.relative_error;
            report.worst_gap = w.gap;
        }
        let points = follow_path(law, &path);
        let mut damage = law.initial_state().damage;
        for (i, p) in points.iter().enumerate() {
            report.finite &= p.traction.iter().all(|t| t.is_finite());
            report.damage_admissible &= p.state.damage >= damage && p.state.damage <= 1.0;
            damage = p.state.damage;
            let dissipated = dissipated_energy(law, &points[i..=i]);
            report.min_dissipation = report.min_dissipation.min(dissipated / energy_scale);
        }
    }
    for mode in [Mode::Normal, Mode::Shear] {
        report.energy[mode.index()] =
            separation_opening(law, mode).map(|opening| pure_mode_energy(law, mode, 1.5 * opening, 30_000));
    }
    report
}
