//! Switchable effects a forward model declares: optional physics whose null value reproduces the
//! base model exactly.
//!
//! A model owns what is known about its effects: where the effect sits in its configuration,
//! its unit, the range real tests show, the value that switches it off and whether a value holds
//! for one specimen or for every test on one machine and material. The diagnosis reads these
//! declarations ([`crate::ForwardModel::effects`]) to build its candidate effects, so adding an
//! effect to a model is one declaration next to its physics, and nothing elsewhere.
//!
//! ```
//! use czid_core::{EffectDeclaration, EffectKind, EffectScope, Sign, Typical};
//!
//! let machine = EffectDeclaration {
//!     name: "machine_compliance",
//!     description: "compliance of the machine and load train in series with the specimen",
//!     field: "effects.machine_compliance",
//!     unit: "mm/N",
//!     kind: EffectKind::Size { range: [0.0, 1e-2], null: 0.0 },
//!     scope: EffectScope::Shared,
//!     typical: Some(Typical { magnitude: [2e-3, 8e-3], sign: Sign::Positive }),
//! };
//! assert_eq!(machine.null(), 0.0);
//! assert_eq!(machine.range(), [0.0, 1e-2]);
//! ```

/// What kind of value switches the effect on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EffectKind {
    /// A number: `range` is what real tests show, `null` reproduces the base model.
    Size {
        /// Realistic range (the effect's unit).
        range: [f64; 2],
        /// The value that reproduces the base model.
        null: f64,
    },
    /// A boolean switch, off in the base model (e.g. large rotations).
    Switch,
}

/// Whom one value of the effect describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EffectScope {
    /// Every test of one machine and material (machine compliance, a modulus error): one value
    /// shared by the experiments of a problem, and carried over to other tests.
    Shared,
    /// One specimen (a crack-length error, a seating toe): one value per experiment, and nothing
    /// carried over.
    PerExperiment,
}

/// The sign a typical value takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sign {
    /// Positive.
    Positive,
    /// Negative (e.g. drying shrinkage).
    Negative,
    /// Either, equally likely (e.g. a crack-length error).
    Either,
}

/// Sizes of an effect seen in real tests, clearly above the noise: what synthetic tests plant to
/// check that the diagnosis finds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Typical {
    /// Smallest and largest magnitude (the effect's unit).
    pub magnitude: [f64; 2],
    /// The sign of the value.
    pub sign: Sign,
}

/// A switchable effect of a forward model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EffectDeclaration {
    /// Short name, shared by every model that has the same physics (e.g. `machine_compliance`).
    pub name: &'static str,
    /// The physics, in one sentence.
    pub description: &'static str,
    /// Dotted path of the value in the model's configuration (e.g. `effects.machine_compliance`).
    pub field: &'static str,
    /// Unit of the value (`on/off` for a switch).
    pub unit: &'static str,
    /// A size or a switch.
    pub kind: EffectKind,
    /// One value per specimen or shared.
    pub scope: EffectScope,
    /// Sizes seen in real tests (`None`: not planted in synthetic tests).
    pub typical: Option<Typical>,
}

impl EffectDeclaration {
    /// The value that reproduces the base model (0 for a switch: off).
    pub fn null(&self) -> f64 {
        match self.kind {
            EffectKind::Size { null, .. } => null,
            EffectKind::Switch => 0.0,
        }
    }

    /// The realistic range (`[0, 1]` for a switch).
    pub fn range(&self) -> [f64; 2] {
        match self.kind {
            EffectKind::Size { range, .. } => range,
            EffectKind::Switch => [0.0, 1.0],
        }
    }

    /// Whether the effect is an on/off switch.
    pub fn is_switch(&self) -> bool {
        self.kind == EffectKind::Switch
    }
}
