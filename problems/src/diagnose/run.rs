//! The whole diagnosis: base fit, where, identifiability, which, how far, transfer, verdict.

use crate::diagnose::candidate::Library;
use crate::diagnose::gauge::{Gauge, NoiseLevels};
use crate::diagnose::regimes::{self, Regime, RegimeMisfit};
use crate::diagnose::score::Score;
use crate::diagnose::stages::model_form::{self, ModelForm};
use crate::diagnose::stages::transfer::{Holdout, Withheld};
use crate::diagnose::stages::verdict::{self as decide, Outcome};
use crate::diagnose::stages::{base, ranking, refit};
use crate::farm::{TaskFarm, Threads};
use crate::identification::{Setup, Term};
use crate::identify::optimize;
use crate::problem_file::LoadedProblem;
use czid_core::{Budget, CzError, Observer, Parameter, ParameterSpace, Progress, Record, Result};
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// Significance of the base misfit against the noise (χ² with n − p degrees of freedom).
pub const NOISE_LEVEL: f64 = 1e-3;
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
    /// At most how many significant candidates to refit (best score first); every significant
    /// one up to this number is refitted, and the cause is decided on the refits. The default
    /// (`usize::MAX`) refits every significant candidate: the cause is the refit that removes
    /// most, which need not be among the best scores.
    pub refit: usize,
    /// Noise levels instead of estimates from the data.
    pub noise: NoiseLevels,
    /// Other tests predicted with the calibrated parameters (transfer), e.g. other specimens.
    pub withheld: Vec<LoadedProblem>,
    /// Also check transfer to the held-out last regime of each curve (the late stage; a beam's
    /// debonding, [`czid_core::RegimeRule::held_out`]).
    pub holdout: bool,
    /// Candidates refitted whatever their score (e.g. the planted effect of a benchmark case); a
    /// name that is not among the diagnosis's candidates is an error.
    pub always_refit: Vec<String>,
    /// Account for the model-form misfit with the models' reference models
    /// ([`super::stages::model_form`]) before judging any candidate.
    pub model_form: bool,
    /// Called with a short message as each stage starts (e.g. for a progress display).
    pub progress: Option<ProgressFn>,
    /// Where the candidates' refits run (`None`: this process's threads); e.g. spread over MPI
    /// ranks that each build the same diagnosis up to the refits. The diagnosis is the same
    /// wherever they run.
    pub farm: Option<std::sync::Arc<dyn TaskFarm>>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            candidates: Vec::new(),
            start: None,
            refit: usize::MAX,
            noise: NoiseLevels::default(),
            withheld: Vec::new(),
            holdout: true,
            always_refit: Vec::new(),
            model_form: true,
            progress: None,
            farm: None,
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
    /// Probability of the structure in its residuals under white noise
    /// ([`crate::diagnose::stats::structure_p`]).
    pub structure_p: f64,
    /// Whether the model-form floor was accounted for (the data shifted by the reference model's
    /// difference).
    pub model_form_accounted: bool,
    /// Residual evaluations of the fit (after the file's optimizer, if run).
    pub evaluations: usize,
    /// Runs that stopped early at the fit.
    pub failures: Vec<String>,
    /// Fitted parameters that sit at a bound of their range after the restarts (the truth may
    /// lie beyond it, or the fit is lost).
    pub at_bound: Vec<String>,
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
    /// The effect is a switch (large rotations: on or off), so the refit has no size of the
    /// effect to fit, only the fitted parameters.
    pub switch: bool,
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
    /// χ² once the model-form misfit is estimated again at this refit's fitted parameters and the
    /// refit polished on it (the named cause only, when the floor applies): what "more is
    /// missing" is judged on.
    pub chi2_reestimated: Option<f64>,
    /// Probability of the structure left in the refit's residuals under white noise
    /// ([`crate::diagnose::stats::structure_p`]; on the re-estimated floor when there is one):
    /// below the noise level, more is missing even when the χ² of all readings cannot tell.
    pub structure_p: f64,
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
    /// Refitted only because the caller asked for it ([`Options::always_refit`], e.g. a
    /// benchmark's planted effect): its refit is reported, but it takes no part in the verdict,
    /// which stays the one a diagnosis without that knowledge gives.
    pub on_request: bool,
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
    /// The model-form floor.
    pub model_form: ModelForm,
    /// The verdict, machine-readable.
    pub outcome: Outcome,
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
    /// The gauge (its data with the model-form shift when it was accounted for).
    #[serde(skip)]
    pub gauge: Option<Gauge>,
    /// The data as measured (for plots).
    #[serde(skip)]
    pub measured: Option<Gauge>,
}

