//! `gap-bench`: the diagnosis checked on cases whose answer is known.
//!
//! Each planted case is a synthetic test of a [`Family`] (a DCB made like the bundled real ones,
//! or the paper's FRP-strengthened beam) with one candidate effect switched on at a random
//! realistic size, then diagnosed with the base model, which does not know it. Null cases have no
//! effect. The answer of a case is the best-scoring candidate when it is significant, else
//! "none". Each finished case can be kept in a folder, so that an interrupted run resumes.

mod family;
mod truth;

pub use family::{Family, Specimen, TestDraw};
pub use truth::Truth;

use crate::data::Experiment;
use crate::diagnose::candidate::{CandidateEffect, Library};
use crate::diagnose::run::{diagnose_subject, Diagnosis, Options, Subject};
use crate::diagnose::stats::chi2_survival;
use crate::farm::TaskFarm;
use crate::identification::Setup;
use crate::output::OutputDir;
use crate::synthetic::{synthesize, Noise};
use czid_core::{columns, Curve, CzError, Record, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Label of a case with no effect, and of a diagnosis that names none.
pub const NONE: &str = "none";
/// The effect planted outside the library on purpose: a displacement transducer whose gain is
/// off, the recorded displacement `(1 + g) δ` with `g` of 2–5 %. No candidate is this effect; the
/// right answer is "unexplained", or a cause with "more is missing".
pub const GAIN: &str = "displacement_gain";
/// Range of the planted gain error.
const GAIN_RANGE: std::ops::Range<f64> = 0.02..0.05;
/// Mean cosine (beyond the fitted parameters) above which a pair of effects is predicted to be
/// confusable.
pub const CONFUSABLE: f64 = 0.9;

/// Benchmark settings.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Planted cases per effect.
    pub cases: usize,
    /// Null cases (no effect).
    pub nulls: usize,
    /// Seed of the whole benchmark (cases are reproducible one by one).
    pub seed: u64,
    /// Effects to plant (empty: every bundled one that applies to the family).
    pub effects: Vec<String>,
    /// The synthetic tests.
    pub family: Family,
    /// The model that makes them.
    pub truth: Truth,
}

/// One case's outcome.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct CaseResult {
    /// Case index.
    pub index: usize,
    /// Planted effect ([`NONE`] for a null case).
    pub planted: String,
    /// The specimen ([`Specimen::name`]).
    #[serde(default)]
    pub specimen: String,
    /// Its values (physical units, per parameter).
    pub size: Vec<f64>,
    /// True values of the fitted parameters (physical units, in the order of [`Family::space`]),
    /// then the known modulus (MPa).
    pub truth: [f64; 3],
    /// Load (N) and crack-length (mm) noise.
    pub noise: [f64; 2],
    /// Readings of the synthetic test.
    pub readings: usize,
    /// Its final displacement (mm): a DCB's opening, a beam's mid-span deflection.
    pub end: f64,
    /// Diagnosed effect ([`NONE`] when the verdict names none).
    pub diagnosed: String,
    /// The verdict's kind: `cause`, `none_needed` or `unexplained`.
    #[serde(default)]
    pub kind: String,
    /// Whether the verdict says more is missing besides the cause.
    #[serde(default)]
    pub more_missing: bool,
    /// Candidates the verdict says the data can hardly tell from the cause.
    #[serde(default)]
    pub confusable_with: Vec<String>,
    /// Candidates the verdict names beside the cause as removing nearly as much.
    #[serde(default)]
    pub rivals: Vec<String>,
    /// Whether the verdict is provisional.
    #[serde(default)]
    pub provisional: bool,
    /// Why it is provisional, and candidates set aside.
    #[serde(default)]
    pub reasons: Vec<String>,
    /// Refitted candidates with ΔBIC and shrinkage, largest shrinkage first.
    #[serde(default)]
    pub refits: Vec<(String, f64, f64)>,
    /// Candidates by score, best first, with whether they are significant.
    pub ranking: Vec<(String, f64, bool)>,
    /// The base fit's values of the fitted parameters (physical units, as `truth`).
    #[serde(default)]
    pub base_fit: Vec<f64>,
    /// χ²/dof of the base fit.
    pub base_reduced_chi2: f64,
    /// Probability of the structure left in the base fit's residuals under white noise.
    #[serde(default)]
    pub base_structure_p: f64,
    /// The same for the named cause's refit (`None` without a cause).
    #[serde(default)]
    pub cause_structure_p: Option<f64>,
    /// RMS of the model-form shift accounted for (noise units; 0 when it was not).
    #[serde(default)]
    pub model_form_shift_rms: f64,
    /// χ²/dof of the base fit on the data as measured (before the model form was accounted for).
    #[serde(default)]
    pub base_reduced_chi2_as_measured: f64,
    /// Whether the base fit is at the noise level (the planted effect is then undetectable).
    pub base_at_noise_level: bool,
    /// χ²/dof with the true effect refitted.
    pub true_reduced_chi2: Option<f64>,
    /// Whether the refit with the true effect is at the noise level.
    pub true_at_noise_level: Option<bool>,
    /// The true effect's values found by the refit.
    pub true_refit: Vec<f64>,
    /// Whether the true effect was refitted only on request: the diagnosis itself did not refit
    /// it, so the verdict could not name it.
    #[serde(default)]
    pub true_refit_on_request: bool,
    /// Candidates that could not be scored or refitted, with the reason.
    pub notes: Vec<String>,
    /// Cosines between candidates (beyond the fitted parameters) at this case's base fit.
    pub pairs: Vec<(String, String, f64)>,
    /// Effect sizes drawn again because the planted model did not run to the end.
    pub redraws: usize,
    /// Where the planted model stopped early, and why, when it stopped past the test's end (its
    /// run up to there made the test).
    #[serde(default)]
    pub planted_stopped: Option<String>,
    /// Wall time (s): the synthetic test made, then diagnosed.
    pub seconds: f64,
    /// Of which making the synthetic test (s): the planted model's run (a continuum run for
    /// `--truth continuum`) and the noisy readings.
    #[serde(default)]
    pub data_seconds: f64,
    /// Of which the diagnosis (s).
    #[serde(default)]
    pub diagnosis_seconds: f64,
    /// Why the case could not be diagnosed, if so.
    pub error: Option<String>,
}

