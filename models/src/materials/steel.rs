//! Reinforcing steel: elastic, yield at `f_y`, linear hardening with tangent modulus `E_h`,
//! symmetric in tension and compression.
//!
//! Under cycles the hardening is kinematic (the elastic range keeps its width `2 f_y` and moves
//! with the back stress `H ε_p`, `H = E E_h/(E − E_h)`), so a reversal yields after a stress change
//! of `2 f_y` (Bauschinger-like); monotonic loading gives the bilinear curve
//! `σ = f_y + E_h (ε − ε_y)`. Return mapping in closed form. No rupture strain: beam tests end
//! by concrete crushing or debonding long before bars break.
//!
//! History: `history[0]` = plastic strain ε_p.

use super::{UniaxialMaterial, UniaxialResponse, UniaxialState};
use czid_core::error::{require_non_negative, require_positive};
use czid_core::{CzError, Result};
use serde::{Deserialize, Serialize};

const OWNER: &str = "material steel";

/// Bilinear steel with kinematic hardening.
///
/// ```
/// use czid_models::materials::{Steel, UniaxialMaterial};
/// let steel = Steel::new(200_000.0, 500.0, 2_000.0).unwrap();
/// assert_eq!(steel.envelope(0.0025), 500.0);
/// assert!((steel.envelope(0.0125) - (500.0 + 2_000.0 * 0.01)).abs() < 1e-9);
/// assert!((steel.envelope(-0.0125) + 520.0).abs() < 1e-9);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Steel {
    /// Young's modulus E_s (MPa).
    pub elastic_modulus: f64,
    /// Yield strength f_y (MPa).
    pub yield_strength: f64,
    /// Tangent modulus after yield E_h, `0 ≤ E_h < E_s` (MPa).
    pub hardening_modulus: f64,
}

impl Steel {
    /// A validated steel.
    pub fn new(elastic_modulus: f64, yield_strength: f64, hardening_modulus: f64) -> Result<Self> {
        let steel = Steel { elastic_modulus, yield_strength, hardening_modulus };
        steel.validate()?;
        Ok(steel)
    }

    /// Yield strain `ε_y = f_y/E_s`.
    pub fn yield_strain(&self) -> f64 {
        self.yield_strength / self.elastic_modulus
    }

    /// Kinematic hardening modulus `H = E E_h/(E − E_h)` (stress per unit plastic strain).
    fn plastic_modulus(&self) -> f64 {
        let (e, eh) = (self.elastic_modulus, self.hardening_modulus);
        e * eh / (e - eh)
    }
}

/// A [`Steel`] with its plastic modulus worked out once: [`PreparedSteel::respond`] gives exactly
/// [`Steel::respond`]'s results.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedSteel {
    e: f64,
    fy: f64,
    eh: f64,
    h: f64,
}

impl Steel {
    /// The steel with its plastic modulus worked out (see [`PreparedSteel`]).
    pub fn prepared(&self) -> PreparedSteel {
        PreparedSteel {
            e: self.elastic_modulus,
            fy: self.yield_strength,
            eh: self.hardening_modulus,
            h: self.plastic_modulus(),
        }
    }
}

impl PreparedSteel {
    /// Young's modulus (MPa).
    #[inline(always)]
    pub fn elastic_modulus(&self) -> f64 {
        self.e
    }

    /// Exactly [`Steel::respond`].
    #[inline(always)]
    pub fn respond(&self, strain: f64, previous: &UniaxialState) -> UniaxialResponse {
        let (e, h) = (self.e, self.h);
        let plastic = previous.history[0];
        let trial = e * (strain - plastic);
        let relative = trial - h * plastic;
        let excess = relative.abs() - self.fy;
        if excess <= 0.0 {
            return UniaxialResponse { stress: trial, tangent: e, state: *previous };
        }
        let increment = excess / (e + h) * relative.signum();
        let mut state = *previous;
        state.history[0] = plastic + increment;
        UniaxialResponse { stress: trial - e * increment, tangent: self.eh, state }
    }
}

impl UniaxialMaterial for Steel {
    fn validate(&self) -> Result<()> {
        require_positive(OWNER, "elastic_modulus", self.elastic_modulus)?;
        require_positive(OWNER, "yield_strength", self.yield_strength)?;
        require_non_negative(OWNER, "hardening_modulus", self.hardening_modulus)?;
        if self.hardening_modulus >= self.elastic_modulus {
            return Err(CzError::invalid(
                OWNER,
                "hardening_modulus",
                self.hardening_modulus,
                format!("must be below the elastic modulus {}", self.elastic_modulus),
            ));
        }
        Ok(())
    }

