//! The whole diagnosis: base fit, where, identifiability, which, how far, transfer, verdict.

use crate::diagnose::candidate::{CandidateEffect, Library};
use crate::diagnose::gauge::{Gauge, Misfit, NoiseLevels};
use crate::diagnose::lsq::{self, LsOptions};
use crate::diagnose::regimes::{self, Regime, RegimeMisfit};
use crate::diagnose::score::{self, Linearisation, Score, Sensitivity};
use crate::diagnose::stats::chi2_survival;
use crate::identifiability::{assess_jacobian, FD_STEP};
use crate::identification::{Setup, Term};
use crate::identify::optimize;
use crate::problem_file::LoadedProblem;
use czid_core::{Budget, CzError, Observer, Parameter, ParameterSpace, Progress, Record, Result};
use nalgebra::DMatrix;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// Significance of the base misfit against the noise (χ² with n − p degrees of freedom).
const NOISE_LEVEL: f64 = 1e-3;
/// Realised shrinkage below which the held-out part (late stage; a beam's debonding) is not
/// refitted for a candidate.
const TRANSFER_FROM: f64 = 0.05;
/// Cosine above which two candidates are reported as confusable.
pub const CONFUSABLE: f64 = 0.9;

/// A callback receiving a short message as each stage starts.
pub type ProgressFn = Box<dyn Fn(&str) + Sync>;

/// What to diagnose and how.
pub struct Options {
    /// Candidates to score (names in the library; empty: every one that applies).
    pub candidates: Vec<String>,
    /// Fitted values to start from (physical, in the problem's parameter order), e.g. from an
    /// `identify` result; `None`: fit with the problem file's optimizer first.
    pub start: Option<Vec<f64>>,
    /// How many of the best-scoring candidates to refit.
    pub refit: usize,
    /// Noise levels instead of estimates from the data.
    pub noise: NoiseLevels,
    /// Other tests predicted with the calibrated parameters (transfer), e.g. other specimens.
    pub withheld: Vec<LoadedProblem>,
    /// Also check transfer to the held-out last regime of each curve (the late stage; a beam's
    /// debonding, [`czid_core::RegimeRule::held_out`]).
    pub holdout: bool,
    /// Candidates refitted whatever their score (e.g. the planted effect of a benchmark case).
    pub always_refit: Vec<String>,
    /// Called with a short message as each stage starts (e.g. for a progress display).
    pub progress: Option<ProgressFn>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            candidates: Vec::new(),
            start: None,
            refit: 3,
            noise: NoiseLevels::default(),
            withheld: Vec::new(),
            holdout: true,
            always_refit: Vec::new(),
            progress: None,
        }
    }
}

/// A physical value with its unit.
#[derive(Clone, Debug, Serialize)]
pub struct Value {
    /// Parameter path or label.
    pub name: String,
    /// Value.
    pub value: f64,
    /// Unit.
    pub unit: String,
}

/// A fitted parameter and what the data say about it.
#[derive(Clone, Debug, Serialize)]
pub struct FittedParameter {
    /// Path.
    pub path: String,
    /// Value.
    pub value: f64,
    /// Unit.
    pub unit: String,
    /// Standard error (same unit), when defined.
    pub standard_error: Option<f64>,
    /// Sensitivity: RMS of its Jacobian column (noise units per range).
    pub sensitivity: f64,
    /// Plain verdict.
    pub verdict: String,
}

/// Identifiability of the fitted parameters at the base fit.
#[derive(Clone, Debug, Serialize)]
pub struct Identifiability {
    /// Singular values of the Jacobian (noise units, unit-cube coordinates).
    pub singular_values: Vec<f64>,
    /// Collinearity index (1: orthogonal; above ~10–15: a poorly determined combination).
    pub collinearity_index: f64,
    /// Correlation matrix, row by row.
    pub correlations: Vec<Vec<f64>>,
}

/// The base fit.
#[derive(Clone, Debug, Serialize)]
pub struct BaseFit {
    /// Fitted parameters.
    pub parameters: Vec<FittedParameter>,
    /// Sum of squared residuals in noise units.
    pub chi2: f64,
    /// `chi2 / (n − p)`: 1 at the noise level.
    pub reduced_chi2: f64,
    /// `P(χ²_{n−p} > chi2)`.
    pub p_value: f64,
    /// Whether the misfit is consistent with the noise alone.
    pub at_noise_level: bool,
    /// Residual evaluations of the fit (after the file's optimizer, if run).
    pub evaluations: usize,
    /// Runs that stopped early at the fit.
    pub failures: Vec<String>,
}

