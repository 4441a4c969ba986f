//! Names of the bundled laws and models, and a guarantee that their registrations are linked.
//!
//! `typetag` registers each `impl CohesiveLaw` / `impl ForwardModel` at link time. A program
//! that only ever reads laws and models from files never names the Rust types, and the linker may
//! then leave their registrations out ("unknown variant `dcb`"). [`ensure_linked`] names them.

use czid_core::{CohesiveLaw, ForwardModel};

/// `type` names of the bundled cohesive laws.
pub const LAW_TYPES: &[&str] = &["st_czm", "bilinear", "exponential", "bridging", "lu_bond_slip", "series_compliance"];
/// `type` names of the bundled forward models.
pub const MODEL_TYPES: &[&str] = &["dcb", "enf", "frp_pull", "frp_beam", "dcb_2d", "enf_2d", "mmb"];

/// Makes sure every bundled law and model can be read from a configuration file. Cheap; call it
/// before deserialising laws or models in a program that does not otherwise use their types.
pub fn ensure_linked() {
    // Taking the address of a method of each impl keeps the object code holding it, and with it
    // the registration emitted beside it in the same module.
    std::hint::black_box(<crate::laws::StCzm as CohesiveLaw>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::laws::Bilinear as CohesiveLaw>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::laws::Exponential as CohesiveLaw>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::laws::Bridging as CohesiveLaw>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::laws::LuBondSlip as CohesiveLaw>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::laws::SeriesCompliance as CohesiveLaw>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::dcb::Dcb as ForwardModel>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::enf::Enf as ForwardModel>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::frp::pull::FrpPull as ForwardModel>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::frp::beam::FrpBeam as ForwardModel>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::dcb_2d::Dcb2d as ForwardModel>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::enf_2d::Enf2d as ForwardModel>::validate as fn(&_) -> _);
    std::hint::black_box(<crate::mmb::Mmb as ForwardModel>::validate as fn(&_) -> _);
}
