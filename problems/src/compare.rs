//! `compare`: several optimizers × seeds on one problem at equal evaluation budgets.
//!
//! Writes `summary.csv` (one row per run: best objective, evaluations to reach the target, wall
//! time, identified values), `convergence.csv` (best-so-far per run on a common evaluation grid),
//! and plots: convergence (median and quartile band per optimizer) and final objective per
//! optimizer.

use crate::identify::optimize;
use crate::output::OutputDir;
use crate::plot::{Figure, Series};
use crate::problem_file::LoadedProblem;
use czid_core::{Budget, CzError, NoObserver, Result};
use czid_optimizers::registry::{method_from_config, Method};

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

/// Runs the comparison and writes its outputs into `out`.
pub fn compare(problem: &LoadedProblem, opts: &CompareOptions, out: &OutputDir) -> Result<Vec<RunSummary>> {
    if opts.optimizers.is_empty() || opts.seeds == 0 {
        return Err(CzError::config("compare", "give at least one optimizer and one seed"));
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
    for name in &opts.optimizers {
        let (kind, settings) = problem.file.optimizer_named(name);
        for seed in 1..=opts.seeds {
            let spread = opts.spread.as_ref().map(|s| s.0.as_ref());
            let run = optimize(&id, &kind, &settings, seed, &budget, None, spread, &mut NoObserver)?;
            let h = &run.result.history;
            let at = |n: usize| h.iter().take_while(|(e, _)| *e <= n).last().map_or(f64::NAN, |(_, v)| *v);
            let curve = grid.iter().map(|&n| at(n)).collect();
            let evaluations_to_target = h.iter().find(|(_, v)| *v <= opts.target).map(|(e, _)| *e);
            eprintln!(
                "{name:>20} seed {seed:>3}: f = {:.4e} in {} evaluations, {:.2} s",
                run.result.best.value, run.result.evaluations, run.wall_seconds
            );
            runs.push(RunSummary {
                optimizer: name.clone(),
                seed,
                best: run.result.best.value,
                evaluations_to_target,
                evaluations: run.result.evaluations,
                wall_seconds: run.wall_seconds,
                x: id.space().from_unit(&run.result.best_x),
                curve,
            });
        }
    }
    write_outputs(&id, &runs, &grid, opts, out)?;
    Ok(runs)
}

fn write_outputs(
    id: &crate::identification::Identification,
    runs: &[RunSummary],
    grid: &[usize],
    opts: &CompareOptions,
    out: &OutputDir,
) -> Result<()> {
    let mut text = String::from("optimizer,seed,best_objective,evaluations_to_target,evaluations,wall_seconds");
    for p in id.space().parameters() {
        text.push_str(&format!(",{} ({})", p.path, p.unit));
    }
    text.push('\n');
    for r in runs {
        let ett = r.evaluations_to_target.map_or(String::new(), |e| e.to_string());
        text.push_str(&format!("{},{},{},{},{},{}", r.optimizer, r.seed, r.best, ett, r.evaluations, r.wall_seconds));
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
    out.write("convergence.csv", &conv)?;

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
