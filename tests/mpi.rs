//! `mpiexec -n 2 czid identify ...` gives the serial result bit for bit, with evaluations done on
//! both ranks, and a killed 2-rank run resumes to it (on one rank as well); `compare`, `gap-bench`
//! and `diagnose` give their serial outputs on 2 ranks too. Built and run with
//! `cargo test --features mpi --test mpi` on a machine with MPI (`mpiexec` on the path).
#![cfg(feature = "mpi")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const PROBLEM: &str = "examples/paper-dcb/problem.toml";

/// Runs czid with `args`, on `ranks` MPI ranks through `mpiexec` or as one plain process.
fn czid<S: AsRef<std::ffi::OsStr>>(ranks: Option<usize>, args: &[S]) -> Output {
    let bin = env!("CARGO_BIN_EXE_czid");
    let mut cmd = match ranks {
        Some(n) => {
            let mut c = Command::new("mpiexec");
            c.args(["-n", &n.to_string(), bin]);
            c
        }
        None => Command::new(bin),
    };
    cmd.args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap()
}

fn run(ranks: Option<usize>, out: &Path, extra: &[&str]) -> Output {
    let base = ["identify", PROBLEM, "--optimizer", "miga", "--budget", "400", "--out", out.to_str().unwrap()];
    czid(ranks, &[&base[..], extra].concat())
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("czid-mpi-{}-{name}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    dir
}

fn result(dir: &Path) -> serde_json::Value {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("result.json")).unwrap()).unwrap();
    for k in ["wall_seconds", "forward_share", "resumed", "shared_evaluations"] {
        v.as_object_mut().unwrap().remove(k);
    }
    v
}

#[test]
fn two_ranks_give_the_serial_result_and_a_killed_run_resumes_to_it() {
    let serial = scratch("serial");
    assert!(run(None, &serial, &[]).status.success());

    let two = scratch("two");
    let o = run(Some(2), &two, &[]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(result(&two), result(&serial));
    assert_eq!(
        std::fs::read_to_string(two.join("history.csv")).unwrap(),
        std::fs::read_to_string(serial.join("history.csv")).unwrap()
    );
    // Both ranks evaluated: "evaluations on 2 ranks: rank 0: a, rank 1: b" with a, b > 0.
    let line = stdout.lines().find(|l| l.starts_with("evaluations on 2 ranks")).expect("the per-rank counts");
    let counts: Vec<usize> =
        line.split(": ").skip(2).map(|c| c.split(',').next().unwrap().trim().parse().unwrap()).collect();
    assert!(counts.len() == 2 && counts.iter().all(|&c| c > 0), "{line}");

    // Killed on 2 ranks after 200 evaluations; resumed on 2 ranks and on 1.
    for resume_ranks in [Some(2), None] {
        let cut = scratch(&format!("cut-{resume_ranks:?}"));
        assert!(!run(Some(2), &cut, &["--abort-after-evaluations", "200"]).status.success());
        let r = run(resume_ranks, &cut, &["--resume"]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        assert_eq!(result(&cut), result(&serial), "resumed on {resume_ranks:?} ranks");
        std::fs::remove_dir_all(cut).ok();
    }
    for d in [serial, two] {
        std::fs::remove_dir_all(d).ok();
    }
}

fn compare(ranks: Option<usize>, out: &Path) -> Output {
    let args = [
        "compare",
        PROBLEM,
        "--optimizers",
        "miga,lm",
        "--seeds",
        "2",
        "--budget",
        "200",
        "--out",
        out.to_str().unwrap(),
    ];
    czid(ranks, &args)
}

/// `summary.csv` without its wall-time column.
fn summary(dir: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(dir.join("summary.csv")).unwrap();
    let rows: Vec<Vec<String>> = text.lines().map(|l| l.split(',').map(str::to_string).collect()).collect();
    let keep: Vec<usize> = (0..rows[0].len()).filter(|&i| rows[0][i] != "wall_seconds").collect();
    rows.iter().map(|r| keep.iter().map(|&i| r[i].clone()).collect()).collect()
}

#[test]
fn compare_on_two_ranks_gives_the_serial_table() {
    let serial = scratch("compare-serial");
    assert!(compare(None, &serial).status.success());
    let two = scratch("compare-two");
    let o = compare(Some(2), &two);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(summary(&two), summary(&serial));
    assert!(String::from_utf8_lossy(&o.stdout).contains("evaluations on 2 ranks"));
    for d in [serial, two] {
        std::fs::remove_dir_all(d).ok();
    }
}

#[test]
fn gap_bench_cases_spread_over_two_ranks_give_the_serial_cases() {
    let args = |out: &Path| {
        ["gap-bench", "--cases", "1", "--nulls", "1", "--effects", "machine_compliance", "--out", out.to_str().unwrap()]
            .map(str::to_string)
    };
    let serial = scratch("bench-serial");
    assert!(czid(None, &args(&serial)).status.success());
    let two = scratch("bench-two");
    let o = czid(Some(2), &args(&two));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("cases on 2 ranks: rank 0: 1, rank 1: 1"));
    for name in ["case-dcb-seed1-0000-machine_compliance.json", "case-dcb-seed1-0001-none.json"] {
        let read = |d: &Path| {
            let mut v: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(d.join("cases").join(name)).unwrap()).unwrap();
            // Times differ from run to run; everything else must not.
            for time in ["seconds", "data_seconds", "diagnosis_seconds"] {
                v.as_object_mut().unwrap().remove(time);
            }
            v
        };
        assert_eq!(read(&two), read(&serial), "{name}");
    }
    for d in [serial, two] {
        std::fs::remove_dir_all(d).ok();
    }
}

