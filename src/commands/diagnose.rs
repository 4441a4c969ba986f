//! `czid diagnose`: where a fitted model misses the test, which unmodelled effect most likely
//! causes it, and how far the misfit shrinks once it is added.
//!
//! ```text
//! czid diagnose examples/hartlen-dcb/dcb01.toml --out out/gap-dcb01 \
//!     --withheld examples/hartlen-dcb/dcb02.toml,examples/hartlen-dcb/dcb03.toml
//! czid diagnose PROBLEM --out DIR --from out/fit/result.json --candidates fibre_bridging,large_rotation
//! mpiexec -n 4 czid diagnose examples/hartlen-dcb/dcb01.toml --out out/gap-dcb01
//! ```
//!
//! On several MPI ranks every rank builds the same diagnosis up to the refits, which rank 0 then
//! hands out to whichever rank is free; rank 0 writes everything.

use crate::cluster::Cluster;
use czid_core::CzError;
use czid_problems::diagnose::{self, Library, NoiseLevels, Options};
use czid_problems::output::OutputDir;
use czid_problems::problem_file::LoadedProblem;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `czid diagnose`.
#[derive(Debug, Clone, clap::Args)]
pub struct DiagnoseArgs {
    /// Problem file (TOML).
    pub problem: PathBuf,
    /// Output folder (gap.json, report.md, plots).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite results already in the output folder.
    #[arg(long)]
    pub force: bool,
    /// Start from the parameters of an `identify` result (result.json) instead of fitting with the
    /// problem file's optimizer.
    #[arg(long, value_name = "RESULT_JSON")]
    pub from: Option<PathBuf>,
    /// Candidate effects to score, comma separated (default: every one that applies).
    #[arg(long, value_delimiter = ',')]
    pub candidates: Vec<String>,
    /// At most how many significant candidates to refit (best score first; default: every
    /// significant one); the cause is decided on the refits.
    #[arg(long)]
    pub refit: Option<usize>,
    /// Judge the candidates against the noise alone, without accounting for the misfit the base
    /// model's form leaves (estimated with its reference model, e.g. the continuum DCB).
    #[arg(long)]
    pub no_model_form: bool,
    /// Other problem files (e.g. other specimens) predicted with the calibrated parameters, with
    /// and without the effect, comma separated.
    #[arg(long, value_delimiter = ',')]
    pub withheld: Vec<PathBuf>,
    /// Skip the transfer check on the held-out late stage of each curve.
    #[arg(long)]
    pub no_holdout: bool,
    /// Load noise standard deviation (N) instead of the estimate from the data.
    #[arg(long)]
    pub noise_load: Option<f64>,
    /// Debonded-length noise standard deviation (mm) instead of the estimate from the data.
    #[arg(long)]
    pub noise_length: Option<f64>,
    /// Replace a value of the problem file (repeatable), as for `identify`.
    #[arg(long = "set", value_name = "PATH=VALUE", value_parser = crate::parse_set)]
    pub sets: Vec<(String, String)>,
}

/// Reads the fitted values of `result.json` in the order of the problem's parameters.
fn read_start(path: &Path, problem: &LoadedProblem) -> Result<Vec<f64>, CzError> {
    let shown = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|e| CzError::Io { path: shown.clone(), message: e.to_string() })?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| CzError::config(&shown, format!("{e} (expected the result.json written by `czid identify`)")))?;
    problem
        .file
        .parameter
        .iter()
        .map(|p| {
            v["parameters"][&p.path]["value"].as_f64().ok_or_else(|| {
                CzError::config(&shown, format!("has no value for parameter `{}` of the problem file", p.path))
            })
        })
        .collect()
}

/// Runs the diagnosis and writes its outputs (on rank 0; the other ranks run refits for it).
pub fn run(args: &DiagnoseArgs, cluster: &Cluster) -> Result<(), CzError> {
    let problem = LoadedProblem::read_with(&args.problem, &args.sets)?;
    if !cluster.is_worker() {
        for note in problem.reading_notes() {
            eprintln!("note: {note}");
        }
    }
    let library = Library::builtin();
    // Unknown candidate names are reported before any work.
    library.select(&problem.setup()?, &args.candidates)?;
    let withheld = args.withheld.iter().map(|p| LoadedProblem::read(p)).collect::<Result<Vec<_>, _>>()?;
    let start = args.from.as_ref().map(|p| read_start(p, &problem)).transpose()?;
    let mut opts = Options {
        candidates: args.candidates.clone(),
        start,
        refit: args.refit.unwrap_or(usize::MAX),
        noise: NoiseLevels { load: args.noise_load, length: args.noise_length },
        withheld,
        holdout: !args.no_holdout,
        always_refit: Vec::new(),
        model_form: !args.no_model_form,
        progress: None,
        farm: cluster.task_farm(),
    };
    if cluster.is_worker() {
        // The same diagnosis as rank 0 up to the refits, then the refits rank 0 hands out.
        return match diagnose::diagnose(&problem, &library, &opts) {
            Err(_) if cluster.served() => Ok(()),
            outcome => outcome.map(|_| ()),
        };
    }
    let dir = OutputDir::create(&args.out, args.force, false)?;
    let clock = Instant::now();
    opts.progress = Some(Box::new(move |m: &str| eprintln!("[{:6.1} s] {m}", clock.elapsed().as_secs_f64())));
    let d = diagnose::diagnose(&problem, &library, &opts)?;
    diagnose::report::write(&d, &dir)?;
    println!("{}", d.verdict);
    println!();
    println!("{:<22} {:>10} {:>9} {:>10} {:>10}", "candidate", "score", "explained", "refit", "transfer");
    for c in &d.candidates {
        let (score, explained) = c.score.as_ref().map_or(("–".into(), "–".into()), |s| {
            (
                format!("{:.1}{}", s.statistic, if s.significant { "*" } else { "" }),
                format!("{:.0}%", 100.0 * s.explained),
            )
        });
        let refit = c.refit.as_ref().map_or("".into(), |r| format!("{:.0}%", 100.0 * r.shrinkage));
        let transfer: Vec<String> =
            c.transfer.iter().map(|t| t.shrinkage.map_or("n/a".into(), |s| format!("{:.0}%", 100.0 * s))).collect();
        println!("{:<22} {:>10} {:>9} {:>10} {:>10}", c.name, score, explained, refit, transfer.join(" "));
    }
    println!(
        "(* significant)  diagnosis in {:.1} s; gap.json, report.md and plots in {}",
        d.wall_seconds,
        dir.path().display()
    );
    Ok(())
}
