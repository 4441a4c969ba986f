//! `compare`: several optimizers × seeds on one problem at equal evaluation budgets.
//!
//! A local method (Levenberg–Marquardt, Nelder–Mead, …) draws no random numbers and runs once:
//! its other seeds would repeat that run.
//!
//! Runs that end in different minima can fit equally well: the column `in_95_region` of
//! `summary.csv` marks the runs inside the 95 % confidence region of the best one
//! ([`crate::confidence_region`]), and [`Comparison::equivalent`] gives the spread of each
//! parameter over them, which the standard errors at one run's end point cannot show.
//!
//! Writes `summary.csv` (one row per run: best objective, evaluations to reach the target, wall
//! time, identified values), `convergence.csv` (best-so-far per run on a common evaluation grid),
//! and plots: convergence (median and quartile band per optimizer) and final objective per
//! optimizer.
//!
//! A comparison on a slow model runs for hours, so nothing of it is lost to an interruption. Each
//! run works in its own folder, `runs/<optimizer>-seed<k>/`, as an identification does (`run.json`
//! with the run's [`Fingerprint`], `checkpoint.json` after every iteration of a global method, the
//! journal `evaluations.jsonl` of a local one), and leaves `finished.json` when it ends; the two
//! tables are rewritten after every run. `resume` keeps the finished runs, continues the
//! interrupted one where it stopped and runs the rest: the outputs are those of the uninterrupted
//! comparison, wall times apart.

use crate::confidence_region::{equivalent_fits, EquivalentFits};
use crate::identify::{optimize_with, AbortAfter};
use crate::output::OutputDir;
use crate::plot::{Figure, Series};
use crate::problem_file::LoadedProblem;
use crate::resume::{Fingerprint, RunClock, RunFile};
use czid_core::{Budget, CzError, Result};
use czid_optimizers::checkpoint::{read_checkpoint, CheckpointWriter};
use czid_optimizers::observers::{Observers, ProgressBar};
use czid_optimizers::registry::{method_from_config, Method};
use serde::{Deserialize, Serialize};

/// What to compare.
#[derive(Clone, Debug)]
pub struct CompareOptions {
    /// Optimizer names.
    pub optimizers: Vec<String>,
    /// Number of seeds (1..=seeds).
    pub seeds: u64,
    /// Evaluation budget per run (default: the file's).
    pub budget: Option<usize>,
    /// Objective value counted as success (default 1e-3: a thousandfold reduction from the
    /// balanced initial guess).
    pub target: f64,
    /// Where the runs' batches go (default: this process's threads), e.g. MPI ranks.
    pub spread: Option<crate::identify::Spread>,
    /// Keep the runs an interrupted comparison in the same folder finished, and continue the one
    /// it was in.
    pub resume: bool,
    /// Abort the process, as a kill would, once the runs of this call have done this many
    /// evaluations (for tests of interruption and resume).
    pub abort_after: Option<usize>,
    /// Show each run's progress (a bar on a terminal, a line every tenth of the budget in a log).
    pub progress: bool,
}

/// One run's outcome.
#[derive(Clone, Debug)]
pub struct RunSummary {
    /// Optimizer.
    pub optimizer: String,
    /// Seed.
    pub seed: u64,
    /// Best objective.
    pub best: f64,
    /// Evaluations until the best value first reached the target (None: never).
    pub evaluations_to_target: Option<usize>,
    /// Evaluations spent.
    pub evaluations: usize,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// Identified physical values.
    pub x: Vec<f64>,
    /// Best-so-far on the evaluation grid.
    pub curve: Vec<f64>,
}

/// What a comparison found.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// Every run, in the order they ran.
    pub runs: Vec<RunSummary>,
    /// The runs inside the 95 % confidence region of the best one and each parameter's range over
    /// them, or why there is no region (no run ended with a finite value, the model failed at the
    /// best run's values, or there are no more residuals than parameters).
    pub equivalent: std::result::Result<EquivalentFits, String>,
}

