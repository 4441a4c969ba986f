//! The benchmark harness: optimizers × problems × seeds at equal evaluation budgets.
//!
//! [`run`] writes into its output directory:
//! * `runs.csv`: one row per run (optimizer, problem, dim, seed, best value, evaluations,
//!   failures, target, evaluations to target, wall seconds);
//! * `convergence.csv`: the exact best-so-far curve of every run, one row per improvement
//!   (`optimizer, problem, seed, evaluations, best_value`): between two rows the best value
//!   is constant, so the curve is known at every evaluation;
//! * `summary.md`: success rates, evaluations to target, ERT and best values per problem;
//! * `convergence_<problem>.svg/.png` (median and quartile band of `f − f*` per optimizer)
//!   and `data_profile.svg/.png` (Moré–Wild data profiles).
//!
//! It scales to a cluster through independent runs: each job runs some seeds
//! (`seed_offset`, `seeds`) into its own `part-<offset>` directory (`replicate`), and
//! [`merge`] combines the parts and redraws the summary and plots. Every file is written
//! atomically; an existing non-empty output directory is only reused with `force`.

mod plots;
mod records;
mod report;
mod speedup;

pub use records::{ConvergencePoint, RunRecord};
pub use report::{data_profiles, summary_table, DataProfile, SummaryRow};
pub use speedup::{measure_speedup, SpeedupReport};

use crate::checkpoint::write_atomic;
use crate::registry::optimizer_from_table;
use crate::testfns::{by_name, TestProblem};
use czid_core::{Budget, CzError, NoObserver, Optimizer, Result};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct HarnessConfig {
    /// Optimizer labels: registry names, or keys of `settings` tables.
    pub optimizers: Vec<String>,
    /// Test problem names (see [`crate::testfns::by_name`]).
    pub problems: Vec<String>,
    /// Number of seeds per (optimizer, problem).
    pub seeds: u64,
    /// First seed (job arrays give each job its own offset).
    pub seed_offset: u64,
    /// Evaluation budget of every run.
    pub budget: usize,
    /// Success threshold on `value` for every problem (default: each problem's own).
    pub target: Option<f64>,
    /// Moré–Wild tolerance τ of the data profiles (default 1e-3).
    pub tau: f64,
    /// Optimizer settings by label: `[label]` tables with an optional `type` (default: the
    /// label) and the optimizer's settings.
    pub settings: toml::Table,
    /// Output directory.
    pub out: PathBuf,
    /// Write into `out/part-<seed_offset>` (job arrays sharing `out`).
    pub replicate: bool,
    /// Reuse a non-empty output directory, overwriting its files.
    pub force: bool,
    /// Print one line per run.
    pub verbose: bool,
}

impl Default for HarnessConfig {
    fn default() -> Self {
        HarnessConfig {
            optimizers: vec!["miga".into(), "ga".into()],
            problems: vec!["rastrigin10".into()],
            seeds: 20,
            seed_offset: 0,
            budget: 20_000,
            target: None,
            tau: 1e-3,
            settings: toml::Table::new(),
            out: PathBuf::from("harness-out"),
            replicate: false,
            force: false,
            verbose: false,
        }
    }
}

/// Everything a harness run or merge produced.
#[derive(Clone, Debug, PartialEq)]
pub struct HarnessOutput {
    /// The directory written.
    pub dir: PathBuf,
    /// The runs.
    pub runs: Vec<RunRecord>,
    /// The summary rows.
    pub summary: Vec<SummaryRow>,
    /// The summary as markdown (also in `summary.md`).
    pub markdown: String,
}

/// Builds the optimizer for `label`.
pub fn build_optimizer(label: &str, settings: &toml::Table) -> Result<Box<dyn Optimizer + Send + Sync>> {
    let mut table = match settings.get(label) {
        Some(toml::Value::Table(t)) => t.clone(),
        Some(_) => return Err(CzError::config(format!("harness settings `{label}`"), "expected a table")),
        None => toml::Table::new(),
    };
    table.entry("type").or_insert_with(|| toml::Value::String(label.to_string()));
    optimizer_from_table(&toml::Value::Table(table))
}

/// Creates `dir`, refusing to reuse a non-empty one unless `force`.
pub fn prepare_dir(dir: &Path, force: bool) -> Result<()> {
    let io = |e: std::io::Error| CzError::Io { path: dir.display().to_string(), message: e.to_string() };
    if dir.exists() && !force && std::fs::read_dir(dir).map_err(io)?.next().is_some() {
        return Err(CzError::Io {
            path: dir.display().to_string(),
            message: "output directory exists and is not empty (use --force to overwrite its files)".into(),
        });
    }
    std::fs::create_dir_all(dir).map_err(io)
}

