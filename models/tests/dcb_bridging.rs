//! A DCB (and an ENF) whose law carries a fibre-bridging tail (the diagnosis's bridging
//! candidate). As the tail's strength goes to zero the record approaches the matrix law's own,
//! continuously, on a steep matrix law too, the debonded length included (the matrix crack, the
//! law's visible front). The matrix's failure is a kink of the combined law that its damage does
//! not mark; without a segment front there the kink moved point by point, and these runs either
//! failed or jumped away from the matrix law's record (`CohesiveLaw::inner_kinks`).
use czid_core::{CohesiveLaw, ForwardModel};
use czid_models::dcb::Dcb;
use czid_models::laws::Bilinear;

/// Load (N) and debonded length (mm) at the last reading of a run to 12 mm.
fn last_reading(d: &Dcb, law: &dyn CohesiveLaw) -> (f64, f64) {
    let r = d.simulate(law).unwrap();
    let last = |name: &str| *r.column(name).unwrap().last().unwrap();
    (last("load"), last("debonded_length"))
}

#[test]
fn a_vanishing_bridging_tail_approaches_the_matrix_law_continuously() {
    // Hartlen's DCB-01 with its example's law, and with stiff arms and a strong, brittle matrix
    // (a base fit at the bounds of the example's ranges).
    for (e11, strength, g_ic) in [(19_300.0, 30.0, 0.8), (50_000.0, 40.26, 0.2)] {
        let mut d = Dcb::hartlen_dcb01();
        d.material.e11 = e11;
        d.control.max_displacement = Some(12.0);
        let matrix = Bilinear::bk(1e5, strength, 30.0, g_ic, 2.0, 2.0).unwrap();
        let tail = |s: f64| matrix.with_bridging_tail(s, 1.609).unwrap().unwrap();
        let (p0, a0) = last_reading(&d, &matrix);
        let (p_small, a_small) = last_reading(&d, tail(1e-6).as_ref());
        let (p_large, a_large) = last_reading(&d, tail(1e-4).as_ref());
        // Linear in the tail's strength near zero: at 10⁻⁶ MPa a hundredth of the change at 10⁻⁴.
        let ratio = (p_small - p0) / (p_large - p0);
        assert!(
            p_large > p0 && (ratio - 0.01).abs() < 0.003,
            "E11 {e11}: P {p0} N without the tail, {p_small} and {p_large} N with 1e-6 and 1e-4 MPa (ratio {ratio})"
        );
        // The debonded length is the matrix crack's (the law's visible front), with or without
        // the tail: it too changes linearly, the bridging tractions holding the crack back.
        let ratio = (a_small - a0) / (a_large - a0);
        assert!(
            a_large < a0 && (ratio - 0.01).abs() < 0.003,
            "E11 {e11}: a {a0} mm without the tail, {a_small} and {a_large} mm with 1e-6 and 1e-4 MPa (ratio {ratio})"
        );
    }
}

#[test]
fn an_enf_measures_the_matrix_crack_of_a_bridging_law_too() {
    // Hartlen's ENF-03 with a mode II toughness that lets the crack grow stably to the nose.
    let e = czid_models::enf::Enf::hartlen_enf03();

    let matrix = Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap();
    let tail = |s: f64| matrix.with_bridging_tail(s, 1.609).unwrap().unwrap();
    let reading = |law: &dyn CohesiveLaw| {
        let r = e.simulate(law).unwrap();
        let last = |name: &str| *r.column(name).unwrap().last().unwrap();
        (last("load"), last("debonded_length"))
    };
    let (p0, a0) = reading(&matrix);
    let (p_small, a_small) = reading(tail(1e-6).as_ref());
    let (p_large, a_large) = reading(tail(1e-4).as_ref());
    // The tail has failed nowhere, yet the crack the record measures is the matrix's: with a
    // vanishing tail it is the matrix law's crack, and both readings move linearly in the tail.
    let (ratio_p, ratio_a) = ((p_small - p0) / (p_large - p0), (a_small - a0) / (a_large - a0));
    assert!(a0 > 20.0, "ENF: the matrix law's crack grew by {a0} mm only");
    assert!(
        (ratio_p - 0.01).abs() < 0.003 && (ratio_a - 0.01).abs() < 0.003,
        "ENF: P {p0}, {p_small}, {p_large} N; a {a0}, {a_small}, {a_large} mm (ratios {ratio_p}, {ratio_a})"
    );
}

#[test]
fn the_visible_front_level_is_the_damage_where_the_matrix_fails_in_the_tests_mode() {
    use czid_models::fe::crack::visible_front_level;
    use czid_models::laws::Bridging;
    // Matrix 30 / 45 MPa, 0.25 / 0.8 N/mm; tail 3 / 4.5 MPa, 0.5 / 1.0 N/mm; penalties split
    // in the ratio of the strengths (1e5 in all).
    let law = Bridging::trilinear(1e5, [30.0, 45.0, 0.25, 0.8], [3.0, 4.5, 0.5, 1.0], 2.0).unwrap();
    let k_tail = 1e5 * 3.0 / 33.0;
    // Where the matrix fails (δ_c = 2 G / σ) the tail, on its linear softening branch, carries
    // t_b = σ_b (δ_f − δ_c) / (δ_f − δ_0), and the combined damage is 1 − t_b / (K δ_c).
    let level = |sigma_m: f64, g_m: f64, sigma_b: f64, g_b: f64| {
        let dc = 2.0 * g_m / sigma_m;
        let (d0, df) = (sigma_b / k_tail, 2.0 * g_b / sigma_b);
        1.0 - sigma_b * (df - dc) / (df - d0) / (1e5 * dc)
    };
    let (opening, slip) = (visible_front_level(&law, 0).unwrap(), visible_front_level(&law, 1).unwrap());
    assert!((opening - level(30.0, 0.25, 3.0, 0.5)).abs() < 1e-9, "opening: {opening}");
    assert!((slip - level(45.0, 0.8, 4.5, 1.0)).abs() < 1e-9, "slip: {slip}");
    // A law without a visible front other than complete failure has none.
    assert_eq!(visible_front_level(&Bilinear::bk(1e5, 30.0, 45.0, 0.25, 0.8, 2.0).unwrap(), 0), None);
}
