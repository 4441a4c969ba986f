//! The `czid` command: simulate, identify and compare on problem files; the bundled demo.

mod cluster;
mod commands;

use cluster::Cluster;

use clap::{Args, Parser, Subcommand};
use czid_core::CzError;
use czid_problems::compare::{compare, CompareOptions};
use czid_problems::identify::{identify, simulate, RunOptions};
use czid_problems::output::OutputDir;
use czid_problems::problem_file::LoadedProblem;
use czid_problems::synthetic::TruthFile;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// Identify cohesive-zone interface laws from laboratory tests (units: N, mm, MPa).
#[derive(Parser)]
#[command(name = "czid", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the bundled paper-DCB identification end to end and say where the results are.
    Demo {
        /// Output folder (overwritten).
        #[arg(long, default_value = "out/demo")]
        out: PathBuf,
    },
    /// Run the forward models at the problem file's initial values.
    Simulate {
        /// Problem file (TOML).
        problem: PathBuf,
        #[command(flatten)]
        out: OutArgs,
        #[command(flatten)]
        set: SetArgs,
    },
    /// Identify the problem file's parameters.
    Identify {
        /// Problem file (TOML).
        problem: PathBuf,
        #[command(flatten)]
        out: OutArgs,
        #[command(flatten)]
        set: SetArgs,
        /// Optimizer instead of the file's (e.g. miga, ga, nsga2, nelder-mead, lbfgs, levenberg-marquardt, hybrid).
        #[arg(long)]
        optimizer: Option<String>,
        /// Random seed instead of the file's.
        #[arg(long)]
        seed: Option<u64>,
        /// Evaluation budget instead of the file's.
        #[arg(long)]
        budget: Option<usize>,
        /// Continue an interrupted run from the checkpoint in the output folder.
        #[arg(long)]
        resume: bool,
        /// Leave these experiments out (comma separated names), to predict them afterwards with
        /// `czid predict`.
        #[arg(long, value_delimiter = ',')]
        leave_out: Vec<String>,
        /// Abort the process once this many evaluations are done, as a kill would (for tests of
        /// interruption and resume).
        #[arg(long, hide = true)]
        abort_after_evaluations: Option<usize>,
    },
    /// Profile an identification: how far each parameter can move, the others refitted, before
    /// the data reject the fit (95 % intervals beside the linearised ones; profile.json, .csv
    /// and a plot per parameter).
    Profile {
        /// Problem file (TOML).
        problem: PathBuf,
        /// The identification's result.json (from `czid identify`).
        #[arg(long)]
        from: PathBuf,
        /// Parameters to profile (comma-separated paths; default: all).
        #[arg(long, value_delimiter = ',')]
        parameters: Vec<String>,
        /// Steps allowed on each side of the fit before a side is left open.
        #[arg(long, default_value_t = 12)]
        max_steps: usize,
        /// Finite-difference step of the refits, as a share of each parameter's range (larger
        /// steps average over an objective that is rough at small scales).
        #[arg(long, default_value_t = 1e-3)]
        fd_step: f64,
        #[command(flatten)]
        out: OutArgs,
        #[command(flatten)]
        set: SetArgs,
    },
    /// Run every experiment of a problem file at the values a calibration identified and report
    /// how far each test lies from its prediction (prediction.json, fits and plots).
    Predict {
        /// Problem file (TOML).
        problem: PathBuf,
        /// The calibration's result.json (from `czid identify`, e.g. with `--leave-out`).
        #[arg(long)]
        from: PathBuf,
        #[command(flatten)]
        out: OutArgs,
        #[command(flatten)]
        set: SetArgs,
    },
    /// Make a synthetic test (CSV) from a truth file: a law, a model and a noise description.
    Synthesize {
        /// Truth file (TOML with [law], [model], [noise] and optional [[event]]s, printed as
        /// problem-file event tables).
        truth: PathBuf,
        /// CSV file to write (columns displacement_mm, load_N, debonded_length_mm).
        #[arg(long)]
        out: PathBuf,
        /// Overwrite an existing file.
        #[arg(long)]
        force: bool,
    },
    /// Diagnose the sim-to-real gap: where the fitted model misses, which unmodelled effect most
    /// likely causes it, how far the misfit shrinks with it (gap.json, report.md, plots).
    Diagnose(commands::diagnose::DiagnoseArgs),
    /// Check the diagnosis on planted-effect synthetic cases (confusion matrix, accuracy, false alarms).
    GapBench(commands::gap_bench::GapBenchArgs),
    /// Benchmark optimizers on standard test functions (optimizers × problems × seeds).
    Harness(commands::harness::HarnessArgs),
    /// Compare optimizers over several seeds at equal budgets.
    Compare {
        /// Problem file (TOML).
        problem: PathBuf,
        /// Optimizers, comma separated (e.g. miga,nsga2,nelder-mead,hybrid).
        #[arg(long, value_delimiter = ',', required = true)]
        optimizers: Vec<String>,
        /// Number of seeds per optimizer.
        #[arg(long, default_value_t = 10)]
        seeds: u64,
        /// Evaluation budget per run instead of the file's.
        #[arg(long)]
        budget: Option<usize>,
        /// Objective value that counts as success.
        #[arg(long, default_value_t = 1e-3)]
        target: f64,
        /// Continue an interrupted comparison in the output folder: its finished runs are kept,
        /// the one it was in continues from its checkpoint.
        #[arg(long)]
        resume: bool,
        /// Abort the process once the runs have done this many evaluations, as a kill would (for
        /// tests of interruption and resume).
        #[arg(long, hide = true)]
        abort_after_evaluations: Option<usize>,
        #[command(flatten)]
        out: OutArgs,
        #[command(flatten)]
        set: SetArgs,
    },
}