/// Shrinkage of the misfit in one regime.
#[derive(Clone, Debug, Serialize)]
pub struct RegimeShrinkage {
    /// Experiment.
    pub experiment: String,
    /// Regime.
    pub regime: String,
    /// χ² of the base fit there.
    pub before: f64,
    /// χ² with the effect.
    pub after: f64,
    /// `1 − after/before`.
    pub shrinkage: f64,
}

/// A refit with the effect switched on.
#[derive(Clone, Debug, Serialize)]
pub struct Refit {
    /// Fitted parameters.
    pub parameters: Vec<Value>,
    /// Effect parameters.
    pub effect: Vec<Value>,
    /// χ² (noise units).
    pub chi2: f64,
    /// Realised shrinkage `1 − χ²/χ²_base`.
    pub shrinkage: f64,
    /// Per regime.
    pub by_regime: Vec<RegimeShrinkage>,
    /// Akaike information criterion `n ln(χ²/n) + 2k`.
    pub aic: f64,
    /// Bayesian information criterion `n ln(χ²/n) + k ln n`.
    pub bic: f64,
    /// AIC − AIC of the base (negative: the effect is worth its parameters).
    pub delta_aic: f64,
    /// BIC − BIC of the base.
    pub delta_bic: f64,
    /// Residual evaluations.
    pub evaluations: usize,
}

/// Prediction of withheld data with and without the effect.
#[derive(Clone, Debug, Serialize)]
pub struct Transfer {
    /// What was withheld.
    pub withheld: String,
    /// Readings predicted.
    pub readings: usize,
    /// χ² of the prediction without the effect.
    pub base_chi2: f64,
    /// χ² with the effect (None when the effect does not carry over).
    pub effect_chi2: Option<f64>,
    /// `1 − effect/base`.
    pub shrinkage: Option<f64>,
    /// Why the effect does not carry over, when it does not.
    pub note: Option<String>,
}

/// One candidate's results.
#[derive(Clone, Debug, Serialize)]
pub struct CandidateResult {
    /// Name.
    pub name: String,
    /// The physics.
    pub description: String,
    /// Score at the base fit (None when it could not be evaluated).
    pub score: Option<Score>,
    /// Why it has no score.
    pub error: Option<String>,
    /// Refit with the effect on (the best-scoring candidates only).
    pub refit: Option<Refit>,
    /// Transfer to withheld data.
    pub transfer: Vec<Transfer>,
}

/// A pair of candidates the data cannot tell apart.
#[derive(Clone, Debug, Serialize)]
pub struct Confusable {
    /// First candidate.
    pub a: String,
    /// Second candidate.
    pub b: String,
    /// Cosine between their sensitivities once the fitted parameters' span is removed.
    pub cos: f64,
}

/// Noise level of one response.
#[derive(Clone, Debug, Serialize)]
pub struct NoiseReport {
    /// Experiment.
    pub experiment: String,
    /// Load or debonded length (serialised as `F` or `L`).
    pub term: Term,
    /// Standard deviation.
    pub sigma: f64,
    /// `N` or `mm`.
    pub unit: String,
    /// Estimated from the data (false: given).
    pub estimated: bool,
}

/// Everything `gap.json` holds.
#[derive(Debug, Serialize)]
pub struct Diagnosis {
    /// Problem file.
    pub problem: String,
    /// Readings compared.
    pub readings: usize,
    /// Noise per response.
    pub noise: Vec<NoiseReport>,
    /// The base fit.
    pub base: BaseFit,
    /// Regimes per experiment.
    pub regimes: Vec<Regime>,
    /// Misfit per experiment, regime and response.
    pub misfit: Vec<RegimeMisfit>,
    /// Identifiability of the fitted parameters.
    pub identifiability: Identifiability,
    /// Candidates, best score first.
    pub candidates: Vec<CandidateResult>,
    /// Candidates that do not apply, with the reason.
    pub skipped: Vec<(String, String)>,
    /// Pairs of candidates the data cannot tell apart.
    pub confusable: Vec<Confusable>,
    /// Every pair's cosine (beyond the fitted parameters' span).
    pub pairs: Vec<Confusable>,
    /// Plain-words verdict.
    pub verdict: String,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// Records of the base fit (for plots).
    #[serde(skip)]
    pub base_records: BTreeMap<String, Record>,
    /// Records of the best candidate's refit (for plots).
    #[serde(skip)]
    pub best_records: Option<(String, BTreeMap<String, Record>)>,
    /// Residuals of the base fit (noise units, blocks as in the gauge).
    #[serde(skip)]
    pub base_residuals: Vec<f64>,
    /// The gauge.
    #[serde(skip)]
    pub gauge: Option<Gauge>,
}