/// The benchmark's results.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Labels of the confusion matrix (planted effects, then [`NONE`]).
    pub labels: Vec<String>,
    /// `confusion[planted][diagnosed]` counts.
    pub confusion: Vec<Vec<usize>>,
    /// Top-1 accuracy per planted effect.
    pub top1: BTreeMap<String, f64>,
    /// Top-2 accuracy per planted effect (the planted effect among the two best significant).
    pub top2: BTreeMap<String, f64>,
    /// Share of null cases where an effect was named.
    pub false_alarms: f64,
    /// Mean cosine per pair of effects, over the cases.
    pub mean_cos: Vec<(String, String, f64)>,
    /// Pairs predicted confusable (mean cosine above [`CONFUSABLE`]).
    pub confusable: Vec<(String, String, f64)>,
    /// Effects in no confusable pair.
    pub separable: Vec<String>,
    /// Top-1 accuracy over the separable effects' cases.
    pub top1_separable: f64,
    /// Share of planted cases where refitting the true effect brings the misfit to the noise level.
    pub true_effect_at_noise_level: f64,
    /// Cases.
    pub cases: Vec<CaseResult>,
    /// Wall time (s).
    pub wall_seconds: f64,
}

/// Runs one case: `planted` names the effect (`effect`, the candidate that plants it; `None` for a
/// null case).
#[allow(clippy::too_many_arguments)]
fn case(
    index: usize,
    planted: &str,
    effect: Option<&dyn CandidateEffect>,
    seed: u64,
    family: Family,
    made_by: Truth,
    library: &Library,
    mut keep: Option<&mut Option<PreparedCase>>,
) -> CaseResult {
    let clock = std::time::Instant::now();
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15).wrapping_add(index as u64));
    let draw = family.draw(index, &mut rng);
    let TestDraw { specimen, truth, noise, readings, end } = draw.clone();
    let mut size = if planted == GAIN {
        vec![rng.random_range(GAIN_RANGE)]
    } else {
        effect.and_then(|c| c.plant(&mut rng)).unwrap_or_default()
    };
    let jitter: Vec<f64> = (0..3).map(|_| rng.random_range(-0.05..0.05)).collect();
    let noise_seed: u64 = rng.random();
    let mut out = CaseResult {
        index,
        planted: planted.into(),
        specimen: specimen.name().into(),
        size: size.clone(),
        truth,
        noise,
        readings,
        end: end.unwrap_or(f64::NAN),
        diagnosed: NONE.into(),
        kind: String::new(),
        more_missing: false,
        confusable_with: Vec::new(),
        rivals: Vec::new(),
        provisional: false,
        reasons: Vec::new(),
        refits: Vec::new(),
        ranking: Vec::new(),
        base_fit: Vec::new(),
        base_reduced_chi2: f64::NAN,
        base_structure_p: f64::NAN,
        cause_structure_p: None,
        model_form_shift_rms: 0.0,
        base_reduced_chi2_as_measured: f64::NAN,
        base_at_noise_level: false,
        true_reduced_chi2: None,
        true_at_noise_level: None,
        true_refit: Vec::new(),
        true_refit_on_request: false,
        notes: Vec::new(),
        pairs: Vec::new(),
        redraws: 0,
        planted_stopped: None,
        seconds: 0.0,
        data_seconds: 0.0,
        diagnosis_seconds: 0.0,
        error: None,
    };
    let mut run = || -> Result<()> {
        let made = std::time::Instant::now();
        let base = family.base_setup(&draw)?;
        let record = planted_record(&base, effect, (family, made_by, end), &mut size, &mut rng, &mut out);
        // Also when the planted model failed: its run is most of the case's time.
        out.data_seconds = made.elapsed().as_secs_f64();
        let record = record?;
        // Without a set end the test is read up to a share of the deflection at its peak load.
        let end = match end {
            Some(e) => e,
            None => {
                let load = record.curve(columns::DISPLACEMENT, columns::LOAD)?;
                let peak = (0..load.len()).max_by(|&a, &b| load.y()[a].total_cmp(&load.y()[b])).unwrap_or(0);
                family.share_of_peak() * load.x()[peak]
            }
        };
        out.end = end;
        let noise = Noise { load_sd: noise[0], length_sd: noise[1], seed: noise_seed };
        let mut experiment = synthetic_experiment(family, &record, readings, end, &noise)?;
        if planted == GAIN {
            experiment = with_gain(experiment, size[0])?;
        }
        let space = family.space();
        let u0: Vec<f64> =
            space.to_unit(&truth[..space.dim()]).iter().zip(&jitter).map(|(u, j)| (u + j).clamp(0.0, 1.0)).collect();
        let subject = Subject {
            name: format!("case {index}"),
            setup: base,
            space,
            experiments: vec![experiment],
            use_length: family.fits_length(),
        };
        // A user's defaults (refits, the held-out late stage), so that the bench scores the
        // diagnosis users run. The planted effect is refitted in any case, for the "true effect
        // refitted" figure, but only on request: the verdict is the one the diagnosis gives
        // without knowing it.
        let opts = Options {
            always_refit: if planted == NONE || planted == GAIN { Vec::new() } else { vec![planted.to_string()] },
            // A test made by the diagnosed model itself has no model-form misfit: accounting for
            // its reference model's difference would add one.
            model_form: made_by != Truth::Beam,
            ..Options::default()
        };
        out.data_seconds = made.elapsed().as_secs_f64();
        if let Some(k) = keep.as_deref_mut() {
            *k = Some(PreparedCase { subject, start: u0, options: opts });
            return Ok(());
        }
        let diagnosing = std::time::Instant::now();
        let d = diagnose_subject(&subject, &u0, library, &opts);
        out.diagnosis_seconds = diagnosing.elapsed().as_secs_f64();
        record_diagnosis(&mut out, &d?, planted);
        Ok(())
    };
    if let Err(e) = run() {
        out.error = Some(e.to_string());
    }
    out.seconds = clock.elapsed().as_secs_f64();
    out
}

