//! Profile likelihood: how far each identified parameter can move before the data reject the fit.
//!
//! The standard errors of [`crate::identifiability`] linearise the objective at the fit. Where the
//! objective is not quadratic over the region the data allow (a curved valley, a second minimum
//! nearby), they can be far too small: two fits that the data cannot tell apart may then lie many
//! standard errors from each other. The profile does not linearise. For parameter `j` it fixes
//! `θ_j` at a sequence of values stepping away from the fit, minimises the objective over the
//! other parameters at each (Levenberg–Marquardt, started from the previous point), and stops
//! where the minimum crosses
//!
//! `f_min (1 + F_{1, n−p}(0.95) / (n − p))`,
//!
//! the bound of a one-parameter 95 % interval in nonlinear least squares (the same `σ² =
//! f/(n − p)` as the standard errors; Bates & Watts, *Nonlinear Regression Analysis*, §6.1;
//! Venzon & Moolgavkar, Appl. Stat. 37 (1988) 87; Raue et al., Bioinformatics 25 (2009) 1923).
//! For a model linear in its parameters the interval is exactly `θ̂ ± t_{n−p}(0.975) SE`; otherwise
//! it can be asymmetric, open at a bound (the data do not bound the parameter on that side), or
//! reveal a better fit than the one profiled (then the identification stopped short of the
//! minimum, which the profile reports instead of hiding).

use crate::confidence_region::{f_quantile, LEVEL};
use crate::identifiability::assess;
use crate::identification::Identification;
use crate::output::OutputDir;
use crate::plot::{Figure, Series};
use crate::predict::Calibration;
use crate::problem_file::LoadedProblem;
use czid_core::{CzError, Result};
use czid_optimizers::least_squares::{self, LmOptions, Parallel, ResidualSource};
use serde::Serialize;

/// How an interval ends on one side (in the parameter's physical unit in a [`Profile`], in
/// unit-cube coordinates in a [`UnitProfile`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "value")]
pub enum End {
    /// The profile crosses the threshold here.
    Crossed(f64),
    /// The profile stays below the threshold up to the parameter's bound: the data do not bound
    /// it on this side within the search range.
    AtBound(f64),
    /// The steps allowed ran out before the threshold (the interval reaches at least this far).
    NotReached(f64),
}

impl End {
    /// The value where the side ends.
    pub fn value(self) -> f64 {
        match self {
            End::Crossed(v) | End::AtBound(v) | End::NotReached(v) => v,
        }
    }

    /// Whether the data bound the parameter on this side.
    pub fn is_crossed(self) -> bool {
        matches!(self, End::Crossed(_))
    }
}

/// One point of a profile.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProfilePoint {
    /// The profiled parameter's value (physical unit in a [`Profile`], unit-cube coordinates in a
    /// [`UnitProfile`]).
    pub value: f64,
    /// The objective minimised over the other parameters.
    pub objective: f64,
    /// Where that minimum lies: every parameter (unit-cube coordinates).
    pub at: Vec<f64>,
}

/// The profile of one parameter.
#[derive(Clone, Debug, Serialize)]
pub struct Profile {
    /// Index of the parameter in the problem's parameter space.
    pub parameter: usize,
    /// The fit's value (physical unit).
    pub best: f64,
    /// Its linearised standard error (physical unit), when defined.
    pub standard_error: Option<f64>,
    /// The objective at the fit.
    pub best_objective: f64,
    /// The objective bound of the 95 % interval.
    pub threshold: f64,
    /// The interval's two sides.
    pub lower: End,
    /// The upper side.
    pub upper: End,
    /// Every point evaluated, sorted by value (the fit included).
    pub points: Vec<ProfilePoint>,
    /// A point with a lower objective than the fit, if the profile found one.
    pub better: Option<ProfilePoint>,
    /// Refits that failed, the parameter's value (physical unit) and why: the side ended there.
    pub failures: Vec<(f64, String)>,
}

