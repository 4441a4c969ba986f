//! The `czid` command as a user runs it: bundled problem files load, results land where promised,
//! and bad input gives a clear message and a non-zero exit code without clobbering anything.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn czid(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_czid")).args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("czid-cli-{}-{name}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    dir
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn toml_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            toml_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "toml") {
            out.push(path);
        }
    }
}

/// Every bundled example file reads: problem files (`[[experiment]]`) with their data, and model
/// files (`[law]` and `[model]`, what `czid simulate` and `czid synthesize` run) with their
/// checks. A key renamed or a data file moved then fails here, not in a user's first command.
#[test]
fn every_bundled_example_file_reads() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut files = Vec::new();
    toml_files(&root, &mut files);
    files.sort();
    // The problem and model files of the README's table and the book (28 when this was written).
    assert!(files.len() >= 28, "only {} example files found under {}", files.len(), root.display());
    let mut failures = Vec::new();
    for path in &files {
        let table: toml::Table = std::fs::read_to_string(path).unwrap().parse().unwrap();
        // As `czid simulate` tells them apart.
        let read = if table.contains_key("model") && !table.contains_key("experiment") {
            czid_problems::synthetic::TruthFile::read(path).map(|_| ())
        } else {
            czid_problems::problem_file::LoadedProblem::read(path).map(|p| assert!(!p.experiments.is_empty()))
        };
        if let Err(e) = read {
            failures.push(format!("{}: {e}", path.display()));
        }
    }
    assert!(failures.is_empty(), "example files that do not read:\n{}", failures.join("\n"));
}

#[test]
fn identify_writes_results_and_refuses_to_clobber_them() {
    let out = scratch("identify");
    let o = out.to_str().unwrap();
    let coarse = ["--set", "models.dcb.mesh.interface_element=0.5", "--set", "models.dcb.control.max_displacement=4.0"];
    let mut args =
        vec!["identify", "examples/paper-dcb/problem.toml", "--out", o, "--optimizer", "nelder-mead", "--budget", "12"];
    args.extend(coarse);
    let first = czid(&args);
    assert!(first.status.success(), "{}", stderr(&first));
    let result: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("result.json")).unwrap()).unwrap();
    assert_eq!(result["evaluations"].as_u64().unwrap(), 12);
    assert_eq!(result["parameters"]["law.strength_n"]["unit"], "MPa");
    // The symmetric DCB never slips: its shear parameters must not be reported as identified.
    assert_eq!(result["parameters"]["law.strength_t"]["verdict"], "not determined by these data");
    let before = std::fs::read(out.join("result.json")).unwrap();

    let again = czid(&args);
    assert!(!again.status.success());
    assert!(stderr(&again).contains("--force"), "{}", stderr(&again));
    assert_eq!(std::fs::read(out.join("result.json")).unwrap(), before, "an existing result was modified");
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn bad_input_fails_with_a_message_naming_it() {
    let out = scratch("bad");
    let o = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["identify", "no/such/problem.toml", "--out", o], "no/such/problem.toml"),
        (
            vec!["identify", "examples/paper-dcb/problem.toml", "--out", o, "--optimizer", "simplexx"],
            "unknown optimizer `simplexx`",
        ),
        (vec!["simulate", "examples/paper-dcb/problem.toml", "--out", o, "--set", "models.dcb.h=-1"], "`h`"),
        (vec!["simulate", "examples/paper-dcb/problem.toml", "--out", o, "--set", "law.u_c_n=0.0001"], "u_c_n"),
        (
            vec!["identify", "examples/paper-dcb/problem.toml", "--out", o, "--set", "law.strength_n=100"],
            "within its bounds",
        ),
        // A hybrid whose global phase cannot run on its share of the budget says so, in identify and
        // in compare (before any run).
        (
            vec!["identify", "examples/paper-dcb/problem.toml", "--out", o, "--optimizer", "hybrid", "--budget", "100"],
            "its global phase (miga) gets 80 of the budget's 100 evaluations",
        ),
        (
            vec![
                "compare",
                "examples/paper-dcb/problem.toml",
                "--out",
                o,
                "--optimizers",
                "lm,hybrid",
                "--budget",
                "100",
            ],
            "its global phase (miga) gets 80",
        ),
        // Meshes that cannot resolve the law, or would take gigabytes, are refused before a run.
        (
            vec![
                "simulate",
                "examples/hartlen-dcb/dcb01.toml",
                "--out",
                o,
                "--set",
                "models.dcb01.mesh.interface_element=1000",
            ],
            "longer than the law's cohesive zone (about 4.287 mm",
        ),
        (
            vec![
                "simulate",
                "examples/hartlen-dcb/dcb01.toml",
                "--out",
                o,
                "--set",
                "models.dcb01.mesh.interface_element=1e-5",
            ],
            "far finer than any cohesive zone needs",
        ),
    ];
    for (args, expect) in cases {
        let r = czid(&args);
        assert!(!r.status.success(), "{args:?} should fail");
        assert!(stderr(&r).contains(expect), "{args:?}: `{}` should mention `{expect}`", stderr(&r));
        assert!(!stderr(&r).contains(" seed   1: f ="), "{args:?} ran before failing");
        std::fs::remove_dir_all(&out).ok();
    }
}