/// A case's synthetic test, made and ready to diagnose as the benchmark does.
pub struct PreparedCase {
    /// The base model, fitted parameters and synthetic data.
    pub subject: Subject,
    /// Where the diagnosis starts (unit cube: the true values jittered).
    pub start: Vec<f64>,
    /// The benchmark's diagnosis options.
    pub options: Options,
}

/// Redraws of a planted effect's size whose model stops early or is refused (a root compliance
/// too large for a steep law is refused at once, see
/// [`czid_models::effects::ROOT_COMPLIANCE_SHARE`]).
const PLANT_REDRAWS: usize = 20;

/// The planted model's record. A planted model that stops after the test's `end` (mm, the
/// recorded displacement) made the whole test: its rows up to there are the record, and `out`
/// says where and why it stopped. One that stops before is drawn again (up to [`PLANT_REDRAWS`]
/// times, the redraws counted in `out`), unless the effect has no size to draw (a switch, or no
/// effect): the same model would stop at the same place again.
fn planted_record(
    base: &Setup,
    effect: Option<&dyn CandidateEffect>,
    (family, made_by, end): (Family, Truth, Option<f64>),
    size: &mut Vec<f64>,
    rng: &mut ChaCha8Rng,
    out: &mut CaseResult,
) -> Result<Record> {
    let mut attempt = 0;
    loop {
        let true_setup = match effect {
            None => base.duplicate()?,
            Some(c) => c.apply(base, size)?,
        };
        let model = made_by.model(true_setup.models[family.name()].as_ref())?;
        let failure = match model.simulate(true_setup.law.as_ref()) {
            Ok(r) => return Ok(r),
            Err(f) => f,
        };
        let reached = failure.partial.column(columns::DISPLACEMENT).ok().and_then(|d| d.last().copied());
        if let (Some(end), Some(reached)) = (end, reached) {
            if reached >= end {
                out.planted_stopped = Some(format!(
                    "the planted model stopped at {reached:.4} mm, past the test's end at {end:.4} mm: {}",
                    failure.error
                ));
                return Ok(failure.partial);
            }
        }
        let redrawn = effect.and_then(|c| c.plant(rng)).unwrap_or_default();
        if attempt < PLANT_REDRAWS && redrawn != *size {
            attempt += 1;
            out.redraws = attempt;
            *size = redrawn;
            out.size = size.clone();
        } else {
            return Err(CzError::Simulation(format!("planted model: {}", failure.error)));
        }
    }
}

/// The synthetic test read off a planted record up to `end` (mm), with noise.
fn synthetic_experiment(
    family: Family,
    record: &Record,
    readings: usize,
    end: f64,
    noise: &Noise,
) -> Result<Experiment> {
    synthesize(record, readings, Some(end), noise)?.experiment(family.name())
}

/// The experiment read by a displacement transducer of gain `1 + g`.
fn with_gain(e: Experiment, g: f64) -> Result<Experiment> {
    let scale = |c: &Curve| Curve::new(c.x().iter().map(|x| (1.0 + g) * x).collect(), c.y().to_vec());
    Ok(Experiment { load: scale(&e.load)?, debonded_length: e.debonded_length.as_ref().map(scale).transpose()?, ..e })
}

