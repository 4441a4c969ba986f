//! Interrupted identifications resume to the uninterrupted result, bit for bit, for every kind of
//! optimizer; the interruption is a deterministic abort after a number of evaluations (what a
//! `SIGKILL` leaves: no partial result, files as they were at that instant).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The paper's DCB: its runs are cheaper than DCB-01's across MIGA's samples of the bounds (about
/// 0.05 s against 0.2 s each). Six parameters; MIGA's default 10 islands × 10 make a first
/// generation of 100 evaluations and 90 in each later one (the elites are not evaluated again).
const PROBLEM: &str = "examples/paper-dcb/problem.toml";

fn czid(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_czid")).args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("czid-resume-{}-{name}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    dir
}

fn identify(out: &Path, optimizer: &str, budget: &str, extra: &[&str]) -> Output {
    identify_file(PROBLEM, out, optimizer, budget, extra)
}

fn identify_file(problem: &str, out: &Path, optimizer: &str, budget: &str, extra: &[&str]) -> Output {
    let mut args = vec!["identify", problem, "--optimizer", optimizer, "--budget", budget, "--out"];
    let out = out.to_str().unwrap();
    args.push(out);
    args.extend_from_slice(extra);
    czid(&args)
}

/// `result.json` without what depends on the clock or on the interruption itself.
fn result(dir: &Path) -> serde_json::Value {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("result.json")).unwrap()).unwrap();
    for k in ["wall_seconds", "forward_share", "resumed", "shared_evaluations"] {
        v.as_object_mut().unwrap().remove(k);
    }
    v
}

fn killed_then_resumed_equals_whole(optimizer: &str, budget: &str, abort_after: &str) {
    let whole = scratch(&format!("{optimizer}-whole"));
    assert!(identify(&whole, optimizer, budget, &[]).status.success());
    let cut = scratch(&format!("{optimizer}-cut-{abort_after}"));
    let killed = identify(&cut, optimizer, budget, &["--abort-after-evaluations", abort_after]);
    assert!(!killed.status.success(), "{optimizer}: the abort did not happen");
    assert!(!cut.join("result.json").exists());
    let resumed = identify(&cut, optimizer, budget, &["--resume"]);
    assert!(resumed.status.success(), "{optimizer}: {}", String::from_utf8_lossy(&resumed.stderr));
    assert!(String::from_utf8_lossy(&resumed.stdout).contains("resumed an interrupted run"));
    assert_eq!(result(&cut), result(&whole), "{optimizer} aborted after {abort_after} evaluations");
    assert_eq!(
        std::fs::read_to_string(cut.join("history.csv")).unwrap(),
        std::fs::read_to_string(whole.join("history.csv")).unwrap(),
        "{optimizer}: history"
    );
    for d in [whole, cut] {
        std::fs::remove_dir_all(d).ok();
    }
}

#[test]
fn every_kind_of_optimizer_resumes_after_a_kill_to_the_uninterrupted_result() {
    killed_then_resumed_equals_whole("levenberg-marquardt", "60", "30");
    killed_then_resumed_equals_whole("nelder-mead", "60", "30");
    killed_then_resumed_equals_whole("miga", "200", "100");
    // The file's hybrid (MIGA on 160 evaluations, that is its first generation of 100, then a
    // Levenberg–Marquardt polish until about 190): killed in either phase.
    killed_then_resumed_equals_whole("hybrid", "200", "100");
    killed_then_resumed_equals_whole("hybrid", "200", "150");
}