/// Settings of a profile.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileOptions {
    /// Steps allowed on each side before the search stops.
    pub max_steps: usize,
    /// Trial steps of each inner Levenberg–Marquardt fit.
    pub fit_iterations: u64,
    /// Central-difference step of the inner fits (unit-cube coordinates).
    pub fd_step: f64,
    /// Fits that place a crossing once it is bracketed (regula falsi).
    pub refinements: usize,
    /// A crossing is placed when the profile there is within this share of `threshold − f_min`
    /// of the threshold (0.02: about 1 % of the interval's half width where the profile is
    /// quadratic).
    pub crossing_tolerance: f64,
}

impl Default for ProfileOptions {
    fn default() -> Self {
        ProfileOptions { max_steps: 12, fit_iterations: 30, fd_step: 1e-3, refinements: 4, crossing_tolerance: 0.02 }
    }
}

/// The objective bound of a one-parameter `LEVEL` interval for `n` residuals and `p` parameters
/// at the minimum `f_min`.
pub fn threshold(f_min: f64, n: usize, p: usize) -> Option<f64> {
    (n > p && f_min.is_finite()).then(|| {
        let d2 = (n - p) as f64;
        f_min * (1.0 + f_quantile(LEVEL, 1.0, d2) / d2)
    })
}

/// Profiles coordinate `j` of a least-squares problem on the unit cube: `src` gives the residuals
/// (`f = ||r||²`) at unit-cube points, `u` is the fit, `f_min` its objective, `se_u` the
/// linearised standard error of coordinate `j` (unit cube; sets the first step). Values are
/// reported in unit-cube coordinates (see [`profiles`] for physical ones).
pub fn profile_unit<S: ResidualSource<Error = CzError>>(
    src: &S,
    u: &[f64],
    j: usize,
    f_min: f64,
    threshold: f64,
    se_u: Option<f64>,
    opts: &ProfileOptions,
) -> Result<UnitProfile> {
    if j >= u.len() {
        return Err(CzError::config("profile", format!("no coordinate {j} in a problem of {} parameters", u.len())));
    }
    let gap = threshold - f_min;
    if !(gap > 0.0 && gap.is_finite()) {
        return Err(CzError::config(
            "profile",
            format!("the threshold {threshold} does not lie above the fit's {f_min}"),
        ));
    }
    // The linear prediction of the interval's half width is √F·SE ≈ 2 SE: the first step goes a
    // third of that way, so that a nearly quadratic profile crosses within a few steps.
    let first = se_u.filter(|s| s.is_finite() && *s > 0.0).map_or(0.02, |s| (0.7 * s).clamp(1e-4, 0.1));
    let mut points = vec![ProfilePoint { value: u[j], objective: f_min, at: u.to_vec() }];
    let mut ends = [End::NotReached(u[j]); 2];
    let mut failures = Vec::new();
    for (side, dir) in [-1.0f64, 1.0].into_iter().enumerate() {
        let mut prev = points[0].clone();
        let mut h = first;
        ends[side] = End::NotReached(u[j]);
        for _ in 0..opts.max_steps {
            let v = (prev.value + dir * h).clamp(0.0, 1.0);
            if v == prev.value {
                ends[side] = End::AtBound(v);
                break;
            }
            // A model that fails there (a run that does not converge, a finite difference that
            // cannot be taken) ends this side where it last succeeded, said in `failures`.
            let next = match fit_at(src, &prev.at, j, v, opts) {
                Ok(next) => next,
                Err(e) => {
                    failures.push((v, e.to_string()));
                    break;
                }
            };
            points.push(next.clone());
            if next.objective > threshold {
                match refine(src, &prev, &next, j, threshold, gap, opts, &mut points) {
                    Ok(crossing) => ends[side] = End::Crossed(crossing),
                    Err(e) => {
                        // Bracketed all the same: the crossing lies between the two points.
                        failures.push((v, e.to_string()));
                        ends[side] = End::Crossed(next.value);
                    }
                }
                break;
            }
            if v == 0.0 || v == 1.0 {
                ends[side] = End::AtBound(v);
                break;
            }
            ends[side] = End::NotReached(v);
            // Keep each step's rise between a tenth and a half of the way to the threshold: a
            // profile is near-quadratic close to the fit, so a small rise allows a longer step.
            let rise = next.objective - prev.objective;
            h *= if rise < 0.1 * gap {
                2.0
            } else if rise > 0.5 * gap {
                0.5
            } else {
                1.0
            };
            prev = next;
        }
    }
    points.sort_by(|a, b| a.value.total_cmp(&b.value));
    let lowest = points.iter().min_by(|a, b| a.objective.total_cmp(&b.objective)).cloned();
    // A fit that was not quite converged is not news: report a better point only when it lies
    // below the fit by a twentieth of the interval's rise, enough to move the interval.
    let better = lowest.filter(|p| p.objective < f_min - 0.05 * gap);
    Ok(UnitProfile { lower: ends[0], upper: ends[1], points, better, failures })
}

