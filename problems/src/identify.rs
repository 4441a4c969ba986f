//! `identify`: run an optimizer on a problem file and write the identified parameters, fits,
//! history and plots. `simulate`: run the forward models at the initial values.

use crate::event::MISSED_EVENT_FACTOR;
use crate::identifiability::{assess, Verdict};
use crate::identification::{event_term_name, Identification, Outcome, RmsError};
use crate::output::OutputDir;
use crate::plot::{Figure, Series};
use crate::problem_file::LoadedProblem;
use crate::resume::{earlier_rows, Fingerprint, RunClock, RunFile};
use czid_core::{
    columns, BatchEvaluator, Batched, Budget, CzError, Evaluation, Observer, OptimizationResult, Problem, Progress,
    Result,
};
use czid_optimizers::checkpoint::CheckpointWriter;
use czid_optimizers::journal::Journal;
use czid_optimizers::observers::{CsvHistory, Observers, ProgressBar};
use czid_optimizers::registry::{method_from_config, Method};
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Command-line overrides and run options.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Optimizer instead of the file's: a label of `[optimizers.<label>]` or a registered name (see
    /// [`crate::problem_file::ProblemFile::optimizer_named`]).
    pub optimizer: Option<String>,
    /// Seed instead of the file's.
    pub seed: Option<u64>,
    /// Evaluation budget instead of the file's.
    pub budget: Option<usize>,
    /// Draw a progress bar.
    pub progress: bool,
    /// Continue from `checkpoint.json` in the output folder.
    pub resume: bool,
    /// Set to true (e.g. by Ctrl-C) to stop after the current iteration, leaving a checkpoint.
    pub stop: Option<Arc<AtomicBool>>,
    /// Abort the process, as a `SIGKILL` would, once this many evaluations are done (for tests
    /// of what an interruption leaves behind).
    pub abort_after: Option<usize>,
    /// Where the batches of evaluations go (default: this process's threads); e.g. MPI ranks.
    pub spread: Option<Spread>,
}

/// A [`BatchEvaluator`] shared by the runs of a command.
#[derive(Clone)]
pub struct Spread(pub Arc<dyn BatchEvaluator>);

impl std::fmt::Debug for Spread {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Spread(..)")
    }
}

/// One identified parameter in `result.json`.
#[derive(Clone, Debug, Serialize)]
pub struct ParameterResult {
    /// Identified value.
    pub value: f64,
    /// Unit.
    pub unit: String,
    /// Initial value.
    pub initial: f64,
    /// Bounds.
    pub bounds: [f64; 2],
    /// Standard error from the Gauss–Newton covariance at the optimum (same unit), if defined.
    pub standard_error: Option<f64>,
    /// Plain verdict: determined, correlated with another, not determined, or at a bound.
    pub verdict: String,
}

/// `result.json`.
#[derive(Clone, Debug, Serialize)]
pub struct IdentifyResult {
    /// The problem file.
    pub problem: String,
    /// True when the run was interrupted: the values are the best found so far.
    pub partial: bool,
    /// Optimizer name.
    pub optimizer: String,
    /// Seed.
    pub seed: u64,
    /// Evaluation budget.
    pub budget: usize,
    /// Identified parameters by path.
    pub parameters: BTreeMap<String, ParameterResult>,
    /// Objective f at the identified parameters.
    pub objective: f64,
    /// Weighted parts of f: `F` (load) and `L` (debonded length).
    pub objective_terms: BTreeMap<String, f64>,
    /// Unweighted ||φ||² per experiment and term.
    pub misfit: BTreeMap<String, f64>,
    /// Weights α per experiment and term.
    pub weights: BTreeMap<String, f64>,
    /// Root-mean-square error per experiment and term, in the data's unit and in % of its peak.
    pub rms_error: BTreeMap<String, crate::identification::RmsError>,
    /// Objective evaluations spent.
    pub evaluations: usize,
    /// Evaluations whose simulation failed.
    pub failed_evaluations: usize,
    /// Evaluations of a point evaluated before, answered without running it again (a genetic
    /// algorithm's child equal to a member).
    #[serde(default)]
    pub repeated_evaluations: usize,
    /// Evaluations answered from another candidate's whose forward runs take the same from it,
    /// without running them (a symmetric DCB's candidates that differ only in the law's shear
    /// branch; `ForwardModel::law_key`), in this process's part of the run.
    #[serde(default)]
    pub shared_evaluations: usize,
    /// Wall time of the optimisation (s).
    pub wall_seconds: f64,
    /// Share of the run's CPU time (wall time × worker threads) spent in forward simulations.
    pub forward_share: f64,
    /// Times the run was interrupted and resumed.
    pub resumed: usize,
    /// Whether the optimizer converged before its budget ran out (see the book's criterion per
    /// method); when not, the verdicts are marked provisional.
    pub converged: bool,
    /// Warnings worth reading.
    pub warnings: Vec<String>,
}

