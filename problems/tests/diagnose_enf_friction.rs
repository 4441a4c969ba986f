//! Friction between the cracked faces of an ENF, planted in a synthetic test, is found by the
//! diagnosis among the ENF's declared effects.
//!
//! The test is made by a finer ENF (half the diagnosing model's interface element), so the
//! diagnosing model is not judged on data it made itself. The arms' modulus is known (as in the
//! diagnosis bench): the law's shear strength and G_IIc are fitted.

use czid_core::{CohesiveLaw, Curve, ForwardModel, Parameter, ParameterSpace};
use czid_models::enf::Enf;
use czid_models::laws::Bilinear;
use czid_problems::data::Experiment;
use czid_problems::diagnose::run::{diagnose_subject, Subject};
use czid_problems::diagnose::{Library, Options};
use czid_problems::identification::Setup;
use czid_problems::synthetic::{synthesize, Noise};
use std::collections::BTreeMap;

/// Hartlen's ENF-03 with a plausible glass/epoxy mode II law, run to 8 mm (past the unstable
/// propagation, with the crack under the loading nose at the end).
fn setup(interface_element: f64, friction: f64) -> Setup {
    let mut e = Enf::hartlen_enf03();
    e.mesh.interface_element = interface_element;
    e.control.max_displacement = Some(8.0);
    e.control.output_points = 60;
    e.effects.crack_face_friction = friction;
    let law: Box<dyn CohesiveLaw> = Box::new(Bilinear::bk(1e5, 40.0, 60.0, 1.0, 3.5, 2.0).unwrap());
    let models: BTreeMap<String, Box<dyn ForwardModel>> =
        [("enf".to_string(), Box::new(e) as Box<dyn ForwardModel>)].into();
    Setup { law, models }
}

/// The diagnosis of a synthetic ENF test made with friction `mu` (0: none) by a finer model.
fn diagnose_made_with(mu: f64) -> czid_problems::diagnose::Diagnosis {
    let truth = setup(0.25, mu);
    let record = truth.models["enf"].simulate(truth.law.as_ref()).unwrap();
    let data = synthesize(&record, 80, Some(8.0), &Noise { load_sd: 0.5, length_sd: 0.3, seed: 5 }).unwrap();
    let experiment = Experiment {
        name: "enf".into(),
        load: Curve::new(data.displacement, data.load).unwrap(),
        debonded_length: None,
        initial_crack: None,
        dropped: Default::default(),
        events: Vec::new(),
        ordinate: Default::default(),
        noise: Default::default(),
    };
    let space = ParameterSpace::new(vec![
        Parameter::new("law.strength_t", "MPa", 10.0, 150.0).log(),
        Parameter::new("law.g_iic", "N/mm", 0.5, 8.0),
    ])
    .unwrap();
    let u0: Vec<f64> = space.to_unit(&[60.0, 3.5]).iter().zip([0.05, -0.05]).map(|(u, d)| u + d).collect();
    let subject = Subject {
        name: "enf-friction".into(),
        setup: setup(0.5, 0.0),
        space,
        experiments: vec![experiment],
        use_length: false,
    };
    let opts = Options {
        candidates: ["crack_face_friction", "crack_length_offset", "machine_compliance", "shear_compliance"]
            .map(String::from)
            .to_vec(),
        refit: 2,
        holdout: false,
        // Made by the beam model (finer): no model-form misfit to account for with the continuum.
        model_form: false,
        ..Options::default()
    };
    let t = std::time::Instant::now();
    let d = diagnose_subject(&subject, &u0, &Library::builtin(), &opts).unwrap();
    println!("μ = {mu}: {}\n(in {:.1} s)", d.verdict, t.elapsed().as_secs_f64());
    for c in &d.candidates {
        let refit =
            c.refit.as_ref().map(|r| (r.shrinkage, r.delta_bic, r.effect.iter().map(|v| v.value).collect::<Vec<_>>()));
        println!(
            "  {}: significant {:?}, refit (shrinkage, ΔBIC, values) {refit:?}",
            c.name,
            c.score.as_ref().map(|s| s.significant)
        );
    }
    d
}

#[test]
fn planted_crack_face_friction_is_named_and_refitted_near_its_value() {
    let mu = 0.4;
    let d = diagnose_made_with(mu);
    assert!(!d.base.at_noise_level, "the planted friction leaves a misfit: reduced χ² {}", d.base.reduced_chi2);
    let friction = d.candidates.iter().find(|c| c.name == "crack_face_friction").expect("the ENF declares friction");
    let refit = friction.refit.as_ref().expect("friction is refitted");
    // Nearly all the misfit goes, at a coefficient near the planted one.
    assert!(refit.shrinkage > 0.9, "friction's refit removes only {:.3} of the misfit", refit.shrinkage);
    let found = refit.effect[0].value;
    assert!((found - mu).abs() < 0.05, "friction refitted at μ = {found}, planted {mu}");
    assert_eq!(d.outcome.cause.as_deref(), Some("crack_face_friction"), "{}", d.verdict);
}

#[test]
fn a_frictionless_enf_test_is_not_blamed_on_friction() {
    let d = diagnose_made_with(0.0);
    assert_ne!(d.outcome.cause.as_deref(), Some("crack_face_friction"), "{}", d.verdict);
}
