//! The stages of a diagnosis, in the order [`super::run::diagnose_subject`] calls them:
//!
//! * [`base`]: the base fit polished on the misfit in noise units, and what the data say about
//!   its parameters (identifiability);
//! * [`ranking`]: which candidate effects apply, their score statistics at the base fit, the
//!   ranking and the pairs the data cannot tell apart;
//! * [`refit`]: how far the misfit shrinks when the best candidates are switched on and refitted;
//! * [`transfer`]: whether a refitted effect predicts data withheld from the fit (the held-out
//!   late stage of each curve, other tests).

pub mod base;
pub mod ranking;
pub mod refit;
pub mod transfer;