/// Measures the time spent in forward simulations.
struct Timed<'a> {
    inner: &'a Identification,
    nanos: AtomicU64,
}

impl Problem for Timed<'_> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        self.inner.bounds()
    }
    fn evaluate(&self, x: &[f64]) -> Result<Evaluation> {
        let t = Instant::now();
        let r = self.inner.evaluate(x);
        self.nanos.fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
        r
    }
    fn evaluate_batch(&self, xs: &[Vec<f64>]) -> Vec<Result<Evaluation>> {
        self.inner.evaluate_batch_timed(xs, &self.nanos)
    }
    fn objectives(&self) -> usize {
        self.inner.objectives()
    }
}

/// Aborts the process once `.0` evaluations are done, leaving files as a kill would.
pub(crate) struct AbortAfter(pub(crate) Option<usize>);

impl Observer for AbortAfter {
    fn observe(&mut self, p: &Progress<'_>) -> bool {
        if self.0.is_some_and(|n| p.evaluations >= n) {
            std::process::abort();
        }
        true
    }
}

/// Stops the run when the flag is set.
struct StopFlag(Option<Arc<AtomicBool>>, bool);

impl Observer for StopFlag {
    fn observe(&mut self, _: &Progress<'_>) -> bool {
        let stop = self.0.as_ref().is_some_and(|f| f.load(Ordering::SeqCst));
        self.1 |= stop;
        !stop
    }
}

/// One optimisation run and what it cost.
pub struct Run {
    /// The optimizer's result (unit-cube coordinates).
    pub result: OptimizationResult,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// Time spent in forward simulations, summed over threads (s).
    pub forward_seconds: f64,
}

/// Runs optimizer `name` with `settings` on `id`. Local methods start from the initial values;
/// global ones sample the bounds. `resume` continues from a checkpoint's state; batches go
/// through `spread` when given (e.g. MPI ranks).
#[allow(clippy::too_many_arguments)]
pub fn optimize(
    id: &Identification,
    name: &str,
    settings: &toml::Value,
    seed: u64,
    budget: &Budget,
    resume: Option<&str>,
    spread: Option<&dyn BatchEvaluator>,
    observer: &mut dyn Observer,
) -> Result<Run> {
    let method = method_from_config(name, settings)?;
    if resume.is_some() && matches!(method, Method::Local(_)) {
        return Err(CzError::config("--resume", format!("`{name}` keeps no state; it resumes from its journal")));
    }
    optimize_with(id, &method, seed, budget, resume, None, spread, observer)
}

/// [`optimize`] with a built method; a local method's evaluations go through `journal` when given
/// (at `path`: recorded, and replayed when it already holds them), and every batch through
/// `spread` when given.
#[allow(clippy::too_many_arguments)]
pub(crate) fn optimize_with(
    id: &Identification,
    method: &Method,
    seed: u64,
    budget: &Budget,
    resume: Option<&str>,
    journal: Option<(&std::path::Path, bool)>,
    spread: Option<&dyn BatchEvaluator>,
    observer: &mut dyn Observer,
) -> Result<Run> {
    let timed = Timed { inner: id, nanos: AtomicU64::new(0) };
    let batched = spread.map(|by| Batched { problem: &timed, by });
    let problem: &dyn Problem = match &batched {
        Some(b) => b,
        None => &timed,
    };
    let start = Instant::now();
    let result = match method {
        Method::Local(local) => {
            let u0 = id.space().to_unit(&id.initial()?);
            match journal {
                Some((path, replay)) => {
                    let j = if replay { Journal::resume(problem, path)? } else { Journal::create(problem, path)? };
                    local.minimize_from(&j, budget, &u0, observer)?
                }
                None => local.minimize_from(problem, budget, &u0, observer)?,
            }
        }
        Method::Global(optimizer) => match resume {
            Some(state) => optimizer.resume(problem, budget, state, observer)?,
            None => optimizer.minimize(problem, budget, seed, observer)?,
        },
    };
    Ok(Run {
        result,
        wall_seconds: start.elapsed().as_secs_f64(),
        forward_seconds: timed.nanos.load(Ordering::Relaxed) as f64 * 1e-9,
    })
}