/// Runs the comparison and writes its outputs into `out`.
pub fn compare(problem: &LoadedProblem, opts: &CompareOptions, out: &OutputDir) -> Result<Comparison> {
    if opts.optimizers.is_empty() || opts.seeds == 0 {
        return Err(CzError::config("compare", "give at least one optimizer and one seed"));
    }
    let runs_folder = out.file("runs");
    if opts.resume && !runs_folder.is_dir() {
        return Err(CzError::Io {
            path: runs_folder.display().to_string(),
            message: "no runs of a comparison here: nothing to resume (run without --resume to start)".into(),
        });
    }
    let id = problem.identification()?;
    let budget = Budget { evaluations: opts.budget.unwrap_or(problem.file.optimizer.budget), target: None };
    let grid: Vec<usize> = (1..=50).map(|k| (budget.evaluations * k).div_ceil(50)).collect();
    // Every optimizer and its budget are checked before the first run, not after the others ran.
    for name in &opts.optimizers {
        let (kind, settings) = problem.file.optimizer_named(name);
        if let Method::Global(g) = method_from_config(&kind, &settings)? {
            g.check_budget(&budget)?;
        }
    }
    let mut runs = Vec::new();
    let mut spent = 0usize;
    for name in &opts.optimizers {
        let (kind, settings) = problem.file.optimizer_named(name);
        // A local method draws no random numbers: every seed would repeat the same run (hours
        // on a slow model), so it runs once and stands for all of them.
        let seeds = if matches!(method_from_config(&kind, &settings)?, Method::Local(_)) { 1 } else { opts.seeds };
        if seeds < opts.seeds {
            eprintln!("{name:>20}: draws no random numbers, so one run stands for every seed");
        }
        for seed in 1..=seeds {
            let folder = OutputDir::create(&out.file(&format!("runs/{}-seed{seed}", slug(name))), true, true)?;
            let fingerprint = Fingerprint::of(&id, &problem.experiments, name, &settings, seed, budget.evaluations)?;
            let (finished, kept) = match kept_run(&folder, &fingerprint, opts.resume)? {
                Some(f) => (f, true),
                None => {
                    if opts.progress {
                        eprintln!("{name:>20} seed {seed:>3}: running ({} evaluations)", budget.evaluations);
                    }
                    let abort = opts.abort_after.map(|n| n.saturating_sub(spent));
                    let f = run_one(&id, &kind, &settings, seed, &budget, fingerprint, &folder, opts, abort)?;
                    spent += f.evaluations;
                    (f, false)
                }
            };
            eprintln!(
                "{name:>20} seed {seed:>3}: f = {:.4e} in {} evaluations, {:.2} s{}",
                finished.best,
                finished.evaluations,
                finished.wall_seconds,
                if kept { " (finished before the resume)" } else { "" }
            );
            runs.push(finished.summary(name, seed, &grid, opts.target));
            write_tables(&id, &runs, &grid, None, out)?;
        }
    }
    let equivalent = equivalent_runs(&id, &runs);
    write_tables(&id, &runs, &grid, equivalent.as_ref().ok(), out)?;
    write_plots(&runs, &grid, opts, out)?;
    Ok(Comparison { runs, equivalent })
}

/// The runs inside the 95 % region of the best one, or why there is none; the number of residuals
/// comes from a run of the model at the best run's values.
fn equivalent_runs(
    id: &crate::identification::Identification,
    runs: &[RunSummary],
) -> std::result::Result<EquivalentFits, String> {
    let best = runs
        .iter()
        .filter(|r| r.best.is_finite())
        .min_by(|a, b| a.best.total_cmp(&b.best))
        .ok_or("no run ended with a finite objective value")?;
    let n = match id.simulate(&best.x) {
        Ok(sim) => sim.evaluation.residuals.len(),
        Err(e) => return Err(format!("the model failed at the best run's values ({e})")),
    };
    let f: Vec<f64> = runs.iter().map(|r| r.best).collect();
    let x: Vec<Vec<f64>> = runs.iter().map(|r| r.x.clone()).collect();
    let p = x.first().map_or(0, Vec::len);
    equivalent_fits(&f, &x, n)
        .ok_or_else(|| format!("{n} residuals for {p} parameters: the region needs more residuals than parameters"))
}

