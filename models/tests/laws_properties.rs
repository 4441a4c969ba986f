//! Property tests: for random valid parameters and random gap histories, every law keeps finite
//! tractions and tangents, damage in [0, 1] and non-decreasing, non-negative stored energy, and
//! never creates energy (work − stored energy ≥ 0 up to roundoff).
//!
//! The work is integrated here with the trapezoidal rule on paths whose steps never cross zero in
//! either component (crossings are inserted as path points). For any secant-damage law the
//! trapezoidal dissipation of a step is then `½ Σ_m ΔS_m u_m,k u_m,k+1 ≥ 0` exactly, with `ΔS_m`
//! the loss of secant stiffness, so a negative value beyond roundoff is a genuine defect, not
//! integration error.

use czid_core::{CohesiveLaw, Gap};
use czid_models::laws::verify::{self, Mode};
use czid_models::laws::{Bilinear, Bridging, Exponential, LuBondSlip, MixedModeCriterion, StCzm, StrengthShape};
use proptest::prelude::*;

/// Log-uniform in `[lo, hi]`.
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (0.0..=1.0f64).prop_map(move |x| (lo.ln() + x * (hi.ln() - lo.ln())).exp())
}

fn shape() -> impl Strategy<Value = StrengthShape> {
    prop_oneof![
        Just(StrengthShape::Sawtooth),
        log_uniform(0.01, 40.0).prop_map(|alpha| StrengthShape::Exponential { alpha }),
        (0.01..0.99f64, 0.01..=1.0f64).prop_map(|(kink_fraction, kink_strength_ratio)| StrengthShape::Trilinear {
            kink_fraction,
            kink_strength_ratio
        }),
    ]
}

fn st_czm() -> impl Strategy<Value = StCzm> {
    let mode = || (log_uniform(0.5, 200.0), log_uniform(1e-5, 0.1), log_uniform(1.01, 200.0), shape());
    (mode(), mode()).prop_map(|((sn, uen, rn, shn), (st, uet, rt, sht))| StCzm {
        strength_n: sn,
        u_e_n: uen,
        u_c_n: uen * rn,
        strength_t: st,
        u_e_t: uet,
        u_c_t: uet * rt,
        shape_n: shn,
        shape_t: sht,
    })
}

fn bilinear() -> impl Strategy<Value = Bilinear> {
    (
        log_uniform(1e2, 1e6),
        log_uniform(0.5, 200.0),
        log_uniform(0.5, 200.0),
        log_uniform(1.2, 500.0),
        log_uniform(1.2, 500.0),
        0.6..4.0f64,
        prop_oneof![Just(MixedModeCriterion::Bk), Just(MixedModeCriterion::PowerLaw)],
    )
        .prop_map(|(penalty, n, s, ratio_i, ratio_ii, eta, criterion)| Bilinear {
            penalty,
            strength_n: n,
            strength_t: s,
            // Toughness as a multiple of the elastic energy at the strength, σ²/(2K).
            g_ic: ratio_i * n * n / (2.0 * penalty),
            g_iic: ratio_ii * s * s / (2.0 * penalty),
            eta,
            criterion,
        })
        .prop_filter("valid at every mixity", |law| law.validate().is_ok())
}

fn exponential() -> impl Strategy<Value = Exponential> {
    (log_uniform(0.5, 200.0), log_uniform(1e-5, 0.1), log_uniform(0.5, 200.0), log_uniform(1e-5, 0.1)).prop_map(
        |(strength_n, peak_opening_n, strength_t, peak_opening_t)| Exponential {
            strength_n,
            peak_opening_n,
            strength_t,
            peak_opening_t,
        },
    )
}

fn bridging() -> impl Strategy<Value = Bridging> {
    (bilinear(), bilinear()).prop_map(|(matrix, bridging)| Bridging { matrix, bridging })
}

