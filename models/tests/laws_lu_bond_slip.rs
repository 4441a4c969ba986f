//! Lu, Teng, Ye & Jiang's (2005) bond–slip law: parameters from the concrete against Lu et al.'s
//! formulas and the design figures, the energy G_f, the limit of Lu et al.'s simplified model,
//! tangent, damage and peeling, configuration files and errors. Expected values are computed here
//! from the published formulas, never by the law.

use czid_core::{law_from_toml, law_to_toml, CohesiveLaw, Gap, LawState};
use czid_models::laws::verify::{self, Mode};
use czid_models::laws::LuBondSlip;
use czid_models::registry::LAW_TYPES;

/// The paper's concrete (f'c = 47 MPa) under a 100 mm plate on a 200 mm wide beam.
fn paper_law() -> LuBondSlip {
    LuBondSlip::from_concrete(47.0, 100.0, 200.0, 1000.0).unwrap()
}

/// Composite 5-point Gauss–Legendre integral of `f` over `[a, b]` with `panels` panels, the
/// panel ends graded as `a + (b − a) (i/n)^grading` (grading > 1 refines near `a`).
fn gauss(f: &dyn Fn(f64) -> f64, a: f64, b: f64, panels: usize, grading: f64) -> f64 {
    let nodes = [0.0, -0.538_469_310_105_683_1, 0.538_469_310_105_683_1, -0.906_179_845_938_664, 0.906_179_845_938_664];
    let weights = [
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
        0.236_926_885_056_189_1,
    ];
    let end = |i: usize| a + (b - a) * (i as f64 / panels as f64).powf(grading);
    (0..panels)
        .map(|i| {
            let (lo, hi) = (end(i), end(i + 1));
            let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            half * nodes.iter().zip(&weights).map(|(x, w)| w * f(mid + half * x)).sum::<f64>()
        })
        .sum()
}

#[test]
fn parameters_follow_lu_et_al_and_the_design_figures() {
    // f_cu = f'c/0.8 = 58.75 MPa, f_t = 0.395 f_cu^0.55, β_w = √((2.25 − ½)/(1.25 + ½)) = 1.
    let f_t = 0.395 * 58.75f64.powf(0.55);
    let law = paper_law();
    assert!((law.tau_max - 1.5 * f_t).abs() < 1e-12);
    assert!((law.peak_slip - 0.0195 * f_t).abs() < 1e-15);
    assert!((law.g_f - 0.308 * f_t.sqrt()).abs() < 1e-14);
    // DESIGN.md: τ_max ≈ 5.6 MPa, G_f ≈ 0.59 N/mm, to the digits given.
    assert!((law.tau_max - 5.6).abs() < 0.05, "τ_max = {}", law.tau_max);
    assert!((law.g_f - 0.59).abs() < 0.005, "G_f = {}", law.g_f);
    // Peeling from the same concrete: f_t and fib MC2010's 73 f_cm^0.18 N/m.
    assert!((law.peel_strength - f_t).abs() < 1e-12);
    assert!((law.peel_energy - 0.073 * 47f64.powf(0.18)).abs() < 1e-15);
    assert_eq!(law.strength(), [law.peel_strength, law.tau_max]);
    assert_eq!(law.fracture_energy(), [law.peel_energy, law.g_f]);

    // A narrow plate: b_f/b_c = 0.25, β_w = √(2/1.5).
    let narrow = LuBondSlip::from_concrete(47.0, 50.0, 200.0, 1000.0).unwrap();
    let beta = (2.0f64 / 1.5).sqrt();
    assert!((narrow.tau_max - 1.5 * beta * f_t).abs() < 1e-12);
    assert!((narrow.g_f - 0.308 * beta * beta * f_t.sqrt()).abs() < 1e-14);
    assert!((LuBondSlip::width_factor(200.0, 200.0).unwrap() - (1.25f64 / 2.25).sqrt()).abs() < 1e-15);
}