/// [`profile_unit`]'s result.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitProfile {
    /// Lower side.
    pub lower: End,
    /// Upper side.
    pub upper: End,
    /// Points sorted by the profiled coordinate.
    pub points: Vec<ProfilePoint>,
    /// A point below the fit's objective, if found.
    pub better: Option<ProfilePoint>,
    /// Refits that failed: the profiled coordinate and why (the side ended there).
    pub failures: Vec<(f64, String)>,
}

/// The minimum over the other coordinates with coordinate `j` fixed at `v`, started from `start`.
fn fit_at<S: ResidualSource<Error = CzError>>(
    src: &S,
    start: &[f64],
    j: usize,
    v: f64,
    opts: &ProfileOptions,
) -> Result<ProfilePoint> {
    let mut z0 = start.to_vec();
    z0[j] = v;
    let mut lm = LmOptions::unit_cube(z0.len(), opts.fd_step);
    lm.max_iterations = opts.fit_iterations;
    lm.fixed = vec![j];
    let out = least_squares::minimize(src, &z0, &lm, None)?;
    Ok(ProfilePoint { value: v, objective: out.cost, at: out.z })
}

/// Places the crossing of `threshold` between `a` (below) and `b` (above) by regula falsi with
/// the Illinois modification, adding every fit to `points`.
#[allow(clippy::too_many_arguments)]
fn refine<S: ResidualSource<Error = CzError>>(
    src: &S,
    a: &ProfilePoint,
    b: &ProfilePoint,
    j: usize,
    threshold: f64,
    gap: f64,
    opts: &ProfileOptions,
    points: &mut Vec<ProfilePoint>,
) -> Result<f64> {
    let (mut a, mut b) = (a.clone(), b.clone());
    let (mut ga, mut gb) = (a.objective - threshold, b.objective - threshold);
    let mut kept = 0i8;
    for _ in 0..opts.refinements {
        let v = b.value - gb * (b.value - a.value) / (gb - ga);
        let m = fit_at(src, &a.at, j, v, opts)?;
        points.push(m.clone());
        let gm = m.objective - threshold;
        if gm.abs() <= opts.crossing_tolerance * gap {
            return Ok(v);
        }
        if gm < 0.0 {
            a = m;
            ga = gm;
            if kept == -1 {
                gb *= 0.5;
            }
            kept = -1;
        } else {
            b = m;
            gb = gm;
            if kept == 1 {
                ga *= 0.5;
            }
            kept = 1;
        }
    }
    Ok(a.value - ga * (b.value - a.value) / (gb - ga))
}

/// How often [`profiles`] moves to a better fit that a profile turned up before it reports one.
const RECENTRES: usize = 2;

/// A move of the profiles' centre to a better fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Recentre {
    /// Index of the parameter whose profile found it.
    pub by: usize,
    /// The objective at the old centre and at the new one (refitted with every parameter free).
    pub from: f64,
    /// See `from`.
    pub to: f64,
}

/// What [`profiles`] found.
#[derive(Clone, Debug)]
pub struct Profiles {
    /// The point the intervals are centred on (physical values): the fit profiled, or a better
    /// one its profiles found (see `recentred`).
    pub centre: Vec<f64>,
    /// The objective there.
    pub centre_objective: f64,
    /// Residuals of the objective (the intervals' degrees of freedom are this minus the
    /// parameters).
    pub residuals: usize,
    /// Moves to better fits, in order.
    pub recentred: Vec<Recentre>,
    /// One profile per parameter asked for.
    pub profiles: Vec<Profile>,
}