#[test]
fn diagnose_refits_spread_over_two_ranks_give_the_serial_diagnosis() {
    // Four cheap candidates, all refitted; the cause's refit is judged again with the model-form
    // floor re-estimated, and the held-out late stage is predicted (about 5 s serial).
    let args = |out: &Path| {
        [
            "diagnose",
            "examples/hartlen-dcb/dcb01.toml",
            "--out",
            out.to_str().unwrap(),
            "--set",
            "models.dcb01.control.max_displacement=12",
            "--set",
            "optimizer.budget=8",
            "--candidates",
            "machine_compliance,crack_length_offset,displacement_offset,load_offset",
            "--refit",
            "4",
        ]
        .map(str::to_string)
    };
    let serial = scratch("diagnose-serial");
    let o = czid(None, &args(&serial));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let two = scratch("diagnose-two");
    let o = czid(Some(2), &args(&two));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Both ranks refitted: "refits on 2 ranks: rank 0: a, rank 1: b" with a + b = 4, a, b > 0.
    let stdout = String::from_utf8_lossy(&o.stdout);
    let line = stdout.lines().find(|l| l.starts_with("refits on 2 ranks")).expect("the per-rank counts");
    let counts: Vec<usize> =
        line.split(": ").skip(2).map(|c| c.split(',').next().unwrap().trim().parse().unwrap()).collect();
    assert!(counts.len() == 2 && counts.iter().all(|&c| c > 0) && counts.iter().sum::<usize>() == 4, "{line}");
    let gap = |d: &Path| {
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("gap.json")).unwrap()).unwrap();
        v.as_object_mut().unwrap().remove("wall_seconds");
        v
    };
    let (g2, g1) = (gap(&two), gap(&serial));
    assert_eq!(g2, g1);
    // The case is what it should exercise: four refits, a cause judged again, transfer checked.
    let refitted = g1["candidates"].as_array().unwrap().iter().filter(|c| c["refit"].is_object()).count();
    assert_eq!(refitted, 4, "{}", g1["candidates"]);
    assert_eq!(g1["outcome"]["kind"], "cause", "{}", g1["outcome"]);
    let cause = g1["candidates"].as_array().unwrap().iter().find(|c| c["name"] == g1["outcome"]["cause"]).unwrap();
    assert!(cause["refit"]["chi2_reestimated"].is_f64() && cause["transfer"][0]["shrinkage"].is_f64(), "{cause}");
    // The plots, the cause's refit among them, byte for byte.
    for name in ["fit-dcb01-F.png", "fit-dcb01-L.png", "residual-dcb01-F.png", "scores.png"] {
        assert!(std::fs::read(two.join(name)).unwrap() == std::fs::read(serial.join(name)).unwrap(), "{name}");
    }
    for d in [serial, two] {
        std::fs::remove_dir_all(d).ok();
    }
}