#[test]
fn peak_initial_slope_and_separation() {
    let law = paper_law();
    let s0 = law.peak_slip;
    assert!((law.bond_stress(s0) - law.tau_max).abs() < 1e-12 * law.tau_max);
    // The peak is the maximum.
    for i in 1..2000 {
        let s = law.separation_slip() * i as f64 / 2000.0;
        assert!(law.bond_stress(s) <= law.tau_max * (1.0 + 1e-12), "{s}");
    }
    // Initial slope K0.
    let h = 1e-10;
    assert!((law.bond_stress(h) / h / 1000.0 - 1.0).abs() < 1e-6);
    // Ends at s_u = s0 (1 + ln(1/c)/α) with damage exactly 1.
    let s_u = law.separation_slip();
    assert!((s_u - s0 * (1.0 + (1.0 / law.residual).ln() / law.alpha())).abs() < 1e-15);
    let before = law.evaluate(&Gap::new(0.0, s_u * (1.0 - 1e-9)), &LawState::default());
    let after = law.evaluate(&Gap::new(0.0, s_u * (1.0 + 1e-12)), &LawState::default());
    assert!(before.state.damage < 1.0 && before.traction.y > 0.0 && before.traction.y < 1e-6);
    assert_eq!((after.state.damage, after.traction.y), (1.0, 0.0));
    // Damage at the peak is the secant loss 1 − τ_max/(K0 s0).
    let peak = law.evaluate(&Gap::new(0.0, s0), &LawState::default());
    assert!((peak.state.damage - (1.0 - law.tau_max / (1000.0 * s0))).abs() < 1e-12);
}

#[test]
fn shear_energy_is_g_f_and_peel_energy_is_g_n() {
    for law in [
        paper_law(),
        LuBondSlip { residual: 1e-6, ..paper_law() },
        LuBondSlip { shear_stiffness: 150.0, residual: 0.05, ..paper_law() },
    ] {
        let (s0, s_u) = (law.peak_slip, law.separation_slip());
        // Independent quadrature of the law's own curve up to the cut-off, where it is zero.
        let tau = |s: f64| law.evaluate(&Gap::new(0.0, s), &LawState::default()).traction.y;
        let work = gauss(&tau, 0.0, s0, 400, 2.0) + gauss(&tau, s0, s_u, 2000, 1.0);
        let expected = 0.308 * (law.tau_max / 1.5).sqrt(); // G_f of Lu et al. (β_w = 1)
        assert!((work - expected).abs() < 1e-6 * expected, "{law:?}: {work} vs {expected}");
        assert_eq!(tau(1.000_001 * s_u), 0.0);
        // Pure opening: Lu's curve scaled to σ_n and G_n.
        let sigma = |u: f64| law.evaluate(&Gap::new(u, 0.0), &LawState::default()).traction.x;
        let lambda = law.normal_scale();
        let opening = gauss(&sigma, 0.0, s0 / lambda, 400, 2.0) + gauss(&sigma, s0 / lambda, s_u / lambda, 2000, 1.0);
        assert!((opening - law.peel_energy).abs() < 1e-6 * law.peel_energy, "{opening} vs {}", law.peel_energy);
        assert!((sigma(s0 / lambda) - law.peel_strength).abs() < 1e-12 * law.peel_strength);
        // And the verification kit's path integral agrees.
        for mode in [Mode::Normal, Mode::Shear] {
            let check = verify::pure_mode_energy(&law, mode, 1.2 * s_u.max(s_u / lambda), 40_000);
            assert!(check.relative_error < 1e-6 && check.final_damage == 1.0, "{check:?}");
        }
    }
}

