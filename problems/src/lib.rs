//! # czid-problems: inverse problems built from laws, forward models and optimizers
//!
//! * [`compare`]: several optimizers × seeds at equal budgets, with summary and plots.
//! * [`data`]: experimental curves from CSV, checked and converted to N and mm.
//! * [`identification`]: a shared law, per-experiment forward models, parameters and the
//!   composite objective as a [`czid_core::Problem`] on the unit cube.
//! * [`diagnose`]: where a fitted model misses the test, which unmodelled effect most likely
//!   causes it, and how far the misfit shrinks once it is added.
//! * [`farm`]: independent tasks run side by side, on threads or spread over processes.
//! * [`identify`]: the `identify` and `simulate` workflows, writing results, fits and plots.
//! * [`identifiability`]: standard errors, correlations and a verdict per identified parameter.
//! * [`output`]: output folders that are never clobbered by accident, files written atomically.
//! * [`plot`]: line plots (PNG/SVG) with a bundled font, written atomically (from czid-optimizers).
//! * [`profile`]: profile-likelihood 95 % intervals of a fit's parameters (`czid profile`).
//! * [`problem_file`]: the TOML problem file (law, experiments, parameters, objective, optimizer).
//! * [`resume`]: what an identification keeps to continue after an interruption (fingerprint,
//!   wall time, history).
//! * [`synthetic`]: synthetic tests with documented noise, for studies with a known truth.

pub mod compare;
pub mod confidence_region;
pub mod data;
pub mod diagnose;
pub mod event;
pub mod farm;
pub mod identifiability;
pub mod identification;
pub mod identify;
pub mod output;
pub mod predict;
pub mod profile;
pub use czid_optimizers::plot;
pub mod problem_file;
pub mod resume;
pub mod synthetic;
