//! `czid gap-bench`: the diagnosis checked on planted-effect synthetic cases and null cases.
//!
//! ```text
//! czid gap-bench --cases 20 --nulls 20 --seed 1 --out out/gap-bench
//! czid gap-bench --family beam --cases 20 --out out/gap-bench-beam
//! czid gap-bench --truth continuum --cases 20 --out out/gap-bench-continuum
//! ```

use crate::cluster::Cluster;
use czid_core::CzError;
use czid_problems::diagnose::bench::{self, BenchOptions, CaseStore, Family};
use czid_problems::output::OutputDir;
use std::path::PathBuf;

/// Arguments of `czid gap-bench`.
#[derive(Debug, Clone, clap::Args)]
pub struct GapBenchArgs {
    /// Planted cases per effect.
    #[arg(long, default_value_t = 20)]
    pub cases: usize,
    /// Null cases (no effect); default: as many as --cases.
    #[arg(long)]
    pub nulls: Option<usize>,
    /// Seed of the benchmark.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Effects to plant, comma separated (default: every bundled candidate of the family).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Synthetic tests: `dcb` (Hartlen's and the paper's DCB specimens, one case in two each; the
    /// arm modulus known, strength and toughness fitted) or `beam` (the paper's FRP-strengthened beam).
    #[arg(long, default_value = "dcb")]
    pub family: String,
    /// Model that makes the synthetic tests: `beam` (the diagnosed model itself) or `continuum`
    /// (the continuum DCB: a different model of the same test; DCB family only).
    #[arg(long, default_value = "beam")]
    pub truth: String,
    /// Output folder (bench.json, bench.md, and each finished case in cases/).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite results already in the output folder (every case is run again).
    #[arg(long, conflicts_with = "resume")]
    pub force: bool,
    /// Continue an interrupted run in the same folder: cases already finished are reused.
    #[arg(long)]
    pub resume: bool,
}

/// Runs the benchmark and writes `bench.json` and `bench.md`; on several MPI ranks, the cases
/// are spread over them (rank 0 writes everything).
pub fn run(args: &GapBenchArgs, cluster: &Cluster) -> Result<(), CzError> {
    let opts = BenchOptions {
        cases: args.cases,
        nulls: args.nulls.unwrap_or(args.cases),
        seed: args.seed,
        effects: args.effects.clone(),
        family: args.family.parse::<Family>()?,
        truth: args.truth.parse()?,
    };
    if cluster.is_worker() {
        let plan = bench::Plan::new(&opts)?;
        return cluster.serve_tasks(&|i| plan.run_case_json(i).into_bytes());
    }
    let farm = cluster.task_farm();
    let dir = OutputDir::create(&args.out, args.force, args.resume)?;
    let store = CaseStore { dir: OutputDir::create(&dir.file("cases"), true, true)?, reuse: args.resume };
    let bar = indicatif::ProgressBar::new(0);
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} cases  eta {eta}")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    let report = bench::run(&opts, Some(&store), farm.as_deref(), &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })?;
    bar.finish();
    let json = serde_json::to_string_pretty(&report).map_err(|e| CzError::config("bench.json", e.to_string()))?;
    dir.write("bench.json", &json)?;
    let md = bench::markdown(&report, &opts);
    dir.write("bench.md", &md)?;
    println!("{md}");
    println!("bench.json and bench.md in {}", dir.path().display());
    Ok(())
}