/// What a case keeps of its diagnosis: the base fit, the ranking and named cause, the true
/// effect's refit, failures and the candidates' angles.
fn record_diagnosis(out: &mut CaseResult, d: &Diagnosis, planted: &str) {
    out.base_reduced_chi2 = d.base.reduced_chi2;
    out.base_structure_p = d.base.structure_p;
    out.cause_structure_p = d
        .outcome
        .cause
        .as_ref()
        .and_then(|c| d.candidates.iter().find(|x| &x.name == c))
        .and_then(|x| x.refit.as_ref().map(|r| r.structure_p));
    out.model_form_shift_rms = d.model_form.shift_rms;
    out.base_reduced_chi2_as_measured =
        d.base.reduced_chi2 * d.model_form.chi2_as_measured / d.base.chi2.max(f64::MIN_POSITIVE);
    out.base_fit = d.base.parameters.iter().map(|q| q.value).collect();
    out.base_at_noise_level = d.base.at_noise_level;
    out.ranking = d
        .candidates
        .iter()
        .filter_map(|c| c.score.as_ref().map(|s| (c.name.clone(), s.statistic, s.significant)))
        .collect();
    out.diagnosed = d.outcome.cause.clone().unwrap_or_else(|| NONE.into());
    out.kind = serde_json::to_value(d.outcome.kind).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default();
    out.more_missing = d.outcome.more_missing;
    out.confusable_with = d.outcome.confusable_with.clone();
    out.rivals = d.outcome.rivals.iter().map(|(name, _)| name.clone()).collect();
    out.provisional = d.outcome.provisional;
    out.reasons = d.outcome.reasons.clone();
    out.refits = d
        .candidates
        .iter()
        .filter_map(|c| c.refit.as_ref().map(|r| (c.name.clone(), r.delta_bic, r.shrinkage)))
        .collect();
    out.refits.sort_by(|a, b| b.2.total_cmp(&a.2));
    if let Some(c) = d.candidates.iter().find(|c| c.name == planted) {
        if let Some(r) = &c.refit {
            out.true_refit = r.effect.iter().map(|v| v.value).collect();
            out.true_refit_on_request = c.on_request;
            let dof = d.readings.saturating_sub(r.parameters.len() + r.effect.len()).max(1) as f64;
            let chi2 = r.chi2_reestimated.unwrap_or(r.chi2);
            out.true_reduced_chi2 = Some(chi2 / dof);
            out.true_at_noise_level = Some(chi2_survival(chi2, dof) > 1e-3);
        }
    }
    out.notes = d.candidates.iter().filter_map(|c| c.error.as_ref().map(|e| format!("{}: {e}", c.name))).collect();
    out.pairs = d.pairs.iter().map(|p| (p.a.clone(), p.b.clone(), p.cos)).collect();
}

/// Where a finished case is kept: its file name in the store (family, seed, index and planted
/// effect say which case it is).
fn case_file(opts: &BenchOptions, index: usize, planted: &str) -> String {
    let truth = match opts.truth {
        Truth::Beam => String::new(),
        t => format!("-{}", t.name()),
    };
    format!("case-{}{truth}-seed{}-{index:04}-{planted}.json", opts.family.name(), opts.seed)
}

/// A folder where each finished case is written at once (atomically).
pub struct CaseStore {
    /// The folder.
    pub dir: OutputDir,
    /// Reuse the cases already there instead of running them again (resume an interrupted run).
    pub reuse: bool,
}

/// What a benchmark runs: the planted effect of every case, and how to run one.
pub struct Plan {
    opts: BenchOptions,
    library: Library,
    candidates: Vec<std::sync::Arc<dyn CandidateEffect>>,
    effects: Vec<String>,
    /// The planted effect of each case, in case order (`none` for a null case).
    pub cases: Vec<String>,
}

impl Plan {
    /// The plan of `opts` (the same on every rank that builds it).
    pub fn new(opts: &BenchOptions) -> Result<Plan> {
        let library = Library::builtin();
        let family = opts.family;
        opts.truth.check(family)?;
        // Every candidate that applies to the family's model and that it knows how to plant.
        let sample = family.base_setup(&TestDraw { end: None, ..family.draw(0, &mut ChaCha8Rng::seed_from_u64(0)) })?;
        let offered = library.names(&sample);
        let gain = family == Family::Dcb && (opts.effects.is_empty() || opts.effects.iter().any(|e| e == GAIN));
        let asked: Vec<String> = opts.effects.iter().filter(|e| *e != GAIN).cloned().collect();
        if let Some(unknown) = asked.iter().find(|e| !offered.contains(e)) {
            return Err(CzError::config(
                "--effects",
                format!(
                    "`{unknown}` cannot be planted in the {} benchmark; its model's candidates: {}",
                    family.name(),
                    offered.join(", ")
                ),
            ));
        }
        let candidates = library.select(&sample, &asked)?;
        let known = |c: &dyn CandidateEffect| c.plant(&mut ChaCha8Rng::seed_from_u64(0)).is_some();
        let mut effects: Vec<String> = if asked.is_empty() && !opts.effects.is_empty() {
            Vec::new()
        } else if asked.is_empty() {
            candidates
                .iter()
                .filter(|c| c.applies(&sample) && known(c.as_ref()))
                .map(|c| c.name().to_string())
                .collect()
        } else {
            for c in &candidates {
                if !c.applies(&sample) || !known(c.as_ref()) {
                    return Err(CzError::config(
                        "--effects",
                        format!("`{}` cannot be planted in the {} benchmark", c.name(), family.name()),
                    ));
                }
            }
            asked
        };
        if gain {
            effects.push(GAIN.into());
        }
        if opts.cases == 0 && opts.nulls == 0 {
            return Err(CzError::config("gap-bench", "no cases: give --cases and/or --nulls of at least 1"));
        }
        let mut cases: Vec<String> = effects.iter().flat_map(|e| std::iter::repeat_n(e.clone(), opts.cases)).collect();
        cases.extend(std::iter::repeat_n(NONE.to_string(), opts.nulls));
        Ok(Plan { opts: opts.clone(), library, candidates, effects, cases })
    }

