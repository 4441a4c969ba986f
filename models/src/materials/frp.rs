//! FRP plate or sheet: linear elastic up to its tensile strength, then brittle rupture.
//!
//! Once the rupture strain `ε_fu = f_fu/E_f` has been exceeded the point carries nothing, in
//! tension or compression, for the rest of the analysis (`history[0] = 1`). In compression the
//! plate is linear elastic with the same modulus: a plate on the soffit of a sagging beam is never
//! compressed much, and no compressive failure is modelled.

use super::{UniaxialMaterial, UniaxialResponse, UniaxialState};
use czid_core::error::require_positive;
use czid_core::Result;
use serde::{Deserialize, Serialize};

const OWNER: &str = "material frp";

/// Linear elastic FRP with brittle tensile rupture.
///
/// ```
/// use czid_models::materials::{Frp, UniaxialMaterial, UniaxialState};
/// let frp = Frp::new(200_000.0, 3_000.0).unwrap();
/// assert_eq!(frp.envelope(0.01), 2_000.0);
/// let broken = frp.respond(0.016, &UniaxialState::default());
/// assert_eq!(broken.stress, 0.0);
/// assert_eq!(frp.respond(0.001, &broken.state).stress, 0.0);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Frp {
    /// Elastic modulus E_f (MPa), on the thickness used for the plate's area.
    pub elastic_modulus: f64,
    /// Tensile strength f_fu (MPa).
    pub tensile_strength: f64,
}

impl Frp {
    /// A validated FRP material.
    pub fn new(elastic_modulus: f64, tensile_strength: f64) -> Result<Self> {
        let frp = Frp { elastic_modulus, tensile_strength };
        frp.validate()?;
        Ok(frp)
    }

    /// Rupture strain `ε_fu = f_fu/E_f`.
    pub fn rupture_strain(&self) -> f64 {
        self.tensile_strength / self.elastic_modulus
    }
}

impl UniaxialMaterial for Frp {
    fn validate(&self) -> Result<()> {
        require_positive(OWNER, "elastic_modulus", self.elastic_modulus)?;
        require_positive(OWNER, "tensile_strength", self.tensile_strength)
    }

    fn respond(&self, strain: f64, previous: &UniaxialState) -> UniaxialResponse {
        let mut state = *previous;
        if previous.history[0] >= 1.0 || strain > self.rupture_strain() {
            state.history[0] = 1.0;
            return UniaxialResponse { stress: 0.0, tangent: 0.0, state };
        }
        UniaxialResponse { stress: self.elastic_modulus * strain, tangent: self.elastic_modulus, state }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_to_rupture_then_nothing() {
        let frp = Frp::new(200_000.0, 3_000.0).unwrap();
        assert_eq!(frp.rupture_strain(), 0.015);
        assert_eq!(frp.envelope(0.015), 3_000.0);
        assert_eq!(frp.envelope(-0.002), -400.0);
        let r = frp.respond(0.0150001, &UniaxialState::default());
        assert_eq!((r.stress, r.tangent, r.state.history[0]), (0.0, 0.0, 1.0));
        assert_eq!(frp.respond(-0.001, &r.state).stress, 0.0);
    }

    #[test]
    fn invalid_parameters_are_named() {
        let e = Frp::new(200_000.0, -5.0).unwrap_err().to_string();
        assert!(e.contains("`tensile_strength`"), "{e}");
        assert!(Frp::new(f64::INFINITY, 3000.0).unwrap_err().to_string().contains("`elastic_modulus`"));
    }
}
