//! Switchable physical effects shared by the beam test models.
//!
//! Each effect is a plain number (or flag) in the model configuration whose null value reproduces
//! the base model exactly: the code path with the effect switched off is the base model's, not a
//! limit of the effect. With the effect on, responses vary smoothly with its value, so an
//! identification can switch it on, estimate it and take finite-difference sensitivities to it.

use crate::laws::SeriesCompliance;
use czid_core::error::require_non_negative;
use czid_core::{CohesiveLaw, CzError, EffectDeclaration, EffectKind, EffectScope, Result, Sign, Typical};
use serde::{Deserialize, Serialize};

/// Optional physics of a beam test. `Effects::default()` is the base model.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Effects {
    /// Compliance of the machine and load train in series with the specimen (mm/N). The recorded
    /// displacement is the crosshead's, `δ_specimen + C_m P`. 0: rigid machine.
    pub machine_compliance: f64,
    /// Added to the nominal initial crack length (mm); models an uncertain or blunted pre-crack
    /// front. 0: nominal length.
    pub crack_length_offset: f64,
    /// Seating / zero offset (mm): the recorded displacement is `δ + offset`, with an unloaded
    /// segment from 0 to the offset (the "toe" of a test curve). 0: none.
    pub displacement_offset: f64,
    /// Through-thickness compliance of each adherend between its mid-plane and the interface
    /// (mm/MPa, i.e. mm³/N per unit area), in series with the cohesive law: the elastic
    /// foundation of Kanninen's DCB model, which lets the crack-tip root rotate. A physical value is
    /// `h / (2 E22)`. 0: rigid through the thickness.
    pub root_compliance: f64,
    /// Extra transverse shear compliance of the adherends (1/MPa), added to `1/G13`: the beams
    /// deform in shear with `G = 1 / (1/G13 + shear_compliance)`. Represents more shear
    /// deformation than the nominal G13 gives (a lower interlaminar shear modulus, resin-rich
    /// layers). 0: the nominal G13.
    pub shear_compliance: f64,
    /// Large rotations (co-rotational beams and interface frames) instead of small rotations.
    pub large_rotation: bool,
    /// Load-cell zero offset (N): every recorded load is `P + offset`. 0: none.
    pub load_offset: f64,
    /// Depth of a smooth seating toe (mm), see [`crate::measurement::Readout`]. 0: none.
    pub seating_toe: f64,
    /// Coulomb friction coefficient μ between the cracked faces (dimensionless): where the arms
    /// press on each other behind the crack front (ENF, MMB), a slip is resisted by up to μ times
    /// the contact pressure ([`crate::fe::interface::frictional_contact`]); the friction work is
    /// dissipated energy. 0: frictionless contact. Only models with contact on the cracked faces
    /// accept a non-zero value.
    pub crack_face_friction: f64,
}

/// Coulomb friction between the cracked faces of a mode II or mixed-mode test.
pub const CRACK_FACE_FRICTION: EffectDeclaration = EffectDeclaration {
    name: "crack_face_friction",
    description: "Coulomb friction between the cracked faces where the arms press on each other",
    field: "effects.crack_face_friction",
    unit: "1 (coefficient μ)",
    kind: EffectKind::Size { range: [0.0, 0.5], null: 0.0 },
    scope: EffectScope::Shared,
    // Dry friction of cured epoxy composite faces, as assumed for ENF (Carlsson, Gillespie &
    // Pipes 1986 take 0.25–0.5).
    typical: Some(Typical { magnitude: [0.2, 0.5], sign: Sign::Positive }),
};

/// Large rotations of the arms (a switch).
pub const LARGE_ROTATION: EffectDeclaration = EffectDeclaration {
    name: "large_rotation",
    description: "large rotations of the arms (geometric non-linearity at large openings)",
    field: "effects.large_rotation",
    unit: "on/off",
    kind: EffectKind::Switch,
    scope: EffectScope::Shared,
    typical: None,
};

/// An initial crack length other than the nominal one.
pub const CRACK_LENGTH_OFFSET: EffectDeclaration = EffectDeclaration {
    name: "crack_length_offset",
    description: "initial crack length different from the nominal one (blunt insert, misread pre-crack)",
    field: "effects.crack_length_offset",
    unit: "mm",
    kind: EffectKind::Size { range: [-5.0, 5.0], null: 0.0 },
    scope: EffectScope::PerExperiment,
    typical: Some(Typical { magnitude: [1.0, 4.0], sign: Sign::Either }),
};

