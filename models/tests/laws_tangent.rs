//! Every law's tangent equals central finite differences of its traction (norm-based relative
//! error ≤ 1e-6) along loading, unloading, reloading, compression and mixed-mode paths.

use czid_core::{CohesiveLaw, Gap, LawState};
use czid_models::laws::verify::{self, worst_tangent_along};
use czid_models::laws::{Bilinear, Bridging, Exponential, MixedModeCriterion, StCzm, StrengthShape};

const TOLERANCE: f64 = 1e-6;

/// Each law with the openings `[normal, shear]` (mm) at which it has fully separated in pure mode,
/// computed here from the laws' definitions.
fn laws() -> Vec<(&'static str, Box<dyn CohesiveLaw>, [f64; 2])> {
    let table3 = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let table8 = StCzm::sawtooth(12.0, 0.02513, 0.1457, 14.0, 0.02897, 0.1504).unwrap();
    let shaped = table3
        .clone()
        .with_shapes(
            StrengthShape::Exponential { alpha: 4.0 },
            StrengthShape::Trilinear { kink_fraction: 0.15, kink_strength_ratio: 0.35 },
        )
        .unwrap();
    let shaped_swapped = table8
        .clone()
        .with_shapes(
            StrengthShape::Trilinear { kink_fraction: 0.4, kink_strength_ratio: 1.0 },
            StrengthShape::Exponential { alpha: 0.7 },
        )
        .unwrap();
    let moose = Bilinear::bk(100.0, 1.0, 1.0, 1.0, 2.0, 2.0).unwrap();
    let carbon = Bilinear::bk(1e5, 30.0, 45.0, 0.28, 0.9, 2.1).unwrap();
    let power = carbon.clone().with_criterion(MixedModeCriterion::PowerLaw).unwrap();
    let exponential = Exponential::new(30.0, 0.001, 40.0, 0.002).unwrap();
    let bridging = Bridging::trilinear(1e5, [30.0, 45.0, 0.25, 0.8], [3.0, 4.5, 0.5, 1.0], 2.0).unwrap();
    let mismatched = Bridging::new(carbon.clone(), Bilinear::bk(2e3, 2.0, 5.0, 0.4, 1.1, 1.5).unwrap()).unwrap();
    vec![
        ("st_czm table 3", Box::new(table3), [0.003273, 0.003273]),
        ("st_czm table 8", Box::new(table8), [0.1457, 0.1504]),
        ("st_czm exponential/trilinear", Box::new(shaped), [0.003273, 0.003273]),
        ("st_czm trilinear/exponential", Box::new(shaped_swapped), [0.1457, 0.1504]),
        ("bilinear moose", Box::new(moose), [2.0, 4.0]),
        ("bilinear carbon", Box::new(carbon), [2.0 * 0.28 / 30.0, 2.0 * 0.9 / 45.0]),
        ("bilinear power law", Box::new(power), [2.0 * 0.28 / 30.0, 2.0 * 0.9 / 45.0]),
        ("exponential", Box::new(exponential), [20.0 * 0.001, 20.0 * 0.002]),
        ("bridging trilinear", Box::new(bridging), [2.0 * 0.5 / 3.0, 2.0 * 1.0 / 4.5]),
        ("bridging mismatched", Box::new(mismatched), [2.0 * 0.4 / 2.0, 2.0 * 1.1 / 5.0]),
    ]
}

/// Paths as vertices in units of the separation openings; the odd fractions keep path points off
/// the laws' break points.
fn paths() -> Vec<(&'static str, Vec<[f64; 2]>)> {
    vec![
        ("mode I loading", vec![[0.93, 0.0]]),
        ("mode I unload and reload", vec![[0.413, 0.0], [0.121, 0.0], [0.687, 0.0], [0.0, 0.0], [0.871, 0.0]]),
        ("mode II loading under compression", vec![[-0.0191, 0.917]]),
        ("mode II unload, reverse, reload", vec![[0.0093, 0.377], [0.0093, -0.213], [0.0093, 0.781]]),
        ("radial mixed 30°", vec![[0.757, 0.437]]),
        ("radial mixed 60°, unload, reload", vec![[0.233, 0.403], [0.07, 0.121], [0.451, 0.781]]),
        ("compression then shear", vec![[-0.0413, 0.0], [-0.0413, 0.631], [0.2, 0.617]]),
        ("non-proportional", vec![[0.297, 0.0], [0.311, 0.353], [0.051, 0.587], [0.583, -0.219], [0.917, 0.0]]),
    ]
}

#[test]
fn tangent_matches_finite_differences_on_every_path() {
    for (law_name, law, separation) in laws() {
        for (path_name, vertices) in paths() {
            let vertices: Vec<Gap> =
                vertices.iter().map(|v| Gap::new(v[0] * separation[0], v[1] * separation[1])).collect();
            let path = verify::polyline(&vertices, 211);
            let (worst, skipped) = worst_tangent_along(law.as_ref(), &path);
            let worst = worst.expect("at least one smooth point");
            assert!(
                worst.relative_error <= TOLERANCE,
                "{law_name}, {path_name}: tangent error {:e} at {:?}\nanalytic {}\nfinite difference {}",
                worst.relative_error,
                worst.gap,
                worst.analytic,
                worst.finite_difference
            );
            // Kinks are isolated points (onset, reversal, closure, separation), never a stretch.
            assert!(skipped <= 8, "{law_name}, {path_name}: {skipped} of {} points flagged as kinks", path.len());
        }
    }
}

#[test]
fn unloading_uses_the_damaged_secant_and_loading_an_unsymmetric_tangent() {
    for (law_name, law, separation) in laws() {
        let peak = Gap::new(0.35 * separation[0], 0.3 * separation[1]);
        let loaded = law.evaluate(&peak, &LawState::default());
        let damage = loaded.state.damage;
        assert!(damage > 0.0 && damage < 1.0, "{law_name}: damage {damage} at the test point");
        // Damage grows along a mixed path: the consistent tangent is unsymmetric.
        let k = loaded.tangent;
        assert!((k[(0, 1)] - k[(1, 0)]).abs() > 1e-6 * k.norm(), "{law_name}: tangent {k}");
        // Back to half the gap: secant response, tangent diagonal, same damage.
        let back = law.evaluate(&(0.5 * peak), &loaded.state);
        assert_eq!(back.state.damage, damage, "{law_name}");
        assert_eq!(back.tangent[(0, 1)], 0.0, "{law_name}");
        assert_eq!(back.tangent[(1, 0)], 0.0, "{law_name}");
        assert!((back.traction - 0.5 * loaded.traction).norm() <= 1e-12 * loaded.traction.norm(), "{law_name}");
    }
}

#[test]
fn compression_meets_the_undamaged_penalty() {
    for (law_name, law, separation) in laws() {
        let k_n = law.initial_stiffness()[0];
        // Damage the interface first, then close it.
        let damaged = law.evaluate(&Gap::new(0.5 * separation[0], 0.0), &LawState::default()).state;
        assert!(damaged.damage > 0.0, "{law_name}");
        let closed = law.evaluate(&Gap::new(-0.01 * separation[0], 0.0), &damaged);
        assert_eq!(closed.state.damage, damaged.damage, "{law_name}: compression must not damage");
        assert!((closed.traction[0] + 0.01 * separation[0] * k_n).abs() <= 1e-12 * k_n * separation[0], "{law_name}");
        assert_eq!(closed.tangent[(0, 0)], k_n, "{law_name}");
    }
}
