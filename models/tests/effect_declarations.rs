//! Every bundled model's declared effects: the field exists in the model's configuration, holds
//! the null value in the base model, writing the null value back changes nothing, and writing a
//! value inside the declared range changes the model; names are unique per model.

use czid_core::{EffectKind, ForwardModel, Parameter, ParameterSpace};
use czid_models::dcb::Dcb;
use czid_models::enf::Enf;
use czid_models::frp::beam::FrpBeam;

fn models() -> Vec<Box<dyn ForwardModel>> {
    vec![
        Box::new(Dcb::paper()),
        Box::new(Dcb::hartlen_dcb01()),
        Box::new(Enf::hartlen_enf03()),
        Box::new(FrpBeam::paper().unwrap()),
        Box::new(czid_models::dcb_2d::Dcb2d::hartlen_dcb01()),
        Box::new(czid_models::enf_2d::Enf2d::hartlen_enf03()),
        Box::new(czid_models::mmb::Mmb::hartlen(50.0)),
    ]
}

#[test]
fn every_declared_field_exists_and_its_null_is_the_base_model() {
    for model in models() {
        let declared = model.effects();
        assert!(!declared.is_empty(), "{} declares no effect", model.name());
        for (i, d) in declared.iter().enumerate() {
            assert!(declared[..i].iter().all(|e| e.name != d.name), "{}: `{}` twice", model.name(), d.name);
            let [lo, hi] = d.range();
            assert!(lo < hi && (lo..=hi).contains(&d.null()), "{}: range of `{}`", model.name(), d.name);
            let space = ParameterSpace::new(vec![Parameter::new(d.field, d.unit, lo, hi)]).unwrap();
            let value = space.read(&model).unwrap_or_else(|e| panic!("{}: `{}`: {e}", model.name(), d.field));
            assert_eq!(value, vec![d.null()], "{}: `{}` is not at its null value", model.name(), d.name);
            let same: Box<dyn ForwardModel> = space.apply(&model, &[d.null()]).unwrap();
            assert_eq!(serde_json::to_value(&same).unwrap(), serde_json::to_value(&model).unwrap(), "{}", d.name);
            same.validate().unwrap();
            let on = match d.kind {
                EffectKind::Switch => 1.0,
                EffectKind::Size { .. } => d.typical.map_or(if d.null() == lo { hi } else { lo }, |t| {
                    let m = 0.5 * (t.magnitude[0] + t.magnitude[1]);
                    if t.sign == czid_core::Sign::Negative {
                        -m
                    } else {
                        m
                    }
                }),
            };
            let changed: Box<dyn ForwardModel> = space.apply(&model, &[on]).unwrap();
            assert_ne!(serde_json::to_value(&changed).unwrap(), serde_json::to_value(&model).unwrap(), "{}", d.name);
            changed.validate().unwrap_or_else(|e| panic!("{}: `{}` = {on}: {e}", model.name(), d.name));
        }
    }
}