#[test]
fn tends_to_lu_et_al_simplified_model() {
    // Stiff start and a tiny residual: the simplified model's α = 1/(G_f/(τ_max s0) − 2/3) and
    // curve τ_max √(s/s0), τ_max e^{−α(s/s0 − 1)}.
    let law = LuBondSlip { shear_stiffness: 1e8, residual: 1e-9, ..paper_law() };
    let (tau_max, s0, g_f) = (law.tau_max, law.peak_slip, law.g_f);
    let alpha = 1.0 / (g_f / (tau_max * s0) - 2.0 / 3.0);
    assert!((law.simplified_alpha() - alpha).abs() < 1e-15);
    assert!((law.alpha() / alpha - 1.0).abs() < 1e-4, "{} vs {alpha}", law.alpha());
    for i in 1..=400 {
        let s = 0.01 * s0 * f64::from(i);
        let lu = if s <= s0 { tau_max * (s / s0).sqrt() } else { tau_max * (-alpha * (s / s0 - 1.0)).exp() };
        assert!((law.bond_stress(s) - lu).abs() < 2e-3 * tau_max, "s = {s}: {} vs {lu}", law.bond_stress(s));
    }
    // With the defaults (K0 = 1000 MPa/mm, c = 1e-3) the curve departs from the simplified model
    // by at most 3.1 % of τ_max on the ascending branch (the finite initial stiffness) and 0.8 %
    // on the descending one.
    let law = paper_law();
    let (ascending, descending) = (0..=4000).fold((0.0f64, 0.0f64), |(asc, desc), i| {
        let s = law.separation_slip() * f64::from(i) / 4000.0;
        if s <= s0 {
            (asc.max((law.bond_stress(s) - tau_max * (s / s0).sqrt()).abs()), desc)
        } else {
            (asc, desc.max((law.bond_stress(s) - tau_max * (-alpha * (s / s0 - 1.0)).exp()).abs()))
        }
    });
    assert!(ascending < 0.031 * tau_max && descending < 0.008 * tau_max, "{ascending}, {descending}");
}

#[test]
fn verification_kit_audit_passes() {
    for law in [
        paper_law(),
        LuBondSlip::from_concrete(30.0, 50.0, 150.0, 400.0).unwrap(),
        LuBondSlip { residual: 0.05, peel_energy: 0.5, ..paper_law() },
    ] {
        let report = verify::audit(&law);
        assert!(report.passed(1e-6), "{law:?}\n{report:?}");
        assert!(report.tangent_error < 1e-7, "{report:?}");
    }
}

#[test]
fn tangent_matches_finite_differences_on_every_branch() {
    let law = paper_law();
    let (s0, lambda) = (law.peak_slip, law.normal_scale());
    let virgin = LawState::default();
    let damaged = law.evaluate(&Gap::new(0.0, 2.0 * s0), &virgin).state;
    // Pure-shear points sit under a slight compression: u_n = 0 is a kink (closure).
    let closed = -1e-4;
    for (gap, state) in [
        (Gap::new(closed, 0.3 * s0), virgin),
        (Gap::new(closed, -0.7 * s0), virgin),
        (Gap::new(closed, 3.3 * s0), virgin),
        (Gap::new(0.4 * s0 / lambda, 0.0), virgin),
        (Gap::new(0.5 * s0 / lambda, 0.8 * s0), virgin),
        (Gap::new(1.3 * s0 / lambda, -1.9 * s0), virgin),
        (Gap::new(-0.01, 0.6 * s0), virgin),
        (Gap::new(closed, 1.1 * s0), damaged),
        (Gap::new(0.3 * s0 / lambda, 0.7 * s0), damaged),
        (Gap::new(closed, 2.7 * s0), damaged),
    ] {
        let check = verify::check_tangent(&law, &gap, &state);
        assert!(!check.near_kink && check.relative_error < 1e-7, "{gap:?}: {check:?}");
    }
}

