//! Bilinear mixed-mode law of Camanho & Dávila (NASA/TM-2002-211737), with the
//! Benzeggagh–Kenane (or power-law) propagation criterion, as MOOSE's
//! `BiLinearMixedModeTraction` (mode mixity taken from the current gap, not lagged).
//!
//! With `m = ⟨u_n⟩`, `s = |u_t|`, the effective opening is `δ = √(m² + s²)` and the mixity
//! `B = s²/δ²` (= G_II/G_T on a radial path). Damage starts at `δ_0` with
//! `1/δ_0² = (1 − B)/δ_n0² + B/δ_s0²` (`δ_n0 = N/K`, `δ_s0 = S/K`: a quadratic traction criterion),
//! ends at `δ_f = 2 G_c(B)/(K δ_0)` and in between `D = δ_f (δ − δ_0) / (δ (δ_f − δ_0))`, so the
//! effective traction falls linearly; `D` never decreases.

use crate::laws::dual::Dual;
use crate::laws::response::{add_damage_growth, secant};
use czid_core::error::require_positive;
use czid_core::{CohesiveLaw, CzError, Gap, LawEval, LawState, ParameterInfo, Result, Tangent, Traction};
use serde::{Deserialize, Serialize};

const OWNER: &str = "law bilinear";

/// How the mixed-mode toughness `G_c(B)` depends on the mixity `B = G_II/G_T`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MixedModeCriterion {
    /// Benzeggagh–Kenane: `G_c = G_Ic + (G_IIc − G_Ic) B^η`.
    #[default]
    Bk,
    /// Power law: `((1 − B) G_c / G_Ic)^η + (B G_c / G_IIc)^η = 1`.
    PowerLaw,
}

/// Bilinear (triangular) mixed-mode law: penalty stiffness, strengths, toughnesses and a mixed-mode
/// criterion.
///
/// Pure-mode toughness is `G_Ic` (`g_ic`) and `G_IIc` (`g_iic`); the final separations are
/// `2 G_Ic / N` and `2 G_IIc / S`. In compression the penalty `K` acts undamaged.
///
/// ```
/// use czid_core::CohesiveLaw;
/// use czid_models::laws::Bilinear;
/// let law = Bilinear::bk(100.0, 1.0, 1.0, 1.0, 2.0, 2.0).unwrap();
/// assert_eq!(law.fracture_energy(), [1.0, 2.0]);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bilinear {
    /// Penalty (initial) stiffness K, both modes (MPa/mm).
    pub penalty: f64,
    /// Normal strength N (MPa).
    pub strength_n: f64,
    /// Shear strength S (MPa).
    pub strength_t: f64,
    /// Mode I critical energy release rate G_Ic (N/mm).
    pub g_ic: f64,
    /// Mode II critical energy release rate G_IIc (N/mm).
    pub g_iic: f64,
    /// Exponent η of the mixed-mode criterion (dimensionless, > 1/2).
    pub eta: f64,
    /// Mixed-mode criterion (default `bk`).
    #[serde(default)]
    pub criterion: MixedModeCriterion,
}

impl Bilinear {
    /// A validated law with the Benzeggagh–Kenane criterion.
    pub fn bk(penalty: f64, strength_n: f64, strength_t: f64, g_ic: f64, g_iic: f64, eta: f64) -> Result<Self> {
        let law = Bilinear { penalty, strength_n, strength_t, g_ic, g_iic, eta, criterion: MixedModeCriterion::Bk };
        law.validate()?;
        Ok(law)
    }

    /// The same law with another mixed-mode criterion, validated.
    pub fn with_criterion(mut self, criterion: MixedModeCriterion) -> Result<Self> {
        self.criterion = criterion;
        self.validate()?;
        Ok(self)
    }