struct Quiet;
impl Observer for Quiet {
    fn observe(&mut self, _: &Progress<'_>) -> bool {
        true
    }
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

/// Diagnoses `subject` from the unit-cube point `u0` of its parameters (polished first): the
/// base fit, where the misfit lies, what the data determine, which candidates explain it, how far
/// the misfit shrinks with the best of them and whether that carries over to withheld data.
pub fn diagnose_subject(subject: &Subject, u0: &[f64], library: &Library, opts: &Options) -> Result<Diagnosis> {
    let clock = Instant::now();
    let say = |m: &str| {
        if let Some(p) = &opts.progress {
            p(m)
        }
    };
    let chosen = library.select(&subject.setup, &opts.candidates)?;
    // A refit asked for by name must not be dropped in silence (a misspelt name would be).
    if let Some(n) = opts.always_refit.iter().find(|n| !chosen.iter().any(|c| c.name() == n.as_str())) {
        let known: Vec<&str> = chosen.iter().map(|c| c.name()).collect();
        return Err(CzError::config(
            "always_refit",
            format!(
                "`{n}` is not among this diagnosis's candidates, so it cannot be refitted; they are: {}",
                known.join(", ")
            ),
        ));
    }
    let gauge = Gauge::new(&subject.experiments, subject.use_length, opts.noise)?;
    let measured = gauge.clone();
    say("polishing the base fit on the misfit in noise units");
    let first = base::fit(subject, u0, gauge)?;
    let (base, model_form) = if opts.model_form {
        say("the model-form floor: the base fit run through the reference model");
        match model_form::account(&first)? {
            (Some(accounted), mut form) => {
                say("polishing the base fit with the model-form misfit accounted for");
                let b = base::fit(subject, &first.u, accounted)?;
                form.chi2_accounted = b.chi2;
                (b, form)
            }
            (None, form) => (first, form),
        }
    } else {
        let chi2 = first.chi2;
        (first, ModelForm::not_estimated(chi2, "not asked for".into()))
    };
    // Where.
    let regs = regimes::split_setup(&base.gauge, &base.setup, &subject.experiments);
    let by_regime = regimes::misfit_by_regime(&base.gauge, &regs, &base.misfit);
    say("identifiability of the fitted parameters");
    let (parameters, identifiability, lin) = base::assess(&base)?;
    // Which.
    say(&format!("scoring {} candidate effects", chosen.iter().filter(|c| c.applies(&base.fitted)).count()));
    let mut ranking = ranking::rank(&base, &lin, chosen);
    // How far, and transfer.
    let holdout = Holdout::prepare(&base, &regs, &lin, opts.holdout, &say)?;
    let withheld = Withheld::prepare(&base, &opts.withheld, opts.noise)?;
    let above_noise = base.p_noise <= NOISE_LEVEL;
    let todo = ranking.to_refit(opts.refit, above_noise, &opts.always_refit);
    let farm = opts.farm.as_deref().unwrap_or(&Threads);
    let Some(mut refits) =
        refit_candidates(&base, &lin, &regs, &mut ranking, &todo, (holdout.as_ref(), &withheld), &say, farm)?
    else {
        return Err(CzError::config("diagnose", "this process ran refits for another one, which keeps the diagnosis"));
    };
    let ranking::Ranking { ranked, skipped, pairs, confusable } = ranking;
    let mut candidates: Vec<CandidateResult> = ranked.into_iter().map(|r| r.result).collect();
    let base_fit = BaseFit {
        parameters,
        chi2: base.chi2,
        reduced_chi2: base.chi2 / base.dof as f64,
        p_value: base.p_noise,
        at_noise_level: base.p_noise > NOISE_LEVEL,
        structure_p: base.gauge.structure_p(&base.misfit.r),
        model_form_accounted: model_form.applied(),
        evaluations: base.evaluations,
        failures: base.misfit.failures.clone(),
        at_bound: base::at_bound(&base.u).into_iter().map(|j| base.space.parameters()[j].path.clone()).collect(),
    };
    let first = decide::decide(&base_fit, base.readings(), &candidates, &confusable);
    if let (Some(cause), true) = (&first.cause, model_form.applied()) {
        // The floor was estimated at the base fit, which an effect may have pulled away from the
        // truth; the cause's refit is judged again with the floor re-estimated at its parameters.
        if let Some((c, params, out)) = refits.get(cause) {
            say(&format!("{cause}: the model-form floor re-estimated at its refit"));
            let again = reestimated(&base, &measured, c.as_ref(), params, out)?;
            if let Some(r) = candidates.iter_mut().find(|x| &x.name == cause).and_then(|x| x.refit.as_mut()) {
                if let Some((chi2, structure)) = again {
                    r.chi2_reestimated = Some(chi2);
                    r.structure_p = structure;
                }
            }
        }
    }
    let outcome = decide::decide(&base_fit, base.readings(), &candidates, &confusable);
    let verdict = decide::text(&base_fit, &model_form, &by_regime, &candidates, &outcome);
    let best_records = outcome.cause.as_ref().and_then(|c| refits.remove(c).map(|r| (c.clone(), r.2.misfit.records)));
    let noise = base
        .gauge
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
        readings: base.readings(),
        noise,
        base: base_fit,
        regimes: regs,
        misfit: by_regime,
        identifiability,
        candidates,
        skipped,
        confusable,
        pairs,
        model_form,
        outcome,
        verdict,
        wall_seconds: clock.elapsed().as_secs_f64(),
        base_records: base.misfit.records,
        best_records,
        base_residuals: base.misfit.r,
        gauge: Some(base.gauge),
        measured: Some(measured),
    })
}

