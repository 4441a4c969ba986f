//! The harness writes its CSVs, summary and plots, refuses to clobber, and merges job parts.

use czid_optimizers::harness::{merge, run, HarnessConfig};

fn config(out: &std::path::Path) -> HarnessConfig {
    HarnessConfig {
        optimizers: vec!["miga".into(), "nelder-mead".into()],
        problems: vec!["rastrigin3".into(), "zdt1-4".into()],
        seeds: 2,
        budget: 1000,
        out: out.to_path_buf(),
        ..HarnessConfig::default()
    }
}

#[test]
fn harness_outputs_and_merge() {
    let root = std::env::temp_dir().join(format!("czid-harness-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let whole = run(&config(&root.join("whole"))).unwrap();
    assert_eq!(whole.runs.len(), 2 * 2 * 2);
    assert!(whole.runs.iter().all(|r| r.evaluations <= 1000));
    for f in ["runs.csv", "convergence.csv", "summary.md", "data_profile.svg", "data_profile.png"] {
        assert!(root.join("whole").join(f).exists(), "{f}");
    }
    for p in ["rastrigin3", "zdt1-4"] {
        let svg = std::fs::read_to_string(root.join("whole").join(format!("convergence_{p}.svg"))).unwrap();
        assert!(svg.contains("evaluations") && svg.contains("miga"), "axis label and legend drawn as text");
    }
    // No clobbering without --force.
    assert!(run(&config(&root.join("whole"))).is_err());
    assert!(run(&HarnessConfig { force: true, ..config(&root.join("whole")) }).is_ok());

    // Two array jobs (one seed each) merged give the same runs as one job.
    for seed in 0..2 {
        run(&HarnessConfig { seeds: 1, seed_offset: seed, replicate: true, ..config(&root.join("parts")) }).unwrap();
    }
    let merged = merge(&[root.join("parts")], &root.join("merged"), false, 1e-3).unwrap();
    let key = |r: &czid_optimizers::harness::RunRecord| {
        (r.optimizer.clone(), r.problem.clone(), r.seed, r.best_value.to_bits())
    };
    let mut a: Vec<_> = whole.runs.iter().map(key).collect();
    let mut b: Vec<_> = merged.runs.iter().map(key).collect();
    a.sort();
    b.sort();
    assert_eq!(a, b);
    // A run present twice is refused.
    assert!(merge(&[root.join("parts"), root.join("whole")], &root.join("twice"), false, 1e-3).is_err());
    // Unknown names fail before any run.
    assert!(run(&HarnessConfig { optimizers: vec!["simplex".into()], ..config(&root.join("bad")) }).is_err());
    std::fs::remove_dir_all(&root).unwrap();
}