    /// Runs case `i`.
    pub fn run_case(&self, i: usize) -> CaseResult {
        let p = &self.cases[i];
        let effect = self.candidates.iter().find(|c| c.name() == p).map(|c| c.as_ref());
        case(i, p, effect, self.opts.seed, self.opts.family, self.opts.truth, &self.library, None)
    }

    /// Makes case `i`'s synthetic test without diagnosing it (e.g. to diagnose it alone, or
    /// write it out), with what the case records of its making.
    pub fn prepare_case(&self, i: usize) -> (CaseResult, Result<PreparedCase>) {
        let p = &self.cases[i];
        let effect = self.candidates.iter().find(|c| c.name() == p).map(|c| c.as_ref());
        let mut kept = None;
        let out = case(i, p, effect, self.opts.seed, self.opts.family, self.opts.truth, &self.library, Some(&mut kept));
        let prepared = kept.ok_or_else(|| {
            CzError::Simulation(out.error.clone().unwrap_or_else(|| "the case's test could not be made".into()))
        });
        (out, prepared)
    }

    /// The library the cases are diagnosed with.
    pub fn library(&self) -> &Library {
        &self.library
    }

    /// Runs case `i` and gives its result as JSON (what a [`TaskFarm`] moves).
    pub fn run_case_json(&self, i: usize) -> String {
        serde_json::to_string(&self.run_case(i)).unwrap_or_default()
    }
}