#[test]
fn damage_is_irreversible_unloading_is_secant_and_compression_is_undamaged() {
    let law = paper_law();
    let s0 = law.peak_slip;
    let loaded = law.evaluate(&Gap::new(0.0, 2.0 * s0), &LawState::default());
    assert_eq!(loaded.state.history[0], 2.0 * s0);
    // Unloading to half the slip halves the traction: the secant to the origin.
    let half = law.evaluate(&Gap::new(0.0, s0), &loaded.state);
    assert!((half.traction.y - 0.5 * loaded.traction.y).abs() < 1e-12);
    assert_eq!(half.state.damage, loaded.state.damage);
    assert!((half.tangent[(1, 1)] - loaded.traction.y / (2.0 * s0)).abs() < 1e-9);
    // Reversed slip: same secant, opposite sign.
    let reversed = law.evaluate(&Gap::new(0.0, -s0), &loaded.state);
    assert!((reversed.traction.y + half.traction.y).abs() < 1e-12);
    // Closing: the undamaged normal penalty, whatever the damage.
    let closed = law.evaluate(&Gap::new(-1e-3, 0.0), &loaded.state);
    assert_eq!(closed.traction.x, -1e-3 * law.peel_stiffness());
    let separated = law.evaluate(&Gap::new(0.0, 1.1 * law.separation_slip()), &LawState::default());
    let after = law.evaluate(&Gap::new(0.05, 0.01), &separated.state);
    assert_eq!((after.traction.x, after.traction.y, after.state.damage), (0.0, 0.0, 1.0));
    let pressed = law.evaluate(&Gap::new(-1e-3, 0.01), &separated.state);
    assert_eq!((pressed.traction.x, pressed.traction.y), (-1e-3 * law.peel_stiffness(), 0.0));
    // Opening damages slip: shared damage through κ = √(u_t² + (λ u_n)²).
    let opened = law.evaluate(&Gap::new(s0 / law.normal_scale(), 0.0), &LawState::default());
    let slip = law.evaluate(&Gap::new(0.0, 0.5 * s0), &opened.state);
    assert!((slip.traction.y - law.bond_stress(s0) * 0.5).abs() < 1e-12);
}

#[test]
fn configuration_files_round_trip_and_errors_are_named() {
    assert!(LAW_TYPES.contains(&"lu_bond_slip"));
    let law = paper_law();
    let text = law_to_toml(&law).unwrap();
    assert!(text.contains("type = \"lu_bond_slip\""), "{text}");
    let back = law_from_toml(&text).unwrap();
    for (a, b) in law.parameters().iter().zip(back.parameters()) {
        assert_eq!((a.name, a.value.to_bits()), (b.name, b.value.to_bits()));
    }
    // Hand-written, `residual` left at its default.
    let written = law_from_toml(
        r#"
        type = "lu_bond_slip"
        tau_max = 5.57
        peak_slip = 0.0724
        g_f = 0.593
        shear_stiffness = 1000.0
        peel_strength = 3.71
        peel_energy = 0.146
        "#,
    )
    .unwrap();
    assert_eq!(written.parameters().last().map(|p| p.value), Some(LuBondSlip::DEFAULT_RESIDUAL));

    let error = |text: String| law_from_toml(&text).unwrap_err().to_string();
    let with = |key: &str, value: &str| {
        let line = text.lines().find(|l| l.starts_with(&format!("{key} ="))).unwrap();
        text.replace(line, &format!("{key} = {value}"))
    };
    assert!(error(with("shear_stiffness", "50.0")).contains("`shear_stiffness`"));
    assert!(error(with("g_f", "0.2")).contains("`g_f`"));
    assert!(error(with("residual", "0.2")).contains("`residual`"));
    assert!(error(with("peel_energy", "-1.0")).contains("`peel_energy`"));
    assert!(error(with("tau_max", "nan")).contains("`tau_max`"));
    assert!(error(text.replace("peak_slip", "peak_slp")).contains("peak_slp"));
    let plate = LuBondSlip::from_concrete(47.0, 250.0, 200.0, 1000.0).unwrap_err().to_string();
    assert!(plate.contains("`plate_width`"), "{plate}");
    let concrete = LuBondSlip::from_concrete(-47.0, 100.0, 200.0, 1000.0).unwrap_err().to_string();
    assert!(concrete.contains("`fc_cylinder`"), "{concrete}");
}
