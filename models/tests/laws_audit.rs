//! The verification kit passes every bundled law and catches broken ones.

use czid_core::{CohesiveLaw, Gap, LawEval, LawState, ParameterInfo, Result};
use czid_models::laws::{
    verify, Bilinear, Bridging, Exponential, LuBondSlip, MixedModeCriterion, StCzm, StrengthShape,
};
use serde::{Deserialize, Serialize};

fn bundled() -> Vec<Box<dyn CohesiveLaw>> {
    let table3 = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
    let shapes = [
        (
            StrengthShape::Exponential { alpha: 2.5 },
            StrengthShape::Trilinear { kink_fraction: 0.3, kink_strength_ratio: 0.5 },
        ),
        (
            StrengthShape::Trilinear { kink_fraction: 0.1, kink_strength_ratio: 0.2 },
            StrengthShape::Exponential { alpha: 9.0 },
        ),
    ];
    let mut laws: Vec<Box<dyn CohesiveLaw>> = vec![
        Box::new(table3.clone()),
        Box::new(StCzm::sawtooth(12.0, 0.02513, 0.1457, 14.0, 0.02897, 0.1504).unwrap()),
        Box::new(Bilinear::bk(100.0, 1.0, 1.0, 1.0, 2.0, 2.0).unwrap()),
        Box::new(
            Bilinear::bk(1e5, 30.0, 45.0, 0.28, 0.9, 2.1)
                .unwrap()
                .with_criterion(MixedModeCriterion::PowerLaw)
                .unwrap(),
        ),
        Box::new(Exponential::new(30.0, 0.001, 40.0, 0.002).unwrap()),
        Box::new(Bridging::trilinear(1e5, [30.0, 45.0, 0.25, 0.8], [3.0, 4.5, 0.5, 1.0], 2.0).unwrap()),
        Box::new(LuBondSlip::from_concrete(47.0, 100.0, 200.0, 1000.0).unwrap()),
    ];
    for (n, t) in shapes {
        laws.push(Box::new(table3.clone().with_shapes(n, t).unwrap()));
    }
    laws
}

#[test]
fn audit_passes_for_every_bundled_law() {
    for law in bundled() {
        let report = verify::audit(law.as_ref());
        assert!(report.passed(1e-6), "{law:?}\n{report:?}");
        assert!(report.kinks_skipped.1 > 1000);
        for energy in report.energy {
            assert!(energy.unwrap().relative_error < 1e-7, "{law:?}: {energy:?}");
        }
    }
}

#[test]
fn the_laws_that_say_their_opening_path_is_piecewise_linear_are() {
    for law in bundled() {
        let claim = law.opening_path_piecewise_linear();
        let nonlinearity = verify::opening_path_nonlinearity(law.as_ref());
        assert_eq!(nonlinearity.is_some(), claim, "{law:?}");
        if let Some(e) = nonlinearity {
            assert!(e < 1e-12, "{law:?}: second differences {e:e} of the strength");
        }
    }
    // The sawtooth ST-CZM and the bilinear law say so; curved softening does not.
    let says = |law: &dyn CohesiveLaw| law.opening_path_piecewise_linear();
    assert!(says(&StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap()));
    assert!(says(&Bilinear::bk(1e5, 30.0, 45.0, 0.28, 0.9, 2.1).unwrap()));
    assert!(!says(&Exponential::new(30.0, 0.001, 40.0, 0.002).unwrap()));
}

/// A law with one defect switched on.
#[derive(Debug, Serialize, Deserialize)]
struct Broken {
    inner: Box<dyn CohesiveLaw>,
    defect: Defect,
}

#[derive(Debug, Serialize, Deserialize, PartialEq)]
enum Defect {
    /// Returns the secant instead of the consistent tangent while damage grows.
    SecantTangent,
    /// Claims 10 % more toughness than it dissipates.
    WrongEnergy,
    /// Heals: damage follows the current gap instead of its maximum.
    Heals,
    /// Says its opening path is linear between kinks when it is not.
    ClaimsLinearOpening,
}

#[typetag::serde(name = "test_broken")]
impl CohesiveLaw for Broken {
    fn validate(&self) -> Result<()> {
        self.inner.validate()
    }
    fn evaluate(&self, gap: &Gap, previous: &LawState) -> LawEval {
        let previous = if self.defect == Defect::Heals { LawState::default() } else { *previous };
        let mut eval = self.inner.evaluate(gap, &previous);
        if self.defect == Defect::SecantTangent {
            eval = self.inner.evaluate(gap, &eval.state);
        }
        eval
    }
    fn fracture_energy(&self) -> [f64; 2] {
        let g = self.inner.fracture_energy();
        if self.defect == Defect::WrongEnergy {
            [1.1 * g[0], 1.1 * g[1]]
        } else {
            g
        }
    }
    fn initial_stiffness(&self) -> [f64; 2] {
        self.inner.initial_stiffness()
    }
    fn strength(&self) -> [f64; 2] {
        self.inner.strength()
    }
    fn parameters(&self) -> Vec<ParameterInfo> {
        self.inner.parameters()
    }
    fn opening_path_piecewise_linear(&self) -> bool {
        self.defect == Defect::ClaimsLinearOpening || self.inner.opening_path_piecewise_linear()
    }
}

#[test]
fn audit_catches_each_defect() {
    let inner = || Box::new(Bilinear::bk(1e5, 30.0, 45.0, 0.28, 0.9, 2.1).unwrap()) as Box<dyn CohesiveLaw>;
    let tangent = verify::audit(&Broken { inner: inner(), defect: Defect::SecantTangent });
    assert!(!tangent.passed(1e-6) && tangent.tangent_error > 1e-2, "{tangent:?}");
    let energy = verify::audit(&Broken { inner: inner(), defect: Defect::WrongEnergy });
    assert!(!energy.passed(1e-6) && energy.tangent_error < 1e-6, "{energy:?}");
    assert!(energy.energy[0].unwrap().relative_error > 0.05);
    let heals = verify::audit(&Broken { inner: inner(), defect: Defect::Heals });
    assert!(!heals.passed(1e-6) && !heals.damage_admissible, "{heals:?}");
    assert!(heals.min_dissipation < -1e-5, "{heals:?}");
    // A false claim of a piecewise-linear opening path (the energy integration would skip the
    // law's curvature between kinks).
    let curved = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273)
        .unwrap()
        .with_shapes(StrengthShape::Exponential { alpha: 2.5 }, StrengthShape::Sawtooth)
        .unwrap();
    let claim = verify::audit(&Broken { inner: Box::new(curved), defect: Defect::ClaimsLinearOpening });
    assert!(!claim.passed(1e-6), "{claim:?}");
    assert!(claim.opening_nonlinearity.unwrap() > 1e-8, "{claim:?}");
}