fn lu_bond_slip() -> impl Strategy<Value = LuBondSlip> {
    (
        (log_uniform(0.5, 20.0), log_uniform(1e-3, 0.5), log_uniform(1.5, 1e4), log_uniform(0.7, 20.0)),
        (log_uniform(0.1, 10.0), log_uniform(0.1, 10.0), log_uniform(1e-9, 0.1)),
    )
        .prop_map(|((tau_max, peak_slip, stiffening, energy_ratio), (peel_ratio, peel_energy_ratio, residual))| {
            LuBondSlip {
                tau_max,
                peak_slip,
                // Initial stiffness as a multiple of τ_max/s0, energy as a multiple of τ_max s0.
                shear_stiffness: stiffening * tau_max / peak_slip,
                g_f: energy_ratio * tau_max * peak_slip,
                peel_strength: peel_ratio * tau_max,
                peel_energy: peel_energy_ratio * energy_ratio * tau_max * peak_slip,
                residual,
            }
        })
        .prop_filter("valid", |law| law.validate().is_ok())
}

/// Vertices in units of the pure-mode separation openings.
fn history() -> impl Strategy<Value = Vec<(f64, f64)>> {
    prop::collection::vec((-0.3..1.4f64, -1.4..1.4f64), 1..8)
}

/// Path from the origin through the vertices, `steps` per leg, with every zero crossing of either
/// gap component inserted as a point (set exactly to zero).
fn path(vertices: &[Gap], steps: usize) -> Vec<Gap> {
    let mut out = Vec::new();
    let mut from = Gap::zeros();
    for &to in vertices {
        let mut cuts: Vec<(f64, Option<usize>)> = vec![(1.0, None)];
        for m in 0..2 {
            if from[m] * to[m] < 0.0 {
                cuts.push((from[m] / (from[m] - to[m]), Some(m)));
            }
        }
        cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut start = from;
        for (fraction, crossing) in cuts {
            let mut end = from + (to - from) * fraction;
            if let Some(m) = crossing {
                end[m] = 0.0;
            }
            out.extend(verify::line(start, end, steps));
            *out.last_mut().unwrap() = end;
            start = end;
        }
        from = to;
    }
    out
}

fn check_history(law: &dyn CohesiveLaw, unit_vertices: &[(f64, f64)]) -> Result<(), TestCaseError> {
    prop_assert!(law.validate().is_ok());
    let scale = |mode| verify::separation_opening(law, mode).unwrap_or(1.0);
    let (sn, st) = (scale(Mode::Normal), scale(Mode::Shear));
    let vertices: Vec<Gap> = unit_vertices.iter().map(|&(x, y)| Gap::new(x * sn, y * st)).collect();
    let mut state = law.initial_state();
    let mut previous = (Gap::zeros(), law.evaluate(&Gap::zeros(), &state).traction);
    let (mut work, mut magnitude) = (0.0, 0.0);
    for gap in path(&vertices, 40) {
        let eval = law.evaluate(&gap, &state);
        prop_assert!(eval.traction.iter().chain(eval.tangent.iter()).all(|v| v.is_finite()), "{:?} at {:?}", eval, gap);
        let damage = eval.state.damage;
        prop_assert!(
            (0.0..=1.0).contains(&damage) && damage >= state.damage,
            "damage {} after {}",
            damage,
            state.damage
        );
        let step = 0.5 * (eval.traction + previous.1).dot(&(gap - previous.0));
        work += step;
        magnitude += step.abs();
        let stored = law.stored_energy(&gap, &eval.state);
        prop_assert!(stored >= 0.0, "stored energy {stored}");
        let dissipated = work - stored;
        prop_assert!(
            dissipated >= -1e-12 * magnitude.max(stored),
            "dissipated {dissipated:e} (work {work:e}) at {gap:?}"
        );
        previous = (gap, eval.traction);
        state = eval.state;
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn st_czm_histories_are_admissible(law in st_czm(), vertices in history()) {
        check_history(&law, &vertices)?;
    }

    #[test]
    fn bilinear_histories_are_admissible(law in bilinear(), vertices in history()) {
        check_history(&law, &vertices)?;
    }

    #[test]
    fn exponential_histories_are_admissible(law in exponential(), vertices in history()) {
        check_history(&law, &vertices)?;
    }

    #[test]
    fn bridging_histories_are_admissible(law in bridging(), vertices in history()) {
        check_history(&law, &vertices)?;
    }

    #[test]
    fn lu_bond_slip_histories_are_admissible(law in lu_bond_slip(), vertices in history()) {
        check_history(&law, &vertices)?;
    }
}