/// Profiles the parameters `which` (indices into the problem's parameters) of an identification
/// at its fit `x` (physical values): each one's 95 % interval and its points. A profile that finds
/// a better fit than `x` (the identification stopped short of the minimum: a rough objective, a
/// budget spent) moves the centre there, refitted with every parameter free, and the profiles start
/// again from it, up to twice; a better fit found after that is reported in its profile. `done` is
/// called after each parameter (for progress).
pub fn profiles(
    id: &Identification,
    x: &[f64],
    which: &[usize],
    opts: &ProfileOptions,
    mut done: impl FnMut(&Profile),
) -> Result<Profiles> {
    let space = id.space();
    let p = space.parameters().len();
    if x.len() != p {
        return Err(CzError::config("profile", format!("{} values for {p} parameters", x.len())));
    }
    if let Some(j) = which.iter().find(|&&j| j >= p) {
        return Err(CzError::config("profile", format!("no parameter {j} in a problem of {p}")));
    }
    let src = Parallel(|w: &[f64]| -> Result<Vec<f64>> { Ok(id.simulate(&space.from_unit(w))?.evaluation.residuals) });
    let mut u = space.to_unit(x);
    let mut recentred = Vec::new();
    'centre: loop {
        let x = space.from_unit(&u);
        let r0 = src.residuals_at(&u)?;
        let f_min: f64 = r0.iter().map(|v| v * v).sum();
        let n = r0.len();
        let threshold = threshold(f_min, n, p).ok_or_else(|| {
            CzError::config("profile", format!("{n} residuals for {p} parameters: no interval without more residuals"))
        })?;
        let assessment = assess(id, &u)?;
        let mut out = Vec::with_capacity(which.len());
        for &j in which {
            let se = assessment.standard_errors[j];
            // The standard error in unit-cube coordinates, for the first step.
            let se_u = se.map(|s| {
                let (a, b) = (space.to_unit(&with(&x, j, x[j] - s))[j], space.to_unit(&with(&x, j, x[j] + s))[j]);
                0.5 * (b - a).abs()
            });
            let up = profile_unit(&src, &u, j, f_min, threshold, se_u, opts)?;
            if let Some(b) = up.better.as_ref().filter(|_| recentred.len() < RECENTRES) {
                let polished = polish(&src, &b.at, opts)?;
                let next = if polished.objective < b.objective { polished } else { b.clone() };
                recentred.push(Recentre { by: j, from: f_min, to: next.objective });
                u = next.at;
                continue 'centre;
            }
            let phys = |v: f64| space.from_unit(&with(&u, j, v))[j];
            let end = |e: End| match e {
                End::Crossed(v) => End::Crossed(phys(v)),
                End::AtBound(v) => End::AtBound(phys(v)),
                End::NotReached(v) => End::NotReached(phys(v)),
            };
            let point =
                |q: &ProfilePoint| ProfilePoint { value: phys(q.value), objective: q.objective, at: q.at.clone() };
            let profile = Profile {
                parameter: j,
                best: x[j],
                standard_error: se,
                best_objective: f_min,
                threshold,
                lower: end(up.lower),
                upper: end(up.upper),
                points: up.points.iter().map(point).collect(),
                better: up.better.as_ref().map(point),
                failures: up.failures.iter().map(|(v, e)| (phys(*v), e.clone())).collect(),
            };
            done(&profile);
            out.push(profile);
        }
        return Ok(Profiles { centre: x, centre_objective: f_min, residuals: n, recentred, profiles: out });
    }
}

/// A Levenberg–Marquardt fit of every coordinate from `start`.
fn polish<S: ResidualSource<Error = CzError>>(src: &S, start: &[f64], opts: &ProfileOptions) -> Result<ProfilePoint> {
    let mut lm = LmOptions::unit_cube(start.len(), opts.fd_step);
    lm.max_iterations = opts.fit_iterations;
    let out = least_squares::minimize(src, start, &lm, None)?;
    Ok(ProfilePoint { value: f64::NAN, objective: out.cost, at: out.z })
}

