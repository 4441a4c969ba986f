//! Effects of the measurement rather than the specimen: how the recorded displacement and load
//! differ from the specimen's own (a compliant machine, a seating toe, zero offsets of the
//! transducers). Every beam-test model records displacement and load the same way
//! ([`crate::beamtest`]), so these effects are declared and built once here, and every such model
//! lists them among its effects and asks [`recorded_control`] how its load point is driven and
//! recorded.

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
/// The instruments then read the specimen's displacement and load through `readout` (offsets, a
/// seating toe).
pub fn recorded_control(
    machine_compliance: f64,
    readout: Readout,
    at: LoadPoint,
    springs: &mut Vec<Spring>,
) -> (usize, RowScale) {
    if extra_unknowns(machine_compliance, at.at_first_node) > 0 {
        springs.push(Spring { i: at.dof, j: 0, k: at.share / machine_compliance, ci: at.per_unit });
        let scale = 1.0 / at.share;
        (0, RowScale { displacement: 1.0, compliance: 0.0, load: scale, energy: scale, readout })
    } else {
        let scale = RowScale {
            displacement: at.per_unit,
            compliance: machine_compliance,
            load: at.per_unit.signum(),
            energy: 1.0 / at.share,
            readout,
        };
        (at.dof, scale)
    }
}

/// How the transducers read a specimen's displacement `δ` and load `P`: the recorded pair is
/// `(δ + δ₀ + toe(P), P + P₀)`. All zero (the default): the specimen's own values, bit for bit.
///
/// The seating toe is the smooth, stiffening start of a test curve that ASTM D5528 and D7905
/// compensate: the fixture seats while the load rises, `toe(P) = t (1 − exp(−C₀ |P| / t))`, with
/// `t` the toe's depth and `C₀` the specimen's initial compliance. The curve starts at half the
/// specimen's stiffness, reaches it after about three depths of travel, and its straight part
/// extrapolates to zero load at `δ = t`: the zero a toe compensation would find.
///
/// ```
/// use czid_models::measurement::Readout;
///
/// let toe = Readout { seating_toe: 0.5, ..Readout::default() };
/// let c0 = 0.05; // mm/N
/// // At first twice as compliant as the specimen…
/// let (d, p) = toe.read(c0 * 0.1, 0.1, c0);
/// assert!((d / p / (2.0 * c0) - 1.0).abs() < 0.01);
/// // …then the specimen's own slope, shifted by the depth.
/// let (d, p) = toe.read(c0 * 200.0, 200.0, c0);
/// assert!((d - (c0 * p + 0.5)).abs() < 1e-6);
/// // A load-cell zero offset shifts every load.
/// let zero = Readout { load_offset: 2.0, ..Readout::default() };
/// assert_eq!(zero.read(1.0, 20.0, c0), (1.0, 22.0));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Readout {
    /// Displacement zero offset `δ₀` (mm): a sharp toe, an unloaded segment from 0 to `δ₀`.
    pub displacement_offset: f64,
    /// Load-cell zero offset `P₀` (N): the load the cell reads with the specimen unloaded.
    pub load_offset: f64,
    /// Depth `t` of a smooth seating toe (mm).
    pub seating_toe: f64,
}

impl Readout {
    /// The recorded displacement and load of a specimen state `(δ, P)`, `c0` being the specimen's
    /// initial compliance (mm/N).
    pub fn read(&self, delta: f64, p: f64, c0: f64) -> (f64, f64) {
        let toe = if self.seating_toe > 0.0 {
            self.seating_toe * (1.0 - (-c0 * p.abs() / self.seating_toe).exp())
        } else {
            0.0
        };
        (delta + self.displacement_offset + toe, p + self.load_offset)
    }

    /// The unloaded first reading of a sharp toe (a positive displacement offset), if any.
    pub fn unloaded(&self) -> Option<[f64; 2]> {
        (self.displacement_offset > 0.0).then_some([0.0, self.load_offset])
    }
}

/// Initial compliance (mm/N) of a run's specimen states `(δ, P)`: of its first loaded state (0 if
/// none is loaded).
pub fn initial_compliance(states: impl Iterator<Item = (f64, f64)>) -> f64 {
    states.filter(|(_, p)| p.abs() > 0.0).map(|(d, p)| (d / p).abs()).find(|c| c.is_finite()).unwrap_or(0.0)
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

/// Load-cell zero offset (N): the cell reads a load with the specimen unloaded (a zero not reset,
/// a drifted bridge).
pub const LOAD_OFFSET: EffectDeclaration = EffectDeclaration {
    name: "load_offset",
    description: "load-cell zero offset: the cell reads a load with the specimen unloaded",
    field: "effects.load_offset",
    unit: "N",
    kind: EffectKind::Size { range: [-20.0, 20.0], null: 0.0 },
    scope: EffectScope::PerExperiment,
    // 1–4 N: 1–4 % of a coupon DCB's peak load, a zero not reset before the test.
    typical: Some(Typical { magnitude: [1.0, 4.0], sign: Sign::Either }),
};

/// Depth of a smooth seating toe (mm), see [`Readout`].
pub const SEATING_TOE: EffectDeclaration = EffectDeclaration {
    name: "seating_toe",
    description: "smooth seating toe: the fixture seats while the load rises (the toe ASTM D5528/D7905 compensate)",
    field: "effects.seating_toe",
    unit: "mm",
    kind: EffectKind::Size { range: [0.0, 2.0], null: 0.0 },
    scope: EffectScope::PerExperiment,
    typical: Some(Typical { magnitude: [0.2, 0.8], sign: Sign::Positive }),
};
