//! Effects of the measurement rather than the specimen: how the recorded displacement differs
//! from the specimen's own (a compliant machine, a seating toe). Every beam-test model records
//! displacement and load the same way ([`crate::beamtest`]), so these effects are declared once
//! here and every such model lists them among its effects.

use czid_core::{EffectDeclaration, EffectKind, EffectScope, Sign, Typical};

/// Compliance of the machine and load train (mm/N): the recorded displacement is the
/// crosshead's, `δ_specimen + C_m P`.
pub const MACHINE_COMPLIANCE: EffectDeclaration = EffectDeclaration {
    name: "machine_compliance",
    description: "compliance of the machine and load train in series with the specimen",
    field: "effects.machine_compliance",
    unit: "mm/N",
    kind: EffectKind::Size { range: [0.0, 1e-2], null: 0.0 },
    scope: EffectScope::Shared,
    // 2–8 mm/kN: a light load train, 5–20 % of a coupon DCB's initial compliance.
    typical: Some(Typical { magnitude: [2e-3, 8e-3], sign: Sign::Positive }),
};

/// Displacement zero offset (mm): seating of grips or hinges, the toe of a test curve.
pub const DISPLACEMENT_OFFSET: EffectDeclaration = EffectDeclaration {
    name: "displacement_offset",
    description: "displacement zero offset: seating of the grips or hinges (a toe)",
    field: "effects.displacement_offset",
    unit: "mm",
    kind: EffectKind::Size { range: [-1.0, 1.0], null: 0.0 },
    scope: EffectScope::PerExperiment,
    typical: Some(Typical { magnitude: [0.2, 0.8], sign: Sign::Either }),
};