/// χ² of candidate `c`'s refit `out` polished again on the measured data shifted by the model-form
/// misfit at the refit's fitted parameters, and the structure left in its residuals (`None` when
/// that cannot be estimated or the polish fails).
fn reestimated(
    base: &base::Base,
    measured: &Gauge,
    c: &dyn crate::diagnose::CandidateEffect,
    params: &[Parameter],
    out: &refit::RefitOutcome,
) -> Result<Option<(f64, f64)>> {
    let p = base.space.dim();
    let fitted = base.space.apply(&base.setup, &base.space.from_unit(&out.v[..p]))?;
    let Some(gauge) = model_form::account_at(measured, &fitted)? else { return Ok(None) };
    let gauge = model_form::with_floor_of(gauge, &base.gauge);
    Ok(refit::refit_on(&gauge, base, c, params, &out.v, out.jacobian.clone())
        .ok()
        .map(|o| (o.misfit.rss(), gauge.structure_p(&o.misfit.r))))
}

/// A refitted candidate: the effect, its parameters and the refit.
type Refitted = (std::sync::Arc<dyn crate::diagnose::CandidateEffect>, Vec<Parameter>, refit::RefitOutcome);

/// Refits the candidates `todo` of `ranking` side by side through `farm` (each refit runs one
/// simulation per step, so one refit alone leaves cores idle), checks their transfer, and writes
/// the results into the ranking; returns the refits by candidate name (`None` on a process that
/// only ran refits for another one). The results do not depend on where or in which order the
/// refits run: each crosses as its bit patterns ([`wire`]) and is stored under its candidate.
#[allow(clippy::too_many_arguments)]
fn refit_candidates(
    base: &base::Base,
    lin: &crate::diagnose::score::Linearisation,
    regs: &[Regime],
    ranking: &mut ranking::Ranking,
    todo: &[usize],
    (holdout, withheld): (Option<&Holdout>, &[Withheld]),
    say: &(dyn Fn(&str) + Sync),
    farm: &dyn TaskFarm,
) -> Result<Option<BTreeMap<String, Refitted>>> {
    let ranked = &ranking.ranked;
    let task = |i: usize| -> Vec<u8> {
        let entry = &ranked[i];
        let c = entry.effect.as_ref();
        say(&format!("refitting with {}", c.name()));
        let (sens, score) = (entry.sensitivity.as_ref().expect("scored"), entry.result.score.as_ref().expect("scored"));
        let done = refit::refit(base, lin, c, sens, score).map_err(|e| format!("refit failed: {e}")).map(|out| {
            let report = refit::report(base, regs, entry, &out);
            let params: Vec<Parameter> = sens.parameters.iter().map(|q| q.parameter.clone()).collect();
            let mut transfer = Vec::new();
            if let Some(h) = holdout {
                transfer.push(h.check(base, c, &params, &out, report.shrinkage, say));
            }
            let effect: Vec<f64> = report.effect.iter().map(|v| v.value).collect();
            let x: Vec<f64> = report.parameters.iter().map(|v| v.value).collect();
            transfer.extend(withheld.iter().map(|w| w.predict(c, &x, &effect)));
            (out, transfer)
        });
        wire::encode(&entry.result.name, done)
    };
    let Some(done) = farm.run(todo, &task)? else { return Ok(None) };
    let mut refits = BTreeMap::new();
    for (&i, bytes) in todo.iter().zip(done) {
        let entry = &mut ranking.ranked[i];
        match wire::decode(&entry.result.name, &bytes)? {
            Ok((out, transfer)) => {
                // The report is made again here from the refit itself, as where it ran.
                let report = refit::report(base, regs, entry, &out);
                let sens = entry.sensitivity.as_ref().expect("scored");
                let params: Vec<Parameter> = sens.parameters.iter().map(|q| q.parameter.clone()).collect();
                entry.result.refit = Some(report);
                entry.result.transfer.extend(transfer);
                refits.insert(entry.result.name.clone(), (entry.effect.clone(), params, out));
            }
            Err(e) => entry.result.error = Some(e),
        }
    }
    Ok(Some(refits))
}