#[derive(Args)]
struct SetArgs {
    /// Replace a value of the problem file, e.g. `--set law.strength_n=20` or
    /// `--set models.dcb.effects.large_rotation=true` (`model.…` in a file with one top-level
    /// [model]; repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE", value_parser = parse_set)]
    sets: Vec<(String, String)>,
}

fn parse_set(s: &str) -> Result<(String, String), String> {
    s.split_once('=')
        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
        .ok_or_else(|| format!("`{s}` should look like PATH=VALUE"))
}

#[derive(Args)]
struct OutArgs {
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Overwrite results already in the output folder.
    #[arg(long)]
    force: bool,
}

/// A rank other than 0: builds the same problem as rank 0 (only rank 0 writes anything) and
/// evaluates what it sends; a failure ends every rank.
fn serve(cluster: &Cluster, problem: &Path, sets: &[(String, String)], leave_out: &[String]) -> ExitCode {
    let problem = LoadedProblem::read_with(problem, sets).and_then(|mut p| p.leave_out(leave_out).map(|()| p));
    match problem.and_then(|p| p.identification()).and_then(|id| cluster.serve(&id)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => cluster.abort(&e),
    }
}

fn fail(e: &CzError) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::FAILURE
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Demo { out } => demo(&out),
        Command::Simulate { problem, out, set } => run_simulate(&problem, &set.sets, &out),
        Command::Predict { problem, from, out, set } => run_predict(&problem, &from, &set.sets, &out),
        Command::Profile { problem, from, parameters, max_steps, fd_step, out, set } => {
            run_profile(&problem, &from, &parameters, max_steps, fd_step, &set.sets, &out)
        }
        Command::Identify {
            problem,
            out,
            set,
            optimizer,
            seed,
            budget,
            resume,
            leave_out,
            abort_after_evaluations,
        } => {
            let cluster = Cluster::join();
            if cluster.is_worker() {
                return serve(&cluster, &problem, &set.sets, &leave_out);
            }
            let opts = RunOptions {
                optimizer,
                seed,
                budget,
                progress: true,
                resume,
                stop: Some(interrupt_flag()),
                abort_after: abort_after_evaluations,
                spread: cluster.spread(),
            };
            let outcome = run_identify(&problem, &set.sets, &leave_out, &out, &opts);
            cluster.finish("evaluations");
            outcome
        }
        Command::Harness(args) => commands::harness::run(&args),
        Command::Diagnose(args) => {
            let cluster = Cluster::join();
            let outcome = commands::diagnose::run(&args, &cluster);
            match outcome {
                // The other ranks may still be building the diagnosis, or waiting for refits.
                Err(e) if cluster.is_spread() => cluster.abort(&e),
                outcome => {
                    if !cluster.is_worker() {
                        cluster.finish("refits");
                    }
                    outcome
                }
            }
        }
        Command::GapBench(args) => {
            let cluster = Cluster::join();
            let outcome = commands::gap_bench::run(&args, &cluster);
            if !cluster.is_worker() {
                cluster.finish("cases");
            } else if let Err(e) = &outcome {
                cluster.abort(e);
            }
            outcome
        }
        Command::Synthesize { truth, out, force } => run_synthesize(&truth, &out, force),
        Command::Compare { problem, optimizers, seeds, budget, target, resume, abort_after_evaluations, out, set } => {
            let cluster = Cluster::join();
            if cluster.is_worker() {
                return serve(&cluster, &problem, &set.sets, &[]);
            }
            let opts = CompareOptions {
                optimizers,
                seeds,
                budget,
                target,
                spread: cluster.spread(),
                resume,
                abort_after: abort_after_evaluations,
                progress: true,
            };
            let outcome = run_compare(&problem, &set.sets, &out, &opts);
            cluster.finish("evaluations");
            outcome
        }
    };
    match outcome {
        Ok(()) => exit_after_signal(),
        Err(e) => fail(&e),
    }
}

