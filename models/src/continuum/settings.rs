//! What the continuum test models share: mesh settings, switchable effects, and the conversion
//! of path rows into a record with the beam models' columns.

use czid_core::error::require_non_negative;
use czid_core::{CzError, EffectDeclaration, Record, Result};
use serde::{Deserialize, Serialize};

use super::path::Row;
use crate::beamtest::{self, RowScale};

/// Element sizes of a continuum model (mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContinuumMesh {
    /// Element length along the crack path, where the crack can run (mm): one cohesive point per
    /// node, so this is also the cohesive points' spacing.
    pub interface_element: f64,
    /// Largest element length elsewhere along the arms (mm); elements grow geometrically (×1.2)
    /// from `interface_element` at the crack front to it.
    pub arm_element: f64,
    /// Elements through the thickness of each arm.
    pub thickness_elements: usize,
    /// Ratio of each element's thickness to the next one's towards the interface (≥ 1; 1:
    /// uniform): fine where the crack runs, coarse at the arms' outer faces.
    pub thickness_grading: f64,
    /// Gauss points per interface element (1–4), or 0 for nodal (Newton–Cotes) integration; see
    /// [`crate::continuum::interface`].
    pub interface_points: usize,
}

impl Default for ContinuumMesh {
    fn default() -> Self {
        ContinuumMesh {
            interface_element: 0.1,
            arm_element: 1.0,
            thickness_elements: 4,
            thickness_grading: 1.0,
            interface_points: 4,
        }
    }
}

impl ContinuumMesh {
    /// The same mesh with one element fewer through each arm (`None` below three): the
    /// through-thickness discretisation is what keeps a few-element arm from the converged
    /// bending and shear near the crack front, while the interface elements must stay (they
    /// resolve the cohesive zone). A model run on both tells how far its own discretisation is
    /// from converged ([`czid_core::ForwardModel::coarsened`]).
    pub fn coarsened(&self) -> Option<ContinuumMesh> {
        (self.thickness_elements > 2)
            .then(|| ContinuumMesh { thickness_elements: self.thickness_elements - 1, ..*self })
    }
}

/// Largest number of nodes a continuum mesh may have (about 0.5 GB with the band LU).
pub const MAX_NODES: usize = 2_000_000;

impl ContinuumMesh {
    /// Checks the sizes.
    pub fn validate(&self, owner: &str) -> Result<()> {
        beamtest::positive(owner, "mesh.interface_element", self.interface_element)?;
        beamtest::positive(owner, "mesh.arm_element", self.arm_element)?;
        if self.interface_element < beamtest::MIN_ELEMENT {
            return Err(CzError::invalid(
                owner,
                "mesh.interface_element",
                self.interface_element,
                format!("is below {} mm, far finer than any cohesive zone needs", beamtest::MIN_ELEMENT),
            ));
        }
        if !(1..=64).contains(&self.thickness_elements) {
            return Err(CzError::invalid(
                owner,
                "mesh.thickness_elements",
                self.thickness_elements as f64,
                "must be between 1 and 64",
            ));
        }
        if !(self.thickness_grading.is_finite() && (1.0..=10.0).contains(&self.thickness_grading)) {
            return Err(CzError::invalid(
                owner,
                "mesh.thickness_grading",
                self.thickness_grading,
                "must lie in [1, 10] (1: uniform)",
            ));
        }
        if self.interface_points > 4 {
            return Err(CzError::invalid(
                owner,
                "mesh.interface_points",
                self.interface_points as f64,
                "must be 0 (nodal integration) or 1–4 Gauss points",
            ));
        }
        Ok(())
    }

    /// Refuses a mesh of more than [`MAX_NODES`] nodes over `length` mm and `layers` arms.
    pub fn check_size(&self, owner: &str, length: f64, layers: usize) -> Result<()> {
        let nodes = (length / self.interface_element + 1.0) * ((self.thickness_elements + 1) * layers) as f64;
        if nodes > MAX_NODES as f64 {
            return Err(CzError::invalid(
                owner,
                "mesh.interface_element",
                self.interface_element,
                format!("gives about {nodes:.3e} nodes (at most {MAX_NODES}): use a coarser mesh"),
            ));
        }
        Ok(())
    }
}

/// Optional physics of a continuum test model; the default is the base model. The beam models'
/// `root_compliance` and `shear_compliance` have no counterpart: the continuum resolves both.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContinuumEffects {
    /// Compliance of the machine and load train (mm/N): the recorded displacement is
    /// `δ + C_m P`. 0: rigid machine.
    pub machine_compliance: f64,
    /// Added to the nominal initial crack length (mm). 0: nominal.
    pub crack_length_offset: f64,
    /// Seating offset (mm): an unloaded toe, then every displacement shifted. 0: none.
    pub displacement_offset: f64,
    /// Large displacements (total Lagrangian) instead of small strain.
    pub large_rotation: bool,
    /// Load-cell zero offset (N): every recorded load is `P + offset`. 0: none.
    pub load_offset: f64,
    /// Depth of a smooth seating toe (mm), see [`crate::measurement::Readout`]. 0: none.
    pub seating_toe: f64,
}

impl ContinuumEffects {
    /// Checks the values.
    pub fn validate(&self, owner: &str) -> Result<()> {
        require_non_negative(owner, "effects.machine_compliance", self.machine_compliance)?;
        require_non_negative(owner, "effects.seating_toe", self.seating_toe)?;
        for (name, v) in [
            ("effects.crack_length_offset", self.crack_length_offset),
            ("effects.displacement_offset", self.displacement_offset),
            ("effects.load_offset", self.load_offset),
        ] {
            if !v.is_finite() {
                return Err(CzError::invalid(owner, name, v, "must be finite"));
            }
        }
        Ok(())
    }

    /// The effects a continuum model declares (`large`: whether it offers large displacements).
    pub fn declarations(large: bool) -> Vec<EffectDeclaration> {
        use crate::measurement::{DISPLACEMENT_OFFSET, LOAD_OFFSET, MACHINE_COMPLIANCE, SEATING_TOE};
        let mut out = Vec::new();
        if large {
            out.push(crate::effects::LARGE_ROTATION);
        }
        out.extend([
            MACHINE_COMPLIANCE,
            crate::effects::CRACK_LENGTH_OFFSET,
            DISPLACEMENT_OFFSET,
            LOAD_OFFSET,
            SEATING_TOE,
        ]);
        out
    }

    /// How the instruments read the specimen (the measurement effects but the machine's).
    pub fn readout(&self) -> crate::measurement::Readout {
        crate::measurement::Readout {
            displacement_offset: self.displacement_offset,
            load_offset: self.load_offset,
            seating_toe: self.seating_toe,
        }
    }
}

/// The record of `rows` scaled into the specimen's displacement, load and energies.
pub fn record(rows: &[Row], s: &RowScale) -> Record {
    let states: Vec<beamtest::EngineState> = rows
        .iter()
        .map(|r| beamtest::EngineState {
            control: r.control,
            reaction: r.reaction,
            crack: [r.crack.debonded, r.crack.process_zone, r.crack.tip],
            energies: [r.external_work, r.elastic_energy, r.dissipated_energy],
        })
        .collect();
    beamtest::record_states(&states, s)
}