/// A global method whose best value still fell by more than this share over the last quarter of
/// its budget had not converged.
const STILL_IMPROVING: f64 = 1e-3;
/// ...and the run must have had at least this many iterations (generations), so that its last
/// quarter spans a few.
const ITERATIONS_TO_TELL: usize = 20;

/// Whether the run converged within its budget. A local method (and the hybrid, whose polish is
/// one) converged when it stopped on its own criterion, before spending the budget. A population
/// method always spends its budget: it converged when it ran at least [`ITERATIONS_TO_TELL`]
/// iterations and its best value fell by less than [`STILL_IMPROVING`] (relative) over the last
/// quarter of the evaluations.
/// Returns why not, or `None` when it did.
fn unconverged(method: &Method, result: &OptimizationResult, budget: usize, iterations: usize) -> Option<String> {
    match method {
        Method::Local(_) if result.evaluations < budget => None,
        Method::Global(g) if g.stops_when_converged() && result.evaluations < budget => None,
        Method::Local(_) => Some("the method was still iterating when its last evaluation was spent".into()),
        Method::Global(g) if g.stops_when_converged() => {
            Some("its local polish was still iterating when its last evaluation was spent".into())
        }
        Method::Global(_) if iterations < ITERATIONS_TO_TELL => {
            Some(format!("{iterations} iterations are too few to tell (at least {ITERATIONS_TO_TELL})"))
        }
        Method::Global(_) => {
            let last = result.history.last().map_or(f64::INFINITY, |h| h.1);
            let start = result.evaluations - result.evaluations / 4;
            let before = result.history.iter().rev().find(|(n, _)| *n <= start).map_or(f64::INFINITY, |h| h.1);
            (before - last > STILL_IMPROVING * before.abs()).then(|| {
                format!(
                    "the best value still fell by {:.2} % over the last quarter of the budget (converged: under {:.1} %)",
                    100.0 * (before - last) / before.abs(),
                    100.0 * STILL_IMPROVING
                )
            })
        }
    }
}

/// A relative standard error above which a parameter's linearised uncertainty is worth checking
/// with a profile (its 95 % interval then spans ± 20 % or more, where the objective is rarely
/// still a parabola).
const WIDE_STANDARD_ERROR: f64 = 0.1;

/// Counts the iterations of a run, those before a resume included (iterations are numbered from
/// 0 across the parts of a resumed run).
#[derive(Default)]
struct Iterations(usize);

impl Observer for Iterations {
    fn observe(&mut self, p: &Progress<'_>) -> bool {
        self.0 = self.0.max(p.iteration + 1);
        true
    }
}

/// The verdict in words, with the relative standard error of a determined parameter.
fn describe_with_error(verdict: &Verdict, space: &czid_core::ParameterSpace, value: f64, se: Option<f64>) -> String {
    match (verdict, se) {
        (Verdict::Determined, Some(se)) if value != 0.0 => format!("determined (± {:.2} %)", 100.0 * se / value.abs()),
        (Verdict::Determined, Some(se)) => format!("determined (± {se:.3e})"),
        _ => verdict.describe(space),
    }
}