/// Runs every optimizer on every problem for every seed.
pub fn run(cfg: &HarnessConfig) -> Result<HarnessOutput> {
    if cfg.optimizers.is_empty() || cfg.problems.is_empty() || cfg.seeds == 0 || cfg.budget == 0 {
        return Err(CzError::config("harness", "need at least one optimizer, one problem, one seed and a budget"));
    }
    // Build everything first so that a typo fails before hours of runs.
    let optimizers: Vec<(String, Box<dyn Optimizer + Send + Sync>)> =
        cfg.optimizers.iter().map(|l| Ok((l.clone(), build_optimizer(l, &cfg.settings)?))).collect::<Result<_>>()?;
    let problems: Vec<Box<dyn TestProblem>> = cfg.problems.iter().map(|p| by_name(p)).collect::<Result<_>>()?;
    let dir = if cfg.replicate { cfg.out.join(format!("part-{}", cfg.seed_offset)) } else { cfg.out.clone() };
    prepare_dir(&dir, cfg.force)?;

    let mut runs = Vec::new();
    let mut curves = Vec::new();
    for problem in &problems {
        let target = cfg.target.unwrap_or_else(|| problem.default_target());
        for (label, opt) in &optimizers {
            for seed in cfg.seed_offset..cfg.seed_offset + cfg.seeds {
                let start = Instant::now();
                let r = opt.minimize(problem.as_ref(), &Budget::evaluations(cfg.budget), seed, &mut NoObserver)?;
                let wall = start.elapsed().as_secs_f64();
                let hit = r.history.iter().find(|&&(_, v)| v <= target).map(|&(n, _)| n);
                let rec = RunRecord {
                    optimizer: label.clone(),
                    problem: problem.name(),
                    dim: problem.dim(),
                    seed,
                    best_value: r.best.value,
                    optimum: problem.optimum_value(),
                    evaluations: r.evaluations,
                    failures: r.failures,
                    target,
                    evaluations_to_target: hit,
                    wall_seconds: wall,
                };
                if cfg.verbose {
                    eprintln!(
                        "{:<14} {:<22} seed {:>4}: best {:.4e} after {} evals{} ({:.2} s)",
                        rec.optimizer,
                        rec.problem,
                        seed,
                        rec.best_value,
                        rec.evaluations,
                        hit.map_or(String::new(), |n| format!(", target at {n}")),
                        wall
                    );
                }
                curves.extend(r.history.iter().map(|&(n, v)| ConvergencePoint {
                    optimizer: label.clone(),
                    problem: problem.name(),
                    seed,
                    evaluations: n,
                    best_value: v,
                }));
                runs.push(rec);
            }
        }
    }
    write_outputs(&dir, runs, curves, cfg.tau)
}

/// Combines the `runs.csv` and `convergence.csv` of `inputs` (each a harness output
/// directory, or a directory of `part-*` directories) into `out`, then redraws the summary
/// and plots. A run present in several inputs (same optimizer, problem and seed) is an error.
pub fn merge(inputs: &[PathBuf], out: &Path, force: bool, tau: f64) -> Result<HarnessOutput> {
    let mut dirs = Vec::new();
    for input in inputs {
        if input.join("runs.csv").exists() {
            dirs.push(input.clone());
        } else {
            let io = |e: std::io::Error| CzError::Io { path: input.display().to_string(), message: e.to_string() };
            let mut parts: Vec<PathBuf> = std::fs::read_dir(input)
                .map_err(io)?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.join("runs.csv").exists())
                .collect();
            parts.sort();
            if parts.is_empty() {
                return Err(CzError::data(input.display().to_string(), "no runs.csv here nor in its subdirectories"));
            }
            dirs.extend(parts);
        }
    }
    let mut runs = Vec::new();
    let mut curves = Vec::new();
    for d in &dirs {
        runs.extend(records::read_runs(&d.join("runs.csv"))?);
        curves.extend(records::read_convergence(&d.join("convergence.csv"))?);
    }
    let mut keys: Vec<(&str, &str, u64)> =
        runs.iter().map(|r| (r.optimizer.as_str(), r.problem.as_str(), r.seed)).collect();
    keys.sort_unstable();
    if let Some(w) = keys.windows(2).find(|w| w[0] == w[1]) {
        return Err(CzError::data(
            "harness merge",
            format!("run {} / {} / seed {} appears more than once", w[0].0, w[0].1, w[0].2),
        ));
    }
    prepare_dir(out, force)?;
    write_outputs(out, runs, curves, tau)
}

fn write_outputs(dir: &Path, runs: Vec<RunRecord>, curves: Vec<ConvergencePoint>, tau: f64) -> Result<HarnessOutput> {
    write_atomic(&dir.join("runs.csv"), records::runs_csv(&runs)?.as_bytes())?;
    write_atomic(&dir.join("convergence.csv"), records::convergence_csv(&curves)?.as_bytes())?;
    let summary = summary_table(&runs);
    let profiles = data_profiles(&runs, &curves, tau);
    let markdown = report::markdown(&summary, &profiles, tau);
    write_atomic(&dir.join("summary.md"), markdown.as_bytes())?;
    plots::draw_all(dir, &runs, &curves, &profiles, tau)?;
    Ok(HarnessOutput { dir: dir.to_path_buf(), runs, summary, markdown })
}
