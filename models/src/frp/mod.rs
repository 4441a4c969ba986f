//! The FRP-strengthened RC beam and the FRP-to-concrete pull test (Shi & Zhang's second case):
//!
//! * [`section`]: fibre-section analysis of a rectangular RC section, optionally plated
//!   (moment–curvature; cracking, yield and ultimate moments);
//! * [`bond`]: closed forms for the single-shear pull test (long-bond strength, Chen & Teng's
//!   effective bond length and bond-length factor, exact short-bond strength for a
//!   linear-softening law, and the strength for any bond–slip curve);
//! * [`pull`]: the single-shear pull test on the finite-element engine (forward model
//!   `frp_pull`), any bond–slip law;
//! * [`beam`]: the plated beam in four-point bending on the engine (forward model `frp_beam`):
//!   fibre-section RC beam, plate on a cohesive interface, IC debonding; [`beam_effects`] its
//!   switchable physical effects, [`regimes`] the regimes of its tests (uncracked, cracked,
//!   yielded, debonding);
//! * [`spec`]: the beam's configuration with our documented choices for what the paper leaves
//!   out ([`FrpBeamSpec::paper`]).
//!
//! The bond–slip law itself is [`crate::laws::LuBondSlip`]; the materials are in
//! [`crate::materials`].

pub mod beam;
pub mod beam_effects;
pub mod bond;
pub mod pull;
pub mod regimes;
pub mod section;
pub mod spec;

pub use beam::{BeamRun, FrpBeam, PlateProfile, RunEnd};
pub use beam_effects::BeamEffects;
pub use bond::{BondStrength, BondedJoint};
pub use section::{FrpPlate, RcSection, RebarLayer, SectionMoments, SectionPoint, SectionState, UltimateLimit};
pub use spec::{FrpBeamSpec, Stirrups};