/// What a finished run leaves in its folder (`finished.json`): enough to rebuild its rows for any
/// target and grid.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct FinishedRun {
    /// The run it is (a resume with another problem, budget or settings does not keep it).
    fingerprint: Fingerprint,
    best: f64,
    evaluations: usize,
    /// Wall time over every part of the run (s).
    wall_seconds: f64,
    /// Identified physical values.
    x: Vec<f64>,
    /// Best-so-far after each iteration: (evaluations, best objective).
    history: Vec<(usize, f64)>,
}

impl FinishedRun {
    const NAME: &'static str = "finished.json";

    fn summary(&self, optimizer: &str, seed: u64, grid: &[usize], target: f64) -> RunSummary {
        let h = &self.history;
        let at = |n: usize| h.iter().take_while(|(e, _)| *e <= n).last().map_or(f64::NAN, |(_, v)| *v);
        RunSummary {
            optimizer: optimizer.to_string(),
            seed,
            best: self.best,
            evaluations_to_target: h.iter().find(|(_, v)| *v <= target).map(|(e, _)| *e),
            evaluations: self.evaluations,
            wall_seconds: self.wall_seconds,
            x: self.x.clone(),
            curve: grid.iter().map(|&n| at(n)).collect(),
        }
    }
}

/// The run finished in `folder` by an earlier call, when resuming; refused when it is another run.
fn kept_run(folder: &OutputDir, fingerprint: &Fingerprint, resume: bool) -> Result<Option<FinishedRun>> {
    let path = folder.file(FinishedRun::NAME);
    if !resume || !path.exists() {
        return Ok(None);
    }
    let shown = path.display().to_string();
    let text =
        std::fs::read_to_string(&path).map_err(|e| CzError::Io { path: shown.clone(), message: e.to_string() })?;
    let done: FinishedRun = serde_json::from_str(&text)
        .map_err(|e| CzError::data(shown, format!("not a finished run of `czid compare`: {e}")))?;
    let differences = fingerprint.differences(&done.fingerprint);
    if !differences.is_empty() {
        return Err(CzError::config(
            "--resume",
            format!(
                "the run finished in {} is not this comparison's: {}. Give the same problem, optimizers \
                 and budget to continue it, or start afresh with --force",
                folder.path().display(),
                differences.join("; ")
            ),
        ));
    }
    Ok(Some(done))
}

/// Runs one optimizer and seed in `folder`, continuing what an interrupted call left there when
/// resuming, and writes `finished.json`.
#[allow(clippy::too_many_arguments)]
fn run_one(
    id: &crate::identification::Identification,
    kind: &str,
    settings: &toml::Value,
    seed: u64,
    budget: &Budget,
    fingerprint: Fingerprint,
    folder: &OutputDir,
    opts: &CompareOptions,
    abort: Option<usize>,
) -> Result<FinishedRun> {
    let method = method_from_config(kind, settings)?;
    let local = matches!(method, Method::Local(_));
    // A run interrupted before its first checkpoint (or journal entry) starts again from scratch.
    let started = opts.resume && folder.file(RunFile::NAME).exists();
    let earlier = if started { Some(RunFile::for_resume(folder, &fingerprint)?) } else { None };
    let checkpoint = folder.file("checkpoint.json");
    let journal = folder.file("evaluations.jsonl");
    let state = if started && !local && checkpoint.exists() { Some(read_checkpoint(&checkpoint)?) } else { None };
    let replay = started && local && journal.exists();
    let mut clock = RunClock::start(folder, fingerprint.clone(), earlier)?;
    let mut writer = CheckpointWriter::new(&checkpoint, 1)?;
    let mut abort = AbortAfter(abort);
    let n = budget.evaluations;
    let mut bar = if opts.progress { ProgressBar::new(n) } else { ProgressBar::hidden(n) };
    let run = {
        let mut observers = Observers(vec![&mut writer, &mut clock, &mut abort, &mut bar]);
        let spread = opts.spread.as_ref().map(|s| s.0.as_ref());
        let journal = local.then_some((journal.as_path(), replay));
        optimize_with(id, &method, seed, budget, state.as_deref(), journal, spread, &mut observers)?
    };
    bar.finish();
    let finished = FinishedRun {
        fingerprint,
        best: run.result.best.value,
        evaluations: run.result.evaluations,
        wall_seconds: clock.finish()?,
        x: id.space().from_unit(&run.result.best_x),
        history: run.result.history,
    };
    let json = serde_json::to_string_pretty(&finished).map_err(|e| CzError::config("finished.json", e.to_string()))?;
    folder.write(FinishedRun::NAME, &json)?;
    Ok(finished)
}

