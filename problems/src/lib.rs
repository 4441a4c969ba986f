//! # czid-problems: inverse problems built from laws, forward models and optimizers
//!
//! * [`plot`]: line plots (PNG/SVG) with a bundled font, written atomically.

pub mod plot;