/// The specimen effects of a beam test (the measurement effects are in [`crate::measurement`]).
const SPECIMEN: [EffectDeclaration; 3] = [
    EffectDeclaration {
        name: "root_compliance",
        description: "root rotation at the crack front: through-thickness compliance of the arms (elastic foundation)",
        field: "effects.root_compliance",
        unit: "mm/MPa",
        kind: EffectKind::Size { range: [0.0, 1e-3], null: 0.0 },
        scope: EffectScope::Shared,
        // 0.5–2 × h/(2 E22) for coupon arms (h/(2 E22) ≈ 2.2e-4 mm/MPa for Hartlen's specimens).
        typical: Some(Typical { magnitude: [1.1e-4, 4.4e-4], sign: Sign::Positive }),
    },
    CRACK_LENGTH_OFFSET,
    EffectDeclaration {
        name: "shear_compliance",
        description: "more shear deformation of the arms than the nominal G13 gives",
        field: "effects.shear_compliance",
        unit: "1/MPa",
        kind: EffectKind::Size { range: [0.0, 1e-3], null: 0.0 },
        scope: EffectScope::Shared,
        // An effective G13 of 30–65 % of a nominal 2.3 GPa.
        typical: Some(Typical { magnitude: [2e-4, 8e-4], sign: Sign::Positive }),
    },
];

impl Effects {
    /// The switchable effects of a beam test, in the order the diagnosis lists them: large
    /// rotations when the model supports them, the specimen's effects and the measurement's.
    pub fn declarations(large_rotation: bool) -> Vec<EffectDeclaration> {
        use crate::measurement::{DISPLACEMENT_OFFSET, LOAD_OFFSET, MACHINE_COMPLIANCE, SEATING_TOE};
        let [root, crack, shear] = SPECIMEN;
        let mut out = Vec::new();
        if large_rotation {
            out.push(LARGE_ROTATION);
        }
        out.extend([root, MACHINE_COMPLIANCE, crack, DISPLACEMENT_OFFSET, shear, LOAD_OFFSET, SEATING_TOE]);
        out
    }

    /// The effects of a test whose cracked faces press on each other (ENF, MMB): those of
    /// [`Effects::declarations`] and [`CRACK_FACE_FRICTION`].
    pub fn declarations_with_contact() -> Vec<EffectDeclaration> {
        let mut out = Self::declarations(false);
        out.push(CRACK_FACE_FRICTION);
        out
    }

    /// Refuses a non-zero `crack_face_friction` in a model of type `model` whose cracked faces
    /// never touch (no contact, so nothing for friction to act on).
    pub fn reject_friction(&self, owner: &str, model: &str) -> Result<()> {
        if self.crack_face_friction != 0.0 {
            return Err(CzError::invalid(
                owner,
                "effects.crack_face_friction",
                self.crack_face_friction,
                format!(
                    "the {model} model has no contact between the cracked faces, so no friction; \
                     remove the field or set it to 0"
                ),
            ));
        }
        Ok(())
    }

    /// How the instruments read the specimen (the measurement effects but the machine's).
    pub fn readout(&self) -> crate::measurement::Readout {
        crate::measurement::Readout {
            displacement_offset: self.displacement_offset,
            load_offset: self.load_offset,
            seating_toe: self.seating_toe,
        }
    }

    /// Checks every value, naming the field of `owner` that is invalid.
    pub fn validate(&self, owner: &str) -> Result<()> {
        require_non_negative(owner, "effects.machine_compliance", self.machine_compliance)?;
        require_non_negative(owner, "effects.root_compliance", self.root_compliance)?;
        require_non_negative(owner, "effects.shear_compliance", self.shear_compliance)?;
        require_non_negative(owner, "effects.seating_toe", self.seating_toe)?;
        require_non_negative(owner, "effects.crack_face_friction", self.crack_face_friction)?;
        if !self.load_offset.is_finite() {
            return Err(CzError::invalid(owner, "effects.load_offset", self.load_offset, "must be finite"));
        }
        if !self.crack_length_offset.is_finite() {
            return Err(CzError::invalid(
                owner,
                "effects.crack_length_offset",
                self.crack_length_offset,
                "must be finite",
            ));
        }
        if !self.displacement_offset.is_finite() {
            return Err(CzError::invalid(
                owner,
                "effects.displacement_offset",
                self.displacement_offset,
                "must be finite",
            ));
        }
        Ok(())
    }

