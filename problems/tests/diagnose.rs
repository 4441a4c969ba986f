//! The diagnosis of the sim-to-real gap: candidate effects are the base model at their null
//! values, a planted effect is found and a clean case is left alone, regimes split where a hand
//! analysis of the curve puts them.

use czid_core::{CohesiveLaw, ForwardModel, Parameter, ParameterSpace};
use czid_models::dcb::Dcb;
use czid_models::laws::Bilinear;
use czid_problems::diagnose::regimes::{self, NAMES};
use czid_problems::diagnose::run::{diagnose_subject, Subject};
use czid_problems::diagnose::{CandidateEffect, Kind, Library, Options};
use czid_problems::identification::Setup;
use czid_problems::synthetic::{synthesize, Noise};
use std::collections::BTreeMap;

fn dcb_setup(opening: f64, points: usize) -> Setup {
    let mut d = Dcb::hartlen_dcb01();
    d.control.max_displacement = Some(opening);
    d.control.output_points = points;
    let law: Box<dyn CohesiveLaw> = Box::new(Bilinear::bk(1e5, 30.0, 30.0, 0.8, 2.0, 2.0).unwrap());
    let models: BTreeMap<String, Box<dyn ForwardModel>> =
        [("dcb".to_string(), Box::new(d) as Box<dyn ForwardModel>)].into();
    Setup { law, models }
}

fn nulls(c: &dyn CandidateEffect, s: &Setup) -> Vec<f64> {
    c.parameters(s).unwrap().iter().map(|p| p.null).collect()
}

#[test]
fn every_bundled_dcb_candidate_at_its_null_value_is_the_base_model_exactly() {
    let base = dcb_setup(6.0, 12);
    let reference = base.models["dcb"].simulate(base.law.as_ref()).unwrap();
    let library = Library::builtin();
    let mut checked = Vec::new();
    for c in library.all(&base) {
        let c = c.as_ref();
        if !c.applies(&base) {
            continue;
        }
        let s = c.apply(&base, &nulls(c, &base)).unwrap();
        assert_eq!(serde_json::to_value(&s).unwrap(), serde_json::to_value(&base).unwrap(), "{}", c.name());
        let record = s.models["dcb"].simulate(s.law.as_ref()).unwrap();
        assert_eq!(record, reference, "{}", c.name());
        // And the effect does something away from its null value (half way up its range from a
        // null at the lower end: the far end of the root compliance's is more than this law can
        // hold in series, which the model refuses).
        let params = c.parameters(&base).unwrap();
        let on: Vec<f64> = params
            .iter()
            .map(|p| {
                let (lo, hi) = (p.parameter.lower, p.parameter.upper);
                match (p.null == lo, c.discrete()) {
                    (true, true) => hi,
                    (true, false) => lo + 0.5 * (hi - lo),
                    (false, _) => lo,
                }
            })
            .collect();
        let s = c.apply(&base, &on).unwrap();
        let record = s.models["dcb"].simulate(s.law.as_ref()).unwrap();
        assert_ne!(record, reference, "{} has no effect", c.name());
        checked.push(c.name().to_string());
    }
    assert_eq!(
        checked,
        [
            "fibre_bridging",
            "large_rotation",
            "root_compliance",
            "machine_compliance",
            "crack_length_offset",
            "displacement_offset",
            "shear_compliance",
            "load_offset",
            "seating_toe"
        ]
    );
}

#[test]
fn the_beam_candidates_apply_to_the_frp_beam_only_and_are_null_there() {
    let beam = czid_models::frp::beam::FrpBeam::paper().unwrap();
    let law: Box<dyn CohesiveLaw> = Box::new(Bilinear::bk(1e5, 5.0, 5.0, 0.5, 1.0, 2.0).unwrap());
    let models: BTreeMap<String, Box<dyn ForwardModel>> =
        [("beam".to_string(), Box::new(beam) as Box<dyn ForwardModel>)].into();
    let setup = Setup { law, models };
    let library = Library::builtin();
    let all = library.all(&setup);
    let applies: Vec<&str> = all.iter().filter(|c| c.applies(&setup)).map(|c| c.name()).collect();
    // Bridging applies to any setup with a bilinear law; the rest are the beam's own.
    assert!(applies.len() >= 4, "{applies:?}");
    for name in ["adhesive_compliance", "shrinkage_strain", "steel_hardening", "deflection_offset"] {
        assert!(applies.contains(&name), "{name} missing from {applies:?}");
        let c = library.select(&setup, &[name.to_string()]).unwrap().remove(0);
        let s = c.apply(&setup, &nulls(c.as_ref(), &setup)).unwrap();
        assert_eq!(serde_json::to_value(&s).unwrap(), serde_json::to_value(&setup).unwrap(), "{name}");
        assert!(!c.applies(&dcb_setup(5.0, 5)), "{name} applies to a DCB");
    }
}

