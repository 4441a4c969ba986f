//! `czid gap-bench`: the diagnosis checked on planted-effect synthetic cases and null cases.
//!
//! ```text
//! czid gap-bench --cases 20 --nulls 20 --seed 1 --out out/gap-bench
//! ```

use czid_core::CzError;
use czid_problems::diagnose::bench::{self, BenchOptions};
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
    /// Effects to plant, comma separated (default: every bundled candidate).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Output folder (bench.json, bench.md).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite results already in the output folder.
    #[arg(long)]
    pub force: bool,
}

/// Runs the benchmark and writes `bench.json` and `bench.md`.
pub fn run(args: &GapBenchArgs) -> Result<(), CzError> {
    let opts = BenchOptions {
        cases: args.cases,
        nulls: args.nulls.unwrap_or(args.cases),
        seed: args.seed,
        effects: args.effects.clone(),
    };
    let dir = OutputDir::create(&args.out, args.force, false)?;
    let bar = indicatif::ProgressBar::new(0);
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} cases  eta {eta}")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    let report = bench::run(&opts, &|done, total| {
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