struct Quiet;
impl Observer for Quiet {
    fn observe(&mut self, _: &Progress<'_>) -> bool {
        true
    }
}

fn aic_bic(chi2: f64, n: usize, k: usize) -> (f64, f64) {
    let n = n as f64;
    let l = n * (chi2.max(f64::MIN_POSITIVE) / n).ln();
    (l + 2.0 * k as f64, l + k as f64 * n.ln())
}

/// The fitted model on the base setup, as a residual function of unit-cube coordinates.
fn base_residuals<'a>(
    gauge: &'a Gauge,
    base: &'a Setup,
    space: &'a ParameterSpace,
) -> impl Fn(&[f64]) -> Result<Vec<f64>> + Sync + 'a {
    move |u: &[f64]| Ok(Misfit::of(gauge, &space.apply(base, &space.from_unit(u))?)?.r)
}

/// A candidate's extended model: fitted parameters then the effect's, unit-cube coordinates.
fn extended<'a>(
    gauge: &'a Gauge,
    base: &'a Setup,
    space: &'a ParameterSpace,
    c: &'a dyn CandidateEffect,
    params: &'a [Parameter],
) -> impl Fn(&[f64]) -> Result<Misfit> + Sync + 'a {
    move |v: &[f64]| {
        let p = space.dim();
        let fitted = space.apply(base, &space.from_unit(&v[..p]))?;
        let values: Vec<f64> = params.iter().zip(&v[p..]).map(|(q, &u)| q.from_unit(u)).collect();
        Misfit::of(gauge, &c.apply(&fitted, &values)?)
    }
}

struct RefitOutcome {
    v: Vec<f64>,
    misfit: Misfit,
    evaluations: usize,
    jacobian: Option<DMatrix<f64>>,
}

/// Refits a candidate on `gauge` from `start` (fitted and effect coordinates).
fn refit_on(
    gauge: &Gauge,
    base: &Setup,
    space: &ParameterSpace,
    c: &dyn CandidateEffect,
    params: &[Parameter],
    start: &[f64],
    jacobian: Option<DMatrix<f64>>,
) -> Result<RefitOutcome> {
    let model = extended(gauge, base, space, c, params);
    let f = |v: &[f64]| Ok(model(v)?.r);
    // A switch stays on; only the fitted parameters move.
    let fixed: Vec<usize> = if c.discrete() { (space.dim()..start.len()).collect() } else { Vec::new() };
    let opts = if c.discrete() { &REFIT_SWITCH } else { &REFIT };
    let res = lsq::minimize_from(&f, start, &fixed, opts, jacobian)?;
    let misfit = model(&res.u)?;
    Ok(RefitOutcome { v: res.u, misfit, evaluations: res.evaluations, jacobian: res.jacobian })
}

/// Refits start from the sensitivities of the scores and follow them with Broyden updates: one
/// run per step (a large-rotation run costs ~50 small-rotation ones), one fresh finite-difference
/// Jacobian if they stall.
const REFIT: LsOptions = LsOptions { max_iterations: 40, step: 2e-3, tolerance: 1e-6, fd_jacobians: 3 };
/// Unit-cube values from which the secondary parameters of a several-parameter effect are refitted
/// again.
const SECONDARY_STARTS: [f64; 3] = [0.1, 0.3, 0.6];
/// A switched-on effect only moves the fitted parameters, whose Jacobian barely changes with it;
/// its runs can be far dearer (large rotations), so fewer iterations and one fresh Jacobian.
const REFIT_SWITCH: LsOptions = LsOptions { max_iterations: 8, step: 2e-3, tolerance: 1e-4, fd_jacobians: 1 };

fn select_rows(m: &DMatrix<f64>, rows: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), m.ncols(), |i, j| m[(rows[i], j)])
}

/// What is diagnosed, independent of files: a setup, the fitted parameters and the data.
pub struct Subject {
    /// Shown in reports.
    pub name: String,
    /// The base setup (initial values).
    pub setup: Setup,
    /// The fitted parameters.
    pub space: ParameterSpace,
    /// The data.
    pub experiments: Vec<crate::data::Experiment>,
    /// Compare debonded lengths too (when measured).
    pub use_length: bool,
}