/// Runs the identification described by `problem`, writing into `out`.
pub fn identify(problem: &LoadedProblem, opts: &RunOptions, out: &OutputDir) -> Result<IdentifyResult> {
    let id = problem.identification()?;
    let spec = &problem.file.optimizer;
    let label = opts.optimizer.clone().unwrap_or_else(|| spec.kind.clone());
    let (name, settings) = problem.file.optimizer_named(&label);
    let seed = opts.seed.unwrap_or(spec.seed);
    let budget = Budget { evaluations: opts.budget.unwrap_or(spec.budget), target: spec.target };
    if budget.evaluations == 0 {
        return Err(CzError::config("--budget", "must be at least 1 evaluation"));
    }
    let x0 = id.initial()?;
    // Everything that can be refused is checked before a file is touched: the method, and what
    // a resume needs.
    let method = method_from_config(&name, &settings)?;
    if let Method::Global(g) = &method {
        g.check_budget(&budget)?;
    }
    let fingerprint = Fingerprint::of(&id, &problem.experiments, &label, &settings, seed, budget.evaluations)?;
    let earlier_run = if opts.resume { Some(RunFile::for_resume(out, &fingerprint)?) } else { None };
    let local = matches!(method, Method::Local(_));
    let journal_path = out.file("evaluations.jsonl");
    let resume_state = match (opts.resume, local) {
        (true, false) => Some(czid_optimizers::checkpoint::read_checkpoint(&out.file("checkpoint.json"))?),
        (true, true) if !journal_path.exists() => {
            return Err(CzError::Io {
                path: journal_path.display().to_string(),
                message: "the interrupted run left no journal of its evaluations; start afresh with --force".into(),
            })
        }
        _ => None,
    };
    // A resumed global method keeps the rows written before the interruption; a local method
    // replays its run and writes them again.
    let earlier = if opts.resume && !local { std::fs::read_to_string(out.file("history.csv")).ok() } else { None };

    let mut clock = RunClock::start(out, fingerprint, earlier_run)?;
    let mut history = CsvHistory::create(&out.file("history.csv"))?;
    let mut checkpoint = CheckpointWriter::new(out.file("checkpoint.json"), 1)?;
    let mut bar =
        if opts.progress { ProgressBar::new(budget.evaluations) } else { ProgressBar::hidden(budget.evaluations) };
    let mut stop = StopFlag(opts.stop.clone(), false);
    let mut abort = AbortAfter(opts.abort_after);
    let mut iterations = Iterations::default();
    let run = {
        let mut observers = Observers(vec![
            &mut history,
            &mut checkpoint,
            &mut clock,
            &mut bar,
            &mut iterations,
            &mut stop,
            &mut abort,
        ]);
        let journal = local.then_some((journal_path.as_path(), opts.resume));
        let spread = opts.spread.as_ref().map(|s| s.0.as_ref());
        optimize_with(&id, &method, seed, &budget, resume_state.as_deref(), journal, spread, &mut observers)
    };
    let run = match run {
        Ok(run) => run,
        Err(e) => {
            // A resume that failed leaves the interrupted run's history as it was.
            if let Some(text) = &earlier {
                out.write("history.csv", text)?;
            }
            return Err(e);
        }
    };
    let (result, forward_seconds) = (run.result, run.forward_seconds);
    let wall = clock.finish()?;
    bar.finish();
    history.finish()?;
    relabel_history(&id, out, earlier.as_deref())?;
    let partial = stop.1;

    let x = id.space().from_unit(&result.best_x);
    let outcome = id.simulate(&x)?;
    let mut warnings: Vec<String> = outcome.failures.clone();
    warnings.extend(short_runs(problem, &outcome));
    let errors = id.term_errors(&outcome)?;
    let missed = missed_events(problem, &errors);
    let fit_short = !missed.is_empty();
    let why = if partial { None } else { unconverged(&method, &result, budget.evaluations, iterations.0) };
    let converged = !partial && why.is_none();
    if let Some(why) = why {
        warnings.push(format!(
            "budget exhausted before convergence: {why}; the values and their verdicts are provisional (raise --budget)"
        ));
    }
    warnings.extend(missed);
    let assessment = assess(&id, &result.best_x)?;
    let mut parameters = BTreeMap::new();
    for (i, p) in id.space().parameters().iter().enumerate() {
        let verdict = &assessment.verdicts[i];
        if matches!(verdict, Verdict::NotDetermined) {
            warnings.push(format!("`{}` is not determined by these data: its value is arbitrary", p.path));
        }
        if let (Verdict::Determined, Some(se)) = (verdict, assessment.standard_errors[i]) {
            let relative = se / x[i].abs();
            if relative > WIDE_STANDARD_ERROR {
                warnings.push(format!(
                    "`{}` is determined only to ± {:.0} % (its linearised standard error): over so wide a range the \
                     linearisation can be far off, in either direction; `czid profile` gives its 95 % interval",
                    p.path,
                    100.0 * relative
                ));
            }
        }
        parameters.insert(
            p.path.clone(),
            ParameterResult {
                value: x[i],
                unit: p.unit.clone(),
                initial: x0[i],
                bounds: [p.lower, p.upper],
                standard_error: assessment.standard_errors[i],
                verdict: match describe_with_error(verdict, id.space(), x[i], assessment.standard_errors[i]) {
                    // Data that do not determine a parameter do not at any point.
                    v if matches!(verdict, Verdict::NotDetermined) => v,
                    v if partial => format!("{v}, provisional: the run was interrupted"),
                    v if !converged => format!("{v}, provisional: budget exhausted before convergence"),
                    v if fit_short => format!("{v}, provisional: the fit misses a measured event"),
                    v => v,
                },
            },
        );
    }
    let kinds = id.term_kinds();
    let objective_terms =
        kinds.iter().zip(&outcome.evaluation.objectives).map(|(k, v)| (k.symbol().to_string(), *v)).collect();
    let res = IdentifyResult {
        problem: problem.path.display().to_string(),
        partial,
        optimizer: if label == name { name } else { format!("{label} ({name})") },
        seed,
        budget: budget.evaluations,
        parameters,
        objective: outcome.evaluation.value,
        objective_terms,
        misfit: id.term_values(&outcome)?.into_iter().collect(),
        weights: id.weights().into_iter().collect(),
        rms_error: errors.into_iter().collect(),
        evaluations: result.evaluations,
        failed_evaluations: result.failures,
        repeated_evaluations: result.repeats,
        shared_evaluations: id.shared_evaluations(),
        wall_seconds: wall,
        forward_share: forward_seconds / (run.wall_seconds.max(1e-12) * rayon::current_num_threads() as f64),
        resumed: clock.resumed(),
        converged,
        warnings,
    };
    let json = serde_json::to_string_pretty(&res).map_err(|e| CzError::config("result", e.to_string()))?;
    out.write(if partial { "result.partial.json" } else { "result.json" }, &json)?;
    if !partial {
        // The interrupted run's partial result is superseded.
        std::fs::remove_file(out.file("result.partial.json")).ok();
    }
    write_fits(problem, &outcome, out, "fit")?;
    convergence_plot(&result, out)?;
    Ok(res)
}