/// Exit code of a run stopped by a signal: 128 + the signal's number (130 for SIGINT, 143 for
/// SIGTERM, what shells and schedulers expect), 0 while no signal came.
static SIGNAL_EXIT: std::sync::OnceLock<Arc<AtomicUsize>> = std::sync::OnceLock::new();

/// A flag raised by Ctrl-C (SIGINT) or a scheduler's SIGTERM: the optimizer stops after its
/// current iteration, leaving a checkpoint and a partial result, and the command exits with 130
/// or 143. A second signal ends the process at once (the checkpoint is already on disk).
fn interrupt_flag() -> Arc<AtomicBool> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let flag = Arc::new(AtomicBool::new(false));
    let code = SIGNAL_EXIT.get_or_init(|| Arc::new(AtomicUsize::new(0)));
    for (signal, exit) in [(SIGINT, 130), (SIGTERM, 143)] {
        // Without handlers (they could not be installed) a signal simply ends the process,
        // which loses only the work since the last checkpoint.
        let _ = signal_hook::flag::register_conditional_shutdown(signal, exit as i32, flag.clone());
        let _ = signal_hook::flag::register_usize(signal, code.clone(), exit);
        let _ = signal_hook::flag::register(signal, flag.clone());
    }
    flag
}

/// The exit code for a command that returned `Ok`: 130 or 143 when a signal stopped it.
fn exit_after_signal() -> ExitCode {
    match SIGNAL_EXIT.get().map_or(0, |c| c.load(Ordering::SeqCst)) {
        0 => ExitCode::SUCCESS,
        code => ExitCode::from(code as u8),
    }
}

/// Whether `path` is a model file (a top-level `[model]` table and no `[[experiment]]`).
fn is_model_file(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .is_some_and(|t| t.contains_key("model") && !t.contains_key("experiment"))
}

/// Reads a problem file and says what reading its data left out.
fn read_problem(problem: &Path, sets: &[(String, String)]) -> Result<LoadedProblem, CzError> {
    let problem = LoadedProblem::read_with(problem, sets)?;
    for note in problem.reading_notes() {
        eprintln!("note: {note}");
    }
    Ok(problem)
}

fn run_simulate(problem: &Path, sets: &[(String, String)], out: &OutArgs) -> Result<(), CzError> {
    if is_model_file(problem) {
        // A model file (`[law]` and `[model]`, no test data): the forward run alone.
        let file = TruthFile::read_with(problem, sets)?;
        let dir = OutputDir::create(&out.out, out.force, false)?;
        let record = czid_problems::identify::simulate_model(&file, &dir)?;
        println!("{} steps; curves and plot written to {}", record.rows(), dir.path().display());
        return Ok(());
    }
    let problem = read_problem(problem, sets)?;
    let dir = OutputDir::create(&out.out, out.force, false)?;
    let outcome = simulate(&problem, &dir)?;
    println!("curves and plots written to {}", dir.path().display());
    for w in czid_problems::identify::short_runs(&problem, &outcome) {
        println!("warning: {w}");
    }
    if outcome.failures.is_empty() {
        Ok(())
    } else {
        // The curves computed so far are written; the run itself did not finish.
        Err(CzError::Simulation(format!(
            "stopped early (curves hold the converged steps): {}",
            outcome.failures.join("; ")
        )))
    }
}