#[test]
fn an_unknown_candidate_is_named_with_the_known_ones() {
    let err = Library::builtin().select(&dcb_setup(5.0, 5), &["warp_drive".to_string()]).err().unwrap().to_string();
    assert!(err.contains("unknown candidate `warp_drive`") && err.contains("machine_compliance"), "{err}");
}

#[test]
fn regimes_split_where_the_hand_analysis_puts_them() {
    // Linear to 4 mm (10 N/mm), a softer rise to the 45 N peak at 5 mm, then a fall of 10 N/mm.
    let x: Vec<f64> = (0..=800).map(|i| i as f64 * 0.01).collect();
    let p: Vec<f64> = x
        .iter()
        .map(|&v| {
            if v <= 4.0 {
                10.0 * v
            } else if v <= 5.0 {
                40.0 + 5.0 * (v - 4.0)
            } else {
                45.0 - 10.0 * (v - 5.0)
            }
        })
        .collect();
    let r = regimes::split("t", &x, &p);
    let names: Vec<&str> = r.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, NAMES);
    // Secant 95 % of 10 N/mm: (20 + 5x)/x < 9.5 from x > 4.444; 95 % of the peak: x > 5.225;
    // the late stage is the last third of [5.23, 8].
    let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
    assert!(close(r[0].to, 4.45), "{:?}", r[0]);
    assert!(close(r[1].to, 5.23), "{:?}", r[1]);
    assert!(close(r[2].to, 5.23 + 2.0 / 3.0 * (8.0 - 5.23)), "{:?}", r[2]);
    assert!(close(r[3].to, 8.0), "{:?}", r[3]);
    // A curve that never falls from its peak has no propagation.
    let rising = regimes::split("t", &x[..500], &p[..500]);
    assert_eq!(rising.iter().map(|g| g.name.as_str()).collect::<Vec<_>>(), NAMES[..2]);
}

/// A synthetic test of the DCB with a bridging tail of `bridging` MPa (0: none), made by the beam
/// model itself, diagnosed with it from a start 5 % of the ranges away from the truth.
fn diagnose_synthetic(bridging: f64) -> czid_problems::diagnose::Diagnosis {
    diagnose_made_by(bridging, false)
}

/// As [`diagnose_synthetic`], the test made by the beam model or by a continuum model of the same
/// specimen, finer than the beam model's reference (half its interface element, six elements
/// through each arm). A beam-made test has no model-form misfit: it is diagnosed without the
/// model-form floor, which would otherwise add the continuum's difference to it.
fn diagnose_made_by(bridging: f64, continuum: bool) -> czid_problems::diagnose::Diagnosis {
    let (subject, u0) = synthetic_subject(bridging, continuum);
    let opts = Options {
        candidates: ["machine_compliance", "fibre_bridging", "crack_length_offset", "displacement_offset"]
            .map(String::from)
            .to_vec(),
        refit: 1,
        holdout: false,
        model_form: continuum,
        ..Options::default()
    };
    diagnose_subject(&subject, &u0, &Library::builtin(), &opts).unwrap()
}

/// The test of [`diagnose_made_by`] and the base fit's start (near the truth, not at it).
fn synthetic_subject(bridging: f64, continuum: bool) -> (Subject, Vec<f64>) {
    let base = dcb_setup(16.0, 60);
    let library = Library::builtin();
    let truth = if bridging > 0.0 {
        library.select(&base, &["fibre_bridging".to_string()]).unwrap()[0].apply(&base, &[bridging, 1.0]).unwrap()
    } else {
        base.duplicate().unwrap()
    };
    let record = if continuum {
        let beam: Dcb = serde_json::from_value({
            let mut v = serde_json::to_value(truth.models["dcb"].as_ref()).unwrap();
            v.as_object_mut().unwrap().remove("type");
            v
        })
        .unwrap();
        let mut made = czid_models::dcb_2d::Dcb2d::from_beam(&beam).unwrap();
        made.mesh.interface_element *= 0.5;
        made.mesh.thickness_elements = 6;
        made.simulate(truth.law.as_ref()).unwrap()
    } else {
        truth.models["dcb"].simulate(truth.law.as_ref()).unwrap()
    };
    let data = synthesize(&record, 80, Some(16.0), &Noise { load_sd: 0.4, length_sd: 0.3, seed: 11 }).unwrap();
    let experiment = data.experiment("dcb").unwrap();
    let space = ParameterSpace::new(vec![
        Parameter::new("law.strength_n", "MPa", 5.0, 80.0).log(),
        Parameter::new("law.g_ic", "N/mm", 0.2, 2.0),
        Parameter::new("models.*.material.e11", "MPa", 10_000.0, 50_000.0),
    ])
    .unwrap();
    let u0: Vec<f64> =
        space.to_unit(&[30.0, 0.8, 19_300.0]).iter().zip([0.05, -0.05, 0.05]).map(|(u, d)| u + d).collect();
    let subject =
        Subject { name: "synthetic".into(), setup: base, space, experiments: vec![experiment], use_length: true };
    (subject, u0)
}

