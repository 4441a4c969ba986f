//! `gap-bench` bookkeeping: cases kept as they finish and reused when a run resumes, families
//! named clearly, and the same case drawn whatever else is in the plan.

use czid_problems::diagnose::bench::{self, BenchOptions, CaseStore, Family};
use czid_problems::output::OutputDir;

fn scratch(name: &str) -> std::path::PathBuf {
    let p = std::env::temp_dir().join(format!("czid-gap-bench-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    p
}

fn one_null() -> BenchOptions {
    BenchOptions { cases: 0, nulls: 1, seed: 3, effects: Vec::new(), family: Family::Dcb, truth: Default::default() }
}

#[test]
fn a_resumed_run_reuses_the_cases_already_finished() {
    let dir = scratch("resume");
    let store = CaseStore { dir: OutputDir::create(&dir, false, false).unwrap(), reuse: false };
    let first = bench::run(&one_null(), Some(&store), None, &|_, _| {}).unwrap();
    assert_eq!(first.cases.len(), 1);
    assert!(first.cases[0].error.is_none(), "{:?}", first.cases[0].error);
    let files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(files.len(), 1, "one file per finished case: {files:?}");

    // Mark the kept case: a resumed run must report it as kept, not run it again.
    let text = std::fs::read_to_string(&files[0]).unwrap();
    let mut kept: serde_json::Value = serde_json::from_str(&text).unwrap();
    kept["seconds"] = serde_json::json!(-1.0);
    std::fs::write(&files[0], serde_json::to_string(&kept).unwrap()).unwrap();
    let resumed = CaseStore { dir: OutputDir::create(&dir, false, true).unwrap(), reuse: true };
    let second = bench::run(&one_null(), Some(&resumed), None, &|_, _| {}).unwrap();
    assert_eq!(second.cases[0].seconds, -1.0);
    assert_eq!(second.cases[0].diagnosed, first.cases[0].diagnosed);

    // Without reuse the case runs again, with the same draws and the same answer.
    let fresh = CaseStore { dir: OutputDir::create(&dir, true, false).unwrap(), reuse: false };
    let third = bench::run(&one_null(), Some(&fresh), None, &|_, _| {}).unwrap();
    assert!(third.cases[0].seconds >= 0.0);
    // The case's time is split into making its test and diagnosing it.
    let c = &third.cases[0];
    assert!(c.data_seconds > 0.0 && c.diagnosis_seconds > 0.0, "{} {}", c.data_seconds, c.diagnosis_seconds);
    assert!(c.data_seconds + c.diagnosis_seconds <= c.seconds);
    assert_eq!(third.cases[0].truth, first.cases[0].truth);
    assert_eq!(third.cases[0].ranking, first.cases[0].ranking);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_prepared_case_is_the_test_the_benchmark_diagnoses() {
    let plan = bench::Plan::new(&one_null()).unwrap();
    let ran = plan.run_case(0);
    let (made, prepared) = plan.prepare_case(0);
    let prepared = prepared.unwrap();
    assert_eq!((made.truth, made.readings), (ran.truth, ran.readings));
    assert_eq!(made.diagnosis_seconds, 0.0, "preparing a case does not diagnose it");
    let d = czid_problems::diagnose::run::diagnose_subject(
        &prepared.subject,
        &prepared.start,
        plan.library(),
        &prepared.options,
    )
    .unwrap();
    let ranking: Vec<(String, f64, bool)> = d
        .candidates
        .iter()
        .filter_map(|c| c.score.as_ref().map(|s| (c.name.clone(), s.statistic, s.significant)))
        .collect();
    assert_eq!(ranking, ran.ranking);
    assert_eq!(d.outcome.cause.unwrap_or_else(|| bench::NONE.into()), ran.diagnosed);
}

#[test]
fn families_are_named_and_plant_only_their_own_effects() {
    assert_eq!("beam".parse::<Family>().unwrap(), Family::Beam);
    let e = "enf".parse::<Family>().unwrap_err().to_string();
    assert!(e.contains("unknown family `enf`") && e.contains("dcb, beam"), "{e}");
    let opts = BenchOptions { effects: vec!["steel_hardening".into()], ..one_null() };
    let e = bench::run(&opts, None, None, &|_, _| {}).unwrap_err().to_string();
    assert!(e.contains("cannot be planted in the dcb benchmark"), "{e}");
}

#[test]
fn continuum_truth_makes_the_tests_with_the_continuum_model_and_keeps_its_cases_apart() {
    use bench::Truth;
    let mut dcb = czid_models::dcb::Dcb::hartlen_dcb01();
    dcb.effects.machine_compliance = 0.004;
    let made = Truth::Continuum.model(&dcb).unwrap();
    assert_eq!(made.name(), "dcb_2d");
    assert_eq!(Truth::Beam.model(&dcb).unwrap().name(), "dcb");
    // The planted effect travels with the specimen.
    let json = serde_json::to_value(made.as_ref()).unwrap();
    assert_eq!(json["effects"]["machine_compliance"], serde_json::json!(0.004));

    let e = bench::run(
        &BenchOptions { family: Family::Beam, truth: Truth::Continuum, ..one_null() },
        None,
        None,
        &|_, _| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("no continuum model") && e.contains("--truth beam"), "{e}");
    let e = "fem".parse::<Truth>().unwrap_err().to_string();
    assert!(e.contains("beam, continuum"), "{e}");

    // A continuum-made case runs, and is kept under its own name beside a beam-made one.
    let dir = scratch("truth");
    let store = CaseStore { dir: OutputDir::create(&dir, false, false).unwrap(), reuse: false };
    let r =
        bench::run(&BenchOptions { truth: Truth::Continuum, ..one_null() }, Some(&store), None, &|_, _| {}).unwrap();
    assert!(r.cases[0].error.is_none(), "{:?}", r.cases[0].error);
    let names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(names.iter().all(|n| n.contains("-continuum-")), "{names:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn dcb_cases_alternate_between_two_specimens_and_fit_the_law_with_the_modulus_known() {
    use bench::Specimen;
    use rand::SeedableRng;
    let space = Family::Dcb.space();
    let fitted: Vec<&str> = space.parameters().iter().map(|p| p.path.as_str()).collect();
    assert_eq!(fitted, ["law.strength_n", "law.g_ic"]);
    for index in 0..4 {
        let draw = Family::Dcb.draw(index, &mut rand_chacha::ChaCha8Rng::seed_from_u64(index as u64));
        let (specimen, modulus) = if index % 2 == 0 {
            (Specimen::HartlenDcb, 16_000.0..30_000.0)
        } else {
            (Specimen::PaperDcb, 115_000.0..145_000.0)
        };
        assert_eq!(draw.specimen, specimen);
        assert!(modulus.contains(&draw.truth[2]), "case {index}: {}", draw.truth[2]);
        // The base model is the specimen's, at the drawn (known) modulus, run to the drawn end.
        let setup = Family::Dcb.base_setup(&draw).unwrap();
        let model = serde_json::to_value(setup.models["dcb"].as_ref()).unwrap();
        let (width, a0) = if index % 2 == 0 { (25.0, 37.64) } else { (20.0, 50.0) };
        assert_eq!((model["width"].as_f64(), model["a0"].as_f64()), (Some(width), Some(a0)));
        assert_eq!(model["material"]["e11"].as_f64(), Some(draw.truth[2]));
        assert_eq!(model["control"]["max_displacement"].as_f64(), draw.end);
    }
}
