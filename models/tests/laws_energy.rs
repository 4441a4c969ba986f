//! Pure-mode energies and peak tractions against closed forms and MOOSE's reference values.
//! Expected numbers are computed here from the laws' published definitions, never by the laws.

use czid_core::{CohesiveLaw, Gap, LawState, Traction};
use czid_models::laws::verify::{self, pure_mode_energy, Mode};
use czid_models::laws::{Bilinear, Bridging, Exponential, MixedModeCriterion, StCzm, StrengthShape};
use std::f64::consts::E;

const TOLERANCE: f64 = 1e-6;
const STEPS: usize = 40_000;

fn assert_relative(value: f64, expected: f64, tolerance: f64, what: &str) {
    let error = (value - expected).abs() / expected.abs();
    assert!(error <= tolerance, "{what}: {value} vs {expected} (relative error {error:e})");
}

/// Work done along a radial path from the origin to `end`, with the damage there.
fn radial_work(law: &dyn CohesiveLaw, end: Gap) -> (f64, f64) {
    let points = verify::follow_path(law, &verify::line(Gap::zeros(), end, STEPS));
    let last = points.last().unwrap();
    (last.work, last.state.damage)
}

fn moose_law() -> Bilinear {
    Bilinear::bk(100.0, 1.0, 1.0, 1.0, 2.0, 2.0).unwrap()
}

#[test]
fn bilinear_reproduces_moose_energy_values() {
    let law = moose_law();
    // (direction, expected dissipated energy, expected final effective separation), from MOOSE's
    // BiLinearMixedModeTraction energy tests.
    let s = std::f64::consts::FRAC_1_SQRT_2;
    for (direction, energy, separation) in [([1.0, 0.0], 1.0, 2.0), ([0.0, 1.0], 2.0, 4.0), ([s, s], 1.25, 2.5)] {
        let direction = Gap::new(direction[0], direction[1]);
        let (work, damage) = radial_work(&law, 1.1 * separation * direction);
        assert_eq!(damage, 1.0);
        assert_relative(work, energy, TOLERANCE, &format!("energy along {direction:?}"));
        // Separation completes exactly at the stated effective opening.
        let before = law.evaluate(&((separation * (1.0 - 1e-9)) * direction), &LawState::default());
        let after = law.evaluate(&((separation * (1.0 + 1e-9)) * direction), &LawState::default());
        assert!(before.state.damage < 1.0 && before.traction.norm() > 0.0, "{direction:?}");
        assert_eq!(after.state.damage, 1.0, "{direction:?}");
        assert_eq!(after.traction.norm(), 0.0, "{direction:?}");
    }
    assert_eq!(law.fracture_energy(), [1.0, 2.0]);
}

#[test]
fn bilinear_power_law_mixed_mode_energy() {
    let law = moose_law().with_criterion(MixedModeCriterion::PowerLaw).unwrap();
    // Radial path at 30° from the normal: G_II/G_T = sin²30° = 1/4, and the power law with η = 2
    // gives (G_I/G_Ic)² + (G_II/G_IIc)² = 1 with G_I = 3/4 G_c, G_II = 1/4 G_c.
    let mixity: f64 = 0.25;
    let expected = 1.0 / (((1.0 - mixity) / 1.0).powi(2) + (mixity / 2.0).powi(2)).sqrt();
    let direction = Gap::new(30f64.to_radians().cos(), 30f64.to_radians().sin());
    let (work, damage) = radial_work(&law, 5.0 * direction);
    assert_eq!(damage, 1.0);
    assert_relative(work, expected, TOLERANCE, "power law at 30°");
    // Each component's share of the work matches the mixity.
    let points = verify::follow_path(&law, &verify::line(Gap::zeros(), 5.0 * direction, STEPS));
    let mut normal_work = 0.0;
    let mut previous = (Gap::zeros(), Traction::zeros());
    for p in &points {
        normal_work += 0.5 * (p.traction.x + previous.1.x) * (p.gap.x - previous.0.x);
        previous = (p.gap, p.traction);
    }
    assert_relative(normal_work / work, 1.0 - mixity, 1e-6, "normal share of the work");
}