#[test]
fn a_refit_asked_for_by_a_name_that_is_not_a_candidate_is_an_error() {
    let (subject, u0) = synthetic_subject(0.0, false);
    let opts = Options {
        candidates: vec!["machine_compliance".into()],
        always_refit: vec!["machine_complaince".into()],
        ..Options::default()
    };
    let err = diagnose_subject(&subject, &u0, &Library::builtin(), &opts).err().unwrap().to_string();
    assert!(err.contains("`machine_complaince` is not among") && err.contains("machine_compliance"), "{err}");
}

#[test]
fn a_planted_bridging_tail_ranks_first_and_its_refit_reaches_the_noise() {
    let d = diagnose_synthetic(1.0);
    let best = &d.candidates[0];
    let score = best.score.as_ref().unwrap();
    assert_eq!(best.name, "fibre_bridging", "{}", d.verdict);
    assert!(score.significant);
    assert!(!d.base.at_noise_level, "{}", d.base.reduced_chi2);
    let refit = best.refit.as_ref().unwrap();
    let dof = (d.readings - 5) as f64;
    assert!(czid_problems::diagnose::stats::chi2_survival(refit.chi2, dof) > 1e-3, "{} / {dof}", refit.chi2);
    assert!(d.verdict.contains("Most likely cause: fibre_bridging"), "{}", d.verdict);
    assert_eq!(d.outcome.kind, Kind::Cause);
    assert_eq!(d.outcome.cause.as_deref(), Some("fibre_bridging"));
}

#[test]
fn a_clean_test_needs_no_unmodelled_effect() {
    let d = diagnose_synthetic(0.0);
    assert!(d.base.at_noise_level, "{}", d.base.reduced_chi2);
    assert!(d.candidates.iter().all(|c| !c.score.as_ref().unwrap().significant), "{}", d.verdict);
    assert!(d.verdict.starts_with("No unmodelled effect is needed at this noise level"), "{}", d.verdict);
    assert_eq!(d.outcome.kind, Kind::NoneNeeded);
}

#[test]
fn a_clean_test_made_by_the_continuum_model_needs_no_unmodelled_effect_once_the_model_form_is_accounted_for() {
    let d = diagnose_made_by(0.0, true);
    assert!(d.model_form.applied(), "{:?}", d.model_form.note);
    assert_eq!(d.model_form.reference["dcb"], "dcb_2d");
    // The beam model's form alone sits well away from the continuum's at this noise…
    assert!(d.model_form.shift_max > 1.0, "{:?}", d.model_form);
    // The reference's own discretisation (its coarsened twin against it) is a smaller matter than
    // the model form, but not nothing.
    assert!(d.model_form.floor_rms > 0.0 && d.model_form.floor_rms < d.model_form.shift_rms, "{:?}", d.model_form);
    // …and once that is accounted for, no effect is named.
    assert_eq!(d.outcome.kind, Kind::NoneNeeded, "{}", d.verdict);
    assert!(d.verdict.contains("own discretisation leaves it uncertain by"), "{}", d.verdict);
    assert!(
        d.verdict.starts_with("No unmodelled effect is needed at this noise and model-form level"),
        "{}",
        d.verdict
    );
}

#[test]
fn a_bridging_tail_in_a_continuum_made_test_stands_out_from_the_floor_and_its_uncertainty() {
    let d = diagnose_made_by(1.0, true);
    assert!(d.model_form.applied() && d.model_form.floor_rms > 0.0, "{:?}", d.model_form);
    assert!(!d.base.at_noise_level || d.base.structure_p <= 1e-3, "{}", d.verdict);
    assert_eq!(d.outcome.kind, Kind::Cause, "{}", d.verdict);
    assert_eq!(d.outcome.cause.as_deref(), Some("fibre_bridging"), "{}", d.verdict);
}