    #[inline]
    fn respond(&self, strain: f64, previous: &UniaxialState) -> UniaxialResponse {
        let (e, h) = (self.elastic_modulus, self.plastic_modulus());
        let plastic = previous.history[0];
        let trial = e * (strain - plastic);
        let relative = trial - h * plastic;
        let excess = relative.abs() - self.yield_strength;
        if excess <= 0.0 {
            return UniaxialResponse { stress: trial, tangent: e, state: *previous };
        }
        let increment = excess / (e + h) * relative.signum();
        let mut state = *previous;
        state.history[0] = plastic + increment;
        UniaxialResponse { stress: trial - e * increment, tangent: self.hardening_modulus, state }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steel() -> Steel {
        Steel::new(200_000.0, 500.0, 2_000.0).unwrap()
    }

    #[test]
    fn monotonic_curve_is_bilinear_and_symmetric() {
        let s = steel();
        for strain in [0.001, 0.0025, 0.004, 0.02, 0.08] {
            let expected = if strain <= 0.0025 { 200_000.0 * strain } else { 500.0 + 2_000.0 * (strain - 0.0025) };
            assert!((s.envelope(strain) - expected).abs() < 1e-9 * expected, "{strain}");
            assert!((s.envelope(-strain) + expected).abs() < 1e-9 * expected, "{strain}");
        }
    }

    #[test]
    fn unloading_is_elastic_and_reverse_yield_is_two_fy_below() {
        let s = steel();
        let loaded = s.respond(0.0125, &UniaxialState::default());
        assert!((loaded.stress - 520.0).abs() < 1e-9);
        // Elastic unloading by Δσ = E Δε.
        let back = s.respond(0.0125 - 0.001, &loaded.state);
        assert!((back.stress - 320.0).abs() < 1e-9 && back.tangent == 200_000.0);
        // Kinematic hardening: reverse yield at 520 − 2·500 = −480 MPa.
        let reverse_yield = 0.0125 - 1000.0 / 200_000.0;
        assert!((s.respond(reverse_yield + 1e-7, &loaded.state).tangent - 200_000.0).abs() < 1e-9);
        let beyond = s.respond(reverse_yield - 0.001, &loaded.state);
        assert!((beyond.stress - (-480.0 - 2_000.0 * 0.001)).abs() < 1e-9, "{}", beyond.stress);
        assert_eq!(beyond.tangent, 2_000.0);
    }

    #[test]
    fn tangent_matches_finite_differences() {
        let s = steel();
        let loaded = s.respond(0.01, &UniaxialState::default()).state;
        for (strain, state) in [(0.001, UniaxialState::default()), (0.006, UniaxialState::default()), (0.009, loaded)] {
            let h = 1e-8;
            let fd = (s.respond(strain + h, &state).stress - s.respond(strain - h, &state).stress) / (2.0 * h);
            assert!((s.respond(strain, &state).tangent - fd).abs() < 1e-4 * fd, "{strain}");
        }
    }

    #[test]
    fn prepared_steel_gives_the_same_results() {
        let s = steel();
        let prepared = s.prepared();
        let loaded = s.respond(0.01, &UniaxialState::default()).state;
        let reversed = s.respond(-0.01, &loaded).state;
        for state in [UniaxialState::default(), loaded, reversed] {
            for i in -300..=300 {
                let strain = i as f64 * 5e-5;
                assert_eq!(prepared.respond(strain, &state), s.respond(strain, &state), "{strain}");
            }
        }
    }

    #[test]
    fn invalid_parameters_are_named() {
        let message = |s: Steel| s.validate().unwrap_err().to_string();
        assert!(message(Steel { hardening_modulus: 2e5, ..steel() }).contains("`hardening_modulus`"));
        assert!(message(Steel { hardening_modulus: -1.0, ..steel() }).contains("`hardening_modulus`"));
        assert!(message(Steel { yield_strength: 0.0, ..steel() }).contains("`yield_strength`"));
        assert!(serde_json::from_str::<Steel>(
            r#"{"elastic_modulus": 2e5, "yield_strength": 500, "hardening_modulus": 0, "fu": 600}"#
        )
        .is_err());
    }
}