/// `profile.json`.
#[derive(Clone, Debug, Serialize)]
pub struct ProfileReport {
    /// The problem file.
    pub problem: String,
    /// The `result.json` profiled.
    pub from: String,
    /// Residuals and parameters (the threshold's degrees of freedom).
    pub residuals: usize,
    /// Parameters.
    pub parameters: usize,
    /// The values the intervals are centred on, by path: the result's, or a better fit the
    /// profiles found (see `recentred`).
    pub centre: std::collections::BTreeMap<String, f64>,
    /// The objective there.
    pub centre_objective: f64,
    /// Moves to better fits: the parameter whose profile found one, the objective before and after.
    pub recentred: Vec<(String, f64, f64)>,
    /// One profile per parameter asked for, with its path and unit.
    pub profiles: Vec<NamedProfile>,
}

/// A profile with its parameter's path and unit, and the linearised interval beside it.
#[derive(Clone, Debug, Serialize)]
pub struct NamedProfile {
    /// Parameter path.
    pub path: String,
    /// Unit.
    pub unit: String,
    /// The linearised 95 % interval `θ̂ ± t SE` (when the standard error is defined).
    pub linearised: Option<[f64; 2]>,
    /// What to keep in mind when reading the interval.
    pub notes: Vec<String>,
    /// The profile.
    #[serde(flatten)]
    pub profile: Profile,
}

/// The indices of the parameters named `which` (paths; empty: all) in `problem`, or an error
/// naming the unknown one and the problem's parameters.
pub fn parameter_indices(problem: &LoadedProblem, which: &[String]) -> Result<Vec<usize>> {
    let params = &problem.file.parameter;
    if which.is_empty() {
        return Ok((0..params.len()).collect());
    }
    which
        .iter()
        .map(|w| {
            params.iter().position(|p| p.path == *w).ok_or_else(|| {
                let known: Vec<&str> = params.iter().map(|p| p.path.as_str()).collect();
                CzError::config(
                    "--parameters",
                    format!("`{w}` is not a parameter of this problem; its parameters: {}", known.join(", ")),
                )
            })
        })
        .collect()
}

/// Profiles the parameters `idx` (see [`parameter_indices`]) of `problem` at the values of
/// `calibration`, and writes `profile.json`, `profile.csv` (every point) and one plot per
/// parameter (`profile-<path>.png`: the profile, the threshold, and the parabola the linearised
/// standard error implies) to `out`. `done` is called after each parameter, with its path.
pub fn profile_fit(
    problem: &LoadedProblem,
    calibration: &Calibration,
    idx: &[usize],
    opts: &ProfileOptions,
    out: &OutputDir,
    mut done: impl FnMut(&str, &Profile),
) -> Result<ProfileReport> {
    let id = problem.identification()?;
    let params = id.space().parameters();
    let found = profiles(&id, &calibration.x, idx, opts, |p| done(&params[p.parameter].path, p))?;
    let centre = params.iter().zip(&found.centre).map(|(q, v)| (q.path.clone(), *v)).collect();
    let recentred = found.recentred.iter().map(|r| (params[r.by].path.clone(), r.from, r.to)).collect();
    let residuals = found.residuals;
    let p = params.len();
    let t = f_quantile(LEVEL, 1.0, (residuals - p) as f64).sqrt();
    let mut named = Vec::new();
    let (mut cols, mut names): (Vec<Vec<f64>>, Vec<String>) = (vec![Vec::new(); 3], Vec::new());
    for pr in found.profiles {
        let prm = &params[pr.parameter];
        let linearised = pr.standard_error.map(|se| [pr.best - t * se, pr.best + t * se]);
        for q in &pr.points {
            names.push(prm.path.clone());
            cols[0].push(q.value);
            cols[1].push(q.objective);
            cols[2].push(pr.threshold);
        }
        let (xs, fs): (Vec<f64>, Vec<f64>) = pr.points.iter().map(|q| (q.value, q.objective)).unzip();
        let (lo, hi) = (xs[0], xs[xs.len() - 1]);
        let mut fig =
            Figure::new(&format!("profile of {}", prm.path), &format!("{} ({})", prm.path, prm.unit), "objective f")
                .with(Series::line("profile (the others refitted)", xs.clone(), fs))
                .with(Series::dashed("95 % threshold", vec![lo, hi], vec![pr.threshold; 2]));
        if let Some(se) = pr.standard_error {
            // The linearisation's parabola: f̂ (1 + ((θ − θ̂)/SE)² / (n − p)).
            // Drawn up to three times the threshold's rise, so that it does not flatten the profile.
            let top = pr.best_objective + 3.0 * (pr.threshold - pr.best_objective);
            let (grid, par): (Vec<f64>, Vec<f64>) = (0..=120)
                .map(|k| lo + (hi - lo) * k as f64 / 120.0)
                .map(|v| (v, pr.best_objective * (1.0 + ((v - pr.best) / se).powi(2) / (residuals - p) as f64)))
                .filter(|(_, f)| *f <= top)
                .unzip();
            fig = fig.with(Series::dashed("linearised (standard error)", grid, par));
        }
        fig.with_vline("fit", pr.best).save(&out.file(&format!("profile-{}.png", prm.path.replace('.', "_"))))?;
        let notes = narrowness(&pr, t);
        named.push(NamedProfile { path: prm.path.clone(), unit: prm.unit.clone(), linearised, notes, profile: pr });
    }
    let mut text = String::from("parameter,value,objective,threshold\n");
    for (k, name) in names.iter().enumerate() {
        text.push_str(&format!("{name},{:e},{:e},{:e}\n", cols[0][k], cols[1][k], cols[2][k]));
    }
    out.write("profile.csv", &text)?;
    let report = ProfileReport {
        problem: problem.path.display().to_string(),
        from: calibration.from.clone(),
        residuals,
        parameters: p,
        centre,
        centre_objective: found.centre_objective,
        recentred,
        profiles: named,
    };
    let json = serde_json::to_string_pretty(&report).map_err(|e| CzError::config("profile", e.to_string()))?;
    out.write("profile.json", &json)?;
    Ok(report)
}

