//! A DCB whose law carries a fibre-bridging tail (the diagnosis's bridging candidate). As the
//! tail's strength goes to zero the record approaches the matrix law's own, continuously, on a
//! steep matrix law too. The matrix's failure is a kink of the combined law that its damage does
//! not mark; without a segment front there the kink moved point by point, and these runs either
//! failed or jumped away from the matrix law's record (`CohesiveLaw::inner_kinks`).
use czid_core::{CohesiveLaw, ForwardModel};
use czid_models::dcb::Dcb;
use czid_models::laws::Bilinear;

/// Load (N) at the last reading of a run to 12 mm.
fn last_load(d: &Dcb, law: &dyn CohesiveLaw) -> f64 {
    let r = d.simulate(law).unwrap();
    *r.column("load").unwrap().last().unwrap()
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
        let p0 = last_load(&d, &matrix);
        let (p_small, p_large) = (last_load(&d, tail(1e-6).as_ref()), last_load(&d, tail(1e-4).as_ref()));
        // Linear in the tail's strength near zero: at 10⁻⁶ MPa a hundredth of the change at 10⁻⁴.
        let ratio = (p_small - p0) / (p_large - p0);
        assert!(
            p_large > p0 && (ratio - 0.01).abs() < 0.003,
            "E11 {e11}: P {p0} N without the tail, {p_small} and {p_large} N with 1e-6 and 1e-4 MPa (ratio {ratio})"
        );
    }
}
