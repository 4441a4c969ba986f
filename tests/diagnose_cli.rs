//! `czid diagnose` and `czid gap-bench` from the command line: clear errors on bad input, and a
//! small diagnosis end to end.

use std::path::PathBuf;
use std::process::{Command, Output};

fn czid(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_czid")).args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A path `name` that does not exist yet, inside a scratch folder removed when the test ends.
struct Scratch {
    _folder: tempfile::TempDir,
    path: PathBuf,
}

impl std::ops::Deref for Scratch {
    type Target = PathBuf;
    fn deref(&self) -> &PathBuf {
        &self.path
    }
}

fn scratch(name: &str) -> Scratch {
    let folder = tempfile::Builder::new().prefix("czid-diagnose-cli-").tempdir().unwrap();
    let path = folder.path().join(name);
    Scratch { _folder: folder, path }
}

#[test]
fn a_missing_problem_file_is_named() {
    let out = scratch("missing");
    let o = czid(&["diagnose", "examples/no-such-problem.toml", "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("no-such-problem.toml"), "{}", stderr(&o));
    assert!(!out.exists(), "no output folder for a failed start");
}

#[test]
fn an_unknown_candidate_lists_the_known_ones() {
    let out = scratch("unknown");
    let o = czid(&[
        "diagnose",
        "examples/hartlen-dcb/dcb01.toml",
        "--out",
        out.to_str().unwrap(),
        "--candidates",
        "fibre_bridging,warp_drive",
    ]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("unknown candidate `warp_drive`") && e.contains("large_rotation"), "{e}");
    let o = czid(&["gap-bench", "--cases", "1", "--effects", "adhesive_compliance", "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("cannot be planted"), "{}", stderr(&o));
}

#[test]
fn a_result_file_without_the_parameters_is_explained() {
    let out = scratch("from");
    std::fs::create_dir_all(&*out).unwrap();
    let bad = out.join("result.json");
    std::fs::write(&bad, r#"{"parameters": {"law.strength_n": {"value": 30.0}}}"#).unwrap();
    let o = czid(&[
        "diagnose",
        "examples/hartlen-dcb/dcb01.toml",
        "--out",
        out.join("gap").to_str().unwrap(),
        "--from",
        bad.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("has no value for parameter `law.g_ic`"), "{}", stderr(&o));
}

/// Two cheap candidates (measurement effects): what is checked is the command's output, not a
/// cause; the bridging candidate's refit from this deliberately rough base fit (8 evaluations) takes
/// over a minute, and the benches cover the candidates.
#[test]
fn a_small_diagnosis_writes_its_report_and_never_clobbers_it() {
    let out = scratch("small");
    let args = [
        "diagnose",
        "examples/hartlen-dcb/dcb01.toml",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "models.dcb01.control.max_displacement=12",
        "--set",
        "optimizer.budget=8",
        "--candidates",
        "machine_compliance,load_offset",
        "--refit",
        "1",
    ];
    let o = czid(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let gap: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("gap.json")).unwrap()).unwrap();
    assert!(gap["verdict"].as_str().unwrap().len() > 20);
    // The machine-readable verdict and the model-form floor (the continuum DCB as reference).
    assert!(
        ["cause", "none_needed", "unexplained"].contains(&gap["outcome"]["kind"].as_str().unwrap()),
        "{}",
        gap["outcome"]
    );
    assert_eq!(gap["model_form"]["reference"]["dcb01"], "dcb_2d", "{}", gap["model_form"]);
    assert_eq!(gap["candidates"].as_array().unwrap().len(), 2);
    assert!(gap["regimes"].as_array().unwrap().len() >= 2);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("## Where") && report.contains("## Which"));
    assert!(out.join("residual-dcb01-F.png").exists() && out.join("scores.png").exists());
    // A second run into the same folder needs --force.
    let o = czid(&args);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--force"), "{}", stderr(&o));
}