fn run_identify(
    problem: &Path,
    sets: &[(String, String)],
    leave_out: &[String],
    out: &OutArgs,
    opts: &RunOptions,
) -> Result<(), CzError> {
    let mut problem = read_problem(problem, sets)?;
    problem.leave_out(leave_out)?;
    let dir = OutputDir::create(&out.out, out.force, opts.resume)?;
    let res = identify(&problem, opts, &dir)?;
    if res.resumed > 0 {
        println!("resumed an interrupted run (resumed {} time(s); wall time counts every part)", res.resumed);
    }
    if res.partial {
        println!("interrupted: best so far in {}; continue with --resume", dir.file("result.partial.json").display());
    }
    let repeated = match (res.repeated_evaluations, res.shared_evaluations) {
        (0, 0) => String::new(),
        (n, 0) => format!(" ({n} of them points evaluated before, not run again)"),
        (0, m) => format!(" ({m} of them answered from points whose runs are the same)"),
        (n, m) => format!(
            " ({n} of them points evaluated before and {m} points whose runs are the same as another's, not run)"
        ),
    };
    println!(
        "objective f = {:.4e} after {} evaluations{repeated} in {:.1} s",
        res.objective, res.evaluations, res.wall_seconds
    );
    for (path, p) in &res.parameters {
        println!("  {path:<28} = {:>12.6e} {:<8} {}", p.value, p.unit, p.verdict);
    }
    for (term, e) in &res.rms_error {
        println!(
            "  rms error {term:<18} = {:>10.4} {:<3} ({:.2} % of the test's peak)",
            e.value, e.unit, e.percent_of_peak
        );
    }
    for w in &res.warnings {
        println!("warning: {w}");
    }
    println!("results, fits and plots in {}", dir.path().display());
    Ok(())
}

fn run_predict(problem: &Path, from: &Path, sets: &[(String, String)], out: &OutArgs) -> Result<(), CzError> {
    let problem = read_problem(problem, sets)?;
    let calibration = czid_problems::predict::Calibration::read(&problem, from)?;
    let dir = OutputDir::create(&out.out, out.force, false)?;
    let p = czid_problems::predict::predict(&problem, &calibration, &dir)?;
    for (path, v) in &p.parameters {
        println!("  {path:<28} = {v:>12.6e}");
    }
    println!("  {:<24} {:>13}  {:>8}  role", "term", "rms error", "% peak");
    for t in &p.terms {
        let role = if t.calibrated { "calibrated" } else { "held out" };
        println!(
            "  {:<24} {:>9.4} {:<3}  {:>6.2} %  {role}",
            t.term, t.error.value, t.error.unit, t.error.percent_of_peak
        );
    }
    for f in &p.failures {
        println!("warning: a run failed part way: {f}");
    }
    println!("prediction, fits and plots in {}", dir.path().display());
    Ok(())
}