#[test]
fn the_demo_runs_from_an_empty_folder_with_its_inputs_built_in() {
    // A copy of the binary in an empty folder, run there: nothing may come from the source tree.
    let dir = scratch("demo");
    std::fs::create_dir_all(&dir).unwrap();
    let bin = dir.join("czid");
    std::fs::copy(env!("CARGO_BIN_EXE_czid"), &bin).unwrap();
    let o = Command::new(&bin).args(["demo", "--out", "out"]).current_dir(&dir).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    for file in ["inputs/problem.toml", "inputs/synthetic.csv", "inputs/truth.toml", "result.json", "fit-load.png"] {
        assert!(dir.join("out").join(file).exists(), "{file} missing");
    }
    let result = std::fs::read_to_string(dir.join("out/result.json")).unwrap();
    assert!(result.contains("inputs/problem.toml"), "the demo must read its own copy of the inputs");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sigint_and_sigterm_leave_a_partial_result_and_exit_130_and_143() {
    for (signal, code) in [("-INT", 130), ("-TERM", 143)] {
        let out = scratch(&format!("signal{signal}"));
        let child = Command::new(env!("CARGO_BIN_EXE_czid"))
            .args(["identify", "examples/paper-dcb/problem.toml", "--out", out.to_str().unwrap()])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Signal once the run is under way (its first checkpoint is written), as a user or a
        // scheduler would.
        for _ in 0..600 {
            if out.join("checkpoint.json").exists() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(100));
        }
        let sent = Command::new("kill").args([signal, &child.id().to_string()]).status().unwrap();
        assert!(sent.success());
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(code), "{signal}: {}", stderr(&o));
        assert!(String::from_utf8_lossy(&o.stdout).contains("continue with --resume"), "{signal}");
        assert!(out.join("result.partial.json").exists(), "{signal}: no partial result");
        assert!(out.join("checkpoint.json").exists(), "{signal}: no checkpoint");
        std::fs::remove_dir_all(&out).ok();
    }
}

