//! ST-CZM behaviour from Nairn & Aimene's definition: where damage starts and ends, irreversibility,
//! secant unloading, and the closed-form sawtooth update against the incremental consistency
//! update (Eq. 11 of Shi & Zhang) integrated with shrinking steps.

use czid_core::{CohesiveLaw, Gap, LawState};
use czid_models::laws::{verify, StCzm, StrengthShape};

// Shi & Zhang, Table 3 (shear failure opening changed so the ellipse is not a circle).
const SN: f64 = 27.0;
const UEN: f64 = 0.00027;
const UCN: f64 = 0.003273;
const ST: f64 = 40.0;
const UET: f64 = 0.00025;
const UCT: f64 = 0.0041;

fn law() -> StCzm {
    StCzm::sawtooth(SN, UEN, UCN, ST, UET, UCT).unwrap()
}

fn shaped_laws() -> Vec<StCzm> {
    let exp = StrengthShape::Exponential { alpha: 3.0 };
    let tri = StrengthShape::Trilinear { kink_fraction: 0.3, kink_strength_ratio: 0.4 };
    vec![law(), law().with_shapes(exp, tri).unwrap(), law().with_shapes(tri, exp).unwrap()]
}

/// Radius along direction (cos θ, sin θ) at which `(u_n/a)² + (u_t/b)² = 1`.
fn ellipse_radius(theta: f64, a: f64, b: f64) -> f64 {
    1.0 / ((theta.cos() / a).powi(2) + (theta.sin() / b).powi(2)).sqrt()
}

#[test]
fn damage_starts_on_the_elastic_ellipse_and_completes_on_the_failure_ellipse() {
    for law in shaped_laws() {
        for degrees in [0.0, 10.0, 30.0, 45.0, 60.0, 80.0, 90.0, -35.0] {
            let theta = f64::to_radians(degrees);
            let direction = Gap::new(theta.cos(), theta.sin());
            let damage = |r: f64| law.evaluate(&(r * direction), &LawState::default()).state.damage;
            let onset = ellipse_radius(theta, UEN, UET);
            let failure = ellipse_radius(theta, UCN, UCT);
            assert_eq!(damage(onset * (1.0 - 1e-9)), 0.0, "{degrees}°: no damage inside the elastic ellipse");
            assert!(damage(onset * (1.0 + 1e-6)) > 0.0, "{degrees}°: damage just outside it");
            assert!(damage(failure * (1.0 - 1e-6)) < 1.0, "{degrees}°: not failed inside the failure ellipse");
            assert_eq!(damage(failure * (1.0 + 1e-9)), 1.0, "{degrees}°: failed on it");
        }
    }
}

#[test]
fn compression_never_damages_and_does_not_shift_shear_onset() {
    let law = law();
    // Pure compression, however large: no damage.
    let crushed = law.evaluate(&Gap::new(-10.0 * UCN, 0.0), &LawState::default());
    assert_eq!(crushed.state.damage, 0.0);
    // Under compression the shear onset is the pure-shear one (⟨u_n⟩ = 0).
    let damage = |slip: f64| law.evaluate(&Gap::new(-UEN, slip), &LawState::default()).state.damage;
    assert_eq!(damage(UET * (1.0 - 1e-9)), 0.0);
    assert!(damage(UET * (1.0 + 1e-6)) > 0.0);
}

#[test]
fn damage_never_decreases_and_unloading_follows_the_secant_to_the_origin() {
    for law in shaped_laws() {
        let vertices = [
            Gap::new(0.4 * UCN, 0.1 * UCT),
            Gap::new(0.05 * UCN, -0.3 * UCT),
            Gap::new(-0.2 * UCN, 0.5 * UCT),
            Gap::new(0.6 * UCN, 0.2 * UCT),
            Gap::new(0.0, 0.0),
            Gap::new(0.9 * UCN, 0.6 * UCT),
        ];
        let points = verify::follow_path(&law, &verify::polyline(&vertices, 300));
        let mut previous = 0.0;
        for p in &points {
            assert!(p.state.damage >= previous && p.state.damage <= 1.0, "{:?}", p);
            previous = p.state.damage;
        }
        assert_eq!(previous, 1.0, "the last leg crosses the failure ellipse");

        // Unloading from a damaged point: T(λu) = λ T(u), down to zero at the origin.
        let loaded = law.evaluate(&Gap::new(0.35 * UCN, 0.25 * UCT), &LawState::default());
        assert!(loaded.state.damage > 0.1);
        for lambda in [0.9, 0.5, 0.1, 0.0] {
            let back = law.evaluate(&(lambda * Gap::new(0.35 * UCN, 0.25 * UCT)), &loaded.state);
            assert_eq!(back.state.damage, loaded.state.damage);
            assert!((back.traction - lambda * loaded.traction).norm() <= 1e-12 * loaded.traction.norm());
        }
        // The secant slope is (1 − D) k per mode.
        let k = law.initial_stiffness();
        let back = law.evaluate(&Gap::new(0.1 * UCN, 0.1 * UCT), &loaded.state);
        let intact = 1.0 - loaded.state.damage;
        assert!((back.tangent[(0, 0)] - intact * k[0]).abs() <= 1e-9 * k[0]);
        assert!((back.tangent[(1, 1)] - intact * k[1]).abs() <= 1e-9 * k[1]);
    }
}