/// Diagnoses `problem` with the candidates of `library`.
pub fn diagnose(problem: &LoadedProblem, library: &Library, opts: &Options) -> Result<Diagnosis> {
    let say = |m: &str| {
        if let Some(p) = &opts.progress {
            p(m)
        }
    };
    let id = problem.identification()?;
    library.select(id.setup(), &opts.candidates)?;
    let space = id.space().clone();
    let p = space.dim();
    let clock = Instant::now();
    // Base fit: the file's optimizer unless a result is given; the polish follows in
    // `diagnose_subject`.
    let u0 = match &opts.start {
        Some(x) => {
            if x.len() != p {
                return Err(CzError::config("--from", format!("{} values for the problem's {p} parameters", x.len())));
            }
            space.check_within(x).map_err(|e| CzError::config("--from", e.to_string()))?;
            space.to_unit(x)
        }
        None => {
            say("fitting the base model with the problem file's optimizer");
            let spec = &problem.file.optimizer;
            let budget = Budget { evaluations: spec.budget, target: spec.target };
            let run = optimize(
                &id,
                &spec.kind,
                &toml::Value::Table(spec.settings.clone()),
                spec.seed,
                &budget,
                None,
                &mut Quiet,
            )?;
            run.result.best_x
        }
    };
    let subject = Subject {
        name: problem.path.display().to_string(),
        setup: id.setup().duplicate()?,
        space,
        experiments: problem.experiments.clone(),
        use_length: problem.file.objective.debonded_length,
    };
    let mut d = diagnose_subject(&subject, &u0, library, opts)?;
    d.wall_seconds = clock.elapsed().as_secs_f64();
    Ok(d)
}

