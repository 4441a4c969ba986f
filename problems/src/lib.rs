//! # czid-problems: inverse problems built from laws, forward models and optimizers
//!
//! * [`data`]: experimental curves from CSV, checked and converted to N and mm.
//! * [`plot`]: line plots (PNG/SVG) with a bundled font, written atomically.

pub mod data;
pub mod plot;
