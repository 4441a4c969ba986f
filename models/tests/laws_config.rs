//! Laws in configuration files: TOML round trips through `typetag`, and errors that name what is
//! wrong (unknown law, misspelt key, invalid value).

use czid_core::{law_from_toml, law_to_toml, CohesiveLaw, CzError};
use czid_models::laws::{Bilinear, Bridging, Exponential, LuBondSlip, MixedModeCriterion, StCzm, StrengthShape};

fn all_laws() -> Vec<Box<dyn CohesiveLaw>> {
    let st = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let shaped = st
        .clone()
        .with_shapes(
            StrengthShape::Exponential { alpha: 3.5 },
            StrengthShape::Trilinear { kink_fraction: 0.25, kink_strength_ratio: 0.4 },
        )
        .unwrap();
    let bilinear = Bilinear::bk(1e5, 30.0, 45.0, 0.28, 0.9, 2.1).unwrap();
    let power = bilinear.clone().with_criterion(MixedModeCriterion::PowerLaw).unwrap();
    vec![
        Box::new(st),
        Box::new(shaped),
        Box::new(bilinear),
        Box::new(power),
        Box::new(Exponential::new(30.0, 0.001, 40.0, 0.002).unwrap()),
        Box::new(Bridging::trilinear(1e5, [30.0, 45.0, 0.25, 0.8], [3.0, 4.5, 0.5, 1.0], 2.0).unwrap()),
        Box::new(LuBondSlip::from_concrete(47.0, 100.0, 200.0, 1000.0).unwrap()),
    ]
}

