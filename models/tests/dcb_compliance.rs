//! Pre-crack compliance of the DCB against closed forms.
//!
//! Reference: two Timoshenko arms (κ = 5/6) of free length a0 on a Winkler foundation, solved in
//! closed form in `fe_support::dcb_compliance_foundation` (Kanninen's 1973 model with the arms'
//! shear deformation; it reduces to Kanninen's formula for G → ∞). In the half model the
//! foundation of one arm is the interface penalty acting on twice the arm deflection:
//! k_f = 2 b k_n per unit length.

mod fe_support;
use czid_core::{columns, ForwardModel};
use czid_models::dcb::{Dcb, Symmetry};
use fe_support::*;

fn compliance(dcb: &Dcb, law: &TestBilinear) -> f64 {
    let rec = dcb.simulate(law).unwrap_or_else(|f| panic!("{}", f.error));
    let d = rec.column(columns::DISPLACEMENT).unwrap();
    let p = rec.column(columns::LOAD).unwrap();
    d.last().unwrap() / p.last().unwrap()
}

fn elastic_paper(kn: f64) -> (Dcb, TestBilinear) {
    let mut dcb = Dcb::paper();
    dcb.control.max_displacement = Some(0.2);
    dcb.control.output_points = 2;
    // Strength far above anything reached: the interface stays elastic.
    (dcb, TestBilinear::new(kn, 1e6, 1e6))
}

fn paper_arm() -> Arm {
    Arm { e: 130_000.0, g: 2_700.0, b: 20.0, h: 1.62 }
}

#[test]
fn paper_dcb_precrack_compliance_matches_timoshenko_on_foundation() {
    let (dcb, law) = elastic_paper(1e5);
    let c = compliance(&dcb, &law);
    let reference = dcb_compliance_foundation(&paper_arm(), 50.0, 2.0 * 20.0 * 1e5);
    let kan = kanninen(&paper_arm(), 50.0, 2.0 * 20.0 * 1e5, true);
    let err = c / reference - 1.0;
    println!("C = {c:.6e} mm/N, reference {reference:.6e} (error {:.4} %), Kanninen + shear {kan:.6e}", 100.0 * err);
    assert!(err.abs() < 0.01, "compliance error {err}");
}

#[test]
fn full_model_equals_half_model_for_equal_arms() {
    let (dcb, law) = elastic_paper(1e5);
    let mut full = dcb.clone();
    full.symmetry = Symmetry::Full;
    let (ch, cf) = (compliance(&dcb, &law), compliance(&full, &law));
    // Equal to round-off: the full model carries axial unknowns, whose stiffness EA/l at the
    // 0.025 mm beam elements of the bonded region makes its system far worse conditioned (the
    // difference is 1e-8 at 0.1 mm elements).
    assert!((ch / cf - 1.0).abs() < 1e-6, "{ch} vs {cf}");
}

#[test]
fn stiff_interface_tends_to_rigid_foundation_limit() {
    let (dcb, law) = elastic_paper(1e9);
    let c = compliance(&dcb, &law);
    let limit = rigid_foundation(&paper_arm(), 50.0);
    let err = c / limit - 1.0;
    println!(
        "stiff interface: C = {c:.6e}, limit {limit:.6e} ({:.4} %), clamped {:.6e}",
        100.0 * err,
        clamped(&paper_arm(), 50.0)
    );
    assert!(err.abs() < 0.01, "{err}");
    // Stiffening the shear (G13 × 100) removes the root rotation: the limit approaches the
    // clamped Euler–Bernoulli cantilever (within 3 ℓ/a = 2 % here, ℓ = √(EI/κGA)).
    let mut stiff = dcb.clone();
    stiff.material.g13 = 2.7e5;
    let arm = Arm { g: 2.7e5, ..paper_arm() };
    let c = compliance(&stiff, &law);
    let err = c / rigid_foundation(&arm, 50.0) - 1.0;
    println!(
        "stiff shear: C = {c:.6e}, limit {:.6e} ({:.4} %), clamped {:.6e}",
        rigid_foundation(&arm, 50.0),
        100.0 * err,
        clamped(&arm, 50.0)
    );
    assert!(err.abs() < 0.01, "{err}");
    assert!((c / clamped(&arm, 50.0) - 1.0).abs() < 0.03);
}
