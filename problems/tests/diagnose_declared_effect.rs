//! A forward model owns its effects: a model written here, and nowhere in `czid-problems`,
//! declares a switchable effect; the diagnosis offers it as a candidate with no other code, and
//! on a synthetic test with the effect planted it names it.
//!
//! The model is the simple-beam-theory DCB with a root-rotation length `Δ` added to the crack
//! length in the arms' compliance and energy release rate (the correction of corrected beam
//! theory): `δ = 2P(a + Δ)³ / (3EI)`, `G = P²(a + Δ)² / (b EI)`, while the recorded debonded length
//! is the physical crack's growth `a − a0`. Fitting the toughness and the modulus to the load alone
//! can absorb `Δ`; the debonded length cannot.

use czid_core::{
    columns, CohesiveLaw, EffectDeclaration, EffectKind, EffectScope, ForwardModel, Parameter, ParameterSpace, Record,
    Sign, SimulationFailure, Typical,
};
use czid_models::laws::Bilinear;
use czid_problems::diagnose::run::{diagnose_subject, Subject};
use czid_problems::diagnose::{Library, Options};
use czid_problems::identification::Setup;
use czid_problems::synthetic::{synthesize, Noise};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The effect the test model declares.
const ROOT_LENGTH: EffectDeclaration = EffectDeclaration {
    name: "root_rotation_length",
    description: "root rotation of the arms, as a length added to the crack in their compliance",
    field: "effects.root_length",
    unit: "mm",
    kind: EffectKind::Size { range: [0.0, 10.0], null: 0.0 },
    scope: EffectScope::Shared,
    typical: Some(Typical { magnitude: [2.0, 5.0], sign: Sign::Positive }),
};

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RootEffects {
    root_length: f64,
}

/// A DCB by simple beam theory (units N, mm, MPa).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BeamTheoryDcb {
    a0: f64,
    width: f64,
    h: f64,
    modulus: f64,
    max_displacement: f64,
    outputs: usize,
    effects: RootEffects,
}

#[typetag::serde(name = "test_beam_theory_dcb")]
impl ForwardModel for BeamTheoryDcb {
    fn name(&self) -> &str {
        "test_beam_theory_dcb"
    }

    fn simulate(&self, law: &dyn CohesiveLaw) -> Result<Record, SimulationFailure> {
        let ei = self.modulus * self.width * self.h.powi(3) / 12.0;
        let g = law.fracture_energy()[0];
        let root = self.effects.root_length;
        let mut r =
            Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N"), (columns::DEBONDED_LENGTH, "mm")]);
        for i in 0..=self.outputs {
            let d = self.max_displacement * i as f64 / self.outputs as f64;
            let arm = self.a0 + root;
            let elastic = 3.0 * ei * d / (2.0 * arm.powi(3));
            let critical = (g * self.width * ei).sqrt() / arm;
            if elastic <= critical {
                r.push(&[d, elastic, 0.0]);
            } else {
                // Propagation at G = G_c: (a + Δ)² = 3 EI δ / (2 √(G b EI)).
                let grown = (3.0 * ei * d / (2.0 * (g * self.width * ei).sqrt())).sqrt();
                r.push(&[d, (g * self.width * ei).sqrt() / grown, grown - root - self.a0]);
            }
        }
        Ok(r)
    }

    fn effects(&self) -> Vec<EffectDeclaration> {
        vec![ROOT_LENGTH]
    }
}

fn setup(root_length: f64) -> Setup {
    let model = BeamTheoryDcb {
        a0: 40.0,
        width: 25.0,
        h: 2.7,
        modulus: 20_000.0,
        max_displacement: 20.0,
        outputs: 400,
        effects: RootEffects { root_length },
    };
    let law: Box<dyn CohesiveLaw> = Box::new(Bilinear::bk(1e5, 30.0, 30.0, 0.8, 2.0, 2.0).unwrap());
    let models: BTreeMap<String, Box<dyn ForwardModel>> =
        [("dcb".to_string(), Box::new(model) as Box<dyn ForwardModel>)].into();
    Setup { law, models }
}

#[test]
fn the_library_offers_what_the_model_declares_and_its_null_is_the_base_model() {
    let base = setup(0.0);
    let library = Library::builtin();
    let c = library.select(&base, &["root_rotation_length".to_string()]).unwrap().remove(0);
    assert!(c.applies(&base));
    assert_eq!(c.describe(), ROOT_LENGTH.description);
    let at_null = c.apply(&base, &[0.0]).unwrap();
    let run = |s: &Setup| s.models["dcb"].simulate(s.law.as_ref()).unwrap();
    assert_eq!(run(&at_null), run(&base));
    assert_ne!(run(&c.apply(&base, &[3.0]).unwrap()), run(&base));
    // Switched on already, it is no longer a candidate for that setup.
    assert!(!c.applies(&setup(3.0)));
}

#[test]
fn a_planted_declared_effect_is_named_by_the_diagnosis() {
    let truth = setup(3.0);
    let record = truth.models["dcb"].simulate(truth.law.as_ref()).unwrap();
    let data = synthesize(&record, 200, None, &Noise { load_sd: 0.3, length_sd: 0.3, seed: 3 }).unwrap();
    let experiment = data.experiment("dcb").unwrap();
    let space = ParameterSpace::new(vec![
        Parameter::new("law.g_ic", "N/mm", 0.2, 2.0),
        Parameter::new("models.*.modulus", "MPa", 10_000.0, 40_000.0),
    ])
    .unwrap();
    let u0 = space.to_unit(&[0.7, 22_000.0]);
    let subject =
        Subject { name: "declared".into(), setup: setup(0.0), space, experiments: vec![experiment], use_length: true };
    let opts = Options { refit: 1, holdout: false, ..Options::default() };
    let d = diagnose_subject(&subject, &u0, &Library::builtin(), &opts).unwrap();
    assert!(!d.base.at_noise_level, "{}", d.verdict);
    assert_eq!(d.candidates[0].name, "root_rotation_length", "{}", d.verdict);
    assert!(d.verdict.contains("Most likely cause: root_rotation_length"), "{}", d.verdict);
    let refit = d.candidates[0].refit.as_ref().unwrap();
    // With it the misfit falls to the noise (χ² with n − 3 degrees of freedom).
    let dof = (d.readings - 3) as f64;
    assert!(czid_problems::diagnose::stats::chi2_survival(refit.chi2, dof) > 1e-3, "{} / {dof}", refit.chi2);
    // The refit finds the planted size.
    let size = refit.effect[0].value;
    assert!((size - 3.0).abs() < 0.3, "{size}");
}
