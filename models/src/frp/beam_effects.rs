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
use czid_core::{CzError, EffectDeclaration, EffectKind, EffectScope, Result, Sign, Typical};
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

/// A shared size effect of the beam (one value for every beam of a problem).
const fn shared(
    name: &'static str,
    description: &'static str,
    field: &'static str,
    unit: &'static str,
    range: [f64; 2],
    typical: Typical,
) -> EffectDeclaration {
    EffectDeclaration {
        name,
        description,
        field,
        unit,
        kind: EffectKind::Size { range, null: 0.0 },
        scope: EffectScope::Shared,
        typical: Some(typical),
    }
}

/// The beam's switchable effects, in the order the diagnosis lists them.
const DECLARATIONS: [EffectDeclaration; 5] = [
    shared(
        "adhesive_compliance",
        "shear compliance of the adhesive layer in series with the bond law",
        "effects.adhesive_shear_compliance",
        "mm/MPa",
        [0.0, 2e-3],
        // Adhesive 1–2 mm thick of shear modulus 2–5 GPa: t_a/G_a = 2e-4–1e-3 mm/MPa.
        Typical { magnitude: [2e-4, 1e-3], sign: Sign::Positive },
    ),
    shared(
        "adhesive_normal_compliance",
        "normal (peeling) compliance of the adhesive layer",
        "effects.adhesive_normal_compliance",
        "mm/MPa",
        [0.0, 1e-3],
        // The same layer in peeling, E_a = 5–12 GPa: t_a/E_a = 1e-4–4e-4 mm/MPa.
        Typical { magnitude: [1e-4, 4e-4], sign: Sign::Positive },
    ),
    shared(
        "shrinkage_strain",
        "concrete shrinkage (or swelling) after bonding, prestressing the bond",
        "effects.shrinkage_strain",
        "-",
        [-4e-4, 2e-4],
        // Drying shrinkage of the concrete after the plate was bonded: 100–300 µε.
        Typical { magnitude: [1e-4, 3e-4], sign: Sign::Negative },
    ),
    shared(
        "steel_hardening",
        "a different hardening modulus of the bars after yield",
        "effects.steel_hardening_offset",
        "MPa",
        [-1500.0, 3000.0],
        // Bars hardening at 0.25–0.75 % or 1.25–2.25 % of E_s instead of the assumed 1 %.
        Typical { magnitude: [500.0, 1500.0], sign: Sign::Either },
    ),
    EffectDeclaration {
        name: "deflection_offset",
        description: "seating of the supports (a toe of the load–deflection curve)",
        field: "effects.deflection_offset",
        unit: "mm",
        kind: EffectKind::Size { range: [0.0, 2.0], null: 0.0 },
        scope: EffectScope::PerExperiment,
        // Seating of the supports and load points: 0.3–1.5 mm.
        typical: Some(Typical { magnitude: [0.3, 1.5], sign: Sign::Positive }),
    },
];

impl BeamEffects {
    /// The beam's switchable effects (what the diagnosis offers as candidates for a beam test).
    pub fn declarations() -> Vec<EffectDeclaration> {
        DECLARATIONS.to_vec()
    }

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
