//! # czid-optimizers: search methods behind [`czid_core::Optimizer`]
//!
//! * [`miga::Miga`]: Isight's multi-island GA; [`ga::ga`] builds the single-population GA
//!   (the same code with one island).
//! * [`nsga2::Nsga2`]: NSGA-II for two (or more) objectives.
//! * [`local`]: Nelder–Mead, L-BFGS and Gauss–Newton through argmin, and our
//!   Levenberg–Marquardt, on the box through a [`transform`].
//! * [`hybrid::Hybrid`]: a global method, then a local polish.
//! * [`least_squares`]: the one finite-difference Jacobian and the one Levenberg–Marquardt
//!   (unbounded or on a box, fresh or Broyden Jacobians) that identification, identifiability
//!   and diagnosis share.
//! * [`registry::optimizer_from_config`]: any of these by name and TOML settings.
//! * [`observers`] (progress bar, history CSV), [`checkpoint`] (atomic state files),
//!   [`testfns`], [`metrics`], the benchmark [`harness`], and [`plot`] (PNG/SVG line plots).
//!
//! Every method draws its random numbers from one `ChaCha8Rng` on the calling thread and
//! evaluates populations in parallel with rayon, recording results in index order: the same
//! seed gives bit-identical results with any number of threads.

pub mod checkpoint;
pub mod encoding;
pub mod eval;
pub mod ga;
pub mod harness;
pub mod hybrid;
pub mod journal;
pub mod least_squares;
pub mod local;
pub mod metrics;
pub mod miga;
#[cfg(feature = "mpi")]
pub mod mpi;
pub mod nsga2;
pub mod observers;
pub mod plot;
pub mod registry;
pub mod testfns;
pub mod transform;

pub use checkpoint::CheckpointWriter;
pub use ga::{ga, GaSettings};
pub use hybrid::{Hybrid, HybridSettings};
pub use local::{GaussNewton, Lbfgs, LevenbergMarquardt, LocalOptimizer, LocalSettings, NelderMead};
pub use miga::{Miga, MigaSettings};
pub use nsga2::{Nsga2, Nsga2Settings};
pub use observers::{CsvHistory, Observers, ProgressBar};
pub use registry::{method_from_config, optimizer_from_config, optimizer_from_table, Method, REGISTRY};