/// A refit as it crosses between processes: its candidate's name (checked on arrival: every
/// process must have ranked the same candidates), then the refit and its transfer checks, or why
/// it failed; floating values as their bit patterns, so they arrive exactly.
mod wire {
    use super::Transfer;
    use crate::diagnose::gauge::Misfit;
    use crate::diagnose::stages::refit::RefitOutcome;
    use crate::farm::{bits, values};
    use czid_core::{CzError, Record, Result};
    use nalgebra::DMatrix;
    use serde::{Deserialize, Serialize};

    /// A refit and its transfer checks, or why the refit failed.
    pub type Done = std::result::Result<(RefitOutcome, Vec<Transfer>), String>;

    #[derive(Serialize, Deserialize)]
    struct Message {
        name: String,
        done: std::result::Result<RefitBits, String>,
    }

    /// A column of a record: name, unit, values.
    type ColumnBits = (String, String, Vec<u64>);

    #[derive(Serialize, Deserialize)]
    struct RefitBits {
        v: Vec<u64>,
        r: Vec<u64>,
        records: Vec<(String, Vec<ColumnBits>)>,
        failures: Vec<String>,
        evaluations: usize,
        /// Rows, columns, values column by column.
        jacobian: Option<(usize, usize, Vec<u64>)>,
        transfer: Vec<TransferBits>,
    }

    #[derive(Serialize, Deserialize)]
    struct TransferBits {
        withheld: String,
        readings: usize,
        base_chi2: u64,
        effect_chi2: Option<u64>,
        shrinkage: Option<u64>,
        note: Option<String>,
    }

    fn record(columns: Vec<ColumnBits>) -> Record {
        let spec: Vec<(&str, &str)> = columns.iter().map(|(n, u, _)| (n.as_str(), u.as_str())).collect();
        let mut r = Record::new(&spec);
        let rows = columns.first().map_or(0, |c| c.2.len());
        for i in 0..rows {
            r.push(&columns.iter().map(|c| f64::from_bits(c.2[i])).collect::<Vec<f64>>());
        }
        r
    }

    /// The message of candidate `name`'s refit.
    pub fn encode(name: &str, done: Done) -> Vec<u8> {
        let done = done.map(|(o, transfer)| RefitBits {
            v: bits(&o.v),
            r: bits(&o.misfit.r),
            records: o
                .misfit
                .records
                .iter()
                .map(|(k, rec)| {
                    let columns = rec.columns().iter().map(|c| (c.name.clone(), c.unit.clone(), bits(&c.values)));
                    (k.clone(), columns.collect())
                })
                .collect(),
            failures: o.misfit.failures,
            evaluations: o.evaluations,
            jacobian: o.jacobian.map(|j| (j.nrows(), j.ncols(), bits(j.as_slice()))),
            transfer: transfer
                .into_iter()
                .map(|t| TransferBits {
                    withheld: t.withheld,
                    readings: t.readings,
                    base_chi2: t.base_chi2.to_bits(),
                    effect_chi2: t.effect_chi2.map(f64::to_bits),
                    shrinkage: t.shrinkage.map(f64::to_bits),
                    note: t.note,
                })
                .collect(),
        });
        serde_json::to_vec(&Message { name: name.to_string(), done }).expect("plain data serialises")
    }