    /// Mixed-mode toughness `G_c` at mixity `B` (with its gradient carried along).
    fn toughness(&self, mixity: Dual, complement: Dual) -> Dual {
        match self.criterion {
            MixedModeCriterion::Bk => mixity.powf(self.eta) * (self.g_iic - self.g_ic) + self.g_ic,
            MixedModeCriterion::PowerLaw => {
                let sum =
                    (complement * (1.0 / self.g_ic)).powf(self.eta) + (mixity * (1.0 / self.g_iic)).powf(self.eta);
                sum.powf(-1.0 / self.eta)
            }
        }
    }

    /// Mixed-mode toughness `G_c(B)` for a mixity `B = G_II/G_T` in [0, 1] (N/mm).
    pub fn mixed_mode_toughness(&self, mixity: f64) -> f64 {
        let b = mixity.clamp(0.0, 1.0);
        self.toughness(Dual::constant(b), Dual::constant(1.0 - b)).v
    }

    /// Effective openings `(δ_0, δ_f)` at damage onset and completion for a mixity `B` (mm).
    pub fn onset_and_final_opening(&self, mixity: f64) -> (f64, f64) {
        let b = mixity.clamp(0.0, 1.0);
        let onset = 1.0
            / ((1.0 - b) / (self.strength_n / self.penalty).powi(2) + b / (self.strength_t / self.penalty).powi(2))
                .sqrt();
        (onset, 2.0 * self.mixed_mode_toughness(b) / (self.penalty * onset))
    }

    /// Traction, tangent and damage for a gap given the committed damage (shared with the bridging
    /// law, which superposes two of these).
    pub(crate) fn respond(&self, gap: &Gap, damage_old: f64) -> (Traction, Tangent, f64) {
        let stiffness = [self.penalty, self.penalty];
        let damage_old = damage_old.clamp(0.0, 1.0);
        let open = gap.x > 0.0;
        let m = Dual::new(gap.x.max(0.0), [if open { 1.0 } else { 0.0 }, 0.0]);
        let s = Dual::new(gap.y, [0.0, 1.0]);
        let (m2, s2) = (m * m, s * s);
        let effective2 = m2 + s2;
        // No damage growth: the secant of the committed damage.
        let unchanged = || {
            let (t, k) = secant(stiffness, 1.0 - damage_old, gap);
            (t, k, damage_old)
        };
        if damage_old >= 1.0 || effective2.v == 0.0 {
            return unchanged();
        }
        let effective = effective2.sqrt();
        let mixity = s2 / effective2;
        let complement = m2 / effective2;
        let onset_n2 = (self.strength_n / self.penalty).powi(2);
        let onset_s2 = (self.strength_t / self.penalty).powi(2);
        let onset = (complement * (1.0 / onset_n2) + mixity * (1.0 / onset_s2)).sqrt().recip();
        if effective.v <= onset.v {
            // Inside the elastic envelope, before the mixed-mode toughness is worked out (the B-K
            // power is the costliest part of an evaluation).
            return unchanged();
        }
        let final_opening = self.toughness(mixity, complement) * (2.0 / self.penalty) / onset;
        // The intact fraction 1 − D = δ_0 (δ_f − δ) / (δ (δ_f − δ_0)), computed as such so that the
        // traction keeps its digits as D → 1.
        let intact = if effective.v >= final_opening.v || final_opening.v <= onset.v {
            // Beyond the final separation (or a law too stiff to soften there): fully separated.
            Dual::constant(0.0)
        } else {
            onset * (final_opening - effective) / (effective * (final_opening - onset))
        };
        let damage = 1.0 - intact.v;
        if damage <= damage_old {
            return unchanged();
        }
        let (t, mut k) = secant(stiffness, intact.v, gap);
        add_damage_growth(&mut k, stiffness, gap, [-intact.g[0], -intact.g[1]]);
        (t, k, damage)
    }
}