/// Diagnoses `subject` from the unit-cube point `u0` of its parameters (polished first).
pub fn diagnose_subject(subject: &Subject, u0: &[f64], library: &Library, opts: &Options) -> Result<Diagnosis> {
    let clock = Instant::now();
    let say = |m: &str| {
        if let Some(p) = &opts.progress {
            p(m)
        }
    };
    let space = subject.space.clone();
    let base = subject.setup.duplicate()?;
    let chosen = library.select(&base, &opts.candidates)?;
    let gauge = Gauge::new(&subject.experiments, subject.use_length, opts.noise)?;
    let n = gauge.len();
    let p = space.dim();
    say("polishing the base fit on the misfit in noise units");
    let f = base_residuals(&gauge, &base, &space);
    let fit = lsq::minimize(&f, u0, &[], &LsOptions::default())?;
    let u = fit.u.clone();
    let x = space.from_unit(&u);
    let fitted = space.apply(&base, &x)?;
    let misfit = Misfit::of(&gauge, &fitted)?;
    let chi2 = misfit.rss();
    let dof = n.saturating_sub(p).max(1);
    let p_noise = chi2_survival(chi2, dof as f64);

    // 2. Where.
    let regs = regimes::split_setup(&gauge, &base, &subject.experiments);
    let by_regime = regimes::misfit_by_regime(&gauge, &regs, &misfit);

    // 3. Identifiability.
    say("identifiability of the fitted parameters");
    let jac = lsq::jacobian(&f, &u, FD_STEP)?;
    let assessment = assess_jacobian(&space, &u, &misfit.r, &jac);
    let parameters = space
        .parameters()
        .iter()
        .enumerate()
        .map(|(j, q)| FittedParameter {
            path: q.path.clone(),
            value: x[j],
            unit: q.unit.clone(),
            standard_error: assessment.standard_errors[j],
            sensitivity: assessment.sensitivities[j],
            verdict: assessment.verdicts[j].describe(&space),
        })
        .collect();
    let identifiability = Identifiability {
        singular_values: assessment.singular_values.clone(),
        collinearity_index: assessment.collinearity_index,
        correlations: (0..p).map(|a| (0..p).map(|b| assessment.correlations[a * p + b]).collect()).collect(),
    };
    let lin = Linearisation::new(&misfit.r, jac);

    // 4. Which.
    let mut skipped = Vec::new();
    let applicable: Vec<&dyn CandidateEffect> = chosen
        .iter()
        .map(|c| c.as_ref())
        .filter(|c| {
            let ok = c.applies(&fitted);
            if !ok {
                skipped.push((
                    c.name().to_string(),
                    "does not apply to this setup (other model type or law, or already switched on)".to_string(),
                ));
            }
            ok
        })
        .collect();
    say(&format!("scoring {} candidate effects", applicable.len()));
    let sens = score::sensitivities(&gauge, &fitted, &misfit.r, &applicable);
    let tests = applicable.len();
    let mut results: Vec<(CandidateResult, Option<Sensitivity>, &dyn CandidateEffect)> = applicable
        .iter()
        .zip(sens)
        .map(|(c, s)| {
            let (score, error, sens) = match s {
                Ok(s) => (Some(score::score(&lin, &s, &space, &u, tests)), None, Some(s)),
                Err(e) => (None, Some(e), None),
            };
            (
                CandidateResult {
                    name: c.name().into(),
                    description: c.describe(),
                    score,
                    error,
                    refit: None,
                    transfer: Vec::new(),
                },
                sens,
                *c,
            )
        })
        .collect();
    results.sort_by(|a, b| {
        let s = |r: &CandidateResult| r.score.as_ref().map_or(-1.0, |s| s.statistic);
        s(&b.0).total_cmp(&s(&a.0))
    });
    let mut pairs = Vec::new();
    for i in 0..results.len() {
        for j in i + 1..results.len() {
            if let (Some(a), Some(b)) = (&results[i].1, &results[j].1) {
                let cos = score::confusability(&lin, a, b);
                pairs.push(Confusable { a: a.name.clone(), b: b.name.clone(), cos });
            }
        }
    }
    let confusable: Vec<Confusable> = pairs.iter().filter(|c| c.cos > CONFUSABLE).cloned().collect();

    // 5. How far: refits and transfer.
    let (base_aic, base_bic) = aic_bic(chi2, n, p);
    let base_regime_chi2 = regimes::rss_by_regime(&gauge, &regs, &misfit.r);
    // The held-out part of each curve: its family's held-out regime when that is its last regime
    // (the late stage; a beam's debonding), else the last quarter of its displacements.
    let mut starts: BTreeMap<String, (f64, Option<&'static str>)> = BTreeMap::new();
    for b in gauge.blocks.iter().filter(|b| b.term == Term::Load) {
        let rule = regimes::regime_set(&base, &b.experiment);
        let held = rule.held_out();
        let from = regs.iter().rfind(|r| r.experiment == b.experiment).filter(|r| r.name == held).map(|r| r.from);
        let quarter = b.x[0] + 0.75 * (b.x[b.x.len() - 1] - b.x[0]);
        starts.insert(b.experiment.clone(), (from.unwrap_or(quarter), from.map(|_| rule.held_out_label())));
    }
    let split = |exp: &str| starts.get(exp).map_or(f64::INFINITY, |s| s.0);
    let labels: Vec<Option<&str>> = starts.values().map(|s| s.1).collect();
    let held_label = match labels.first() {
        Some(Some(l)) if labels.iter().all(|g| *g == Some(*l)) => l,
        Some(None) if labels.iter().all(Option::is_none) => "last quarter of each curve",
        _ => "last regime or quarter of each curve",
    };
    let early = gauge.restricted(|e, x| x < split(e));
    let early_rows = gauge.rows(|e, x| x < split(e));
    let late = gauge.restricted(|e, x| x >= split(e));
    let holdout_base = if opts.holdout && !late.is_empty() && !early.is_empty() {
        say(&format!("base fit without the {held_label} (held out)"));
        let fe = base_residuals(&early, &base, &space);
        let r = lsq::minimize_from(&fe, &u, &[], &REFIT, Some(select_rows(&lin.jac, &early_rows)))?;
        let predicted = Misfit::of(&late, &space.apply(&base, &space.from_unit(&r.u))?)?;
        Some(predicted.rss())
    } else {
        None
    };
    let withheld_base: Vec<(String, Gauge, Setup, ParameterSpace, Vec<f64>, f64)> = opts
        .withheld
        .iter()
        .map(|w| {
            let g = Gauge::new(&w.experiments, w.file.objective.debonded_length, opts.noise)?;
            let setup = w.setup()?;
            // Only the parameters that exist in the withheld setup carry over (a law, a shared
            // modulus), not another specimen's own.
            let idx: Vec<usize> = (0..p)
                .filter(|&j| {
                    ParameterSpace::new(vec![space.parameters()[j].clone()]).and_then(|s| s.read(&setup)).is_ok()
                })
                .collect();
            let sub = ParameterSpace::new(idx.iter().map(|&j| space.parameters()[j].clone()).collect())?;
            let xs: Vec<f64> = idx.iter().map(|&j| x[j]).collect();
            let chi = Misfit::of(&g, &sub.apply(&setup, &xs)?)?.rss();
            Ok((w.path.display().to_string(), g, setup, sub, idx.iter().map(|&j| j as f64).collect(), chi))
        })
        .collect::<Result<_>>()?;

    let mut best_records = None;
    let scored: Vec<usize> =
        (0..results.len()).filter(|&i| results[i].0.score.as_ref().is_some_and(|s| s.dof > 0)).collect();
    let mut top: Vec<usize> = scored.iter().copied().take(opts.refit).collect();
    let extra: Vec<usize> = scored
        .iter()
        .copied()
        .filter(|&i| !top.contains(&i) && opts.always_refit.contains(&results[i].0.name))
        .collect();
    top.extend(extra);
    for &i in &top {
        let (res, sens, c) = &mut results[i];
        let sens = sens.as_ref().expect("scored candidates have a sensitivity");
        let s = res.score.as_ref().expect("scored");
        say(&format!("refitting with {}", c.name()));
        let params: Vec<Parameter> = sens.parameters.iter().map(|q| q.parameter.clone()).collect();
        let null_start: Vec<f64> = u.iter().copied().chain(sens.null_u.iter().copied()).collect();
        // The joint first-order prediction: the effect at the size the data ask for, the fitted
        // parameters moved by what they no longer have to absorb. When the response is strongly
        // non-linear in the effect, a fraction of that step is the better start; failing all, the
        // null (a switch: on, with the fitted values).
        let model = extended(&gauge, &base, &space, *c, &params);
        let along = |t: f64| -> Vec<f64> {
            let fitted = u.iter().zip(&s.fitted_shift).map(|(a, b)| (a + t * b).clamp(0.0, 1.0));
            if c.discrete() {
                fitted.chain(std::iter::repeat_n(1.0, params.len())).collect()
            } else {
                let effect = sens.null_u.iter().zip(params.iter().zip(&s.predicted)).map(|(&u0, (q, v))| {
                    let full = q.to_unit(v.1);
                    (u0 + t * (full - u0)).clamp(0.0, 1.0)
                });
                fitted.chain(effect).collect()
            }
        };
        let start = [1.0, 0.5, 0.25, 0.125]
            .into_iter()
            .map(along)
            .find(|v| model(v).is_ok_and(|m| m.rss() <= chi2))
            .unwrap_or_else(|| {
                if c.discrete() {
                    u.iter().copied().chain(std::iter::repeat_n(1.0, params.len())).collect()
                } else {
                    null_start
                }
            });
        let jac0 = if c.discrete() {
            lin.jac.clone()
        } else {
            let mut m = DMatrix::zeros(n, p + params.len());
            m.columns_mut(0, p).copy_from(&lin.jac);
            m.columns_mut(p, params.len()).copy_from(&sens.columns);
            m
        };
        let mut out = match refit_on(&gauge, &base, &space, *c, &params, &start, Some(jac0)) {
            Ok(o) => o,
            Err(e) => {
                res.error = Some(format!("refit failed: {e}"));
                continue;
            }
        };
        // An effect of several parameters can trade one against another along a valley (a
        // bridging tail's strength against its length): the refit is repeated from other values
        // of every parameter but the first, and the best kept.
        if !c.discrete() && params.len() > 1 {
            for j in 1..params.len() {
                for w in SECONDARY_STARTS {
                    if (out.v[p + j] - w).abs() < 0.1 {
                        continue;
                    }
                    let mut v = out.v.clone();
                    v[p + j] = w;
                    if let Ok(o) = refit_on(&gauge, &base, &space, *c, &params, &v, out.jacobian.clone()) {
                        if o.misfit.rss() < out.misfit.rss() {
                            out = RefitOutcome { evaluations: out.evaluations + o.evaluations, ..o };
                        } else {
                            out.evaluations += o.evaluations;
                        }
                    }
                }
            }
        }
        let k = p + if c.discrete() { 1 } else { sens.columns.ncols() };
        let chi = out.misfit.rss();
        let (aic, bic) = aic_bic(chi, n, k);
        let after = regimes::rss_by_regime(&gauge, &regs, &out.misfit.r);
        let by_regime = regs
            .iter()
            .zip(base_regime_chi2.iter().zip(&after))
            .map(|(g, (b, a))| RegimeShrinkage {
                experiment: g.experiment.clone(),
                regime: g.name.clone(),
                before: *b,
                after: *a,
                shrinkage: if *b > 0.0 { 1.0 - a / b } else { 0.0 },
            })
            .collect();
        let xv = space.from_unit(&out.v[..p]);
        let ev: Vec<f64> = params.iter().zip(&out.v[p..]).map(|(q, &w)| q.from_unit(w)).collect();
        res.refit = Some(Refit {
            parameters: space
                .parameters()
                .iter()
                .zip(&xv)
                .map(|(q, &v)| Value { name: q.path.clone(), value: v, unit: q.unit.clone() })
                .collect(),
            effect: params
                .iter()
                .zip(&ev)
                .map(|(q, &v)| Value { name: q.path.clone(), value: v, unit: q.unit.clone() })
                .collect(),
            chi2: chi,
            shrinkage: 1.0 - chi / chi2.max(f64::MIN_POSITIVE),
            by_regime,
            aic,
            bic,
            delta_aic: aic - base_aic,
            delta_bic: bic - base_bic,
            evaluations: out.evaluations,
        });
        if best_records.is_none() {
            best_records = Some((c.name().to_string(), out.misfit.records));
        }
        // Transfer 1: the last regime of every curve (late stage, debonding), held out of both
        // fits. An effect that barely changes the fit has nothing to transfer, and its refit may
        // be dear (large rotations).
        let realised = 1.0 - chi / chi2.max(f64::MIN_POSITIVE);
        if holdout_base.is_some() && realised < TRANSFER_FROM {
            res.transfer.push(Transfer {
                withheld: held_label.into(),
                readings: late.len(),
                base_chi2: holdout_base.unwrap_or(f64::NAN),
                effect_chi2: None,
                shrinkage: None,
                note: Some(format!(
                    "not checked: the effect removes under {:.0}% of the misfit",
                    100.0 * TRANSFER_FROM
                )),
            });
        } else if let Some(base_late) = holdout_base {
            say(&format!("{}: fit without the {held_label}, predict it", c.name()));
            let jac_early = out.jacobian.as_ref().map(|j| select_rows(j, &early_rows));
            let t = refit_on(&early, &base, &space, *c, &params, &out.v, jac_early).and_then(|o| {
                let m = extended(&late, &base, &space, *c, &params);
                Ok(m(&o.v)?.rss())
            });
            res.transfer.push(match t {
                Ok(e) => Transfer {
                    withheld: held_label.into(),
                    readings: late.len(),
                    base_chi2: base_late,
                    effect_chi2: Some(e),
                    shrinkage: Some(1.0 - e / base_late.max(f64::MIN_POSITIVE)),
                    note: None,
                },
                Err(e) => Transfer {
                    withheld: held_label.into(),
                    readings: late.len(),
                    base_chi2: base_late,
                    effect_chi2: None,
                    shrinkage: None,
                    note: Some(format!("the refit without the late stage failed: {e}")),
                },
            });
        }
        // Transfer 2: other tests, predicted with the parameters calibrated here.
        for (name, g, setup, sub, idx, base_chi) in &withheld_base {
            let note = if !c.transferable() {
                Some("specimen-specific effect: its value does not carry over to another test".to_string())
            } else if !c.applies(setup) {
                Some("does not apply to the withheld test's model".to_string())
            } else {
                None
            };
            let mut tr = Transfer {
                withheld: name.clone(),
                readings: g.len(),
                base_chi2: *base_chi,
                effect_chi2: None,
                shrinkage: None,
                note: note.clone(),
            };
            if note.is_none() {
                let xs: Vec<f64> = idx.iter().map(|&j| xv[j as usize]).collect();
                let predicted = sub.apply(setup, &xs).and_then(|s| c.apply(&s, &ev)).and_then(|s| Misfit::of(g, &s));
                match predicted {
                    Ok(m) => {
                        tr.effect_chi2 = Some(m.rss());
                        tr.shrinkage = Some(1.0 - m.rss() / base_chi.max(f64::MIN_POSITIVE));
                    }
                    Err(e) => tr.note = Some(format!("prediction failed: {e}")),
                }
            }
            res.transfer.push(tr);
        }
    }

    let candidates: Vec<CandidateResult> = results.into_iter().map(|(r, _, _)| r).collect();
    drop(f);
    let base_fit = BaseFit {
        parameters,
        chi2,
        reduced_chi2: chi2 / dof as f64,
        p_value: p_noise,
        at_noise_level: p_noise > NOISE_LEVEL,
        evaluations: fit.evaluations,
        failures: misfit.failures.clone(),
    };
    let verdict = verdict(&base_fit, &by_regime, &candidates, &confusable);
    let noise = gauge
        .blocks
        .iter()
        .map(|b| NoiseReport {
            experiment: b.experiment.clone(),
            term: b.term,
            sigma: b.sigma,
            unit: b.term.unit().into(),
            estimated: b.sigma_estimated,
        })
        .collect();
    Ok(Diagnosis {
        problem: subject.name.clone(),
        readings: n,
        noise,
        base: base_fit,
        regimes: regs,
        misfit: by_regime,
        identifiability,
        candidates,
        skipped,
        confusable,
        pairs,
        verdict,
        wall_seconds: clock.elapsed().as_secs_f64(),
        base_records: misfit.records,
        best_records,
        base_residuals: misfit.r,
        gauge: Some(gauge),
    })
}

fn pct(v: f64) -> String {
    format!("{:.0}%", 100.0 * v)
}

/// The verdict in plain words.
pub fn verdict(
    base: &BaseFit,
    misfit: &[RegimeMisfit],
    candidates: &[CandidateResult],
    confusable: &[Confusable],
) -> String {
    let mut out = String::new();
    if let Some(m) = misfit.iter().max_by(|a, b| a.share.total_cmp(&b.share)) {
        let what = m.term.noun();
        out.push_str(&format!(
            "The misfit sits mostly in the {} regime of {} ({} of it; {what}: {}, mean test − model {:+.3} {}).",
            m.regime,
            m.experiment,
            pct(m.share),
            m.sign,
            m.mean,
            m.unit
        ));
    }
    let best = candidates.first().and_then(|c| c.score.as_ref().map(|s| (c, s)));
    match best {
        Some((c, s)) if s.significant => {
            out.push_str(&format!(
                " Most likely cause: {} ({}); to first order it explains {} of the misfit (score {:.1}, p = {:.1e}).",
                c.name, c.description, pct(s.explained), s.statistic, s.p_value
            ));
            if let Some(r) = &c.refit {
                out.push_str(&format!(
                    " Adding it removes {} of the misfit (ΔBIC = {:.1}).",
                    pct(r.shrinkage),
                    r.delta_bic
                ));
            }
            for t in &c.transfer {
                match t.shrinkage {
                    Some(sh) if sh >= 0.0 => {
                        out.push_str(&format!(" On withheld data ({}) it removes {}.", t.withheld, pct(sh)))
                    }
                    Some(sh) => out.push_str(&format!(
                        " On withheld data ({}) it makes the prediction worse (misfit +{}).",
                        t.withheld,
                        pct(-sh)
                    )),
                    None => out.push_str(&format!(
                        " Withheld data ({}): {}.",
                        t.withheld,
                        t.note.clone().unwrap_or_default()
                    )),
                }
            }
            if let (Some(by), Some(shift)) = (&s.absorbed_by, s.absorbed_shift) {
                out.push_str(&format!(" Without it, {by} absorbs it (first-order shift {shift:+.4e}"));
                let before = base.parameters.iter().find(|q| &q.path == by);
                let after = c.refit.as_ref().and_then(|r| r.parameters.iter().find(|q| &q.name == by));
                if let (Some(b), Some(a)) = (before, after) {
                    out.push_str(&format!("; the refit moves it from {:.4e} to {:.4e} {}", b.value, a.value, b.unit));
                }
                out.push_str(").");
            }
            let twins: Vec<String> = confusable
                .iter()
                .filter(|p| p.a == c.name || p.b == c.name)
                .map(|p| if p.a == c.name { p.b.clone() } else { p.a.clone() })
                .collect();
            if !twins.is_empty() {
                out.push_str(&format!(" These data can hardly tell it from {}.", twins.join(", ")));
            }
            if !base.at_noise_level {
                if let Some(r) = &c.refit {
                    if r.chi2 / base.chi2.max(f64::MIN_POSITIVE) * base.reduced_chi2 > 2.0 {
                        out.push_str(" Even with it the misfit stays well above the noise: more is missing.");
                    }
                }
            }
        }
        _ if base.at_noise_level => out = format!(
            "No unmodelled effect is needed at this noise level: the base model fits to χ²/dof = {:.2} and no candidate scores significantly.",
            base.reduced_chi2
        ),
        Some((c, s)) => out.push_str(&format!(
            " The misfit exceeds the noise (χ²/dof = {:.1}) but no candidate explains a significant part of it; the best, {}, explains {}.",
            base.reduced_chi2, c.name, pct(s.explained)
        )),
        None => out.push_str(" No candidate effect could be scored."),
    }
    out
}
