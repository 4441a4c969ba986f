//! Checks the closed-form references themselves (limits and literature values), so the model
//! tests compare against trustworthy numbers.

mod fe_support;
use fe_support::*;

#[test]
fn timoshenko_foundation_reduces_to_kanninen_without_shear() {
    let arm = Arm { e: 130_000.0, g: 2_700.0e9, b: 20.0, h: 1.62 };
    let kf = 2.0 * 20.0 * 1e5;
    let c = dcb_compliance_foundation(&arm, 50.0, kf);
    let k = kanninen(&arm, 50.0, kf, false);
    assert!((c / k - 1.0).abs() < 1e-6, "{c} vs {k}");
}

#[test]
fn timoshenko_foundation_tends_to_rigid_foundation_limit() {
    let arm = Arm { e: 130_000.0, g: 2_700.0, b: 20.0, h: 1.62 };
    let c = dcb_compliance_foundation(&arm, 50.0, 1e14);
    assert!((c / rigid_foundation(&arm, 50.0) - 1.0).abs() < 1e-4, "{c} {}", rigid_foundation(&arm, 50.0));
    // ... and without shear deformation to the clamped cantilever.
    let stiff = Arm { g: 1e12, ..arm };
    let c = dcb_compliance_foundation(&stiff, 50.0, 1e18);
    assert!((c / clamped(&stiff, 50.0) - 1.0).abs() < 1e-4);
}

#[test]
fn cbt_matches_compdam_reference_values() {
    // DESIGN.md §3: corrected beam theory gives 7.97 N peak and 4.37 N at 4.5 mm.
    let arm = Arm { e: 171_420.0, g: 5_290.0, b: 1.0, h: 3.8 };
    let ae = 50.8 + chi_h(171_420.0, 9_080.0, 5_290.0, 3.8);
    let (_, p) = cbt_branch(&arm, ae, 0.277);
    assert!((p - 7.97).abs() < 0.05, "peak {p}");
    let p45 = cbt_load_at(&arm, 4.5, 0.277);
    assert!((p45 - 4.37).abs() < 0.05, "{p45}");
}
