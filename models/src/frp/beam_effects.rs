//! Switchable physical effects of the FRP-strengthened beam, for diagnosing the gap between the
//! model and a test.
//!
//! Every effect is a number whose null value (`BeamEffects::default()`, all zero) reproduces the
//! base model **exactly** (bit for bit: the base code path is taken, not a limit of the effect),
//! and on which the responses depend smoothly away from it, so an identification can switch an
//! effect on, estimate it and take finite-difference sensitivities to it.
//!
//! The concrete's tensile strength and fracture energy are not among them: the model takes its
//! cracks as formed (they carry no tension) and keeps the concrete between them uncracked, so
//! neither would change its response.

use czid_core::error::require_non_negative;
use czid_core::{CzError, Result};
use serde::{Deserialize, Serialize};

/// Optional physics of the plated beam. `BeamEffects::default()` is the base model.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BeamEffects {
    /// Shear compliance of an adhesive layer in series with the interface law (mm/MPa): the slip
    /// the layer adds per unit bond stress, `t_a/G_a` (1 mm of epoxy with G_a = 1.5 GPa: 6.7e-4).
    /// The law then sees only the rest of the slip. 0: none (the law is the whole bond).
    pub adhesive_shear_compliance: f64,
    /// Normal compliance of the adhesive layer in series with the law (mm/MPa), `t_a/E_a`.
    /// 0: none.
    pub adhesive_normal_compliance: f64,
    /// Free shrinkage (negative) or swelling strain of the concrete after the plate was bonded,
    /// an initial strain of every concrete fibre, restrained by the bars and the plate: it
    /// prestresses the bond (shear at the plate ends) and cracks nothing by itself at usual values
    /// (−1e-4 … −3e-4). 0: none.
    pub shrinkage_strain: f64,
    /// Added to the bars' hardening modulus E_h (MPa); the result must stay within
    /// `[0, E_s)`. 0: the nominal E_h.
    pub steel_hardening_offset: f64,
    /// Seating offset (mm) added to the recorded deflection, with an unloaded first row at zero
    /// (the toe of a test curve). 0: none.
    pub deflection_offset: f64,
}

impl BeamEffects {
    /// Checks every value, naming the field of `owner` that is invalid.
    pub fn validate(&self, owner: &str) -> Result<()> {
        require_non_negative(owner, "effects.adhesive_shear_compliance", self.adhesive_shear_compliance)?;
        require_non_negative(owner, "effects.adhesive_normal_compliance", self.adhesive_normal_compliance)?;
        require_non_negative(owner, "effects.deflection_offset", self.deflection_offset)?;
        if !(self.shrinkage_strain.is_finite() && self.shrinkage_strain.abs() < 0.002) {
            return Err(CzError::invalid(
                owner,
                "effects.shrinkage_strain",
                self.shrinkage_strain,
                "must lie within ±0.002",
            ));
        }
        if !self.steel_hardening_offset.is_finite() {
            return Err(CzError::invalid(
                owner,
                "effects.steel_hardening_offset",
                self.steel_hardening_offset,
                "must be finite",
            ));
        }
        Ok(())
    }

    /// Whether every effect is at its null value.
    pub fn is_null(&self) -> bool {
        *self == BeamEffects::default()
    }
}