    /// The law the interface of a split-beam model obeys: `law` itself, or with a root compliance
    /// `law` in series with both adherends' through-thickness compliance, `2 c_r`
    /// ([`crate::laws::SeriesCompliance`]).
    ///
    /// The compliance acts at every point of the interface, as Kanninen's elastic foundation does,
    /// rather than in nodal springs. Springs lump it node by node: with a steep law the series
    /// pair then fails one node at a time, and each drop is a small snap-back of the whole
    /// specimen that displacement control cannot follow.
    pub fn interface_law(&self, law: &dyn CohesiveLaw) -> Result<Option<SeriesCompliance>> {
        if self.root_compliance == 0.0 {
            return Ok(None);
        }
        SeriesCompliance::around(law, 2.0 * self.root_compliance).map(Some)
    }

    /// Checks that `root_compliance` leaves `law` a well-posed mode-I interface.
    ///
    /// The through-thickness compliance sits in series with the law: the total opening is
    /// `u + 2 c_r T(u)`. Where the law softens with slope `dT/du < 0`, the compliance gives back
    /// `2 c_r |dT/du|` of every unit of opening. At a share of 1 the softening turns vertical and
    /// beyond it every point snaps back on its own: the opening no longer determines the state
    /// and no displacement path exists. Beyond [`ROOT_COMPLIANCE_SHARE`] the run is refused at
    /// once, with the limit.
    pub fn check_root_compliance(&self, owner: &str, law: &dyn CohesiveLaw) -> Result<()> {
        let c = self.root_compliance;
        if c == 0.0 {
            return Ok(());
        }
        let slope = steepest_mode_one_softening(law);
        let share = 2.0 * c * slope;
        if share <= ROOT_COMPLIANCE_SHARE {
            return Ok(());
        }
        let limit = ROOT_COMPLIANCE_SHARE / (2.0 * slope);
        Err(CzError::invalid(
            owner,
            "effects.root_compliance",
            c,
            format!(
                "in series with the law's steepest mode-I softening (|dT/du| = {slope:.4} MPa/mm) the \
                 through-thickness compliance gives back {:.0} % of each unit of opening, leaving an \
                 interface that snaps back (or nearly) at every point; use at most {limit:.4e} mm/MPa \
                 with this law ({:.0} % share), or a law with a longer softening branch",
                100.0 * share,
                100.0 * ROOT_COMPLIANCE_SHARE
            ),
        ))
    }

    /// Shear modulus the beams use (MPa): `g13` itself when `shear_compliance` is 0 (the base
    /// model's value, bit for bit), else `1 / (1/g13 + shear_compliance)`.
    pub fn shear_modulus(&self, g13: f64) -> f64 {
        if self.shear_compliance == 0.0 {
            g13
        } else {
            1.0 / (1.0 / g13 + self.shear_compliance)
        }
    }
}

/// Largest share `2 c_r |dT/du|` of the law's softening that root compliance may give back (see
/// [`Effects::check_root_compliance`]). The law in series is well posed below 1; the margin
/// covers what the secant estimate of the steepest slope ([`steepest_mode_one_softening`]) and
/// mixed-mode paths may miss. Below it the DCB runs on the window, in milliseconds, for bilinear
/// laws of 15–60 MPa (`cargo run --release -p czid-models --example root_compliance_limit`).
pub const ROOT_COMPLIANCE_SHARE: f64 = 0.75;

/// The steepest softening slope `|dT_n/du_n|` (MPa/mm) of `law` on a monotonic mode-I opening to
/// failure, from secants over 1/2000 of the opening `2 G_Ic / σ_n` (a vertical drop shows as a very
/// steep secant, as it should: no series spring can follow it).
pub fn steepest_mode_one_softening(law: &dyn CohesiveLaw) -> f64 {
    let (gc, sigma) = (law.fracture_energy()[0], law.strength()[0]);
    if !(gc > 0.0 && sigma > 0.0 && gc.is_finite() && sigma.is_finite()) {
        return 0.0;
    }
    let step = 2.0 * gc / sigma / 2000.0;
    let mut state = law.initial_state();
    let (mut prev, mut steepest, mut peaked) = (0.0f64, 0.0f64, false);
    // Tails (exponential laws) are followed to 50 times the linear-softening opening.
    for k in 1..=100_000 {
        let gap = czid_core::Gap::new(k as f64 * step, 0.0);
        let eval = law.evaluate(&gap, &state);
        state = eval.state;
        let t = eval.traction[0];
        peaked |= t < prev;
        if peaked {
            steepest = steepest.max((prev - t) / step);
        }
        if state.damage >= 1.0 {
            break;
        }
        prev = t;
    }
    steepest
}
