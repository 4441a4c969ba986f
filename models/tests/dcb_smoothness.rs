//! Smoothness in the parameters: central finite differences of the load with respect to the
//! interface strength, at fixed displacements, for two step sizes.
//!
//! Known limitation (measured here and printed): on the propagation branch the discrete crack
//! advances node by node, which superposes a small sawtooth (≈ 0.5 % of the load at 0.1 mm
//! elements with this 2-3 mm process zone) on the curve; finite differences there with steps of
//! 1-2 % of the strength are dominated by it. The assertion covers the loading branch up to the
//! onset of propagation, where the responses are smooth.

mod fe_support;
use czid_core::{columns, ForwardModel, Record};
use czid_models::dcb::Dcb;
use fe_support::{interp, TestBilinear};

fn load_at(strength: f64, xs: &[f64]) -> Vec<f64> {
    let mut d = Dcb::paper();
    d.mesh.interface_element = 0.1;
    d.control.max_displacement = Some(12.5);
    d.control.output_points = 50;
    let rec: Record = d.simulate(&TestBilinear::new(1e5, strength, 0.3)).unwrap_or_else(|f| panic!("{}", f.error));
    let (x, p) = (rec.column(columns::DISPLACEMENT).unwrap(), rec.column(columns::LOAD).unwrap());
    xs.iter().map(|&v| interp(x, p, v)).collect()
}

#[test]
fn load_derivative_with_respect_to_strength_is_step_independent() {
    // Loading branch with a growing process zone (3.5-4.5 mm), the peak (≈ 5 mm) and the
    // propagation branch (8-12 mm).
    let xs = [3.5, 4.0, 4.5, 5.0, 6.0, 8.0, 10.0, 12.0];
    let s = 60.0;
    let fd = |h: f64| -> Vec<f64> {
        let (pp, pm) = (load_at(s + h, &xs), load_at(s - h, &xs));
        pp.iter().zip(&pm).map(|(a, b)| (a - b) / (2.0 * h)).collect()
    };
    let (d1, d2) = (fd(1.2), fd(0.6));
    for ((x, a), b) in xs.iter().zip(&d1).zip(&d2) {
        println!("δ = {x}: dP/dσ = {a:.5e} (h = 2 %), {b:.5e} (h = 1 %), ratio {:.4}", a / b);
    }
    for ((x, a), b) in xs.iter().zip(&d1).zip(&d2).take(3) {
        let scale = a.abs().max(b.abs());
        assert!((a - b).abs() / scale < 0.01, "δ = {x}: {a} vs {b}");
    }
}