#[test]
fn without_a_terminal_identify_prints_progress_lines_for_the_log() {
    let out = scratch("progress-lines");
    let o = czid(&["identify", "examples/hartlen-dcb/dcb01.toml", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines: Vec<String> = stderr(&o).lines().filter(|l| l.starts_with("progress: ")).map(String::from).collect();
    // One line per tenth of the 120-evaluation budget, and a last one where the run ended (a
    // local method that converges stops short of its budget).
    assert!(lines.len() >= 5, "{lines:?}");
    let count = |l: &str| l["progress: ".len()..].split('/').next().unwrap().parse::<usize>().unwrap();
    let counts: Vec<usize> = lines.iter().map(|l| count(l)).collect();
    assert!(counts.windows(2).all(|w| w[0] < w[1]) && counts[counts.len() - 1] <= 120, "{lines:?}");
    // While the run goes on, each line says when the budget will be used up at its pace.
    assert!(lines[..lines.len() - 1].iter().all(|l| l.contains(", budget used up in about ")), "{lines:?}");
    let log = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let evaluations: usize = log.lines().last().unwrap().split(',').nth(1).unwrap().parse().unwrap();
    assert_eq!(counts[counts.len() - 1], evaluations, "{lines:?}");
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn a_model_that_stops_before_the_data_end_is_named() {
    let out = scratch("short");
    let o = out.to_str().unwrap();
    let args = [
        "simulate",
        "examples/hartlen-dcb/dcb01.toml",
        "--out",
        o,
        "--set",
        "models.dcb01.control.max_displacement=10",
    ];
    let r = czid(&args);
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert!(stdout.contains("stops at 10.0000 mm but its test runs to 30.8101 mm"), "{stdout}");
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn a_model_file_without_data_simulates_and_synthesizes_with_partial_noise() {
    let out = scratch("model-only");
    let o = out.to_str().unwrap();
    // The paper's truth file: [law], [model] and [noise], no test data.
    let r = czid(&["simulate", "examples/paper-dcb/truth.toml", "--out", o]);
    assert!(r.status.success(), "{}", stderr(&r));
    let curves = std::fs::read_to_string(out.join("curves.csv")).unwrap();
    assert!(curves.starts_with("displacement (mm),load (N)"), "{}", &curves[..80]);
    assert!(out.join("curves-load.png").exists());
    // A [noise] table giving only the load noise: the rest take their defaults.
    let truth =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/paper-dcb/truth.toml")).unwrap();
    let head = truth.split("[noise]").next().unwrap();
    let file = out.join("partial-noise.toml");
    std::fs::write(&file, format!("{head}[noise]\nload_sd = 0.02\n")).unwrap();
    let csv = out.join("synthetic.csv");
    let r = czid(&["synthesize", file.to_str().unwrap(), "--out", csv.to_str().unwrap()]);
    assert!(r.status.success(), "{}", stderr(&r));
    assert_eq!(std::fs::read_to_string(&csv).unwrap().lines().count(), 1 + 200);
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn a_test_driven_past_the_specimen_split_ends_there_without_bogus_rows() {
    let out = scratch("split");
    let o = out.to_str().unwrap();
    let args = [
        "simulate",
        "examples/hartlen-dcb/dcb01.toml",
        "--out",
        o,
        "--set",
        "models.dcb01.control.max_displacement=200",
    ];
    let r = czid(&args);
    assert!(r.status.success(), "{}", stderr(&r));
    let text = std::fs::read_to_string(out.join("curves.csv")).unwrap();
    let rows: Vec<Vec<f64>> =
        text.lines().skip(1).map(|l| l.split(',').map(|c| c.parse().unwrap()).collect()).collect();
    // Openings and loads stay positive; the run stops once the ligament ahead of the crack is
    // shorter than the cohesive zone (about 4.3 mm of the 123 mm specimen).
    assert!(rows.iter().all(|r| r[0] >= 0.0 && r[1] >= 0.0), "a row with a negative opening or load");
    let tip = rows.last().unwrap()[4];
    assert!(tip > 123.0 - 4.4 && tip < 123.0, "last crack tip {tip}");
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn a_held_out_specimen_is_predicted_at_the_values_calibrated_on_the_others() {
    let (cal, pred) = (scratch("loo-calibrate"), scratch("loo-predict"));
    let coarse = |name: &str| format!("models.{name}.mesh.interface_element=0.5");
    let sets: Vec<String> = ["dcb01", "dcb02", "dcb03"].iter().map(|n| coarse(n)).collect();
    let mut args = vec![
        "identify",
        "examples/hartlen-dcb/joint.toml",
        "--leave-out",
        "dcb03",
        "--optimizer",
        "nelder-mead",
        "--budget",
        "6",
        "--out",
        cal.to_str().unwrap(),
    ];
    for s in &sets[..2] {
        args.extend(["--set", s.as_str()]);
    }
    let r = czid(&args);
    assert!(r.status.success(), "{}", stderr(&r));
    let result: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cal.join("result.json")).unwrap()).unwrap();
    // The calibration saw two specimens; its errors are in N and mm, with % of each test's peak.
    let errors = result["rms_error"].as_object().unwrap();
    assert_eq!(errors.keys().cloned().collect::<Vec<_>>(), ["F:dcb01", "F:dcb02", "L:dcb01", "L:dcb02"]);
    assert_eq!(errors["F:dcb01"]["unit"], "N");
    assert!(errors["F:dcb01"]["percent_of_peak"].as_f64().unwrap() > 0.0);

    let from = cal.join("result.json");
    let mut args = vec!["predict", "examples/hartlen-dcb/joint.toml", "--from", from.to_str().unwrap()];
    args.extend(["--out", pred.to_str().unwrap()]);
    for s in &sets {
        args.extend(["--set", s.as_str()]);
    }
    let r = czid(&args);
    assert!(r.status.success(), "{}", stderr(&r));
    let p: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(pred.join("prediction.json")).unwrap()).unwrap();
    let role: Vec<(String, bool)> = p["terms"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| (t["term"].as_str().unwrap().to_string(), t["calibrated"].as_bool().unwrap()))
        .collect();
    assert!(role.contains(&("F:dcb01".into(), true)) && role.contains(&("F:dcb03".into(), false)), "{role:?}");
    assert!(pred.join("predict-dcb03-load.png").exists());
    // The calibrated values are the calibration's.
    let g = result["parameters"]["law.g_ic"]["value"].as_f64().unwrap();
    assert_eq!(p["parameters"]["law.g_ic"].as_f64().unwrap(), g);

    // Leaving out an unknown specimen, or all of them, says what is wrong.
    let r = czid(&["identify", "examples/hartlen-dcb/joint.toml", "--leave-out", "dcb09", "--out", "unused"]);
    assert!(!r.status.success() && stderr(&r).contains("no experiment is named `dcb09`"), "{}", stderr(&r));
    assert!(stderr(&r).contains("dcb01, dcb02, dcb03"), "{}", stderr(&r));
    let r =
        czid(&["identify", "examples/hartlen-dcb/joint.toml", "--leave-out", "dcb01,dcb02,dcb03", "--out", "unused"]);
    assert!(!r.status.success() && stderr(&r).contains("every experiment would be left out"), "{}", stderr(&r));
    // A result file without the problem's parameters is refused by name.
    let bogus = cal.join("bogus.json");
    std::fs::write(&bogus, r#"{"parameters": {}}"#).unwrap();
    let r = czid(&["predict", "examples/hartlen-dcb/joint.toml", "--from", bogus.to_str().unwrap(), "--out", "unused"]);
    assert!(
        !r.status.success() && stderr(&r).contains("holds no value for the parameter `law.strength_n`"),
        "{}",
        stderr(&r)
    );
    std::fs::remove_dir_all(&cal).ok();
    std::fs::remove_dir_all(&pred).ok();
    assert!(!Path::new("unused").exists());
}

#[test]
fn a_problem_with_events_plots_them_test_beside_model() {
    let out = scratch("events");
    let o = out.to_str().unwrap();
    let r = czid(&["simulate", "examples/frp-beam/identify.toml", "--out", o]);
    assert!(r.status.success(), "{}", stderr(&r));
    // The beam's two debonded lengths (mm); it has no load event, so no load-event figure.
    assert!(out.join("curves-events.png").exists());
    assert!(!out.join("curves-events-load.png").exists());
    // A problem without events draws none.
    let dcb = scratch("no-events");
    let r = czid(&["simulate", "examples/paper-dcb/truth.toml", "--out", dcb.to_str().unwrap()]);
    assert!(r.status.success(), "{}", stderr(&r));
    assert!(!dcb.join("curves-events.png").exists());
    std::fs::remove_dir_all(&out).ok();
    std::fs::remove_dir_all(&dcb).ok();
}

#[test]
fn a_fit_is_profiled_and_its_interval_brackets_it() {
    let (fit, prof) = (scratch("profile-fit"), scratch("profile"));
    let coarse = ["--set", "models.dcb01.mesh.interface_element=0.5"];
    let mut args = vec!["identify", "examples/hartlen-dcb/dcb01.toml", "--out", fit.to_str().unwrap()];
    args.extend(coarse);
    let r = czid(&args);
    assert!(r.status.success(), "{}", stderr(&r));
    // The strength's standard error is wide: the identification points to a profile.
    let said = String::from_utf8_lossy(&r.stdout);
    assert!(said.contains("`law.strength_n` is determined only to ± ") && said.contains("czid profile"), "{said}");
    assert!(!said.contains("`law.g_ic` is determined only to"), "{said}");
    let from = fit.join("result.json");
    let mut args = vec!["profile", "examples/hartlen-dcb/dcb01.toml", "--from", from.to_str().unwrap()];
    args.extend(["--parameters", "law.g_ic", "--out", prof.to_str().unwrap()]);
    args.extend(coarse);
    let r = czid(&args);
    assert!(r.status.success(), "{}", stderr(&r));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(prof.join("profile.json")).unwrap()).unwrap();
    let p = &report["profiles"][0];
    assert_eq!(p["path"], "law.g_ic");
    assert_eq!(p["unit"], "N/mm");
    let best = p["best"].as_f64().unwrap();
    let (lower, upper) = (&p["lower"], &p["upper"]);
    assert_eq!((lower["kind"].as_str(), upper["kind"].as_str()), (Some("crossed"), Some("crossed")), "{p}");
    assert!(lower["value"].as_f64().unwrap() < best && best < upper["value"].as_f64().unwrap(), "{p}");
    // Every profile point is a refit with G_Ic held: none lies below the fit by more than the
    // inner fits' tolerance, and the outermost ones stand above the fit.
    let (f0, th) = (p["best_objective"].as_f64().unwrap(), p["threshold"].as_f64().unwrap());
    let fs: Vec<f64> = p["points"].as_array().unwrap().iter().map(|q| q["objective"].as_f64().unwrap()).collect();
    assert!(fs.iter().all(|f| *f >= f0 - 0.05 * (th - f0)), "{fs:?}");
    assert!(fs[0] > f0 && fs[fs.len() - 1] > f0, "{fs:?}");
    assert!(p["linearised"].as_array().is_some_and(|v| v.len() == 2));
    assert!(prof.join("profile-law_g_ic.png").exists() && prof.join("profile.csv").exists());

    assert!(report["recentred"].as_array().unwrap().is_empty(), "{report}");
    // The same profile on one thread: the same file, byte for byte.
    let one = scratch("profile-one-thread");
    let mut args1 = args.clone();
    let at = args1.iter().position(|a| *a == prof.to_str().unwrap()).unwrap();
    args1[at] = one.to_str().unwrap();
    let r = Command::new(env!("CARGO_BIN_EXE_czid"))
        .args(&args1)
        .env("RAYON_NUM_THREADS", "1")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", stderr(&r));
    assert_eq!(std::fs::read(one.join("profile.json")).unwrap(), std::fs::read(prof.join("profile.json")).unwrap());
    std::fs::remove_dir_all(&one).ok();

    // A result that is not at the minimum (G_Ic moved by 2 %, about two standard errors): the
    // profile finds a better fit, moves there and centres the interval on it.
    let mut off: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&from).unwrap()).unwrap();
    let g = off["parameters"]["law.g_ic"]["value"].as_f64().unwrap();
    off["parameters"]["law.g_ic"]["value"] = serde_json::json!(1.02 * g);
    let off_path = fit.join("off.json");
    std::fs::write(&off_path, off.to_string()).unwrap();
    let prof2 = scratch("profile-off");
    let mut args = vec!["profile", "examples/hartlen-dcb/dcb01.toml", "--from", off_path.to_str().unwrap()];
    args.extend(["--parameters", "law.g_ic", "--out", prof2.to_str().unwrap()]);
    args.extend(coarse);
    let r = czid(&args);
    assert!(r.status.success(), "{}", stderr(&r));
    assert!(String::from_utf8_lossy(&r.stdout).contains("found a better fit than the result's"));
    let moved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(prof2.join("profile.json")).unwrap()).unwrap();
    assert!(!moved["recentred"].as_array().unwrap().is_empty(), "{moved}");
    let (lo, hi) = (lower["value"].as_f64().unwrap(), upper["value"].as_f64().unwrap());
    let centre = moved["centre"]["law.g_ic"].as_f64().unwrap();
    assert!(centre > lo && centre < hi, "centred on {centre}, the fit's interval {lo}–{hi}");
    assert!(moved["centre_objective"].as_f64().unwrap() <= f0 * (1.0 + 1e-3), "{moved}");
    std::fs::remove_dir_all(&prof2).ok();

    // An unknown parameter is named with the problem's parameters; no steps is refused.
    let r = czid(&[
        "profile",
        "examples/hartlen-dcb/dcb01.toml",
        "--from",
        from.to_str().unwrap(),
        "--parameters",
        "law.g_iic",
        "--out",
        "unused",
    ]);
    assert!(!r.status.success() && stderr(&r).contains("`law.g_iic` is not a parameter"), "{}", stderr(&r));
    assert!(stderr(&r).contains("law.strength_n, law.g_ic"), "{}", stderr(&r));
    let r = czid(&[
        "profile",
        "examples/hartlen-dcb/dcb01.toml",
        "--from",
        from.to_str().unwrap(),
        "--max-steps",
        "0",
        "--out",
        "unused",
    ]);
    assert!(!r.status.success() && stderr(&r).contains("--max-steps"), "{}", stderr(&r));
    std::fs::remove_dir_all(&fit).ok();
    std::fs::remove_dir_all(&prof).ok();
    assert!(!Path::new("unused").exists());
}