#[test]
fn st_czm_sawtooth_dissipates_half_strength_times_failure_opening() {
    for (sn, uen, ucn, st, uet, uct) in
        [(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273), (12.0, 0.02513, 0.1457, 14.0, 0.02897, 0.1504)]
    {
        let law = StCzm::sawtooth(sn, uen, ucn, st, uet, uct).unwrap();
        for (mode, strength, u_c) in [(Mode::Normal, sn, ucn), (Mode::Shear, st, uct)] {
            let check = pure_mode_energy(&law, mode, 1.2 * u_c, STEPS);
            assert_eq!(check.final_damage, 1.0);
            assert_relative(check.computed, 0.5 * strength * u_c, TOLERANCE, &format!("{mode:?}"));
            assert_relative(check.expected, 0.5 * strength * u_c, 1e-14, "fracture_energy()");
        }
    }
}

/// `∫₀^{u_c} S dδ` by composite Simpson on a strength curve defined here.
fn integrate(curve: impl Fn(f64) -> f64, u_e: f64, u_c: f64) -> f64 {
    let simpson = |a: f64, b: f64, n: usize| {
        let h = (b - a) / n as f64;
        let mut sum = curve(a) + curve(b);
        for i in 1..n {
            sum += curve(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        sum * h / 3.0
    };
    simpson(0.0, u_e, 2) + simpson(u_e, u_c, 200_000)
}

#[test]
fn st_czm_exponential_and_trilinear_shapes_dissipate_the_area_under_their_curves() {
    let (sigma, u_e, u_c) = (27.0, 0.00027, 0.003273);
    for alpha in [0.3, 2.0, 7.0, 25.0] {
        // Exponential strength model: σ at u_e, zero at u_c, decay rate α.
        let curve = |d: f64| {
            if d <= u_e {
                sigma * d / u_e
            } else {
                let x = (d - u_e) / (u_c - u_e);
                sigma * ((-alpha * x).exp() - (-alpha).exp()) / (1.0 - (-alpha).exp())
            }
        };
        let area = integrate(curve, u_e, u_c);
        // Closed form of the same area, for comparison: ½σu_e + σ L (1/α − 1/(e^α − 1)).
        let closed = 0.5 * sigma * u_e + sigma * (u_c - u_e) * (1.0 / alpha - 1.0 / alpha.exp_m1());
        assert_relative(area, closed, 1e-9, "closed form of the exponential area");
        let shape = StrengthShape::Exponential { alpha };
        let law = StCzm::sawtooth(sigma, u_e, u_c, 40.0, 0.00025, 0.003).unwrap().with_shapes(shape, shape).unwrap();
        let check = pure_mode_energy(&law, Mode::Normal, 1.1 * u_c, STEPS);
        assert_relative(check.computed, area, TOLERANCE, &format!("exponential α = {alpha}"));
        assert_relative(check.expected, area, 1e-9, "fracture_energy() of the exponential shape");
        // Peak traction equals the strength, reached at the elastic limit.
        let peak = law.evaluate(&Gap::new(u_e, 0.0), &LawState::default()).traction.x;
        assert_relative(peak, sigma, 1e-12, "peak");
    }
    // Trilinear: polygon (0,0) – (u_e, σ) – (kink, rσ) – (u_c, 0).
    let (fraction, ratio) = (0.2, 0.3);
    let kink = u_e + fraction * (u_c - u_e);
    let polygon = [(0.0, 0.0), (u_e, sigma), (kink, ratio * sigma), (u_c, 0.0)];
    let area: f64 = polygon.windows(2).map(|w| 0.5 * (w[1].0 - w[0].0) * (w[1].1 + w[0].1)).sum();
    let shape = StrengthShape::Trilinear { kink_fraction: fraction, kink_strength_ratio: ratio };
    let law = StCzm::sawtooth(40.0, 0.00025, 0.003, sigma, u_e, u_c).unwrap().with_shapes(shape, shape).unwrap();
    let check = pure_mode_energy(&law, Mode::Shear, 1.1 * u_c, STEPS);
    assert_relative(check.computed, area, TOLERANCE, "trilinear");
    assert_relative(check.expected, area, 1e-12, "fracture_energy() of the trilinear shape");
    // The traction at the kink is rσ.
    let at_kink = law.evaluate(&Gap::new(0.0, kink), &LawState::default()).traction.y;
    assert_relative(at_kink, ratio * sigma, 1e-9, "traction at the kink");
}

#[test]
fn exponential_law_peaks_at_its_strength_and_releases_e_sigma_delta() {
    let (sn, dn, st, dt) = (30.0, 0.001, 40.0, 0.002);
    let law = Exponential::new(sn, dn, st, dt).unwrap();
    for (mode, sigma, delta) in [(Mode::Normal, sn, dn), (Mode::Shear, st, dt)] {
        // Traction e σ (u/δ) e^{−u/δ}: peak σ at u = δ; work of separation e σ δ. The law stops at
        // 20 δ, leaving out 21 e^{−20} ≈ 4.3e−8 of it.
        let check = pure_mode_energy(&law, mode, 21.0 * delta, STEPS);
        assert_eq!(check.final_damage, 1.0);
        assert_relative(check.computed, E * sigma * delta, TOLERANCE, &format!("{mode:?} work"));
        assert_relative(check.expected, E * sigma * delta, TOLERANCE, "fracture_energy()");
        let i = mode.index();
        let at = |u: f64| law.evaluate(&mode.gap(u), &LawState::default()).traction[i];
        assert_relative(at(delta), sigma, 1e-14, "peak value");
        assert!(at(delta * 0.999) < at(delta) && at(delta * 1.001) < at(delta), "peak position");
        assert_relative(at(0.3 * delta), E * sigma * 0.3 * (-0.3f64).exp(), 1e-14, "traction on the rising branch");
    }
}

#[test]
fn bridging_energy_is_matrix_plus_bridging() {
    let (k, matrix, fibres) = (1e5, [30.0, 45.0, 0.25, 0.8], [3.0, 4.5, 0.5, 1.0]);
    let law = Bridging::trilinear(k, matrix, fibres, 2.0).unwrap();
    for (mode, i) in [(Mode::Normal, 0), (Mode::Shear, 1)] {
        let expected = matrix[2 + i] + fibres[2 + i];
        let tail = 2.0 * fibres[2 + i] / fibres[i];
        let check = pure_mode_energy(&law, mode, 1.05 * tail, STEPS);
        assert_eq!(check.final_damage, 1.0);
        assert_relative(check.computed, expected, TOLERANCE, &format!("{mode:?}"));
        // Trilinear: both parts peak together, so the peak is the sum of the strengths, reached at
        // the opening (σ_matrix + σ_bridging)/K.
        let peak_opening = (matrix[i] + fibres[i]) / k;
        let peak = law.evaluate(&mode.gap(peak_opening), &LawState::default()).traction[i];
        assert_relative(peak, matrix[i] + fibres[i], 1e-12, "peak");
        assert_relative(law.strength()[i], matrix[i] + fibres[i], 1e-12, "strength()");
    }
}

#[test]
fn bridging_damage_is_one_only_when_both_parts_failed() {
    let law = Bridging::trilinear(1e5, [30.0, 45.0, 0.25, 0.8], [3.0, 4.5, 0.5, 1.0], 2.0).unwrap();
    let matrix_gone = 2.0 * 0.25 / 30.0;
    let fibres_gone = 2.0 * 0.5 / 3.0;
    let between = law.evaluate(&Gap::new(0.5 * (matrix_gone + fibres_gone), 0.0), &LawState::default());
    assert_eq!(between.state.history[0], 1.0, "matrix failed");
    assert!(between.state.history[1] < 1.0 && between.state.damage < 1.0, "{:?}", between.state);
    assert!(between.traction.x > 0.0);
    let beyond = law.evaluate(&Gap::new(1.01 * fibres_gone, 0.0), &LawState::default());
    assert_eq!(beyond.state.damage, 1.0);
}
