//! # czid-models: cohesive laws and forward models
//!
//! * [`laws`]: ST-CZM (Nairn & Aimene), bilinear mixed mode (Camanho–Dávila, BK), exponential
//!   (Xu–Needleman) and a bridging (R-curve) law, all behind [`czid_core::CohesiveLaw`].

pub mod beamtest;
pub mod continuum;
pub mod dcb;
pub mod dcb_2d;
pub mod effects;
pub mod enf;
pub mod enf_2d;
pub mod enf_reduction;
pub mod enf_regimes;
pub mod fe;
pub mod frp;
pub mod laws;
pub mod materials;
pub mod measurement;
pub mod mmb;
pub mod registry;
