//! # czid-optimizers: search methods behind [`czid_core::Optimizer`]
