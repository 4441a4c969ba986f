//! Diagnosing the sim-to-real gap: where a fitted model misses the test, which unmodelled effect
//! most likely causes it, and how far the misfit shrinks once that effect is added, checked on
//! data withheld from the fit.
//!
//! * [`gauge`]: the misfit in units of the measurement noise (estimated from the data by
//!   [`czid_core::noise`]).
//! * [`regimes`]: the test split into regimes from its load curve; misfit and sign per regime.
//! * [`candidate`]: the [`CandidateEffect`] plug-in trait and the bundled [`Library`].
//! * [`score`]: score statistics at the base fit, confounding, absorbing parameter.
//! * [`run`]: the whole diagnosis ([`run::diagnose`]), its outline calling the [`stages`] in
//!   turn, and its report ([`report`]).
//! * [`bench`](mod@bench): planted-effect cases with a known answer.

pub mod bench;
pub mod candidate;
pub mod gauge;
pub mod regimes;
pub mod report;
pub mod run;
pub mod score;
pub mod stages;
pub mod stats;

pub use candidate::{BridgingTail, CandidateEffect, Declared, EffectParameter, Library};
pub use gauge::{Gauge, NoiseLevels};
pub use run::{diagnose, Diagnosis, Options};
pub use stages::model_form::ModelForm;
pub use stages::verdict::{Kind, Outcome};
