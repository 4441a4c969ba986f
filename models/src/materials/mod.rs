//! Uniaxial material models for fibre sections and bar/plate elements of the FRP-strengthened
//! beam: stress and tangent for a strain, given the committed history of the material point.
//!
//! * [`Concrete`]: Hognestad parabola in compression, linear to `f_t` then linear softening in
//!   tension, regularised by the fracture energy over a crack band;
//! * [`Steel`]: elastic, yield, linear (kinematic) hardening, symmetric;
//! * [`Frp`]: linear elastic to rupture.
//!
//! Sign convention: tension positive (strain and stress). Units: MPa, mm, N/mm.
//!
//! Like cohesive laws, materials are plain values; the history lives in a [`UniaxialState`] that
//! the caller stores per material point and commits once a step has converged.

pub mod concrete;
pub mod frp;
pub mod steel;

pub use concrete::{Concrete, PreparedConcrete};
pub use frp::Frp;
pub use steel::{PreparedSteel, Steel};

use czid_core::Result;
use serde::{Deserialize, Serialize};

/// History of one material point; the meaning of each entry is the material's own.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct UniaxialState {
    /// Material-specific history variables (all zero for a virgin point).
    pub history: [f64; 2],
}

/// Stress, tangent and trial state of a material at a strain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UniaxialResponse {
    /// Stress (MPa, tension positive).
    pub stress: f64,
    /// `dσ/dε` holding the committed history fixed (MPa).
    pub tangent: f64,
    /// Trial history, to commit once the step converges.
    pub state: UniaxialState,
}

/// A rate-independent uniaxial material.
///
/// Contract: [`UniaxialMaterial::respond`] is pure (depends only on the strain and the committed
/// state), and its tangent is the derivative of its stress with the committed state held fixed.
pub trait UniaxialMaterial {
    /// Checks the parameters; returns an error naming the first invalid one.
    fn validate(&self) -> Result<()>;

    /// Stress, tangent and trial state at `strain` from the committed state `previous`.
    fn respond(&self, strain: f64, previous: &UniaxialState) -> UniaxialResponse;

    /// Stress on the monotonic loading curve (from a virgin state) at `strain` (MPa).
    fn envelope(&self, strain: f64) -> f64 {
        self.respond(strain, &UniaxialState::default()).stress
    }
}