/// Share of the linearised half width below which a side of a profile is suspect.
const SUSPECT: f64 = 1.0 / 3.0;

/// Notes on sides of `pr` that end far inside the linearised interval (`t` SE wide). Close to a
/// minimum a smooth objective follows its parabola, so a profile that rises much faster than the
/// standard error says did not refit the others to the valley's floor: the objective is rough at
/// the refits' finite-difference step (or the fit is not a minimum), and the interval is then too
/// narrow, never too wide (each refit's objective is an upper bound on the profile's).
fn narrowness(pr: &Profile, t: f64) -> Vec<String> {
    let Some(se) = pr.standard_error else { return Vec::new() };
    let half = t * se;
    [("lower", pr.lower), ("upper", pr.upper)]
        .into_iter()
        .filter_map(|(side, e)| {
            let d = (e.value() - pr.best).abs();
            (e.is_crossed() && d < SUSPECT * half).then(|| {
                format!(
                    "the {side} side ends {d:.3e} from the fit, under a third of the linearised {half:.3e}: the refits \
                     did not follow the valley (an objective rough at their finite-difference step, or a fit that is \
                     not a minimum), so the interval is too narrow on this side; compare runs from several seeds \
                     (czid compare) or profile with a larger --fd-step"
                )
            })
        })
        .collect()
}

