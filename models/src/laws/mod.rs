//! Cohesive laws, each behind [`czid_core::CohesiveLaw`] and registered with `typetag` under the
//! name given in brackets:
//!
//! * [`StCzm`] (`st_czm`): Nairn & Aimene's strength-based model, the law of Shi & Zhang, with
//!   sawtooth, exponential or trilinear strength models per mode ([`StrengthShape`]);
//! * [`Bilinear`] (`bilinear`): Camanho & Dávila's bilinear mixed-mode law, BK or power-law
//!   criterion ([`MixedModeCriterion`]);
//! * [`Exponential`] (`exponential`): Xu–Needleman-type exponential law with secant unloading;
//! * [`Bridging`] (`bridging`): matrix plus fibre-bridging superposition (R-curve), Dávila, Rose &
//!   Camanho;
//! * [`SeriesCompliance`] (`series_compliance`): any of them in series with a through-thickness
//!   compliance (the adherends' give between their sections and the interface).
//!
//! All are secant-damage laws: unloading returns along the damaged secant to the origin, a
//! closing gap meets the undamaged normal penalty, and the tangent returned while damage grows is
//! the consistent (generally unsymmetric) one. [`verify`] holds the checks they all pass.
//!
//! Units: N, mm, MPa; gap `[normal opening, tangential slip]`.

mod bilinear;
mod bridging;
mod dual;
mod exponential;
pub mod lu_bond_slip;
mod response;
mod root;
mod series_compliance;
mod st_czm;
mod strength_model;
pub mod verify;

pub use bilinear::{Bilinear, MixedModeCriterion};
pub use bridging::Bridging;
pub use exponential::Exponential;
pub use lu_bond_slip::LuBondSlip;
pub use series_compliance::SeriesCompliance;
pub use st_czm::StCzm;
pub use strength_model::{ModeStrength, StrengthShape};
