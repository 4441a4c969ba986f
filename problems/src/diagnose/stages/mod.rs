//! The stages of a diagnosis, in the order [`super::run::diagnose_subject`] calls them:
//!
//! * [`base`]: the base fit polished on the misfit in noise units, and what the data say about
//!   its parameters (identifiability);
//! * [`model_form`]: the misfit the base model's own form leaves, from its reference model,
//!   accounted for before any candidate is judged;
//! * [`ranking`]: which candidate effects apply, their score statistics at the base fit, the
//!   ranking and the pairs the data cannot tell apart;
//! * [`refit`]: how far the misfit shrinks when the best candidates are switched on and refitted;
//! * [`transfer`]: whether a refitted effect predicts data withheld from the fit (the held-out
//!   late stage of each curve, other tests);
//! * [`verdict`]: the cause decided on the refits' evidence, or none needed, or unexplained.

pub mod base;
pub mod model_form;
pub mod ranking;
pub mod refit;
pub mod transfer;
pub mod verdict;
