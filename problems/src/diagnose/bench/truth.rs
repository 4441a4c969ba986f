//! Which model makes a benchmark's synthetic tests.
//!
//! With [`Truth::Beam`] the planted tests come from the very model the diagnosis fits (the same
//! beam DCB with the effect switched on): a check of the diagnosis's logic, but one whose truth
//! comes from the model under test. With [`Truth::Continuum`] they come from the continuum DCB
//! ([`czid_models::dcb_2d`]), a different valid model of the same test, so the diagnosis also
//! meets the model-form gap (root rotation, local shear at the crack front) that real tests have.

use czid_core::{CzError, ForwardModel, Result};
use czid_models::dcb::Dcb;
use czid_models::dcb_2d::Dcb2d;
use serde::Serialize;

use super::Family;

/// Interface element of the continuum test relative to the beam model's.
const FINER: f64 = 0.5;
/// Elements through each arm of the continuum test (the reference model has 4).
const THICKNESS_ELEMENTS: usize = 6;

/// The model that makes the synthetic tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Truth {
    /// The diagnosed (beam) model itself.
    #[default]
    Beam,
    /// The continuum model of the same specimen.
    Continuum,
}

impl std::str::FromStr for Truth {
    type Err = CzError;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "beam" => Ok(Truth::Beam),
            "continuum" => Ok(Truth::Continuum),
            other => Err(CzError::config("--truth", format!("unknown truth `{other}`; known: beam, continuum"))),
        }
    }
}

impl Truth {
    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Truth::Beam => "beam",
            Truth::Continuum => "continuum",
        }
    }

    /// Refuses a family this truth has no model for.
    pub fn check(self, family: Family) -> Result<()> {
        if self == Truth::Continuum && family != Family::Dcb {
            return Err(CzError::config(
                "--truth",
                format!("the {} family has no continuum model yet; use --truth beam", family.name()),
            ));
        }
        Ok(())
    }

    /// The model that makes the test the (beam) model `model` of a case describes, planted
    /// effect included.
    pub fn model(self, model: &dyn ForwardModel) -> Result<Box<dyn ForwardModel>> {
        let as_json = serde_json::to_value(model).map_err(|e| CzError::config("model", e.to_string()))?;
        let copy = || -> Result<Box<dyn ForwardModel>> {
            serde_json::from_value(as_json.clone()).map_err(|e| CzError::config("model", e.to_string()))
        };
        match self {
            Truth::Beam => copy(),
            Truth::Continuum => {
                let mut fields = as_json.clone();
                if fields.get("type").and_then(|t| t.as_str()) != Some("dcb") {
                    return Err(CzError::config("model", format!("`{}` has no continuum counterpart", model.name())));
                }
                fields.as_object_mut().map(|o| o.remove("type"));
                let beam: Dcb = serde_json::from_value(fields).map_err(|e| CzError::config("model", e.to_string()))?;
                // A finer discretisation than the beam model's reference
                // (`ForwardModel::reference`, which the diagnosis runs to estimate the model-form
                // misfit): the test is not made by the model the diagnosis consults.
                let mut made = Dcb2d::from_beam(&beam)?;
                made.mesh.interface_element *= FINER;
                made.mesh.thickness_elements = THICKNESS_ELEMENTS;
                Ok(Box::new(made))
            }
        }
    }
}
