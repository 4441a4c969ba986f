//! Exponential law of the Xu–Needleman type with secant-damage irreversibility.
//!
//! Loading follows Xu & Needleman's normal law `T_n = e σ_n (u_n/δ_n) e^{−u_n/δ_n}` (peak σ_n at
//! `u_n = δ_n`, work of separation `e σ_n δ_n`), and the same form in shear with σ_t, δ_t (peak σ_t at
//! slip δ_t, work `e σ_t δ_t`). Modes couple through the normalised effective opening
//! `λ = √((⟨u_n⟩/δ_n)² + (u_t/δ_t)²)`: with `K = diag(e σ_n/δ_n, e σ_t/δ_t)` the traction is
//! `T = e^{−λ_max} K ⟨u⟩`, where `λ_max` is the largest λ reached.
//!
//! Choices (the original potential has no unloading rule):
//! * **Damage** is `D = 1 − e^{−λ_max}`, exactly one minus the secant-stiffness ratio, so unloading
//!   and reloading run along the damaged secant to the origin and `½ T·u` is the stored energy.
//!   Damage grows from the first opening: the law has no elastic range.
//! * **Separation.** The exponential never reaches zero; the interface counts as separated, `D = 1`
//!   and zero traction, once `λ_max ≥` [`Exponential::SEPARATED_AT`] = 20, where the traction has
//!   fallen to `20 e^{−19} ≈ 1.1e−7` of the peak. The work beyond is `21 e^{−20} ≈ 4.3e−8` of the
//!   total, and [`CohesiveLaw::fracture_energy`] reports the truncated value.
//! * Xu & Needleman's Gaussian shear term is not used: it gives no consistent damage variable.
//! * `history[0]` holds `λ_max`.

use crate::laws::response::{add_damage_growth, opening, secant};
use czid_core::error::require_positive;
use czid_core::{CohesiveLaw, Gap, LawEval, LawState, ParameterInfo, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::E;

const OWNER: &str = "law exponential";

/// Exponential (Xu–Needleman type) cohesive law: peak traction σ at opening δ per mode.
///
/// ```
/// use czid_core::CohesiveLaw;
/// use czid_models::laws::Exponential;
/// let law = Exponential::new(30.0, 0.001, 40.0, 0.002).unwrap();
/// let g = law.fracture_energy()[0];
/// assert!((g - std::f64::consts::E * 30.0 * 0.001).abs() < 1e-7 * g);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Exponential {
    /// Normal strength σ_n, the peak of the pure mode I law (MPa).
    pub strength_n: f64,
    /// Normal opening δ_n at the peak (mm).
    pub peak_opening_n: f64,
    /// Shear strength σ_t, the peak of the pure mode II law (MPa).
    pub strength_t: f64,
    /// Slip δ_t at the shear peak (mm).
    pub peak_opening_t: f64,
}

impl Exponential {
    /// Normalised effective opening λ at which the interface counts as separated (`D = 1`).
    pub const SEPARATED_AT: f64 = 20.0;

    /// A validated law.
    pub fn new(strength_n: f64, peak_opening_n: f64, strength_t: f64, peak_opening_t: f64) -> Result<Self> {
        let law = Exponential { strength_n, peak_opening_n, strength_t, peak_opening_t };
        law.validate()?;
        Ok(law)
    }

    fn stiffness(&self) -> [f64; 2] {
        [E * self.strength_n / self.peak_opening_n, E * self.strength_t / self.peak_opening_t]
    }

    /// Fraction of `e σ δ` released up to separation: `1 − (1 + λ_s) e^{−λ_s}`.
    fn released_fraction() -> f64 {
        1.0 - (1.0 + Self::SEPARATED_AT) * (-Self::SEPARATED_AT).exp()
    }
}

#[typetag::serde(name = "exponential")]
impl CohesiveLaw for Exponential {
    fn validate(&self) -> Result<()> {
        require_positive(OWNER, "strength_n", self.strength_n)?;
        require_positive(OWNER, "peak_opening_n", self.peak_opening_n)?;
        require_positive(OWNER, "strength_t", self.strength_t)?;
        require_positive(OWNER, "peak_opening_t", self.peak_opening_t)
    }

    fn evaluate(&self, gap: &Gap, previous: &LawState) -> LawEval {
        let stiffness = self.stiffness();
        let (x_n, x_t) = (opening(gap) / self.peak_opening_n, gap.y / self.peak_opening_t);
        let lambda = (x_n * x_n + x_t * x_t).sqrt();
        let lambda_old = previous.history[0];
        let result = |damage: f64, intact: f64, lambda_max: f64| {
            let (traction, tangent) = secant(stiffness, intact, gap);
            let mut history = previous.history;
            history[0] = lambda_max;
            LawEval { traction, tangent, state: LawState { damage, history } }
        };
        if lambda <= lambda_old || previous.damage >= 1.0 {
            return result(previous.damage, 1.0 - previous.damage, lambda_old);
        }
        if lambda >= Self::SEPARATED_AT {
            return result(1.0, 0.0, lambda);
        }
        let intact = (-lambda).exp();
        let mut eval = result(1.0 - intact, intact, lambda);
        // ∂D/∂u = e^{−λ} ∂λ/∂u, ∂λ/∂u = [⟨u_n⟩/δ_n², u_t/δ_t²] / λ.
        let scale = intact / lambda;
        let gradient = [scale * x_n / self.peak_opening_n, scale * x_t / self.peak_opening_t];
        add_damage_growth(&mut eval.tangent, stiffness, gap, gradient);
        eval
    }

    fn fracture_energy(&self) -> [f64; 2] {
        let fraction = Self::released_fraction();
        [E * self.strength_n * self.peak_opening_n * fraction, E * self.strength_t * self.peak_opening_t * fraction]
    }

    fn initial_stiffness(&self) -> [f64; 2] {
        self.stiffness()
    }

    fn strength(&self) -> [f64; 2] {
        [self.strength_n, self.strength_t]
    }

    fn parameters(&self) -> Vec<ParameterInfo> {
        vec![
            ParameterInfo {
                name: "strength_n",
                value: self.strength_n,
                unit: "MPa",
                meaning: "normal peak traction σ_n",
            },
            ParameterInfo {
                name: "peak_opening_n",
                value: self.peak_opening_n,
                unit: "mm",
                meaning: "normal opening at the peak δ_n",
            },
            ParameterInfo {
                name: "strength_t",
                value: self.strength_t,
                unit: "MPa",
                meaning: "shear peak traction σ_t",
            },
            ParameterInfo {
                name: "peak_opening_t",
                value: self.peak_opening_t,
                unit: "mm",
                meaning: "slip at the shear peak δ_t",
            },
        ]
    }
}