    /// Candidate `name`'s refit from its message; an error when the message is unreadable or
    /// belongs to another candidate.
    pub fn decode(name: &str, bytes: &[u8]) -> Result<Done> {
        let m: Message = serde_json::from_slice(bytes)
            .map_err(|e| CzError::Simulation(format!("the refit of {name} came back unreadable: {e}")))?;
        if m.name != name {
            return Err(CzError::Simulation(format!(
                "the refit of {name} came back as {}'s: the processes ranked the candidates differently",
                m.name
            )));
        }
        Ok(m.done.map(|b| {
            let misfit = Misfit {
                r: values(&b.r),
                records: b.records.into_iter().map(|(k, c)| (k, record(c))).collect(),
                failures: b.failures,
            };
            let jacobian = b.jacobian.map(|(n, m, v)| DMatrix::from_vec(n, m, values(&v)));
            let outcome = RefitOutcome { v: values(&b.v), misfit, evaluations: b.evaluations, jacobian };
            let transfer = b
                .transfer
                .into_iter()
                .map(|t| Transfer {
                    withheld: t.withheld,
                    readings: t.readings,
                    base_chi2: f64::from_bits(t.base_chi2),
                    effect_chi2: t.effect_chi2.map(f64::from_bits),
                    shrinkage: t.shrinkage.map(f64::from_bits),
                    note: t.note,
                })
                .collect();
            (outcome, transfer)
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::wire;
    use crate::diagnose::gauge::Misfit;
    use crate::diagnose::run::Transfer;
    use crate::diagnose::stages::refit::RefitOutcome;
    use czid_core::Record;
    use nalgebra::DMatrix;

    fn same(a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
    }

    #[test]
    fn a_refit_crosses_between_processes_bit_for_bit() {
        let awkward = [0.1 + 0.2, -0.0, f64::MIN_POSITIVE / 7.0, f64::NAN, 1.0 / 3.0];
        let mut rec = Record::new(&[("displacement", "mm"), ("load", "N")]);
        rec.push(&[0.0, 1.0 / 3.0]);
        rec.push(&[2.0f64.sqrt(), f64::INFINITY]);
        let out = RefitOutcome {
            v: awkward.to_vec(),
            misfit: Misfit {
                r: awkward.iter().map(|x| x * 7.1).collect(),
                records: [("dcb01".to_string(), rec.clone())].into(),
                failures: vec!["stopped early".into()],
            },
            evaluations: 17,
            jacobian: Some(DMatrix::from_fn(3, 2, |i, j| (i as f64 + 0.1) / (j as f64 + 0.7))),
        };
        let transfer = Transfer {
            withheld: "dcb02".into(),
            readings: 40,
            base_chi2: 0.1 + 0.7,
            effect_chi2: Some(1.0 / 9.0),
            shrinkage: None,
            note: Some("n".into()),
        };
        let bytes = wire::encode("fibre_bridging", Ok((out, vec![transfer.clone()])));
        let (back, t) = wire::decode("fibre_bridging", &bytes).unwrap().unwrap();
        assert!(same(&back.v, &awkward));
        assert!(same(&back.misfit.r, &awkward.map(|x| x * 7.1)));
        assert_eq!(back.misfit.records["dcb01"].columns(), rec.columns());
        assert!(same(back.misfit.records["dcb01"].column("load").unwrap(), &[1.0 / 3.0, f64::INFINITY]));
        assert_eq!(back.misfit.failures, ["stopped early"]);
        assert_eq!(back.evaluations, 17);
        let j = back.jacobian.unwrap();
        assert!(
            j.shape() == (3, 2)
                && same(j.as_slice(), DMatrix::from_fn(3, 2, |i, j| (i as f64 + 0.1) / (j as f64 + 0.7)).as_slice())
        );
        assert_eq!(t.len(), 1);
        assert_eq!(t[0].base_chi2.to_bits(), transfer.base_chi2.to_bits());
        assert_eq!((t[0].effect_chi2, t[0].shrinkage, &t[0].note), (transfer.effect_chi2, None, &transfer.note));
        // A failed refit, and a message that belongs to another candidate.
        let failed = wire::encode("large_rotation", Err("refit failed: no".into()));
        assert_eq!(wire::decode("large_rotation", &failed).unwrap().err().unwrap(), "refit failed: no");
        let e = wire::decode("fibre_bridging", &failed).err().unwrap().to_string();
        assert!(e.contains("ranked the candidates differently"), "{e}");
        assert!(wire::decode("x", b"{").is_err());
    }
}