#[test]
fn a_resume_of_a_different_run_is_refused_and_changes_nothing() {
    let out = scratch("different");
    assert!(!identify(&out, "miga", "300", &["--abort-after-evaluations", "150"]).status.success());
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    // The same problem with a wider bound on the normal strength (the only `upper = 60.0`).
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let problem = root.join(PROBLEM);
    let wider = std::fs::read_to_string(&problem)
        .unwrap()
        .replace("upper = 60.0", "upper = 70.0")
        .replace("\"synthetic.csv\"", &format!("{:?}", problem.with_file_name("synthetic.csv").display().to_string()));
    let wider_file = out.with_extension("toml");
    std::fs::write(&wider_file, wider).unwrap();
    let o = identify_file(wider_file.to_str().unwrap(), &out, "miga", "300", &["--resume"]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success() && err.contains("parameters: law.strength_n in [10, 60]"), "{err}");
    std::fs::remove_file(wider_file).ok();
    for (extra, named) in
        [(vec!["--seed", "7"], "seed: 1 before, 7 now"), (vec!["--set", "law.strength_n=30"], "law and models")]
    {
        let mut args = vec!["--resume"];
        args.extend(extra.iter().copied());
        let o = identify(&out, "miga", "300", &args);
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(!o.status.success(), "{extra:?} was accepted");
        assert!(err.contains("not this run") && err.contains(named), "{extra:?}: {err}");
        assert_eq!(std::fs::read_to_string(out.join("history.csv")).unwrap(), history, "{extra:?} touched history.csv");
    }
    let o = identify(&out, "miga", "400", &["--resume"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("budget: 300 before, 400 now"));
    std::fs::remove_dir_all(out).ok();
}

#[test]
fn a_run_that_fails_to_start_leaves_no_files_in_the_way() {
    let out = scratch("no-start");
    let o = identify(&out, "no-such-method", "100", &[]);
    assert!(!o.status.success());
    // The corrected run starts without --force.
    let o = identify(&out, "nelder-mead", "30", &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_dir_all(out).ok();
}

/// A comparison's table without its wall-time column (the only column a resume changes).
fn without_wall_times(dir: &Path) -> String {
    let text = std::fs::read_to_string(dir.join("summary.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let wall = header.iter().position(|h| *h == "wall_seconds").unwrap();
    text.lines()
        .map(|l| l.split(',').enumerate().filter(|(i, _)| *i != wall).map(|(_, v)| v).collect::<Vec<_>>().join(","))
        .collect::<Vec<_>>()
        .join("\n")
}

fn compare(out: &Path, budget: &str, extra: &[&str]) -> Output {
    let mut args = vec!["compare", PROBLEM, "--optimizers", "miga,nelder-mead", "--seeds", "2", "--budget", budget];
    args.extend_from_slice(&["--out", out.to_str().unwrap()]);
    args.extend_from_slice(extra);
    czid(&args)
}

#[test]
fn an_interrupted_comparison_resumes_to_the_uninterrupted_one() {
    let whole = scratch("compare-whole");
    // Nothing to resume yet: said, and nothing run.
    let early = compare(&whole, "200", &["--resume"]);
    let err = String::from_utf8_lossy(&early.stderr).into_owned();
    assert!(!early.status.success() && err.contains("nothing to resume"), "{err}");
    assert!(!whole.join("summary.csv").exists());
    assert!(compare(&whole, "200", &[]).status.success());
    // Killed in MIGA's second seed: the first run is kept, the second continues from its
    // checkpoint, Nelder–Mead (one run for both seeds) runs. (How local methods replay their journal is checked on
    // identifications above.)
    let cut = scratch("compare-cut");
    let killed = compare(&cut, "200", &["--abort-after-evaluations", "300"]);
    assert!(!killed.status.success(), "the abort did not happen");
    assert!(cut.join("runs/miga-seed1/finished.json").exists());
    assert!(
        cut.join("runs/miga-seed2/checkpoint.json").exists() && !cut.join("runs/miga-seed2/finished.json").exists()
    );
    let rows = std::fs::read_to_string(cut.join("summary.csv")).unwrap().lines().count();
    assert_eq!(rows, 2, "the table holds the header and the finished run");
    let resumed = compare(&cut, "200", &["--resume"]);
    let err = String::from_utf8_lossy(&resumed.stderr).into_owned();
    assert!(resumed.status.success(), "{err}");
    assert_eq!(err.matches("(finished before the resume)").count(), 1, "{err}");
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cut.join("runs/miga-seed2/run.json")).unwrap()).unwrap();
    assert_eq!(run["resumed"], 1, "the interrupted run continued from its checkpoint");
    assert_eq!(without_wall_times(&cut), without_wall_times(&whole));
    assert_eq!(
        std::fs::read_to_string(cut.join("convergence.csv")).unwrap(),
        std::fs::read_to_string(whole.join("convergence.csv")).unwrap()
    );
    // Another budget is another comparison: refused, not mixed in.
    let other = compare(&cut, "300", &["--resume"]);
    let err = String::from_utf8_lossy(&other.stderr).into_owned();
    assert!(!other.status.success() && err.contains("budget: 200 before, 300 now"), "{err}");
    std::fs::remove_dir_all(cut).ok();
    std::fs::remove_dir_all(whole).ok();
}
