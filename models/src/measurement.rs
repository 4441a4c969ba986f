//! Effects of the measurement rather than the specimen: how the recorded displacement differs
//! from the specimen's own (a compliant machine, a seating toe). Every beam-test model records
//! displacement and load the same way ([`crate::beamtest`]), so these effects are declared and
//! built once here, and every such model lists them among its effects and asks
//! [`recorded_control`] how its load point is driven and recorded.

use crate::beamtest::RowScale;
use crate::fe::Spring;
use czid_core::{EffectDeclaration, EffectKind, EffectScope, Sign, Typical};

/// Where a beam test is loaded: the unknown under the load, the recorded displacement per unit
/// of it (its sign, and 2 when a symmetric half model holds one arm of an opening), and the share
/// of the specimen the mesh holds (½ for a half model).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadPoint {
    /// The unknown under the load.
    pub dof: usize,
    /// Recorded displacement per unit of it.
    pub per_unit: f64,
    /// Share of the specimen the mesh holds.
    pub share: f64,
    /// Whether the load acts at the mesh's first node, next to the unknowns a mesh numbers first
    /// ([`extra_unknowns`]).
    pub at_first_node: bool,
}

/// Unknowns the measurement adds to a mesh loaded at its first node or not: the actuator behind a
/// compliant machine, when the load acts at the first node (the mesh numbers its extra unknowns
/// first, so only there does the machine spring stay inside the band of the stiffness matrix).
pub fn extra_unknowns(machine_compliance: f64, at_first_node: bool) -> usize {
    usize::from(machine_compliance > 0.0 && at_first_node)
}

/// The control unknown of a test loaded at `at` and the scaling of its rows into the record.
///
/// With a rigid machine the load point itself is controlled. With machine compliance `C_m`
/// (mm/N) the recorded displacement is the crosshead's, `δ + C_m P`:
/// * loaded at the first node, the control is the actuator (unknown 0, from [`extra_unknowns`])
///   behind a spring of compliance `C_m` in series with the specimen, so the path and its output
///   grid follow the crosshead (its snap-backs included); the spring is added to `springs`, of
///   stiffness `s / C_m` in a model holding a share `s` of the specimen (its energy is shared like
///   the specimen's);
/// * loaded elsewhere (mid-span), the load point is controlled and `C_m P` is added to every
///   recorded state: the same equilibrium states, on an output grid of the specimen's deflection
///   (the machine's energy is then not in the recorded energies).
///
/// The displacement offset shifts every recorded displacement, after an unloaded first row (the
/// toe).
pub fn recorded_control(
    machine_compliance: f64,
    displacement_offset: f64,
    at: LoadPoint,
    springs: &mut Vec<Spring>,
) -> (usize, RowScale) {
    if extra_unknowns(machine_compliance, at.at_first_node) > 0 {
        springs.push(Spring { i: at.dof, j: 0, k: at.share / machine_compliance, ci: at.per_unit });
        let scale = 1.0 / at.share;
        (0, RowScale { displacement: 1.0, offset: displacement_offset, compliance: 0.0, load: scale, energy: scale })
    } else {
        let scale = RowScale {
            displacement: at.per_unit,
            offset: displacement_offset,
            compliance: machine_compliance,
            load: at.per_unit.signum(),
            energy: 1.0 / at.share,
        };
        (at.dof, scale)
    }
}

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
