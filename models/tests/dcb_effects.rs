//! Switchable effects of the DCB: null values reproduce the base model exactly, and each effect
//! does what it says (checked against closed forms where one exists).

mod fe_support;
use czid_core::{columns, ForwardModel, Record};
use czid_models::dcb::Dcb;
use fe_support::*;

fn run(d: &Dcb, law: &TestBilinear) -> Record {
    d.simulate(law).unwrap_or_else(|f| panic!("{}", f.error))
}

fn col<'a>(r: &'a Record, c: &str) -> &'a [f64] {
    r.column(c).unwrap()
}

fn base() -> Dcb {
    let mut d = Dcb::paper();
    d.mesh.interface_element = 0.2;
    d.control.max_displacement = Some(8.0);
    d.control.output_points = 40;
    d
}

fn law() -> TestBilinear {
    TestBilinear::new(1e5, 60.0, 0.3)
}

#[test]
fn null_effects_written_out_reproduce_the_base_model_bitwise() {
    let d = base();
    let mut v = serde_json::to_value(&d).unwrap();
    v["effects"] = serde_json::json!({
        "machine_compliance": 0.0, "crack_length_offset": 0.0, "displacement_offset": 0.0,
        "root_compliance": 0.0, "shear_compliance": 0.0, "large_rotation": false,
        "load_offset": 0.0, "seating_toe": 0.0
    });
    let explicit: Dcb = serde_json::from_value(v).unwrap();
    assert_eq!(run(&d, &law()), run(&explicit, &law()));
}

#[test]
fn crack_length_offset_equals_a_longer_nominal_crack() {
    let mut a = base();
    a.effects.crack_length_offset = 1.5;
    let mut b = base();
    b.a0 += 1.5;
    assert_eq!(run(&a, &law()), run(&b, &law()));
}

#[test]
fn displacement_offset_shifts_the_curve_and_adds_a_toe() {
    let mut d = base();
    d.effects.displacement_offset = 0.3;
    let (r0, r1) = (run(&base(), &law()), run(&d, &law()));
    let (x0, x1) = (col(&r0, columns::DISPLACEMENT), col(&r1, columns::DISPLACEMENT));
    assert_eq!(r1.rows(), r0.rows() + 1);
    assert_eq!((x1[0], col(&r1, columns::LOAD)[0]), (0.0, 0.0));
    for (a, b) in x0.iter().zip(&x1[1..]) {
        assert!((b - a - 0.3).abs() < 1e-12);
    }
}

#[test]
fn load_offset_shifts_every_load_and_nothing_else() {
    let mut d = base();
    d.effects.load_offset = -2.5;
    let (r0, r1) = (run(&base(), &law()), run(&d, &law()));
    assert_eq!(r1.rows(), r0.rows());
    assert_eq!(col(&r1, columns::DISPLACEMENT), col(&r0, columns::DISPLACEMENT));
    assert_eq!(col(&r1, columns::DEBONDED_LENGTH), col(&r0, columns::DEBONDED_LENGTH));
    for (a, b) in col(&r0, columns::LOAD).iter().zip(col(&r1, columns::LOAD)) {
        assert!((b - a + 2.5).abs() < 1e-12);
    }
}

#[test]
fn seating_toe_adds_its_closed_form_to_every_displacement() {
    let t = 0.4;
    let mut d = base();
    d.effects.seating_toe = t;
    let (r0, r1) = (run(&base(), &law()), run(&d, &law()));
    assert_eq!(r1.rows(), r0.rows());
    let (x0, x1, p0) = (col(&r0, columns::DISPLACEMENT), col(&r1, columns::DISPLACEMENT), col(&r0, columns::LOAD));
    assert_eq!(col(&r1, columns::LOAD), p0);
    // The toe's closed form with the specimen's own initial compliance.
    let first = p0.iter().position(|&p| p > 0.0).unwrap();
    let c0 = x0[first] / p0[first];
    for i in 0..x0.len() {
        let toe = t * (1.0 - (-c0 * p0[i].abs() / t).exp());
        assert!((x1[i] - x0[i] - toe).abs() < 1e-12, "row {i}");
    }
}