/// Runs the benchmark; `progress(done, total)` is called as cases finish. With a `store`, each
/// finished case is kept there, and with `store.reuse` a case already there is not run again:
/// an interrupted benchmark resumes where it stopped. With a `farm`, the cases to run go through
/// it (and progress is told when they are all back).
pub fn run(
    opts: &BenchOptions,
    store: Option<&CaseStore>,
    farm: Option<&dyn TaskFarm>,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<BenchReport> {
    let clock = std::time::Instant::now();
    let plan = Plan::new(opts)?;
    let total = plan.cases.len();
    let kept: Vec<Option<CaseResult>> = (0..total)
        .map(|i| {
            store
                .filter(|s| s.reuse)
                .and_then(|s| std::fs::read_to_string(s.dir.file(&case_file(opts, i, &plan.cases[i]))).ok())
                .and_then(|text| serde_json::from_str::<CaseResult>(&text).ok())
                .filter(|c| c.error.is_none())
        })
        .collect();
    let keep = |i: usize, r: &CaseResult| {
        if let (Some(s), Ok(json)) = (store, serde_json::to_string_pretty(r)) {
            // Losing a kept case only costs its rerun.
            let _ = s.dir.write(&case_file(opts, i, &plan.cases[i]), &json);
        }
    };
    let done = std::sync::atomic::AtomicUsize::new(0);
    let cases: Vec<CaseResult> = match farm {
        None => kept
            .into_par_iter()
            .enumerate()
            .map(|(i, k)| {
                let r = k.unwrap_or_else(|| {
                    let r = plan.run_case(i);
                    keep(i, &r);
                    r
                });
                progress(done.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1, total);
                r
            })
            .collect(),
        Some(farm) => {
            let todo: Vec<usize> = (0..total).filter(|&i| kept[i].is_none()).collect();
            let json = farm
                .run(&todo, &|i| plan.run_case_json(i).into_bytes())?
                .ok_or_else(|| CzError::config("gap-bench", "the cases are kept by another process"))?;
            let mut fresh = todo.iter().zip(json).map(|(&i, j)| {
                let r = serde_json::from_slice::<CaseResult>(&j)
                    .map_err(|e| CzError::Simulation(format!("case {i} came back unreadable from its rank: {e}")))?;
                keep(i, &r);
                Ok::<_, CzError>((i, r))
            });
            let mut out = Vec::with_capacity(total);
            for (i, k) in kept.into_iter().enumerate() {
                out.push(match k {
                    Some(r) => r,
                    None => {
                        let (j, r) = fresh.next().expect("one result per case run")?;
                        debug_assert_eq!(i, j);
                        r
                    }
                });
            }
            progress(total, total);
            out
        }
    };
    Ok(summarise(plan.effects, cases, clock.elapsed().as_secs_f64()))
}

/// Whether a case's verdict is right: the planted effect named; for a null case, "no unmodelled
/// effect is needed"; for the out-of-library gain error, "unexplained" or a cause with "more is
/// missing". Cases diagnosed before verdicts had kinds count by the named effect alone.
pub fn right(c: &CaseResult) -> bool {
    match c.planted.as_str() {
        NONE => c.diagnosed == NONE && (c.kind.is_empty() || c.kind == "none_needed"),
        GAIN => c.kind == "unexplained" || c.more_missing,
        p => c.diagnosed == p,
    }
}

/// The scores of finished cases: confusion matrix, top-1/top-2 per effect, false alarms, the
/// effects' mean angles and which pairs are confusable.
fn summarise(effects: Vec<String>, cases: Vec<CaseResult>, wall_seconds: f64) -> BenchReport {
    let mut labels = effects.clone();
    labels.push(NONE.into());
    let at = |l: &str| labels.iter().position(|x| x == l).unwrap_or(labels.len() - 1);
    let mut confusion = vec![vec![0usize; labels.len()]; labels.len()];
    for c in &cases {
        confusion[at(&c.planted)][at(&c.diagnosed)] += 1;
    }
    let mut top1 = BTreeMap::new();
    let mut top2 = BTreeMap::new();
    for e in &effects {
        let mine: Vec<&CaseResult> = cases.iter().filter(|c| &c.planted == e).collect();
        let m = mine.len().max(1) as f64;
        top1.insert(e.clone(), mine.iter().filter(|c| right(c)).count() as f64 / m);
        let in2 = |c: &CaseResult| right(c) || c.confusable_with.contains(e);
        top2.insert(e.clone(), mine.iter().filter(|c| in2(c)).count() as f64 / m);
    }
    let nulls: Vec<&CaseResult> = cases.iter().filter(|c| c.planted == NONE).collect();
    let false_alarms = nulls.iter().filter(|c| !right(c)).count() as f64 / nulls.len().max(1) as f64;
    let mut sums: BTreeMap<(String, String), (f64, usize)> = BTreeMap::new();
    for c in &cases {
        for (a, b, cos) in &c.pairs {
            let key = if a < b { (a.clone(), b.clone()) } else { (b.clone(), a.clone()) };
            let e = sums.entry(key).or_insert((0.0, 0));
            e.0 += cos;
            e.1 += 1;
        }
    }
    let mean_cos: Vec<(String, String, f64)> = sums.into_iter().map(|((a, b), (s, n))| (a, b, s / n as f64)).collect();
    let confusable: Vec<(String, String, f64)> = mean_cos.iter().filter(|p| p.2 > CONFUSABLE).cloned().collect();
    // The out-of-library effect has no sensitivity, so no angle: it is no separable effect.
    let separable: Vec<String> = effects
        .iter()
        .filter(|e| *e != GAIN && !confusable.iter().any(|p| &p.0 == *e || &p.1 == *e))
        .cloned()
        .collect();
    let sep_cases: Vec<&CaseResult> = cases.iter().filter(|c| separable.contains(&c.planted)).collect();
    let top1_separable = sep_cases.iter().filter(|c| right(c)).count() as f64 / sep_cases.len().max(1) as f64;
    let planted: Vec<&CaseResult> = cases.iter().filter(|c| c.planted != NONE && c.planted != GAIN).collect();
    let true_effect_at_noise_level =
        planted.iter().filter(|c| c.true_at_noise_level == Some(true)).count() as f64 / planted.len().max(1) as f64;
    BenchReport {
        labels,
        confusion,
        top1,
        top2,
        false_alarms,
        mean_cos,
        confusable,
        separable,
        top1_separable,
        true_effect_at_noise_level,
        cases,
        wall_seconds,
    }
}

/// The report in Markdown.
pub fn markdown(r: &BenchReport, opts: &BenchOptions) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# gap-bench ({}, tests made by the {} model): {} planted cases per effect, {} null cases, seed {}\n",
        opts.family.name(),
        opts.truth.name(),
        opts.cases,
        opts.nulls,
        opts.seed
    );
    let _ = writeln!(s, "Confusion matrix (rows: planted, columns: diagnosed):\n");
    let _ = writeln!(s, "| planted \\ diagnosed | {} |", r.labels.join(" | "));
    let _ = writeln!(s, "|---|{}", "---|".repeat(r.labels.len()));
    for (l, row) in r.labels.iter().zip(&r.confusion) {
        let cells: Vec<String> = row.iter().map(|c| c.to_string()).collect();
        let _ = writeln!(s, "| {l} | {} |", cells.join(" | "));
    }
    let _ = writeln!(
        s,
        "\n| effect | top-1 | top-2 | detectable (base fit above the noise) | top-1 of detectable | true effect at noise level |\n|---|---|---|---|---|---|"
    );
    for (e, t1) in &r.top1 {
        let mine: Vec<&CaseResult> = r.cases.iter().filter(|c| &c.planted == e).collect();
        let at = mine.iter().filter(|c| c.true_at_noise_level == Some(true)).count();
        let seen: Vec<&&CaseResult> = mine.iter().filter(|c| !c.base_at_noise_level).collect();
        let hit = seen.iter().filter(|c| right(c)).count();
        let _ = writeln!(
            s,
            "| {e} | {:.0}% | {:.0}% | {}/{} | {hit}/{} | {at}/{} |",
            100.0 * t1,
            100.0 * r.top2[e],
            seen.len(),
            mine.len(),
            seen.len(),
            mine.len()
        );
    }
    // Right verdicts by specimen, for a family of several.
    let mut specimens: Vec<&str> = r.cases.iter().map(|c| c.specimen.as_str()).collect();
    specimens.sort_unstable();
    specimens.dedup();
    if specimens.len() > 1 {
        let _ = writeln!(s, "\nRight verdicts by specimen:\n\n| effect | {} |", specimens.join(" | "));
        let _ = writeln!(s, "|---|{}", "---|".repeat(specimens.len()));
        for e in r.labels.iter() {
            let cells: Vec<String> = specimens
                .iter()
                .map(|sp| {
                    let mine: Vec<&CaseResult> =
                        r.cases.iter().filter(|c| &c.planted == e && c.specimen == *sp).collect();
                    format!("{}/{}", mine.iter().filter(|c| right(c)).count(), mine.len())
                })
                .collect();
            let _ = writeln!(s, "| {e} | {} |", cells.join(" | "));
        }
    }
    // Confusions actually observed: a fifth or more of an effect's cases named as another.
    let _ = writeln!(s, "\nObserved confusions (≥ 20 % of an effect's cases diagnosed as another):\n");
    let mut any = false;
    for (i, row) in r.confusion.iter().enumerate() {
        let total: usize = row.iter().sum();
        for (j, &k) in row.iter().enumerate() {
            if i != j && r.labels[j] != NONE && r.labels[i] != NONE && total > 0 && k * 5 >= total {
                any = true;
                let _ = writeln!(s, "* {} diagnosed as {}: {k}/{total}", r.labels[i], r.labels[j]);
            }
        }
    }
    if !any {
        let _ = writeln!(s, "* none");
    }
    let _ = writeln!(
        s,
        "\nNull cases answered \"no unmodelled effect is needed\": {:.0}% (false alarms {:.0}%).",
        100.0 * (1.0 - r.false_alarms),
        100.0 * r.false_alarms
    );
    let kinds = |p: &dyn Fn(&CaseResult) -> bool| {
        let mut k: BTreeMap<String, usize> = BTreeMap::new();
        for c in r.cases.iter().filter(|c| p(c)) {
            let label = if c.more_missing { format!("{} (more missing)", c.kind) } else { c.kind.clone() };
            *k.entry(label).or_default() += 1;
        }
        k.iter().map(|(a, n)| format!("{a} {n}")).collect::<Vec<_>>().join(", ")
    };
    let _ = writeln!(s, "Verdict kinds on null cases: {}.", kinds(&|c| c.planted == NONE));
    if r.cases.iter().any(|c| c.planted == GAIN) {
        let _ = writeln!(s, "Verdict kinds on the out-of-library gain error: {}.", kinds(&|c| c.planted == GAIN));
    }
    let provisional = r.cases.iter().filter(|c| c.provisional).count();
    let _ = writeln!(s, "Provisional verdicts: {provisional} of {}.", r.cases.len());
    let stopped: Vec<String> =
        r.cases.iter().filter(|c| c.planted_stopped.is_some()).map(|c| c.index.to_string()).collect();
    if !stopped.is_empty() {
        let _ = writeln!(
            s,
            "Planted models that stopped early, past their test's end (their rows up to there made the test): \
             cases {}.",
            stopped.join(", ")
        );
    }
    let spread = |f: &dyn Fn(&CaseResult) -> f64| -> Option<(f64, f64)> {
        let mut t: Vec<f64> = r.cases.iter().map(f).filter(|t| t.is_finite() && *t > 0.0).collect();
        t.sort_by(f64::total_cmp);
        t.last().map(|max| (t[t.len() / 2], *max))
    };
    if let Some((median, max)) = spread(&|c| c.seconds) {
        let _ = writeln!(
            s,
            "Case times (synthetic test + diagnosis, cases run side by side): median {median:.1} s, maximum {max:.1} s."
        );
    }
    for (what, f) in [
        ("making the synthetic test", &(|c: &CaseResult| c.data_seconds) as &dyn Fn(&CaseResult) -> f64),
        ("the diagnosis alone", &|c: &CaseResult| c.diagnosis_seconds),
    ] {
        if let Some((median, max)) = spread(f) {
            let _ = writeln!(s, "Of which {what}: median {median:.1} s, maximum {max:.1} s.");
        }
    }
    let slowest = r
        .cases
        .iter()
        .filter(|c| c.diagnosis_seconds > 0.0)
        .max_by(|a, b| a.diagnosis_seconds.total_cmp(&b.diagnosis_seconds));
    if let Some(c) = slowest {
        let _ = writeln!(
            s,
            "Slowest diagnosis: case {} ({}, {}), {:.1} s.",
            c.index, c.planted, c.specimen, c.diagnosis_seconds
        );
    }
    let _ = writeln!(
        s,
        "Top-1 accuracy over the separable effects ({}): {:.0}%.",
        r.separable.join(", "),
        100.0 * r.top1_separable
    );
    let _ = writeln!(
        s,
        "Refitting the true effect brings the misfit to the noise level in {:.0}% of the planted cases.",
        100.0 * r.true_effect_at_noise_level
    );
    let requested = r.cases.iter().filter(|c| c.true_refit_on_request).count();
    let planted = r.cases.iter().filter(|c| c.planted != NONE && c.planted != GAIN).count();
    let _ = writeln!(
        s,
        "The true effect was refitted only on request (not among the diagnosis's own refits, so not \
         nameable) in {requested} of {planted} planted cases.\n"
    );
    let _ = writeln!(s, "Confusable pairs predicted by the Jacobian angles (mean cosine > {CONFUSABLE}):\n");
    if r.confusable.is_empty() {
        let _ = writeln!(s, "* none");
    }
    for (a, b, c) in &r.confusable {
        let _ = writeln!(s, "* {a} and {b}: {c:.3}");
    }
    let _ = writeln!(s, "\nMean cosines of every pair:\n\n| a | b | mean cos |\n|---|---|---|");
    for (a, b, c) in &r.mean_cos {
        let _ = writeln!(s, "| {a} | {b} | {c:.3} |");
    }
    let errors: Vec<&CaseResult> = r.cases.iter().filter(|c| c.error.is_some()).collect();
    if !errors.is_empty() {
        let _ = writeln!(s, "\n{} cases could not be diagnosed:\n", errors.len());
        for c in errors {
            let _ = writeln!(s, "* case {} ({}): {}", c.index, c.planted, c.error.clone().unwrap_or_default());
        }
    }
    let _ = writeln!(s, "\nWall time {:.0} s.", r.wall_seconds);
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::candidate::EffectParameter;
    use czid_core::{CohesiveLaw, ForwardModel, SimulationFailure};
    use serde::{Deserialize, Serialize};
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A test whose model follows the path to `stop` mm of recorded displacement and then fails.
    #[derive(Debug, Serialize, Deserialize)]
    struct StopsAt {
        stop: f64,
    }

    #[typetag::serde(name = "bench_test_stops_at")]
    impl ForwardModel for StopsAt {
        fn name(&self) -> &str {
            "bench_test_stops_at"
        }
        fn simulate(&self, _law: &dyn CohesiveLaw) -> std::result::Result<Record, SimulationFailure> {
            let mut partial = Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N")]);
            for i in 0..=10 {
                let d = self.stop * i as f64 / 10.0;
                partial.push(&[d, 10.0 * d]);
            }
            Err(SimulationFailure { error: CzError::Simulation("Newton did not converge".into()), partial })
        }
    }

    /// An effect that changes nothing and counts how often it is applied; `switch`: it plants a
    /// switch (always 1), else a size drawn at random.
    struct Counted {
        switch: bool,
        applied: AtomicUsize,
    }

    impl CandidateEffect for Counted {
        fn name(&self) -> &str {
            "counted"
        }
        fn describe(&self) -> String {
            "changes nothing".into()
        }
        fn applies(&self, _setup: &Setup) -> bool {
            true
        }
        fn parameters(&self, _setup: &Setup) -> Result<Vec<EffectParameter>> {
            Ok(Vec::new())
        }
        fn apply(&self, setup: &Setup, _values: &[f64]) -> Result<Setup> {
            self.applied.fetch_add(1, Ordering::SeqCst);
            setup.duplicate()
        }
        fn plant(&self, rng: &mut ChaCha8Rng) -> Option<Vec<f64>> {
            Some(vec![if self.switch { 1.0 } else { rng.random_range(0.0..1.0) }])
        }
    }

    fn setup(stop: f64) -> Setup {
        let law = czid_models::laws::Bilinear::bk(1e5, 30.0, 40.0, 0.3, 0.8, 2.0).unwrap();
        let model: Box<dyn ForwardModel> = Box::new(StopsAt { stop });
        Setup { law: Box::new(law), models: [("dcb".to_string(), model)].into_iter().collect() }
    }

    fn planted(effect: &Counted, end: f64) -> (Result<Record>, CaseResult) {
        let mut out = CaseResult::default();
        let mut size = vec![1.0];
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let r = planted_record(
            &setup(5.0),
            Some(effect),
            (Family::Dcb, Truth::Beam, Some(end)),
            &mut size,
            &mut rng,
            &mut out,
        );
        (r, out)
    }

    #[test]
    fn a_planted_model_that_stops_past_the_tests_end_made_the_whole_test() {
        let effect = Counted { switch: true, applied: AtomicUsize::new(0) };
        let (record, out) = planted(&effect, 4.0);
        let record = record.expect("the rows up to the stop cover the test");
        assert_eq!(record.rows(), 11);
        assert_eq!(record.column(columns::DISPLACEMENT).unwrap().last(), Some(&5.0));
        let why = out.planted_stopped.expect("where it stopped is said");
        assert!(why.contains("5.0000 mm") && why.contains("4.0000 mm") && why.contains("Newton"), "{why}");
        assert_eq!((out.redraws, effect.applied.load(Ordering::SeqCst)), (0, 1));
    }

    #[test]
    fn a_planted_switch_that_stops_before_the_tests_end_is_not_run_again() {
        // The same model would stop at the same place: one run, then the error.
        let effect = Counted { switch: true, applied: AtomicUsize::new(0) };
        let (record, out) = planted(&effect, 6.0);
        let e = record.expect_err("the test reads past the stop").to_string();
        assert!(e.contains("planted model") && e.contains("Newton"), "{e}");
        assert_eq!((out.redraws, effect.applied.load(Ordering::SeqCst)), (0, 1));
        assert!(out.planted_stopped.is_none());
    }

    #[test]
    fn a_planted_size_that_stops_before_the_tests_end_is_drawn_again() {
        let effect = Counted { switch: false, applied: AtomicUsize::new(0) };
        let (record, out) = planted(&effect, 6.0);
        assert!(record.is_err());
        assert_eq!((out.redraws, effect.applied.load(Ordering::SeqCst)), (PLANT_REDRAWS, PLANT_REDRAWS + 1));
        assert_eq!(out.size.len(), 1);
    }
}