/// Measured events that the fit misses by more than [`MISSED_EVENT_FACTOR`] times their stated
/// uncertainty (`errors`: [`Identification::term_errors`] at the fit), said in words.
pub fn missed_events(problem: &LoadedProblem, errors: &[(String, RmsError)]) -> Vec<String> {
    let mut out = Vec::new();
    for e in &problem.experiments {
        for ev in &e.events {
            let Some(u) = ev.uncertainty else { continue };
            let term = event_term_name(&e.name, &ev.name);
            let Some((_, err)) = errors.iter().find(|(name, _)| *name == term) else { continue };
            if err.value > MISSED_EVENT_FACTOR * u {
                let unit = ev.unit();
                out.push(format!(
                    "the fit misses `{}` of `{}` (measured {:.4} {unit}) by {:.4} {unit}, {:.1} times its stated \
                     uncertainty of {u:.4} {unit}: the fit is not at the level of the data (a local minimum, or a \
                     model-form difference) and the verdicts are provisional; a global method (miga, hybrid) or \
                     another initial guess may find a better fit",
                    ev.name,
                    e.name,
                    ev.value,
                    err.value,
                    err.value / u
                ));
            }
        }
    }
    out
}

/// Experiments whose simulation ends before their last reading: the readings beyond are compared
/// with the run's last state, which makes the parameters look undetermined; said in words.
pub fn short_runs(problem: &LoadedProblem, outcome: &Outcome) -> Vec<String> {
    let mut out = Vec::new();
    for e in &problem.experiments {
        let Some(ended) =
            outcome.records.get(&e.name).and_then(|r| r.column(columns::DISPLACEMENT).ok()?.last().copied())
        else {
            continue;
        };
        let last = e.load.x_max();
        if ended < 0.99 * last {
            out.push(format!(
                "the model of `{}` stops at {ended:.4} mm but its test runs to {last:.4} mm: the readings beyond are \
                 compared with the model's last state (raise the model's control.max_displacement, or see why the \
                 run stopped)",
                e.name
            ));
        }
    }
    out
}