#[test]
fn machine_compliance_adds_c_m_p_to_the_displacement() {
    let mut d = base();
    d.control.max_displacement = Some(2.0);
    let cm = 0.01;
    let mut m = d.clone();
    m.effects.machine_compliance = cm;
    let (r0, r1) = (run(&d, &law()), run(&m, &law()));
    // Elastic branch: δ_machine(P) = δ_specimen(P) + C_m P.
    let c0 = col(&r0, columns::DISPLACEMENT)[1] / col(&r0, columns::LOAD)[1];
    let c1 = col(&r1, columns::DISPLACEMENT)[1] / col(&r1, columns::LOAD)[1];
    assert!((c1 - c0 - cm).abs() < 1e-9 * c1, "{c1} vs {c0} + {cm}");
    // And it tends continuously to the base model.
    let mut tiny = d.clone();
    tiny.effects.machine_compliance = 1e-8;
    let rt = run(&tiny, &law());
    let (pt, p0) = (col(&rt, columns::LOAD).last().unwrap(), col(&r0, columns::LOAD).last().unwrap());
    assert!((pt / p0 - 1.0).abs() < 1e-5, "{pt} vs {p0}");
}

#[test]
fn root_compliance_is_kanninens_foundation_in_series_with_the_interface() {
    let mut d = base();
    d.mesh.interface_element = 0.1;
    d.control.max_displacement = Some(0.2);
    d.control.output_points = 2;
    // Physical value h/(2 E22).
    let cr = 1.62 / (2.0 * 6_500.0);
    d.effects.root_compliance = cr;
    let elastic = TestBilinear::new(1e5, 1e6, 1e6);
    let r = run(&d, &elastic);
    let c = col(&r, columns::DISPLACEMENT)[1] / col(&r, columns::LOAD)[1];
    // Foundation per unit length of one arm: half-model interface 2 b k_n in series with b / c_r.
    let kf = 1.0 / (1.0 / (2.0 * 20.0 * 1e5) + cr / 20.0);
    let arm = Arm { e: 130_000.0, g: 2_700.0, b: 20.0, h: 1.62 };
    let reference = dcb_compliance_foundation(&arm, 50.0, kf);
    println!("root compliance: C = {c:.6e}, reference {reference:.6e} ({:+.3} %)", 100.0 * (c / reference - 1.0));
    assert!((c / reference - 1.0).abs() < 0.01);
}

#[test]
fn a_root_compliance_that_would_leave_a_nearly_brittle_interface_is_refused_at_once_with_its_limit() {
    // Closed form: a bilinear law softens with slope σ / (δf − δ0), δf = 2 G / σ, δ0 = σ / K.
    let (k, sigma, g) = (1e5, 27.0, 0.744);
    let law = TestBilinear::new(k, sigma, g);
    let slope = sigma / (2.0 * g / sigma - sigma / k);
    let measured = czid_models::effects::steepest_mode_one_softening(&law);
    assert!((measured / slope - 1.0).abs() < 1e-6, "{measured} vs {slope}");
    let limit = czid_models::effects::ROOT_COMPLIANCE_SHARE / (2.0 * slope);
    let mut d = Dcb::paper();
    d.effects.root_compliance = 1.05 * limit;
    let error = d.simulate(&law).unwrap_err().error.to_string();
    assert!(error.contains("effects.root_compliance") && error.contains(&format!("{limit:.4e}")), "{error}");
    // Inside the limit the crack runs on the window, as without the compliance.
    d.effects.root_compliance = 0.7 / (2.0 * slope);
    let (record, stats) = czid_models::dcb::simulate_with_stats(&d, &law).unwrap();
    assert!(stats.windowed, "{stats:?}");
    assert!(record.rows() > 50);
}