/// A folder name for an optimizer's label.
fn slug(label: &str) -> String {
    label.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect()
}

/// `summary.csv` and `convergence.csv` of the runs so far (`in_95_region` is filled once every run
/// has ended).
fn write_tables(
    id: &crate::identification::Identification,
    runs: &[RunSummary],
    grid: &[usize],
    region: Option<&EquivalentFits>,
    out: &OutputDir,
) -> Result<()> {
    let mut text =
        String::from("optimizer,seed,best_objective,evaluations_to_target,evaluations,wall_seconds,in_95_region");
    for p in id.space().parameters() {
        text.push_str(&format!(",{} ({})", p.path, p.unit));
    }
    text.push('\n');
    for (k, r) in runs.iter().enumerate() {
        let ett = r.evaluations_to_target.map_or(String::new(), |e| e.to_string());
        let inside = region.map_or("", |e| if e.inside.contains(&k) { "yes" } else { "no" });
        text.push_str(&format!(
            "{},{},{},{},{},{},{inside}",
            r.optimizer, r.seed, r.best, ett, r.evaluations, r.wall_seconds
        ));
        for v in &r.x {
            text.push_str(&format!(",{v}"));
        }
        text.push('\n');
    }
    out.write("summary.csv", &text)?;

    let mut conv = String::from("optimizer,seed");
    for n in grid {
        conv.push_str(&format!(",{n}"));
    }
    conv.push('\n');
    for r in runs {
        conv.push_str(&format!("{},{}", r.optimizer, r.seed));
        for v in &r.curve {
            conv.push_str(&format!(",{v}"));
        }
        conv.push('\n');
    }
    out.write("convergence.csv", &conv).map(|_| ())
}

/// The convergence and final-objective plots.
fn write_plots(runs: &[RunSummary], grid: &[usize], opts: &CompareOptions, out: &OutputDir) -> Result<()> {
    let xs: Vec<f64> = grid.iter().map(|&n| n as f64).collect();
    let mut fig = Figure::new("convergence (median, quartiles over seeds)", "evaluations", "best objective f").log_y();
    let mut finals =
        Figure::new(&format!("final objective per run (target {})", opts.target), "optimizer", "best objective f")
            .log_y()
            .with_categories(&opts.optimizers);
    for (k, name) in opts.optimizers.iter().enumerate() {
        let mine: Vec<&RunSummary> = runs.iter().filter(|r| &r.optimizer == name).collect();
        let (mut med, mut lo, mut hi) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..grid.len() {
            let mut col: Vec<f64> = mine.iter().map(|r| r.curve[i]).filter(|v| v.is_finite()).collect();
            col.sort_by(f64::total_cmp);
            med.push(quantile(&col, 0.5));
            lo.push(quantile(&col, 0.25));
            hi.push(quantile(&col, 0.75));
        }
        fig = fig.with(Series::line(name, xs.clone(), med).with_band(lo, hi));
        let n = mine.len().max(1) as f64;
        let px: Vec<f64> = (0..mine.len()).map(|j| k as f64 + 1.0 + 0.3 * (j as f64 / n - 0.5)).collect();
        finals = finals.with(Series::points(name, px, mine.iter().map(|r| r.best).collect()));
    }
    fig.save(&out.file("convergence.png"))?;
    finals.save(&out.file("final_objective.png"))
}

/// Linear-interpolated quantile of sorted values (NaN when empty).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let pos = q * (sorted.len() - 1) as f64;
    let (i, f) = (pos.floor() as usize, pos.fract());
    if i + 1 < sorted.len() {
        sorted[i] * (1.0 - f) + sorted[i + 1] * f
    } else {
        sorted[i]
    }
}
