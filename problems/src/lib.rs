//! # czid-problems: inverse problems built from laws, forward models and optimizers
//!
//! * [`data`]: experimental curves from CSV, checked and converted to N and mm.
//! * [`identification`]: a shared law, per-experiment forward models, parameters and the
//!   composite objective as a [`czid_core::Problem`] on the unit cube.
//! * [`plot`]: line plots (PNG/SVG) with a bundled font, written atomically.
//! * [`problem_file`]: the TOML problem file (law, experiments, parameters, objective, optimizer).

pub mod data;
pub mod identification;
pub mod plot;
pub mod problem_file;
