//! `czid harness`: benchmark optimizers on test problems at equal evaluation budgets.
//!
//! ```text
//! czid harness --optimizers miga,ga --problems rastrigin10,schwefel10,rotated-rastrigin10 \
//!     --seeds 20 --budget 20000 --out results
//! # on a cluster, one job per seed, then combine:
//! czid harness ... --seeds 1 --seed-offset $TASK_ID --replicate --out results
//! czid harness --merge results --out results/all
//! # parallel efficiency of population evaluation:
//! czid harness --speedup --out speedup
//! ```

use czid_core::CzError;
use czid_optimizers::harness::{self, HarnessConfig};
use std::path::PathBuf;

/// Arguments of `czid harness`.
#[derive(Debug, Clone, clap::Args)]
pub struct HarnessArgs {
    /// Optimizers (registry names, or labels of tables in --config).
    #[arg(long, value_delimiter = ',', default_value = "miga,ga")]
    pub optimizers: Vec<String>,
    /// Test problems, e.g. rastrigin10, schwefel10, rotated-rastrigin10, ackley10, zdt1.
    #[arg(long, value_delimiter = ',', default_value = "rastrigin10")]
    pub problems: Vec<String>,
    /// Seeds per optimizer and problem.
    #[arg(long, default_value_t = 20)]
    pub seeds: u64,
    /// First seed (for job arrays).
    #[arg(long, default_value_t = 0)]
    pub seed_offset: u64,
    /// Evaluation budget of every run.
    #[arg(long, default_value_t = 20_000)]
    pub budget: usize,
    /// Success threshold on the objective value (default: each problem's own).
    #[arg(long)]
    pub target: Option<f64>,
    /// Tolerance τ of the Moré–Wild data profiles.
    #[arg(long, default_value_t = 1e-3)]
    pub tau: f64,
    /// TOML file of optimizer settings: one `[label]` table per optimizer, with an optional
    /// `type` (default: the label) and its settings.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "harness-out")]
    pub out: PathBuf,
    /// Write into OUT/part-<seed-offset> so that array jobs can share OUT.
    #[arg(long)]
    pub replicate: bool,
    /// Reuse a non-empty output directory, overwriting its files.
    #[arg(long)]
    pub force: bool,
    /// Combine these harness output directories (or directories of part-* directories)
    /// into OUT instead of running.
    #[arg(long, num_args = 1..)]
    pub merge: Vec<PathBuf>,
    /// Measure the parallel speed-up of population evaluation instead of running.
    #[arg(long)]
    pub speedup: bool,
    /// CPU cost of one evaluation for --speedup, milliseconds.
    #[arg(long, default_value_t = 1.0)]
    pub speedup_cost_ms: f64,
    /// Print one line per run.
    #[arg(long, short)]
    pub verbose: bool,
}

/// Runs `czid harness`.
pub fn run(args: &HarnessArgs) -> Result<(), CzError> {
    if args.speedup {
        if !(args.speedup_cost_ms.is_finite() && args.speedup_cost_ms > 0.0) {
            return Err(CzError::invalid("harness", "speedup-cost-ms", args.speedup_cost_ms, "must be positive"));
        }
        harness::prepare_dir(&args.out, args.force)?;
        let r = harness::measure_speedup(args.speedup_cost_ms * 1e-3, 1000, 2)?;
        let text = format!(
            "| evaluations | cost per evaluation | 1 thread | {} threads | speed-up | identical results |\n\
             |---|---|---|---|---|---|\n\
             | {} | {:.3} ms | {:.3} s | {:.3} s | {:.2}× | {} |\n",
            r.threads,
            r.evaluations,
            r.evaluation_seconds * 1e3,
            r.serial_seconds,
            r.parallel_seconds,
            r.speedup,
            r.identical
        );
        czid_optimizers::checkpoint::write_atomic(&args.out.join("speedup.md"), text.as_bytes())?;
        print!("{text}");
        return Ok(());
    }
    let output = if args.merge.is_empty() {
        let settings = match &args.config {
            None => toml::Table::new(),
            Some(path) => {
                let text = std::fs::read_to_string(path)
                    .map_err(|e| CzError::Io { path: path.display().to_string(), message: e.to_string() })?;
                toml::from_str(&text).map_err(|e| CzError::config(path.display().to_string(), e.to_string()))?
            }
        };
        harness::run(&HarnessConfig {
            optimizers: args.optimizers.clone(),
            problems: args.problems.clone(),
            seeds: args.seeds,
            seed_offset: args.seed_offset,
            budget: args.budget,
            target: args.target,
            tau: args.tau,
            settings,
            out: args.out.clone(),
            replicate: args.replicate,
            force: args.force,
            verbose: args.verbose,
        })?
    } else {
        harness::merge(&args.merge, &args.out, args.force, args.tau)?
    };
    print!("{}", output.markdown);
    println!("\nwritten to {}", output.dir.display());
    Ok(())
}
