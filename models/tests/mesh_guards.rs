//! Meshes that cannot resolve a law, or would need gigabytes, are refused before anything is
//! allocated; a marginal mesh is noted.

use czid_core::ForwardModel;
use czid_models::dcb::Dcb;
use czid_models::laws::Bilinear;

fn law(strength: f64, g_ic: f64) -> Bilinear {
    Bilinear::bk(1e5, strength, strength, g_ic, 2.0, 2.0).unwrap()
}

#[test]
fn the_interface_element_is_checked_against_the_cohesive_zone() {
    let mut dcb = Dcb::hartlen_dcb01();
    // (E G / σ²)^¼ h^¾ = (19300 · 0.8 / 30²)^¼ · 2.7^¾ ≈ 4.29 mm.
    let zone = dcb.cohesive_zone_length(&law(30.0, 0.8));
    let expected = (19300.0 * 0.8 / 900.0f64).powf(0.25) * 2.7f64.powf(0.75);
    assert!((zone - expected).abs() < 1e-12 && (zone - 4.287).abs() < 1e-3, "{zone}");
    dcb.mesh.interface_element = 0.2;
    assert!(dcb.check_law(&law(30.0, 0.8)).unwrap().is_empty());
    dcb.mesh.interface_element = 2.0;
    let notes = dcb.check_law(&law(30.0, 0.8)).unwrap();
    assert!(notes.len() == 1 && notes[0].contains("2.1 elements"), "{notes:?}");
    dcb.mesh.interface_element = 5.0;
    let err = dcb.check_law(&law(30.0, 0.8)).unwrap_err().to_string();
    assert!(err.contains("mesh.interface_element") && err.contains("at most 1.429 mm"), "{err}");
}

#[test]
fn a_mesh_that_would_take_gigabytes_is_refused_without_allocating_it() {
    let mut dcb = Dcb::hartlen_dcb01();
    // 85 mm of bonded length in 0.5 µm beam elements: 1.7e8 elements, ~145 GB.
    dcb.mesh.interface_element = 2e-3;
    dcb.mesh.interface_subdivision = 4;
    dcb.length = 1.0e4;
    let err = ForwardModel::validate(&dcb).unwrap_err().to_string();
    assert!(err.contains("GB of memory"), "{err}");
    // The bundled mesh passes.
    assert!(ForwardModel::validate(&Dcb::hartlen_dcb01()).is_ok());
}
