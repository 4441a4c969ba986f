//! A law in series with a through-thickness compliance: checked against the closed form of a
//! bilinear law (in series with `c` it is the bilinear law with the penalty `k/(1 + c k)`), and
//! held to the verification kit of every bundled law.

use czid_core::{law_from_toml, law_to_toml, CohesiveLaw, Gap};
use czid_models::laws::{verify, Bilinear, Bridging, Exponential, SeriesCompliance, StCzm};

fn series(law: &dyn CohesiveLaw, c: f64) -> SeriesCompliance {
    SeriesCompliance::around(law, c).unwrap()
}

#[test]
fn a_bilinear_law_in_series_is_the_bilinear_law_with_the_series_penalty() {
    // Mode I, the steep law at 70 % of the compliance its softening allows.
    let (k, sigma, g) = (1e5, 27.0, 0.744);
    let slope = sigma / (2.0 * g / sigma - sigma / k);
    let c = 0.7 / slope;
    let law = Bilinear::bk(k, sigma, 40.0, g, 1.6, 2.0).unwrap();
    let equivalent = Bilinear::bk(1.0 / (1.0 / k + c), sigma, 40.0, g, 1.6, 2.0).unwrap();
    let wrapped = series(&law, c);
    // Load past the peak, unload to a quarter, reload to complete failure and beyond.
    let failure = 2.0 * g / sigma;
    let path = verify::polyline(
        &[Gap::new(0.8 * failure, 0.0), Gap::new(0.2 * failure, 0.0), Gap::new(1.3 * failure, 0.0)],
        400,
    );
    let (a, b) = (verify::follow_path(&wrapped, &path), verify::follow_path(&equivalent, &path));
    for (p, q) in a.iter().zip(&b) {
        let scale = sigma;
        assert!((p.traction - q.traction).norm() <= 1e-10 * scale, "{p:?}\n{q:?}");
        // (Damage is each law's own measure, relative to its own penalty: not compared.)
        assert_eq!(p.state.damage == 1.0, q.state.damage == 1.0, "{p:?}\n{q:?}");
        let e_a = wrapped.evaluate(&p.gap, &p.state);
        let e_b = equivalent.evaluate(&q.gap, &q.state);
        assert!((e_a.tangent[(0, 0)] - e_b.tangent[(0, 0)]).abs() <= 1e-8 * k, "{e_a:?}\n{e_b:?}");
        let (s_a, s_b) = (wrapped.stored_energy(&p.gap, &p.state), equivalent.stored_energy(&q.gap, &q.state));
        assert!((s_a - s_b).abs() <= 1e-10 * g, "{s_a} vs {s_b}");
    }
    assert_eq!(a.last().unwrap().state.damage, 1.0);
    assert_eq!(
        wrapped.initial_stiffness()[0],
        wrapped.evaluate(&Gap::new(1e-4, 0.0), &law.initial_state()).tangent[(0, 0)]
    );
}

#[test]
fn laws_in_series_pass_the_verification_kit() {
    let table3 = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let laws: Vec<Box<dyn CohesiveLaw>> = vec![
        Box::new(Bilinear::bk(1e5, 30.0, 45.0, 0.28, 0.9, 2.1).unwrap()),
        Box::new(Exponential::new(30.0, 0.001, 40.0, 0.002).unwrap()),
        Box::new(Bridging::trilinear(1e5, [30.0, 45.0, 0.25, 0.8], [3.0, 4.5, 0.5, 1.0], 2.0).unwrap()),
        Box::new(table3),
    ];
    for law in &laws {
        // Half the compliance at which the steepest mode-I softening would snap back.
        let c = 0.5 / czid_models::effects::steepest_mode_one_softening(law.as_ref());
        let wrapped = series(law.as_ref(), c);
        let report = verify::audit(&wrapped);
        assert!(report.passed(1e-6), "{law:?}\n{report:?}");
        for energy in report.energy {
            assert!(energy.unwrap().relative_error < 1e-7, "{law:?}: {energy:?}");
        }
        assert_eq!(wrapped.fracture_energy(), law.fracture_energy());
        assert_eq!(wrapped.inner_kinks(), law.inner_kinks());
        assert_eq!(wrapped.visible_front_kink(), law.visible_front_kink());
    }
}

#[test]
fn a_law_in_series_reads_and_writes_as_a_configuration_and_refuses_a_negative_compliance() {
    let law = Bilinear::bk(1e5, 30.0, 45.0, 0.28, 0.9, 2.1).unwrap();
    let wrapped = series(&law, 2e-4);
    let back = law_from_toml(&law_to_toml(&wrapped).unwrap()).unwrap();
    let gap = Gap::new(0.004, 0.001);
    assert_eq!(back.evaluate(&gap, &back.initial_state()), wrapped.evaluate(&gap, &wrapped.initial_state()));
    let error = SeriesCompliance::around(&law, -1e-4).unwrap_err().to_string();
    assert!(error.contains("normal_compliance") && error.contains("negative"), "{error}");
    let text = "type = \"series_compliance\"\nnormal_compliance = 1e-4\n[law]\ntype = \"bilinear\"\npenalty = 1e5\nstrength_n = -30.0\nstrength_t = 45.0\ng_ic = 0.28\ng_iic = 0.9\neta = 2.1";
    let error = law_from_toml(text).unwrap_err().to_string();
    assert!(error.contains("`law.strength_n`"), "{error}");
    // A wrapped law built in code and never validated is named by its path in a configuration.
    let broken = Bilinear { strength_n: -30.0, ..law };
    let error = SeriesCompliance::new(Box::new(broken), 1e-4).unwrap_err().to_string();
    assert!(error.contains("`law.strength_n`"), "{error}");
}