/// `v` with entry `j` replaced by `value`.
fn with(v: &[f64], j: usize, value: f64) -> Vec<f64> {
    let mut w = v.to_vec();
    w[j] = value;
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    fn source(r: impl Fn(&[f64]) -> Vec<f64> + Sync) -> Parallel<impl Fn(&[f64]) -> Result<Vec<f64>> + Sync> {
        Parallel(move |u: &[f64]| Ok(r(u)))
    }

    fn tight() -> ProfileOptions {
        ProfileOptions { refinements: 40, crossing_tolerance: 1e-9, fit_iterations: 100, ..Default::default() }
    }

    #[test]
    fn a_linear_model_gives_the_t_interval() {
        // r = A u − b with 13 residuals and 3 parameters: the profile is exactly quadratic and the
        // interval is û_j ± t_{10}(0.975) SE_j, t_{10}(0.975) = 2.228139 (Student's table).
        let n = 13;
        let a = DMatrix::from_fn(n, 3, |i, k| {
            ((i + 1) as f64 * 0.37 + k as f64 * 1.3).sin() + if i % 3 == k { 1.0 } else { 0.0 }
        });
        let noise = DVector::from_fn(n, |i, _| 0.01 * ((i * 7 % 5) as f64 - 2.0));
        let truth = DVector::from_vec(vec![0.4, 0.55, 0.6]);
        let b = &a * &truth + noise;
        let ata = a.transpose() * &a;
        let inv = ata.clone().try_inverse().unwrap();
        let fit = inv.clone() * a.transpose() * &b;
        let res = &a * &fit - &b;
        let f_min = res.norm_squared();
        let sigma2 = f_min / (n - 3) as f64;
        let (a2, b2) = (a.clone(), b.clone());
        let src = source(move |u: &[f64]| (&a2 * DVector::from_column_slice(u) - &b2).iter().copied().collect());
        let u: Vec<f64> = fit.iter().copied().collect();
        let th = threshold(f_min, n, 3).unwrap();
        for j in 0..3 {
            let se = (sigma2 * inv[(j, j)]).sqrt();
            let pr = profile_unit(&src, &u, j, f_min, th, Some(se), &tight()).unwrap();
            let half = 2.228139 * se;
            let (End::Crossed(lo), End::Crossed(hi)) = (pr.lower, pr.upper) else {
                panic!("parameter {j}: {:?} {:?}", pr.lower, pr.upper)
            };
            assert!((lo - (u[j] - half)).abs() < 1e-5 * half, "parameter {j}: lower {lo}, t interval {}", u[j] - half);
            assert!((hi - (u[j] + half)).abs() < 1e-5 * half, "parameter {j}: upper {hi}, t interval {}", u[j] + half);
            assert!(pr.better.is_none());
        }
    }

    /// A curved valley: `r = [a (u1 − u0²), b (u0 − 0.6), c (u1 − 0.3)]`. With `u0` fixed the
    /// best `u1` is `(a² u0² + 0.3 c²)/(a² + c²)`, so the profile of `u0` is
    /// `b² (u0 − 0.6)² + a²c²/(a² + c²) (u0² − 0.3)²`.
    const A: f64 = 8.0;
    const B: f64 = 0.3;
    const C: f64 = 1.0;

    fn valley(u: &[f64]) -> Vec<f64> {
        vec![A * (u[1] - u[0] * u[0]), B * (u[0] - 0.6), C * (u[1] - 0.3)]
    }

    fn valley_profile(u0: f64) -> f64 {
        B * B * (u0 - 0.6).powi(2) + A * A * C * C / (A * A + C * C) * (u0 * u0 - 0.3).powi(2)
    }

    /// The profile's minimum by golden section on the closed form.
    fn valley_minimum() -> f64 {
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..200 {
            let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if valley_profile(x1) < valley_profile(x2) {
                hi = x2;
            } else {
                lo = x1;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn a_curved_valley_gives_the_closed_form_profile_and_an_asymmetric_interval() {
        let u0 = valley_minimum();
        let u = vec![u0, (A * A * u0 * u0 + 0.3 * C * C) / (A * A + C * C)];
        let f_min = valley_profile(u0);
        // A small n − p makes the interval wide enough to feel the curvature.
        let th = threshold(f_min, 3, 2).unwrap();
        let src = source(valley);
        let pr = profile_unit(&src, &u, 0, f_min, th, None, &tight()).unwrap();
        for q in &pr.points {
            assert!(
                (q.objective - valley_profile(q.value)).abs() < 1e-9 * th,
                "at u0 = {}: profile {} against the closed form {}",
                q.value,
                q.objective,
                valley_profile(q.value)
            );
        }
        let (End::Crossed(lo), End::Crossed(hi)) = (pr.lower, pr.upper) else {
            panic!("{:?} {:?}", pr.lower, pr.upper)
        };
        assert!((valley_profile(lo) - th).abs() < 1e-6 * th && (valley_profile(hi) - th).abs() < 1e-6 * th);
        // The quartic term makes the interval asymmetric about the minimum.
        let (below, above) = (u0 - lo, hi - u0);
        assert!((below / above - 1.0).abs() > 0.05, "below {below}, above {above}");
        assert!(pr.better.is_none());
    }

    #[test]
    fn a_side_the_data_do_not_bound_ends_at_the_bound_and_a_better_fit_is_reported() {
        // The minimum of the first coordinate lies at 0.97, with a shallow rise: the upper side
        // reaches the box's edge below the threshold (20 residuals: F(1, 18) = 4.41, the
        // threshold 1.2e-4 above the minimum; the rise is 9e-6 at the edge, 0.11 below the fit
        // on the lower side).
        let src = source(|u: &[f64]| {
            let mut r = vec![0.005; 20];
            r[0] = 0.1 * (u[0] - 0.97);
            r[1] = u[1] - 0.5;
            r
        });
        let f_at = |u: &[f64]| src.residuals_at(u).unwrap().iter().map(|v| v * v).sum::<f64>();
        let u = vec![0.97, 0.5];
        let f_min = f_at(&u);
        let th = threshold(f_min, 20, 2).unwrap();
        let pr = profile_unit(&src, &u, 0, f_min, th, Some(0.05), &ProfileOptions::default()).unwrap();
        assert_eq!(pr.upper, End::AtBound(1.0));
        assert!(pr.lower.is_crossed(), "{:?}", pr.lower);
        // Profiled from a point that is not the fit: the other coordinate's minimum is found.
        let start = vec![0.5, 0.9];
        let pr =
            profile_unit(&src, &start, 0, f_at(&start), th.max(f_at(&start) * 1.1), None, &ProfileOptions::default())
                .unwrap();
        let better = pr.better.expect("a better fit than the start");
        assert!((better.at[1] - 0.5).abs() < 1e-6 && better.objective < f_at(&start));
    }

    #[test]
    fn a_side_far_inside_the_linearised_interval_is_flagged() {
        let pr = |lo: f64, hi: f64| Profile {
            parameter: 0,
            best: 10.0,
            standard_error: Some(1.0),
            best_objective: 1.0,
            threshold: 1.1,
            lower: End::Crossed(lo),
            upper: End::Crossed(hi),
            points: Vec::new(),
            better: None,
            failures: Vec::new(),
        };
        // t SE = 2: sides at 1.8 and 2.5 from the fit are what a smooth objective gives.
        assert!(narrowness(&pr(8.2, 12.5), 2.0).is_empty());
        // A side 0.1 from the fit rises twenty times faster than the parabola.
        let notes = narrowness(&pr(9.9, 12.5), 2.0);
        assert_eq!(notes.len(), 1);
        assert!(notes[0].starts_with("the lower side ends 1.000e-1 from the fit"), "{}", notes[0]);
    }

    #[test]
    fn a_model_that_fails_ends_its_side_where_it_last_ran() {
        // The "model" fails for u0 above 0.55; the fit is at 0.5 and the threshold lies beyond.
        let src = Parallel(|u: &[f64]| -> Result<Vec<f64>> {
            if u[0] > 0.55 {
                return Err(CzError::Simulation(format!("no convergence at {}", u[0])));
            }
            let mut r = vec![0.005; 20];
            r[0] = 0.01 * (u[0] - 0.5);
            r[1] = u[1] - 0.5;
            Ok(r)
        });
        let u = vec![0.5, 0.5];
        let f_min = 20.0 * 0.005f64.powi(2) - 0.005f64.powi(2);
        let th = threshold(f_min, 20, 2).unwrap();
        let pr = profile_unit(&src, &u, 0, f_min, th, Some(0.02), &ProfileOptions::default()).unwrap();
        let End::NotReached(v) = pr.upper else { panic!("{:?}", pr.upper) };
        assert!((0.5..=0.55).contains(&v), "{v}");
        assert!(!pr.failures.is_empty() && pr.failures[0].0 > 0.55, "{:?}", pr.failures);
        assert!(pr.failures[0].1.contains("no convergence"), "{:?}", pr.failures);
    }
}
