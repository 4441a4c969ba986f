//! The large-rotation mesh that is fine only around the crack front (`fe::fine_zone`) against the
//! mesh fine everywhere, beyond Hartlen's bilinear runs of `dcb_large_rotation_steps.rs`: the
//! paper's DCB with its steep Table 3 law, both arms meshed, a bridging law whose
//! tail keeps the free arm loaded, and a machine compliance and a root compliance that add
//! unknowns and a law in series.

use czid_core::{columns, CohesiveLaw, Record};
use czid_models::dcb::{self, Dcb, Symmetry};
use czid_models::laws::{Bilinear, Bridging, StCzm};

const FINE: czid_models::fe::RunOptions = czid_models::fe::RunOptions { fine_zone: false, ..dcb::RUN_OPTIONS };

fn col<'a>(r: &'a Record, c: &str) -> &'a [f64] {
    r.column(c).unwrap()
}

/// Runs `d` on both meshes and checks that loads agree within 0.1 % of the peak and debonded
/// lengths within 0.1 % of the length grown.
fn compare(name: &str, d: &Dcb, law: &dyn CohesiveLaw) {
    let zone = dcb::simulate_with_stats(d, law).unwrap();
    let fine = dcb::simulate_with_options(d, law, &FINE).unwrap();
    let (pz, pf) = (col(&zone.0, columns::LOAD), col(&fine.0, columns::LOAD));
    let (az, af) = (col(&zone.0, columns::DEBONDED_LENGTH), col(&fine.0, columns::DEBONDED_LENGTH));
    assert_eq!(pz.len(), pf.len(), "{name}");
    let peak = pf.iter().cloned().fold(0.0, f64::max);
    let load = pz.iter().zip(pf).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / peak;
    let length = az.iter().zip(af).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let grown = af.last().unwrap() - af[0];
    println!(
        "{name}: load within {load:.2e} of the peak, debonded length within {length:.2e} mm of {grown:.1} mm grown; \
         {} against {} assemblies",
        zone.1.assemblies, fine.1.assemblies
    );
    assert!(load <= 1e-3, "{name}: loads differ by {load:.2e} of the peak");
    assert!(length <= 1e-3 * grown.max(1.0), "{name}: debonded lengths differ by {length:.2e} mm");
}

fn hartlen() -> Dcb {
    let mut d = Dcb::hartlen_dcb01();
    d.effects.large_rotation = true;
    d.control.output_points = 60;
    d
}

#[test]
fn the_papers_dcb_with_its_steep_law() {
    let mut d = Dcb::paper();
    d.effects.large_rotation = true;
    d.control.max_displacement = Some(10.0);
    let law = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    compare("paper DCB, Table 3", &d, &law);
}

#[test]
fn both_arms_meshed() {
    let mut d = hartlen();
    d.symmetry = Symmetry::Full;
    compare("DCB-01, both arms", &d, &Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap());
}

#[test]
fn a_bridging_tail_that_keeps_the_free_arm_loaded() {
    let matrix = Bilinear::bk(1e5, 30.0, 40.0, 0.6, 1.2, 2.0).unwrap();
    let law = Bridging::bilinear_with_tail(&matrix, 0.5, 2.0).unwrap();
    compare("DCB-01, bridging", &hartlen(), &law);
}

#[test]
fn machine_and_root_compliance() {
    let mut d = hartlen();
    d.effects.machine_compliance = 2e-3;
    d.effects.root_compliance = 1e-6;
    compare("DCB-01, machine and root compliance", &d, &Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap());
}
