//! An identification answers a candidate whose runs take from it what an earlier candidate's
//! took (`ForwardModel::law_key`: a symmetric DCB sees only the law's normal branch) with that
//! candidate's evaluation. Checked here against identifications that run every candidate afresh:
//! the same values and residuals, to the bit, in a batch and one by one, and after the weights
//! change.

use std::collections::BTreeMap;

use czid_core::{CohesiveLaw, Evaluation, ForwardModel, Parameter, ParameterSpace, Problem};
use czid_models::dcb::Dcb;
use czid_models::laws::Bilinear;
use czid_problems::identification::{Identification, Setup};
use czid_problems::synthetic::{synthesize, Noise};

fn identification() -> Identification {
    let mut d = Dcb::hartlen_dcb01();
    d.control.max_displacement = Some(16.0);
    d.control.output_points = 80;
    let law: Box<dyn CohesiveLaw> = Box::new(Bilinear::bk(1e5, 30.0, 30.0, 0.8, 2.0, 2.0).unwrap());
    let models: BTreeMap<String, Box<dyn ForwardModel>> =
        [("dcb".to_string(), Box::new(d) as Box<dyn ForwardModel>)].into();
    let setup = Setup { law, models };
    let record = setup.models["dcb"].simulate(setup.law.as_ref()).unwrap();
    let data = synthesize(&record, 120, Some(16.0), &Noise { load_sd: 0.4, length_sd: 0.3, seed: 3 }).unwrap();
    // Two parameters of the normal branch, two of the shear branch (which this DCB cannot see).
    let space = ParameterSpace::new(vec![
        Parameter::new("law.strength_n", "MPa", 10.0, 60.0),
        Parameter::new("law.g_ic", "N/mm", 0.4, 1.6),
        Parameter::new("law.strength_t", "MPa", 10.0, 80.0),
        Parameter::new("law.g_iic", "N/mm", 1.0, 4.0),
    ])
    .unwrap();
    Identification::new(setup, space, &[data.experiment("dcb").unwrap()], true).unwrap()
}

fn same(a: &Evaluation, b: &Evaluation) -> bool {
    let bits = |e: &Evaluation| {
        let mut v = vec![e.value.to_bits()];
        v.extend(e.objectives.iter().chain(&e.residuals).map(|x| x.to_bits()));
        v
    };
    bits(a) == bits(b)
}

#[test]
fn a_candidate_that_moves_only_what_no_run_sees_gets_the_evaluation_a_run_gives() {
    // u1 and u2 share the normal branch, u3 moves it; u2 comes twice in the batch.
    let u1 = vec![0.4, 0.3, 0.5, 0.5];
    let u2 = vec![0.4, 0.3, 0.9, 0.1];
    let u3 = vec![0.45, 0.3, 0.5, 0.5];
    let batch = vec![u1.clone(), u2.clone(), u3.clone(), u2.clone()];
    let reusing = identification();
    let answers: Vec<Evaluation> = reusing.evaluate_batch(&batch).into_iter().map(|r| r.unwrap()).collect();
    // Each candidate run on an identification of its own, which has nothing to reuse.
    let fresh: Vec<Evaluation> = batch.iter().map(|u| identification().evaluate(u).unwrap()).collect();
    for (k, (a, f)) in answers.iter().zip(&fresh).enumerate() {
        assert!(same(a, f), "candidate {k}: {} against {} run afresh", a.value, f.value);
    }
    assert!(!fresh[0].residuals.is_empty());
    // The physics behind it: the shear branch does not move this DCB's runs, the normal one does.
    assert!(same(&fresh[0], &fresh[1]));
    assert!(fresh[0].value != fresh[2].value);
    // One by one, now from what the batch left.
    for (u, f) in batch.iter().zip(&fresh) {
        assert!(same(&reusing.evaluate(u).unwrap(), f));
    }
}

#[test]
fn evaluations_kept_under_old_weights_are_not_reused() {
    let u = vec![0.4, 0.3, 0.5, 0.5];
    let mut reusing = identification();
    let before = reusing.evaluate(&u).unwrap();
    reusing.set_weights(3.0, 1.0).unwrap();
    let after = reusing.evaluate(&u).unwrap();
    let mut fresh = identification();
    fresh.set_weights(3.0, 1.0).unwrap();
    assert!(same(&after, &fresh.evaluate(&u).unwrap()));
    assert!(after.value != before.value, "the load's weight tripled: {} and {}", before.value, after.value);
}