/// The sawtooth opening–damage map from the paper's strength model `S = σ (u_c − δ)/(u_c − u_e)`
/// and the secant condition `S(δ) = (1 − D) k δ`: `δ(D) = u_e / (1 − D (1 − u_e/u_c))`, and its
/// derivative.
fn delta(d: f64, u_e: f64, u_c: f64) -> (f64, f64) {
    let c = 1.0 - u_e / u_c;
    (u_e / (1.0 - d * c), u_e * c / (1.0 - d * c).powi(2))
}

/// Integrates Nairn's consistency condition (Eq. 11),
/// `dD = (u_n/δ_n² du_n + u_t/δ_t² du_t) / (u_n² δ_n'/δ_n³ + u_t² δ_t'/δ_t³)`,
/// with forward-Euler steps along `path` (starting on the elastic ellipse).
fn incremental_damage(path: &[Gap]) -> f64 {
    let mut d = 0.0;
    for w in path.windows(2) {
        let (u, du) = (w[0], w[1] - w[0]);
        let ((dn, dn1), (dt, dt1)) = (delta(d, UEN, UCN), delta(d, UET, UCT));
        let numerator = u.x / (dn * dn) * du.x + u.y / (dt * dt) * du.y;
        let denominator = u.x * u.x * dn1 / dn.powi(3) + u.y * u.y * dt1 / dt.powi(3);
        d += (numerator / denominator).max(0.0);
    }
    d
}

#[test]
fn closed_form_sawtooth_update_agrees_with_the_incremental_consistency_update() {
    let law = law();
    // Non-proportional loading: from the onset point at 20° to a point at 65°, well into softening.
    let theta0 = f64::to_radians(20.0);
    let start = ellipse_radius(theta0, UEN, UET) * Gap::new(theta0.cos(), theta0.sin());
    let theta1 = f64::to_radians(65.0);
    let end = 0.55 * ellipse_radius(theta1, UCN, UCT) * Gap::new(theta1.cos(), theta1.sin());

    // The law's closed form (committed along a fine path, though it does not depend on the path
    // while loading).
    let fine: Vec<Gap> = std::iter::once(start).chain(verify::line(start, end, 10_000)).collect();
    let mut state = LawState::default();
    let mut previous_damage = 0.0;
    for g in &fine {
        state = law.evaluate(g, &state).state;
        assert!(state.damage >= previous_damage);
        previous_damage = state.damage;
    }
    let closed = state.damage;
    assert!(closed > 0.3 && closed < 0.95, "test path should reach mid softening: D = {closed}");
    assert_eq!(law.evaluate(&end, &LawState::default()).state.damage, closed, "no path dependence while loading");

    let mut errors = Vec::new();
    for steps in [10, 100, 1_000, 10_000, 100_000] {
        let path: Vec<Gap> = std::iter::once(start).chain(verify::line(start, end, steps)).collect();
        errors.push((incremental_damage(&path) - closed).abs());
    }
    println!("incremental vs closed form, steps 10..1e5: {errors:?}");
    for pair in errors.windows(2) {
        // Forward Euler is first order: ten times the steps, about a tenth of the error.
        assert!(pair[1] < 0.2 * pair[0], "error must shrink with the step: {errors:?}");
    }
    assert!(errors[4] < 1e-5, "{errors:?}");
}

#[test]
fn paper_parameter_mapping() {
    // Table 3 of Shi & Zhang: k_n0 = σ_n,c / Δu_n,f = 27 / 0.00027 = 1e5, k_t0 = 40 / 0.00025 = 1.6e5.
    let law = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let k = law.initial_stiffness();
    assert!((k[0] - 1e5).abs() < 1e-6 && (k[1] - 1.6e5).abs() < 1e-6);
    // G = ½ σ Δu_c: ≈ 0.044 N/mm in mode I (the sanity figure of the design notes).
    assert!((law.fracture_energy()[0] - 0.0441855).abs() < 1e-9);
    assert_eq!(law.strength(), [27.0, 40.0]);
}
