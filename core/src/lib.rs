//! # czid-core: the vocabulary of czid
//!
//! Everything else in czid is written in these terms:
//!
//! * [`CohesiveLaw`]: traction–separation law of an interface (per integration point history,
//!   traction and consistent tangent for a two-component gap). Object safe and registered with
//!   `typetag`, so configuration files name a law by `type = "..."`.
//! * [`ForwardModel`]: a simulated test (DCB, ENF, FRP beam, ...) that runs with any law and returns a
//!   [`Record`] of named, unit-carrying columns per converged step.
//! * [`Response`]: a curve extracted from a record (load vs displacement, debonded length vs
//!   displacement, ...), compared with experimental [`Curve`]s by the [`CompositeObjective`]
//!   (Eq. 14–18 of Shi & Zhang); [`event`] holds the scalar ones (peak load, debonded length at
//!   the onset of debonding and at the end of the test, displacement at a load).
//! * [`ParameterSpace`]: named parameters with units, bounds and optional log scale, mapping an
//!   optimizer's vector onto a configured law or model and back.
//! * [`Optimizer`] and [`Problem`]: the contract between search methods and what they minimise.
//! * [`EffectDeclaration`] and [`RegimeRule`]: what a forward model declares about itself for
//!   the diagnosis of the sim-to-real gap (its switchable effects, the regimes of its tests);
//!   [`noise`] estimates measurement noise from the data alone.
//!
//! Units are N, mm and MPa (N/mm²) throughout; energies per unit area are N/mm.

pub mod curve;
pub mod effect;
pub mod error;
pub mod event;
pub mod law;
pub mod model;
pub mod noise;
pub mod objective;
pub mod optimizer;
pub mod param;
pub mod record;
pub mod regimes;
pub mod response;

pub use curve::Curve;
pub use effect::{EffectDeclaration, EffectKind, EffectScope, Sign, Typical};
pub use error::{CzError, Result};
pub use law::{law_from_toml, law_to_toml, CohesiveLaw, Gap, LawEval, LawState, ParameterInfo, Tangent, Traction};
pub use model::{ForwardModel, SimulationFailure};
pub use objective::{CompositeObjective, ObjectiveTerm, ObjectiveValue};
pub use optimizer::{
    BatchEvaluator, Batched, Budget, Evaluation, NoObserver, Observer, OptimizationResult, Optimizer, Problem,
    Progress, Snapshot,
};
pub use param::{Parameter, ParameterSpace, Scale};
pub use record::{columns, Column, Record};
pub use regimes::{GenericRegimes, RegimeRule, Span};
pub use response::{AtPeak, ColumnResponse, Response};