fn run_profile(
    problem: &Path,
    from: &Path,
    parameters: &[String],
    max_steps: usize,
    fd_step: f64,
    sets: &[(String, String)],
    out: &OutArgs,
) -> Result<(), CzError> {
    use czid_problems::profile::{parameter_indices, profile_fit, End, ProfileOptions};
    if max_steps == 0 {
        return Err(CzError::config("--max-steps", "must be at least 1"));
    }
    if !(fd_step > 0.0 && fd_step < 0.5) {
        return Err(CzError::config("--fd-step", format!("{fd_step} is not a share of a range between 0 and 0.5")));
    }
    let problem = read_problem(problem, sets)?;
    let calibration = czid_problems::predict::Calibration::read(&problem, from)?;
    let idx = parameter_indices(&problem, parameters)?;
    let dir = OutputDir::create(&out.out, out.force, false)?;
    let opts = ProfileOptions { max_steps, fd_step, ..Default::default() };
    let started = std::time::Instant::now();
    eprintln!(
        "profiling {} parameter(s) of {}: each takes some ten to twenty refits",
        idx.len(),
        problem.path.display()
    );
    let report = profile_fit(&problem, &calibration, &idx, &opts, &dir, |path, p| {
        eprintln!("profiled {path} ({} fits, {:.0} s so far)", p.points.len() - 1, started.elapsed().as_secs_f64());
    })?;
    let side = |e: End| match e {
        End::Crossed(v) => format!("{v:.6e}"),
        End::AtBound(v) => format!("{v:.6e} (bound)"),
        End::NotReached(v) => format!("beyond {v:.6e}"),
    };
    for (path, from, to) in &report.recentred {
        println!(
            "note: the profile of `{path}` found a better fit than the result's (f = {from:.6e} → {to:.6e}, refitted \
             with every parameter free): the identification stopped short of the minimum; the intervals below \
             are centred on the better fit (its values in profile.json, `centre`)"
        );
    }
    println!(
        "  {:<24} {:>13} {:>11}  {:>29}  {:>29}",
        "parameter", "value", "std error", "linearised 95 % interval", "profile 95 % interval"
    );
    for p in &report.profiles {
        let se = p.profile.standard_error.map_or("-".to_string(), |s| format!("{s:.3e}"));
        let lin = p.linearised.map_or("-".to_string(), |[a, b]| format!("[{a:.6e}, {b:.6e}]"));
        println!(
            "  {:<24} {:>13.6e} {:>11}  {:>29}  [{}, {}]",
            p.path,
            p.profile.best,
            se,
            lin,
            side(p.profile.lower),
            side(p.profile.upper)
        );
        if let Some(b) = &p.profile.better {
            println!(
                "warning: profiling `{}` found a better fit still (f = {:.6e} against {:.6e}) at {} = {:.6e}: the \
                 intervals are not centred on a minimum; identify again from there",
                p.path, b.objective, p.profile.best_objective, p.path, b.value
            );
        }
        for (v, why) in &p.profile.failures {
            println!("note: `{}`: the refit at {v:.6e} failed, so its side ends before it: {why}", p.path);
        }
        for note in &p.notes {
            println!("note: `{}`: {note}", p.path);
        }
        for (name, e) in [("lower", p.profile.lower), ("upper", p.profile.upper)] {
            match e {
                End::AtBound(_) => {
                    println!("note: `{}` is not bounded by the data on its {name} side within its bounds", p.path)
                }
                // A side that a failed refit ended is said above.
                End::NotReached(_)
                    if p.profile.failures.iter().any(|(v, _)| (*v < p.profile.best) == (name == "lower")) => {}
                End::NotReached(_) => println!(
                    "note: the {name} side of `{}` was not reached in {max_steps} steps (raise --max-steps)",
                    p.path
                ),
                End::Crossed(_) => {}
            }
        }
    }
    println!("profiles and plots in {}", dir.path().display());
    Ok(())
}

fn run_synthesize(truth: &Path, out: &Path, force: bool) -> Result<(), CzError> {
    if out.exists() && !force {
        return Err(CzError::Io {
            path: out.display().to_string(),
            message: "exists; pass --force to overwrite".into(),
        });
    }
    let (data, events) = TruthFile::read(truth)?.generate_with_events()?;
    czid_problems::output::write_atomic(out, data.to_csv().as_bytes())?;
    println!("{} synthetic readings written to {}", data.displacement.len(), out.display());
    for e in &events {
        // The reading as a problem file's event table (paste it under the experiment).
        let mut table = toml::to_string(&e.spec).map_err(|err| CzError::config("synthesize", err.to_string()))?;
        table = table.lines().filter(|l| !l.starts_with("load_unit")).collect::<Vec<_>>().join("\n");
        println!("# model value {:.3} {}\n[[experiment.event]]\n{table}\n", e.truth, e.spec.unit);
    }
    Ok(())
}