/// Runs a model file's model (`[law]` and `[model]`, as in a truth file; no test data) and writes
/// `curves.csv` and `curves-load.png`.
pub fn simulate_model(file: &crate::synthetic::TruthFile, out: &OutputDir) -> Result<czid_core::Record> {
    let (record, stopped) = match file.model.simulate(file.law.as_ref()) {
        Ok(r) => (r, None),
        Err(f) if f.partial.rows() >= 2 => (f.partial.clone(), Some(f.to_string())),
        Err(f) => return Err(CzError::Simulation(f.to_string())),
    };
    let (header, cols): (Vec<String>, Vec<Vec<f64>>) = RECORDED
        .iter()
        .filter_map(|c| {
            let v = record.column(c).ok()?;
            Some((format!("{c} ({})", record.unit(c).unwrap_or("-")), v.to_vec()))
        })
        .unzip();
    out.write_csv("curves.csv", &header, &cols)?;
    let sim = record.curve(columns::DISPLACEMENT, columns::LOAD)?;
    Figure::new(&format!("{}: load", file.model.name()), "displacement (mm)", "load (N)")
        .with(Series::line("model", sim.x().to_vec(), sim.y().to_vec()))
        .save(&out.file("curves-load.png"))?;
    match stopped {
        None => Ok(record),
        Some(why) => Err(CzError::Simulation(format!("stopped early (curves hold the converged steps): {why}"))),
    }
}

/// The record columns written to `curves.csv` and `fit.csv`, when the model records them.
const RECORDED: [&str; 8] = [
    columns::DISPLACEMENT,
    columns::LOAD,
    columns::DEBONDED_LENGTH,
    columns::PROCESS_ZONE_LENGTH,
    columns::CRACK_TIP,
    columns::EXTERNAL_WORK,
    columns::ELASTIC_ENERGY,
    columns::DISSIPATED_ENERGY,
];

/// Runs every experiment's model at the initial values; writes `curves.csv` (or
/// `curves-<experiment>.csv` when there are several) and plots against the data.
pub fn simulate(problem: &LoadedProblem, out: &OutputDir) -> Result<Outcome> {
    let id = Identification::new(
        problem.setup()?,
        czid_core::ParameterSpace::default(),
        &problem.experiments,
        problem.file.objective.debonded_length,
    )?;
    let outcome = id.simulate(&[])?;
    write_fits(problem, &outcome, out, "curves")?;
    Ok(outcome)
}

pub(crate) fn write_fits(problem: &LoadedProblem, outcome: &Outcome, out: &OutputDir, stem: &str) -> Result<()> {
    let several = outcome.records.len() > 1;
    for e in &problem.experiments {
        let record = &outcome.records[&e.name];
        let suffix = if several { format!("-{}", e.name) } else { String::new() };
        let mut header = Vec::new();
        let mut cols = Vec::new();
        for c in RECORDED {
            if let Ok(v) = record.column(c) {
                header.push(format!("{c} ({})", record.unit(c).unwrap_or("-")));
                cols.push(v.to_vec());
            }
        }
        out.write_csv(&format!("{stem}{suffix}.csv"), &header, &cols)?;

        // The curve the experiment is fitted on: the load, or the beam's mid-span moment.
        let (column, unit) = (e.ordinate.column(), e.ordinate.unit());
        let sim = record.curve(columns::DISPLACEMENT, column)?;
        let label = column.replace('_', " ");
        Figure::new(&format!("{}: {label}", e.name), "displacement (mm)", &format!("{label} ({unit})"))
            .with(Series::points("test", e.load.x().to_vec(), e.load.y().to_vec()))
            .with(Series::line("model", sim.x().to_vec(), sim.y().to_vec()))
            .save(&out.file(&format!("{stem}{suffix}-load.png")))?;
        if let (Some(l), Ok(sim)) = (&e.debonded_length, record.curve(columns::DISPLACEMENT, columns::DEBONDED_LENGTH))
        {
            Figure::new(&format!("{}: debonded length", e.name), "displacement (mm)", "debonded length (mm)")
                .with(Series::points("test", l.x().to_vec(), l.y().to_vec()))
                .with(Series::line("model", sim.x().to_vec(), sim.y().to_vec()))
                .save(&out.file(&format!("{stem}{suffix}-debonded.png")))?;
        }
        events_plot(e, record, out, &format!("{stem}{suffix}"))?;
    }
    Ok(())
}