#[typetag::serde(name = "bilinear")]
impl CohesiveLaw for Bilinear {
    fn validate(&self) -> Result<()> {
        require_positive(OWNER, "penalty", self.penalty)?;
        require_positive(OWNER, "strength_n", self.strength_n)?;
        require_positive(OWNER, "strength_t", self.strength_t)?;
        require_positive(OWNER, "g_ic", self.g_ic)?;
        require_positive(OWNER, "g_iic", self.g_iic)?;
        require_positive(OWNER, "eta", self.eta)?;
        if self.eta <= 0.5 {
            return Err(CzError::invalid(
                OWNER,
                "eta",
                self.eta,
                "must exceed 1/2 (the law must stay differentiable in pure mode I)",
            ));
        }
        for (name, strength, toughness) in
            [("g_ic", self.strength_n, self.g_ic), ("g_iic", self.strength_t, self.g_iic)]
        {
            let elastic_energy = 0.5 * strength * strength / self.penalty;
            if toughness <= elastic_energy {
                return Err(CzError::invalid(
                    OWNER,
                    name,
                    toughness,
                    format!("must exceed the elastic energy at the strength, σ²/(2K) = {elastic_energy:e}: raise `penalty` or lower the strength"),
                ));
            }
        }
        // The final separation must exceed the onset at every mixity, not only in pure modes.
        for i in 1..200 {
            let mixity = i as f64 / 200.0;
            let (onset, final_opening) = self.onset_and_final_opening(mixity);
            if final_opening <= onset {
                return Err(CzError::invalid(
                    OWNER,
                    "penalty",
                    self.penalty,
                    format!("too low: at mode mixity G_II/G_T = {mixity} damage would be complete before it starts"),
                ));
            }
        }
        Ok(())
    }

    fn evaluate(&self, gap: &Gap, previous: &LawState) -> LawEval {
        let (traction, tangent, damage) = self.respond(gap, previous.damage);
        LawEval { traction, tangent, state: LawState { damage, history: previous.history } }
    }

    fn fracture_energy(&self) -> [f64; 2] {
        [self.g_ic, self.g_iic]
    }

    fn initial_stiffness(&self) -> [f64; 2] {
        [self.penalty, self.penalty]
    }

    /// Linear softening: `T = K δ₀ (δ_f − δ)/(δ_f − δ₀)` between onset and failure.
    fn opening_path_piecewise_linear(&self) -> bool {
        true
    }

    fn strength(&self) -> [f64; 2] {
        [self.strength_n, self.strength_t]
    }

    /// With the B-K criterion, the penalty, the normal strength and `G_Ic`: at zero slip the mode
    /// mix is an exact zero, so is its power, and `G_c = G_Ic` to the bit. The power law's
    /// `G_c`, a power and its inverse, keeps `η` in its last digits: no key.
    fn mode_one_key(&self) -> Option<Vec<u64>> {
        (self.criterion == MixedModeCriterion::Bk)
            .then(|| vec![self.penalty.to_bits(), self.strength_n.to_bits(), self.g_ic.to_bits()])
    }

    fn with_bridging_tail(&self, strength: f64, opening: f64) -> Option<Result<Box<dyn CohesiveLaw>>> {
        Some(if strength == 0.0 {
            // The null: the law itself, not a superposition with an empty part.
            Ok(Box::new(self.clone()))
        } else {
            crate::laws::Bridging::bilinear_with_tail(self, strength, opening)
                .map(|b| Box::new(b) as Box<dyn CohesiveLaw>)
        })
    }

    fn parameters(&self) -> Vec<ParameterInfo> {
        vec![
            ParameterInfo {
                name: "penalty",
                value: self.penalty,
                unit: "MPa/mm",
                meaning: "penalty (initial) stiffness K",
            },
            ParameterInfo { name: "strength_n", value: self.strength_n, unit: "MPa", meaning: "normal strength N" },
            ParameterInfo { name: "strength_t", value: self.strength_t, unit: "MPa", meaning: "shear strength S" },
            ParameterInfo { name: "g_ic", value: self.g_ic, unit: "N/mm", meaning: "mode I toughness G_Ic" },
            ParameterInfo { name: "g_iic", value: self.g_iic, unit: "N/mm", meaning: "mode II toughness G_IIc" },
            ParameterInfo { name: "eta", value: self.eta, unit: "-", meaning: "mixed-mode criterion exponent η" },
        ]
    }
}