fn run_compare(problem: &Path, sets: &[(String, String)], out: &OutArgs, opts: &CompareOptions) -> Result<(), CzError> {
    let problem = read_problem(problem, sets)?;
    let dir = OutputDir::create(&out.out, out.force, opts.resume)?;
    let comparison = compare(&problem, opts, &dir)?;
    let runs = &comparison.runs;
    println!("{:<20} {:>6} {:>12} {:>12} {:>10}", "optimizer", "runs", "median f", "success", "median s");
    for name in &opts.optimizers {
        let mine: Vec<_> = runs.iter().filter(|r| &r.optimizer == name).collect();
        let mut f: Vec<f64> = mine.iter().map(|r| r.best).collect();
        let mut t: Vec<f64> = mine.iter().map(|r| r.wall_seconds).collect();
        f.sort_by(f64::total_cmp);
        t.sort_by(f64::total_cmp);
        let ok = mine.iter().filter(|r| r.evaluations_to_target.is_some()).count();
        println!(
            "{name:<20} {:>6} {:>12.4e} {:>9}/{:<2} {:>10.2}",
            mine.len(),
            f[f.len() / 2],
            ok,
            mine.len(),
            t[t.len() / 2]
        );
    }
    if let Err(why) = &comparison.equivalent {
        println!("no 95 % confidence region of the best fit ({why}): the column in_95_region is left empty");
    }
    if let Ok(e) = &comparison.equivalent {
        println!(
            "{} of {} runs end inside the 95 % confidence region of the best fit (f ≤ {:.4e}); their values span:",
            e.inside.len(),
            runs.len(),
            e.threshold
        );
        for (p, (lo, hi)) in problem.identification()?.space().parameters().iter().zip(&e.ranges) {
            println!("  {:<28} {lo:>12.5e} … {hi:<12.5e} {}", p.path, p.unit);
        }
    }
    println!("summary, convergence and plots in {}", dir.path().display());
    Ok(())
}

/// The demo's optimizer: `[optimizers.hybrid]` of the paper-DCB problem file (the paper's MIGA for a
/// global search, then a Levenberg–Marquardt polish), with a budget that recovers the normal
/// parameters from each of the paper's initial guesses and runs in well under a minute.
const DEMO_OPTIMIZER: &str = "hybrid";
const DEMO_BUDGET: usize = 2000;

/// The demo's inputs, built into the binary so that `czid demo` runs wherever the binary is (an
/// installed one has no source tree): the paper-DCB problem file, its synthetic data and how the
/// data were made.
const DEMO_INPUTS: [(&str, &str); 3] = [
    ("problem.toml", include_str!("../examples/paper-dcb/problem.toml")),
    ("synthetic.csv", include_str!("../examples/paper-dcb/synthetic.csv")),
    ("truth.toml", include_str!("../examples/paper-dcb/truth.toml")),
];

/// Writes the demo's inputs into `<out>/inputs` and returns the problem file's path.
fn write_demo_inputs(out: &Path) -> Result<PathBuf, CzError> {
    let dir = out.join("inputs");
    let io = |e: std::io::Error| CzError::Io { path: dir.display().to_string(), message: e.to_string() };
    std::fs::create_dir_all(&dir).map_err(io)?;
    for (name, text) in DEMO_INPUTS {
        czid_problems::output::write_atomic(&dir.join(name), text.as_bytes())?;
    }
    Ok(dir.join("problem.toml"))
}

fn demo(out: &Path) -> Result<(), CzError> {
    let problem = write_demo_inputs(out)?;
    println!("czid demo: the paper-DCB study (Shi & Zhang), identifying the six ST-CZM parameters");
    println!("  problem: {}", problem.display());
    println!(
        "  data:    {} (synthetic: Table 3 parameters + stated noise, see truth.toml)",
        problem.with_file_name("synthetic.csv").display()
    );
    run_identify(
        &problem,
        &[],
        &[],
        &OutArgs { out: out.to_path_buf(), force: true },
        &RunOptions {
            optimizer: Some(DEMO_OPTIMIZER.into()),
            budget: Some(DEMO_BUDGET),
            progress: true,
            stop: Some(interrupt_flag()),
            ..RunOptions::default()
        },
    )?;
    println!("truth (Table 3): law.strength_n = 27 MPa, law.u_e_n = 2.7e-4 mm, law.u_c_n = 3.273e-3 mm");
    println!("open {} for the fits (fit-load.png, fit-debonded.png) and convergence.png", out.display());
    Ok(())
}