/// The experiment's scalar events, test (with bars of ± its stated uncertainty) beside model, one
/// figure per unit (`-events.png` for lengths and displacements in mm, `-events-load.png` for
/// loads in N); nothing without events.
fn events_plot(e: &crate::data::Experiment, record: &czid_core::Record, out: &OutputDir, stem: &str) -> Result<()> {
    for (unit, file) in [("mm", "events"), ("N", "events-load")] {
        let mine: Vec<_> = e.events.iter().filter(|v| v.unit() == unit).collect();
        if mine.is_empty() {
            continue;
        }
        let names: Vec<String> = mine.iter().map(|v| v.name.clone()).collect();
        let at: Vec<f64> = (1..=mine.len()).map(|i| i as f64).collect();
        let test: Vec<f64> = mine.iter().map(|v| v.value).collect();
        // The readings' stated uncertainties as ± one-uncertainty bars.
        let spread = |sign: f64| mine.iter().map(|v| v.value + sign * v.uncertainty.unwrap_or(0.0)).collect();
        let test_series = Series::points("test", at.clone(), test);
        let test_series = if mine.iter().any(|v| v.uncertainty.is_some()) {
            test_series.with_band(spread(-1.0), spread(1.0))
        } else {
            test_series
        };
        // An event the model does not reach (a run that stopped early) is left out of the model's
        // points rather than drawn at a made-up value.
        let (model_at, model): (Vec<f64>, Vec<f64>) = mine
            .iter()
            .zip(&at)
            .filter_map(|(v, &x)| {
                v.response.boxed().predict(record, &[0.0]).ok().and_then(|p| p.first().map(|&y| (x, y)))
            })
            .unzip();
        Figure::new(&format!("{}: events", e.name), "event", &format!("value ({unit})"))
            .with(test_series)
            .with(Series::points("model", model_at, model))
            .with_categories(&names)
            .save(&out.file(&format!("{stem}-{file}.png")))?;
    }
    Ok(())
}

/// Rewrites `history.csv` with physical values under `path (unit)` headers instead of the
/// optimizer's unit-cube coordinates `x0, x1, …`, after the rows of an interrupted run (`earlier`:
/// relabelled already when that run ended on a signal, not when it was killed) when this one
/// resumed it.
fn relabel_history(id: &Identification, out: &OutputDir, earlier: Option<&str>) -> Result<()> {
    let path = out.file("history.csv");
    let text = std::fs::read_to_string(&path)
        .map_err(|e| CzError::Io { path: path.display().to_string(), message: e.to_string() })?;
    let params = id.space().parameters();
    let mut lines = text.lines();
    let Some(header) = lines.next() else { return Ok(()) };
    let fixed = header.split(',').count().saturating_sub(params.len());
    let mut outtext: Vec<String> = header.split(',').take(fixed).map(str::to_string).collect();
    outtext.extend(params.iter().map(|p| format!("{} ({})", p.path, p.unit)));
    let mut result = outtext.join(",");
    result.push('\n');
    let physical = |line: &str| -> String {
        let cells: Vec<&str> = line.split(',').collect();
        let mut row: Vec<String> = cells.iter().take(fixed).map(|c| c.to_string()).collect();
        for (p, c) in params.iter().zip(cells.iter().skip(fixed)) {
            let u: f64 = c.parse().unwrap_or(f64::NAN);
            row.push(format!("{}", p.from_unit(u)));
        }
        row.join(",")
    };
    let rows: Vec<&str> = lines.collect();
    let first_new = rows.first().and_then(|l| l.split(',').next()).and_then(|c| c.parse::<usize>().ok());
    let kept = earlier.map(|e| earlier_rows(e, first_new)).unwrap_or_default();
    let relabelled = kept.first().is_some_and(|h| *h == result.trim_end());
    for line in kept.iter().skip(1) {
        result.push_str(&if relabelled { line.clone() } else { physical(line) });
        result.push('\n');
    }
    for line in rows {
        result.push_str(&physical(line));
        result.push('\n');
    }
    out.write("history.csv", &result).map(|_| ())
}

fn convergence_plot(result: &OptimizationResult, out: &OutputDir) -> Result<()> {
    // A staircase: the best value holds until the next improvement.
    let mut x = Vec::new();
    let mut y = Vec::new();
    for (i, &(n, v)) in result.history.iter().enumerate() {
        if i > 0 {
            x.push(n as f64);
            y.push(*y.last().expect("previous point"));
        }
        x.push(n as f64);
        y.push(v);
    }
    if let Some(&last) = y.last() {
        x.push(result.evaluations as f64);
        y.push(last);
    }
    Figure::new("convergence", "evaluations", "best objective f")
        .log_y()
        .with(Series::line("best so far", x, y))
        .save(&out.file("convergence.png"))
}
