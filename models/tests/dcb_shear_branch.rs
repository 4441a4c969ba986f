//! A symmetric DCB opens its interface without shearing it, so its record cannot depend on the
//! law's shear branch: the half model's gaps have an exactly zero shear component and gradient.
//! This is what `Dcb::law_key` claims (and an identification relies on, answering a candidate that
//! moves only the shear branch from one evaluated before). Checked against runs: laws with the
//! same normal branch and shear branches drawn across the identification ranges give the paper's
//! DCB (ST-CZM) and Hartlen's (bilinear, B-K) records equal to the bit, and the keys follow the
//! normal branch only, and only where the model and the law can say.

use czid_core::{CohesiveLaw, ForwardModel, Record};
use czid_models::dcb::{Dcb, Symmetry};
use czid_models::laws::{Bilinear, MixedModeCriterion, StCzm};

/// Every value of the record as bits, column by column.
fn bits(r: &Record) -> Vec<(String, Vec<u64>)> {
    r.columns()
        .iter()
        .map(|c| (c.name.clone(), r.column(&c.name).unwrap().iter().map(|v| v.to_bits()).collect()))
        .collect()
}

/// Runs `dcb` with `base` and each of `others` (the same normal branch), and checks that the
/// records and the keys are the same.
fn same_runs(dcb: &Dcb, base: &dyn CohesiveLaw, others: &[&dyn CohesiveLaw]) {
    let key = dcb.law_key(base).expect("a symmetric DCB and a law that can say");
    let record = bits(&dcb.simulate(base).unwrap());
    assert!(record[0].1.len() > 50, "the run went through the propagation");
    for (k, law) in others.iter().enumerate() {
        assert_eq!(dcb.law_key(*law).as_ref(), Some(&key), "shear branch {k}: the key follows the normal branch only");
        assert!(bits(&dcb.simulate(*law).unwrap()) == record, "shear branch {k}: the record moved");
    }
}

#[test]
fn the_paper_dcb_runs_alike_whatever_the_st_czm_shear_branch() {
    let dcb = Dcb::paper();
    let law = |st: f64, ue: f64, uc: f64| StCzm::sawtooth(27.0, 0.00027, 0.003273, st, ue, uc).unwrap();
    let base = law(40.0, 0.00025, 0.003273);
    // The corners and the middle of the paper problem's shear ranges ([10, 80] MPa, [1e-4, 1e-3]
    // and [1.5e-3, 1e-2] mm).
    let others =
        [law(10.0, 0.0001, 0.0015), law(80.0, 0.001, 0.01), law(33.1, 0.000439, 0.00778), law(60.0, 0.000722, 0.003)];
    let refs: Vec<&dyn CohesiveLaw> = others.iter().map(|l| l as &dyn CohesiveLaw).collect();
    same_runs(&dcb, &base, &refs);
    // A normal branch one unit in the last place away is another key.
    let moved = StCzm::sawtooth(27.0f64.next_up(), 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    assert_ne!(dcb.law_key(&moved), dcb.law_key(&base));
}

#[test]
fn hartlens_dcb_runs_alike_whatever_the_bilinear_shear_branch() {
    let mut dcb = Dcb::hartlen_dcb01();
    dcb.control.max_displacement = Some(16.0);
    let law = |st: f64, giic: f64, eta: f64| Bilinear::bk(1e5, 30.0, st, 0.8, giic, eta).unwrap();
    let base = law(40.0, 1.6, 2.0);
    let others = [law(15.0, 0.9, 0.6), law(90.0, 4.0, 4.0), law(35.0, 3.0, 2.2)];
    let refs: Vec<&dyn CohesiveLaw> = others.iter().map(|l| l as &dyn CohesiveLaw).collect();
    same_runs(&dcb, &base, &refs);
    assert_ne!(dcb.law_key(&law(40.0, 1.6, 2.0)), dcb.law_key(&Bilinear::bk(1e5, 30.0, 40.0, 0.81, 1.6, 2.0).unwrap()));
}

#[test]
fn no_key_where_the_model_or_the_law_cannot_say() {
    let base = Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap();
    // Both arms: the gaps are not shear-free by construction.
    let mut full = Dcb::hartlen_dcb01();
    full.symmetry = Symmetry::Full;
    assert_eq!(full.law_key(&base), None);
    // Large rotations: the co-rotated gaps are not the small-rotation ones.
    let mut large = Dcb::hartlen_dcb01();
    large.effects.large_rotation = true;
    assert_eq!(large.law_key(&base), None);
    // The power-law criterion keeps η in the last digits of G_c even in pure mode I.
    let power = Bilinear { criterion: MixedModeCriterion::PowerLaw, ..base.clone() };
    assert_eq!(power.mode_one_key(), None);
    assert_eq!(Dcb::hartlen_dcb01().law_key(&power), None);
    assert!(Dcb::hartlen_dcb01().law_key(&base).is_some());
}
