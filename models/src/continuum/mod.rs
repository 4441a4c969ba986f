//! The continuum engine: orthotropic plane-stress arms meshed with quadrilaterals, joined by a
//! zero-thickness cohesive line, with its own path following. It shares nothing with the beam
//! engine ([`crate::fe`]) but the cohesive laws and the band LU, so the two are independent
//! models of the same tests: the continuum one resolves what beam theory leaves out (root
//! rotation, local shear and through-thickness deformation at the crack front).
//!
//! One concept per module:
//! * [`elasticity`]: plane-stress orthotropic stiffness in the 1–3 plane;
//! * [`quad`]: the 4-node quadrilateral with incompatible modes (small strain or total Lagrangian);
//! * [`grid`]: structured, graded meshes of the arms numbered column by column;
//! * [`interface`]: integration points of the cohesive line (Gauss or nodal);
//! * [`problem`]: the discrete problem (elements, nodal cohesive and contact points) and assembly;
//! * [`solver`]: band LU or faer's sparse LU;
//! * [`path`]: displacement and dissipation control, energies integrated at the points;
//! * [`measures`]: debonded length, process zone and crack tip.

// The kernels index small fixed-size arrays (element and point matrices) by position; index loops
// state the algebra more plainly than iterator chains there.
#![allow(clippy::needless_range_loop)]

pub mod elasticity;
pub mod grid;
pub mod interface;
pub mod measures;
pub mod path;
pub mod problem;
pub mod quad;
pub mod settings;
pub mod solver;

pub use path::{PathSettings, Row, Stats};
pub use problem::{ContinuumProblem, InterfacePoint};
pub use settings::{ContinuumEffects, ContinuumMesh};
pub use solver::SolverKind;