#[test]
fn root_compliance_with_a_bilinear_law_is_the_bilinear_law_with_the_series_penalty() {
    // In series with the two arms' through-thickness compliance 2 c_r, a bilinear law opens as the
    // bilinear law of penalty 1/(1/K + 2 c_r), the same strength and toughness (mode I). Hartlen's
    // DCB with a steep law at 70 % of the limit: nodal springs snapped back there node by node.
    let (k, sigma, g) = (1e5, 27.0, 0.744);
    let slope = sigma / (2.0 * g / sigma - sigma / k);
    let cr = 0.7 / (2.0 * slope);
    let mut d = Dcb::hartlen_dcb01();
    d.effects.root_compliance = cr;
    let (with, stats) = czid_models::dcb::simulate_with_stats(&d, &TestBilinear::new(k, sigma, g)).unwrap();
    assert!(stats.windowed && stats.dissipation_steps == 0, "{stats:?}");
    d.effects.root_compliance = 0.0;
    let equivalent = TestBilinear::new(1.0 / (1.0 / k + 2.0 * cr), sigma, g);
    let (without, _) = czid_models::dcb::simulate_with_stats(&d, &equivalent).unwrap();
    assert_eq!(with.rows(), without.rows());
    let peak = col(&without, columns::LOAD).iter().cloned().fold(0.0, f64::max);
    for c in [columns::DISPLACEMENT, columns::LOAD, columns::DEBONDED_LENGTH] {
        for (a, b) in col(&with, c).iter().zip(col(&without, c)) {
            let scale = if c == columns::LOAD { peak } else { 1.0 };
            assert!((a - b).abs() <= 1e-9 * scale.max(b.abs()), "{c}: {a} vs {b}");
        }
    }
    assert!(*col(&with, columns::DEBONDED_LENGTH).last().unwrap() > 20.0, "the crack ran");
}

#[test]
fn large_rotations_agree_with_small_ones_at_small_openings() {
    let mut d = base();
    d.control.max_displacement = Some(1.0);
    d.control.output_points = 4;
    let mut l = d.clone();
    l.effects.large_rotation = true;
    let (rs, rl) = (run(&d, &law()), run(&l, &law()));
    let (ps, pl) = (col(&rs, columns::LOAD)[1], col(&rl, columns::LOAD)[1]);
    println!("P at 0.25 mm: small {ps:.6}, large {pl:.6}");
    assert!((pl / ps - 1.0).abs() < 1e-3);
}

#[test]
fn shear_compliance_equals_a_lower_shear_modulus() {
    // 1/G = 1/G13 + s: the effect is the same arm with the combined modulus, exactly.
    let s = 2e-4;
    let mut a = base();
    a.effects.shear_compliance = s;
    let mut b = base();
    b.material.g13 = 1.0 / (1.0 / b.material.g13 + s);
    assert_eq!(run(&a, &law()), run(&b, &law()));
    // And it makes the specimen more compliant: more shear deflection of the arms.
    let (r0, r1) = (run(&base(), &law()), run(&a, &law()));
    let (p0, p1) = (col(&r0, columns::LOAD)[1], col(&r1, columns::LOAD)[1]);
    assert!(p1 < p0, "{p1} vs {p0}");
}

#[test]
fn zero_shear_compliance_is_the_base_model_in_the_enf_too() {
    use czid_models::enf::Enf;
    let mut e = Enf::hartlen_enf03();
    e.control.max_displacement = Some(1.0);
    e.control.output_points = 5;
    let mut v = serde_json::to_value(&e).unwrap();
    v["effects"]["shear_compliance"] = serde_json::json!(0.0);
    let explicit: Enf = serde_json::from_value(v).unwrap();
    let law = TestBilinear::new(1e5, 60.0, 0.3);
    assert_eq!(e.simulate(&law).unwrap(), explicit.simulate(&law).unwrap());
    let mut s = e.clone();
    s.effects.shear_compliance = 2e-4;
    let (p0, p1) = (e.simulate(&law).unwrap(), s.simulate(&law).unwrap());
    assert!(col(&p1, columns::LOAD)[1] < col(&p0, columns::LOAD)[1]);
}
