//! The finite-element engine: beam layers joined by zero-thickness cohesive interfaces, in 2D.
//!
//! One concept per module:
//! * [`mesh`]: layers on a shared axial grid and the node-by-node numbering of unknowns;
//! * [`beam`]: the two-node shear-locking-free Timoshenko element (small rotations);
//! * [`corotational`]: the same element under large rotations (co-rotational);
//! * [`interface`]: gap kinematics of nodal interface points, contact;
//! * [`segment`]: exact integration of the interface between points, with kinks at damage fronts;
//! * [`assembly`]: the discrete problem and assembly of forces and tangent;
//! * [`banded`]: band LU factorisation (the linear solver);
//! * [`span_lu`]: the band LU refactorising only the rows that changed since the last one;
//! * [`symmetric_band`]: its `L D Lᵀ` counterpart for symmetric iteration matrices;
//! * [`newton`]: Newton–Raphson under displacement or dissipation control;
//! * [`path`]: path following (adaptive steps, output grid, snap-back detours);
//! * `fine_zone`: under large rotations, a beam mesh fine only around the crack front, moving with
//!   it (used by [`path::run_with`]);
//! * [`run_types`]: what a run is asked and returns (settings, rows, statistics), shared by `path` and `window`;
//! * `pool`: work arrays reused across the runs of a thread;
//! * `window`: the solution restricted to the nodes around a crack front, the linear regions
//!   behind and ahead condensed exactly (used by [`path::run_with`]);
//! * [`energy`]: external work, elastic and dissipated energy;
//! * [`crack`]: debonded length, process zone and crack tip from the damage profile;
//! * [`fibre`]: the fibre-section beam element (uniaxial materials with history through the depth);
//! * [`nonlinear`]: problems with fibre layers under indirect displacement control (their own
//!   assembly, Newton and path, energies including the materials' dissipation).
//!
//! Forward models ([`crate::dcb`], [`crate::enf`]) build an [`assembly::FeProblem`] from their
//! configuration and call [`path::run_with`] (or [`path::run`]: nodal rule, every step recorded).

// The kernels index small fixed-size arrays (element and point matrices) by position; index loops
// state the algebra more plainly than iterator chains there.
#![allow(clippy::needless_range_loop)]

pub mod assembly;
pub mod banded;
pub mod beam;
pub(crate) mod changed_rows;
pub mod corotational;
pub mod crack;
pub mod energy;
pub mod fibre;
pub(crate) mod fine_zone;
pub mod interface;
pub mod mesh;
pub mod newton;
pub mod nonlinear;
pub mod path;
pub(crate) mod pool;
pub mod run_types;
pub mod segment;
pub mod span_lu;
pub(crate) mod switch_point;
pub mod symmetric_band;
pub(crate) mod window;

pub use assembly::{FeProblem, InterfaceRule, Spring};
pub use interface::{InterfacePoint, PointKind};
pub use mesh::{Layer, Mesh, Section};
pub use newton::NewtonSettings;
pub use path::{run, run_with};
pub use run_types::{PathFailure, PathSettings, RunOptions, RunStats, StepRow};