fn error_text(toml: &str) -> String {
    match law_from_toml(toml) {
        Ok(law) => panic!("accepted {law:?} from\n{toml}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn every_law_round_trips_through_toml() {
    for law in all_laws() {
        let text = law_to_toml(law.as_ref()).unwrap();
        let back = law_from_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        let (a, b) = (law.parameters(), back.parameters());
        assert_eq!(a.len(), b.len(), "{text}");
        for (x, y) in a.iter().zip(&b) {
            assert_eq!((x.name, x.value.to_bits()), (y.name, y.value.to_bits()), "{text}");
        }
        // Same configuration text, so shapes and criteria survived too.
        assert_eq!(law_to_toml(back.as_ref()).unwrap(), text);
        assert!(text.contains("type = "), "{text}");
    }
}

#[test]
fn hand_written_configurations_load() {
    let st = law_from_toml(
        r#"
        # Shi & Zhang, Table 3; `type` need not come first.
        strength_n = 27.0
        u_e_n = 0.00027
        u_c_n = 0.003273
        type = "st_czm"
        strength_t = 40.0
        u_e_t = 0.00025
        u_c_t = 0.003273
        shape_t = { kind = "exponential", alpha = 2.0 }
        "#,
    )
    .unwrap();
    assert_eq!(st.strength(), [27.0, 40.0]);
    assert_eq!(st.parameters().last().unwrap().name, "shape_t.alpha");

    let bridging = law_from_toml(
        r#"
        type = "bridging"
        [matrix]
        penalty = 9e4
        strength_n = 30.0
        strength_t = 45.0
        g_ic = 0.25
        g_iic = 0.8
        eta = 2.0
        [bridging]
        penalty = 1e4
        strength_n = 3.0
        strength_t = 4.5
        g_ic = 0.5
        g_iic = 1.0
        eta = 2.0
        criterion = "power_law"
        "#,
    )
    .unwrap();
    assert!((bridging.fracture_energy()[0] - 0.75).abs() < 1e-12);
}

#[test]
fn unknown_law_type_is_named() {
    let text = error_text("type = \"st_czn\"\nstrength_n = 27.0");
    assert!(text.contains("st_czn"), "{text}");
}

#[test]
fn misspelt_keys_are_named() {
    let cases = [
        // top-level key of each law
        (
            "type = \"st_czm\"\nstrenght_n = 27.0\nu_e_n = 0.00027\nu_c_n = 0.003\nstrength_t = 40.0\nu_e_t = 0.00025\nu_c_t = 0.003",
            "strenght_n",
        ),
        ("type = \"bilinear\"\npenalty = 1e5\nstrength_n = 30.0\nstrength_t = 45.0\ng_ic = 0.3\ng_iic = 0.9\neta = 2.0\ncriterio = \"bk\"", "criterio"),
        ("type = \"exponential\"\nstrength_n = 30.0\npeak_opening_n = 0.001\nstrength_t = 40.0\npeak_opening_t = 0.002\nalpha = 3.0", "alpha"),
        // nested tables
        (
            "type = \"st_czm\"\nstrength_n = 27.0\nu_e_n = 0.00027\nu_c_n = 0.003\nstrength_t = 40.0\nu_e_t = 0.00025\nu_c_t = 0.003\nshape_n = { kind = \"exponential\", alpah = 3.0 }",
            "alpah",
        ),
        (
            "type = \"st_czm\"\nstrength_n = 27.0\nu_e_n = 0.00027\nu_c_n = 0.003\nstrength_t = 40.0\nu_e_t = 0.00025\nu_c_t = 0.003\nshape_n = { kind = \"sawtoth\" }",
            "sawtoth",
        ),
        (
            "type = \"bridging\"\n[matrix]\npenalty = 9e4\nstrength_n = 30.0\nstrength_t = 45.0\ng_ic = 0.25\ng_iic = 0.8\neta = 2.0\n[bridging]\npenalty = 1e4\nstrength_n = 3.0\nstrength_t = 4.5\ng_ic = 0.5\ng_iic = 1.0\netta = 2.0",
            "etta",
        ),
        // missing key
        ("type = \"exponential\"\nstrength_n = 30.0\npeak_opening_n = 0.001\nstrength_t = 40.0", "peak_opening_t"),
    ];
    for (toml, name) in cases {
        let text = error_text(toml);
        assert!(text.contains(name), "error for `{name}` does not name it: {text}");
    }
}

#[test]
fn invalid_values_are_named() {
    let st = |overrides: &str| {
        let mut fields = [
            ("strength_n", "27.0"),
            ("u_e_n", "0.00027"),
            ("u_c_n", "0.003273"),
            ("strength_t", "40.0"),
            ("u_e_t", "0.00025"),
            ("u_c_t", "0.003273"),
        ];
        let (key, value) = overrides.split_once('=').unwrap();
        fields.iter_mut().filter(|f| f.0 == key).for_each(|f| f.1 = value);
        let body: Vec<String> = fields.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        format!("type = \"st_czm\"\n{}", body.join("\n"))
    };
    let parameter_of = |toml: &str| match law_from_toml(toml) {
        Err(CzError::InvalidParameter { name, reason, .. }) => (name, reason),
        other => panic!("expected an invalid-parameter error, got {other:?}"),
    };
    let (name, reason) = parameter_of(&st("strength_n=-27.0"));
    assert_eq!(name, "strength_n");
    assert!(reason.contains("positive"), "{reason}");
    let (name, reason) = parameter_of(&st("u_e_t=nan"));
    assert_eq!(name, "u_e_t");
    assert!(reason.contains("finite"), "{reason}");
    let (name, reason) = parameter_of(&st("u_c_n=0.0002"));
    assert_eq!(name, "u_c_n");
    assert!(reason.contains("u_c_n must exceed u_e_n"), "{reason}");
    let (name, _) = parameter_of(&st("u_c_t=0.00025"));
    assert_eq!(name, "u_c_t");
    let (name, _) = parameter_of(&st("strength_t=inf"));
    assert_eq!(name, "strength_t");

    let with_shape = |shape: &str| format!("{}\nshape_n = {shape}", st("strength_n=27.0"));
    let (name, _) =
        parameter_of(&with_shape("{ kind = \"trilinear\", kink_fraction = 1.2, kink_strength_ratio = 0.3 }"));
    assert_eq!(name, "shape_n.kink_fraction");
    let (name, _) =
        parameter_of(&with_shape("{ kind = \"trilinear\", kink_fraction = 0.2, kink_strength_ratio = 0.0 }"));
    assert_eq!(name, "shape_n.kink_strength_ratio");
    let (name, _) = parameter_of(&with_shape("{ kind = \"exponential\", alpha = -1.0 }"));
    assert_eq!(name, "shape_n.alpha");

    let bilinear = "type = \"bilinear\"\npenalty = 100.0\nstrength_n = 1.0\nstrength_t = 1.0\ng_iic = 2.0\neta = 2.0\n";
    let (name, _) = parameter_of(&format!("{bilinear}g_ic = -1.0"));
    assert_eq!(name, "g_ic");
    // A penalty so soft that the final separation precedes the onset.
    let (name, reason) = parameter_of(&format!("{bilinear}g_ic = 0.004"));
    assert_eq!(name, "g_ic");
    assert!(reason.contains("penalty"), "{reason}");
    let (name, _) = parameter_of(&format!("{bilinear}g_ic = 1.0\neta = 0.4").replace("eta = 2.0\n", ""));
    assert_eq!(name, "eta");

    let exponential =
        "type = \"exponential\"\nstrength_n = 30.0\npeak_opening_n = 0.0\nstrength_t = 40.0\npeak_opening_t = 0.002";
    assert_eq!(parameter_of(exponential).0, "peak_opening_n");

    let bridging = "type = \"bridging\"\n[matrix]\npenalty = 9e4\nstrength_n = 30.0\nstrength_t = 45.0\ng_ic = 0.25\ng_iic = 0.8\neta = 2.0\n[bridging]\npenalty = 1e4\nstrength_n = -3.0\nstrength_t = 4.5\ng_ic = 0.5\ng_iic = 1.0\neta = 2.0";
    assert_eq!(parameter_of(bridging).0, "bridging.strength_n");
}

#[test]
fn constructors_validate_too() {
    assert!(StCzm::sawtooth(27.0, 0.003, 0.0003, 40.0, 0.00025, 0.003).is_err());
    assert!(Bilinear::bk(1e5, f64::NAN, 45.0, 0.28, 0.9, 2.1).is_err());
    assert!(Exponential::new(30.0, 0.001, -40.0, 0.002).is_err());
    assert!(Bridging::trilinear(1e5, [30.0, 45.0, 0.25, 0.8], [3.0, 9.0, 0.5, 1.0], 2.0).is_err());
}
