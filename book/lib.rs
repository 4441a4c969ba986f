//! Every chapter of the czid book is included here so that `cargo test` compiles and runs its
//! code blocks, the way the book shows them.

#[doc = include_str!("src/introduction.md")]
pub mod introduction {}
#[doc = include_str!("src/concepts.md")]
pub mod concepts {}
#[doc = include_str!("src/laws.md")]
pub mod laws {}
#[doc = include_str!("src/custom_law.md")]
pub mod custom_law {}
#[doc = include_str!("src/forward_models.md")]
pub mod forward_models {}
#[doc = include_str!("src/beam_or_continuum.md")]
pub mod beam_or_continuum {}
#[doc = include_str!("src/frp_beam.md")]
pub mod frp_beam {}
#[doc = include_str!("src/frp_beam_identification.md")]
pub mod frp_beam_identification {}
#[doc = include_str!("src/optimizers.md")]
pub mod optimizers {}
#[doc = include_str!("src/cluster.md")]
pub mod cluster {}
#[doc = include_str!("src/problem_files.md")]
pub mod problem_files {}
#[doc = include_str!("src/quick_start.md")]
pub mod quick_start {}
#[doc = include_str!("src/paper_dcb.md")]
pub mod paper_dcb {}
#[doc = include_str!("src/real_dcb.md")]
pub mod real_dcb {}
#[doc = include_str!("src/mixed_mode.md")]
pub mod mixed_mode {}
#[doc = include_str!("src/diagnose.md")]
pub mod diagnose {}
#[doc = include_str!("src/diagnose_beam.md")]
pub mod diagnose_beam {}
