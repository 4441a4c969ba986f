//! Double cantilever beam (DCB, mode I) on the beam/interface engine.
//!
//! The specimen runs from the load line (`x = 0`, where hinges pull the arms apart) to its far
//! end (`x = length`); the arms are unbonded over `0 ≤ x < a0` and joined by the cohesive
//! interface beyond. The applied displacement is the load-line opening `δ` (crosshead motion when
//! a machine compliance is switched on) and the load is the hinge force `P`.
//!
//! * **Half model** (default): one arm above the symmetry plane. The opening is twice the arm's
//!   load-point deflection, the interface gap `g_n = 2 w_surface`, `g_t = 0` by symmetry, and every
//!   energy is doubled in the record. With small rotations the arm carries no axial force, so its
//!   axial unknowns are dropped (exact, and it halves the band).
//! * **Full model**: two arms, possibly of different thickness (`h_lower`); the lower hinge is
//!   held, the upper hinge moves by `δ`; both hinges are held on the load line horizontally.
//!
//! ```
//! use czid_core::{columns, ForwardModel};
//! use czid_models::dcb::Dcb;
//! # use czid_core::{CohesiveLaw, Gap, LawEval, LawState, ParameterInfo, Result};
//! # #[derive(Debug, serde::Serialize, serde::Deserialize)] struct L;
//! # #[typetag::serde(name = "dcb_doc_law")] impl CohesiveLaw for L {
//! #   fn validate(&self) -> Result<()> { Ok(()) }
//! #   fn evaluate(&self, g: &Gap, _p: &LawState) -> LawEval {
//! #     LawEval { traction: g * 1e5, tangent: czid_core::Tangent::identity() * 1e5, state: LawState::default() } }
//! #   fn fracture_energy(&self) -> [f64; 2] { [0.3, 0.6] }
//! #   fn initial_stiffness(&self) -> [f64; 2] { [1e5, 1e5] }
//! #   fn strength(&self) -> [f64; 2] { [60.0, 60.0] }
//! #   fn parameters(&self) -> Vec<ParameterInfo> { vec![] } }
//! let mut dcb = Dcb::paper();
//! dcb.mesh.interface_element = 0.5;
//! dcb.control.max_displacement = Some(0.5);
//! dcb.control.output_points = 5;
//! let record = dcb.simulate(&L).unwrap();
//! let load = record.column(columns::LOAD).unwrap();
//! assert!(load.last().unwrap() > &0.0);
//! ```

use czid_core::{CohesiveLaw, CzError, ForwardModel, Record, Result, SimulationFailure};
use serde::{Deserialize, Serialize};

use crate::beamtest::{self, ControlSettings, Material, MeshSettings, RowScale};
use crate::effects::Effects;
use crate::fe::mesh::graded;
use crate::fe::{self, FeProblem, InterfacePoint, Layer, Mesh, PathSettings, PointKind, Section};
use crate::measurement::{recorded_control, LoadPoint};

/// Half (symmetric) or full (two-arm) model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Symmetry {
    /// One arm above a symmetry plane (equal arms only).
    #[default]
    Half,
    /// Both arms and the interface between them.
    Full,
}

/// DCB configuration. All lengths in mm, moduli in MPa.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dcb {
    /// Initial crack length from the load line to the crack front (mm).
    pub a0: f64,
    /// Specimen length from the load line to the far end (mm).
    pub length: f64,
    /// Width b (mm).
    pub width: f64,
    /// Arm thickness h (mm) (the upper arm in the full model).
    pub h: f64,
    /// Lower arm thickness (mm), full model only; `None`: equal arms.
    #[serde(default)]
    pub h_lower: Option<f64>,
    /// Adherend constants.
    pub material: Material,
    /// Half (default) or full model.
    #[serde(default)]
    pub symmetry: Symmetry,
    /// Element sizes.
    #[serde(default)]
    pub mesh: MeshSettings,
    /// Loading and output; `control.max_displacement` is the final load-line opening (mm),
    /// by default the opening at which beam theory puts the crack 60 % of the way to the far end.
    #[serde(default)]
    pub control: ControlSettings,
    /// Optional physics (all off by default).
    #[serde(default)]
    pub effects: Effects,
}

const OWNER: &str = "model dcb";

/// The engine's choices for DCB runs: segment integration of the interface (smooth crack growth,
/// see [`crate::fe::segment`]), records on the output grid, the window around the crack front,
/// and under large rotations the whole mesh cut far ahead of the front and its free arm behind
/// the front merged into elements as long as the pre-crack arm's.
pub const RUN_OPTIONS: fe::RunOptions = RUN;
const RUN: fe::RunOptions =
    fe::RunOptions { window: true, cut_far_field: true, fine_zone: true, ..fe::RunOptions::segments() };

impl Dcb {
    /// The DCB of Shi & Zhang (l = 180, b = 20, a0 = 50, 2h = 3.24 mm; E11 = 130, E22 = 6.5,
    /// G13 = 2.7 GPa), plane stress, 0.1 mm interface elements.
    pub fn paper() -> Self {
        Dcb {
            a0: 50.0,
            length: 180.0,
            width: 20.0,
            h: 1.62,
            h_lower: None,
            material: Material { e11: 130_000.0, e22: 6_500.0, g13: 2_700.0, nu13: 0.26, plane: Default::default() },
            symmetry: Symmetry::Half,
            mesh: MeshSettings::default(),
            control: ControlSettings::default(),
            effects: Effects::default(),
        }
    }

    /// Hartlen's specimen DCB-01 (b = 25, h = 2.7 per arm, L = 123, a0 = 37.64 mm; E_L = 19.3,
    /// E_T = 6.11, G_LT = 2.288 GPa), loaded to 30 mm opening.
    pub fn hartlen_dcb01() -> Self {
        Dcb {
            a0: 37.64,
            length: 123.0,
            width: 25.0,
            h: 2.7,
            h_lower: None,
            material: Material { e11: 19_300.0, e22: 6_110.0, g13: 2_288.0, nu13: 0.0, plane: Default::default() },
            symmetry: Symmetry::Half,
            mesh: MeshSettings { interface_element: 0.2, arm_element: 1.0, ..Default::default() },
            control: ControlSettings { max_displacement: Some(30.0), ..Default::default() },
            effects: Effects::default(),
        }
    }

    /// Checks the configuration, naming the first invalid field.
    pub fn validate(&self) -> Result<()> {
        beamtest::positive(OWNER, "a0", self.a0)?;
        beamtest::positive(OWNER, "length", self.length)?;
        beamtest::positive(OWNER, "width", self.width)?;
        beamtest::positive(OWNER, "h", self.h)?;
        if let Some(hl) = self.h_lower {
            beamtest::positive(OWNER, "h_lower", hl)?;
            if self.symmetry == Symmetry::Half && hl != self.h {
                return Err(CzError::invalid(OWNER, "h_lower", hl, "unequal arms need `symmetry = \"full\"`"));
            }
        }
        self.material.validate(OWNER)?;
        self.mesh.validate(OWNER)?;
        beamtest::check_memory(OWNER, &self.mesh, (self.length - self.a0).max(0.0) / self.mesh.crack_element())?;
        self.control.validate(OWNER)?;
        self.effects.validate(OWNER)?;
        self.effects.reject_friction(OWNER, "DCB")?;
        let a = self.effective_crack_length();
        if !(a > 0.0 && a < self.length) {
            return Err(CzError::invalid(
                OWNER,
                "a0",
                self.a0,
                format!(
                    "the crack front a0 + effects.crack_length_offset = {a} must lie inside the specimen (0, {})",
                    self.length
                ),
            ));
        }
        Ok(())
    }

    /// Length of the mode-I cohesive zone of `law` along this DCB's arm (mm), by the slender-arm
    /// estimate of Yang & Cox (Int. J. Solids Struct. 42, 2005): `(E₁₁ G_Ic / σ_n²)^¼ h^¾`.
    pub fn cohesive_zone_length(&self, law: &dyn CohesiveLaw) -> f64 {
        let (gc, sigma) = (law.fracture_energy()[0], law.strength()[0]);
        (self.material.e11 * gc / (sigma * sigma)).powf(0.25) * self.h.powf(0.75)
    }

    /// The record up to the step where the bonded ligament left ahead of the crack front is
    /// shorter than the law's cohesive zone (or two interface elements): the specimen is then
    /// splitting and the steps after it (the arms springing back, openings falling below zero)
    /// describe no test. `Err` (with the record unchanged) when the crack never got there.
    ///
    /// The cohesive zone's length is an estimate; the arms springing back is the split itself: a
    /// row whose stored elastic energy fell below 1 % of the largest so far, once the crack has
    /// grown, ends the record before it.
    fn until_split(&self, mut record: Record, law: &dyn CohesiveLaw) -> std::result::Result<Record, Record> {
        let zone = self.cohesive_zone_length(law);
        let end = self.length - (2.0 * self.mesh.interface_element).max(if zone.is_finite() { zone } else { 0.0 });
        let by_length = record
            .column(czid_core::columns::CRACK_TIP)
            .ok()
            .and_then(|tip| tip.iter().position(|&t| t >= end))
            .map(|i| i + 1);
        let by_springback = self.springback(&record);
        let Some(keep) = by_length.into_iter().chain(by_springback).min() else {
            return Err(record);
        };
        record.truncate(keep);
        Ok(record)
    }

    /// Rows before the first one where the arms have sprung back: the elastic energy below 1 % of
    /// its largest value so far after the crack has grown.
    fn springback(&self, record: &Record) -> Option<usize> {
        let elastic = record.column(czid_core::columns::ELASTIC_ENERGY).ok()?;
        let grown = record.column(czid_core::columns::DEBONDED_LENGTH).ok()?;
        let mut most = 0.0f64;
        for (i, (&u, &l)) in elastic.iter().zip(grown).enumerate() {
            if fe::run_types::separated(u, most, l) {
                return Some(i);
            }
            most = most.max(u);
        }
        None
    }

    /// Crack length the mesh uses: `a0 + effects.crack_length_offset` (mm).
    pub fn effective_crack_length(&self) -> f64 {
        self.a0 + self.effects.crack_length_offset
    }

    /// Final opening: the configured one, or the simple-beam-theory opening at which the crack
    /// reaches 60 % of the bonded length, `δ = (2a²/3) √(b G_Ic / EI)` at `a = a0 + 0.6 (L − a0)`.
    pub fn max_opening(&self, law: &dyn CohesiveLaw) -> f64 {
        if let Some(d) = self.control.max_displacement {
            return d;
        }
        let a = self.a0 + 0.6 * (self.length - self.a0);
        let ei = self.section(self.h).ei();
        let gc = law.fracture_energy()[0].max(1e-12);
        2.0 * a * a / 3.0 * (self.width * gc / ei).sqrt()
    }

    fn section(&self, h: f64) -> Section {
        Section { e: self.material.axial_modulus(), g: self.effects.shear_modulus(self.material.g13), b: self.width, h }
    }

    /// Builds the discrete problem (mesh built per run: it costs well under 1 % of a run, and
    /// keeps the model plain data that any parameter change invalidates automatically).
    pub fn problem(&self) -> Result<(FeProblem, RowScale)> {
        self.validate()?;
        let fx = &self.effects;
        let a = self.effective_crack_length();
        let x = graded(&[0.0, a, self.length], &[self.mesh.arm_element, self.mesh.crack_element()]);
        let nn = x.len();
        let tip = x.iter().position(|&v| (v - a).abs() <= 1e-9 * self.length).unwrap_or(0);
        let large = fx.large_rotation;
        let extra = crate::measurement::extra_unknowns(fx.machine_compliance, true);
        let half = self.symmetry == Symmetry::Half;
        let (layers, factor) = if half {
            let up = Layer { section: self.section(self.h), y: 0.5 * self.h, axial: large, first: 0, last: nn - 1 };
            (vec![up], 0.5)
        } else {
            let hl = self.h_lower.unwrap_or(self.h);
            let lo = Layer { section: self.section(hl), y: 0.5 * hl, axial: true, first: 0, last: nn - 1 };
            let up = Layer { section: self.section(self.h), y: hl + 0.5 * self.h, axial: true, first: 0, last: nn - 1 };
            (vec![lo, up], 1.0)
        };
        let mesh = Mesh::new(x, layers, extra)?;
        let upper = mesh.layers.len() - 1;
        let mut points = Vec::with_capacity(nn - tip);
        let mut springs = Vec::new();
        for i in tip..nn {
            let left = if i > tip { 0.5 * (mesh.x[i] - mesh.x[i - 1]) } else { 0.0 };
            let right = if i + 1 < nn { 0.5 * (mesh.x[i + 1] - mesh.x[i]) } else { 0.0 };
            let area = self.width * (left + right);
            points.push(InterfacePoint {
                node: i,
                upper,
                lower: if half { None } else { Some(0) },
                area,
                factor,
                kind: PointKind::Cohesive,
            });
        }
        let mut fixed = Vec::new();
        let w_up = mesh.dofs(upper, 0)[1];
        if large || !half {
            fixed.push(mesh.dofs(upper, 0)[0]);
        }
        if !half {
            fixed.push(mesh.dofs(0, 0)[0]);
            fixed.push(mesh.dofs(0, 0)[1]);
        }
        // Opening per unit of the loaded arm's deflection.
        let arm_to_opening = if half { 2.0 } else { 1.0 };
        let load_point = LoadPoint { dof: w_up, per_unit: arm_to_opening, share: factor, at_first_node: true };
        let (control, scale) = recorded_control(fx.machine_compliance, fx.readout(), load_point, &mut springs);
        let p = FeProblem {
            mesh,
            points,
            springs,
            fixed,
            control,
            large_rotation: large,
            contact_stiffness: 0.0,
            contact_friction: 0.0,
        };
        Ok((p, scale))
    }

    /// Checks `law` and the root compliance it meets, and returns the law in series with that
    /// compliance when there is one ([`Effects::interface_law`]).
    fn interface_law(&self, law: &dyn CohesiveLaw) -> Result<Option<crate::laws::SeriesCompliance>> {
        law.validate()?;
        self.effects.check_root_compliance("dcb", law)?;
        self.effects.interface_law(law)
    }

    pub(crate) fn path(&self, law: &dyn CohesiveLaw, scale: &RowScale) -> PathSettings {
        // The debonded length is the visible crack (what a camera sees). The record ends where the
        // arms have sprung back (`until_split`): the run need not go further.
        let path = self.control.path(self.max_opening(law) / scale.displacement, self.effective_crack_length());
        PathSettings { end_at_separation: true, ..path.with_visible_front(law, 0) }
    }
}

#[typetag::serde(name = "dcb")]
impl ForwardModel for Dcb {
    fn name(&self) -> &str {
        "dcb"
    }

    fn validate(&self) -> Result<()> {
        Dcb::validate(self)
    }

    fn effects(&self) -> Vec<czid_core::EffectDeclaration> {
        Effects::declarations(true)
    }

    /// The continuum DCB of the same specimen ([`crate::dcb_2d::Dcb2d::from_beam`]); none for
    /// unequal arms or a whole-specimen mesh.
    fn reference(&self) -> Option<Box<dyn ForwardModel>> {
        crate::dcb_2d::Dcb2d::from_beam(self).ok().map(|m| Box::new(m) as Box<dyn ForwardModel>)
    }

    /// The interface elements must be shorter than the cohesive zone (refused otherwise: the
    /// crack would jump element by element and the curve have no softening); fewer than three in
    /// it is noted (Turon et al. ask for three or more).
    fn check_law(&self, law: &dyn CohesiveLaw) -> Result<Vec<String>> {
        let zone = self.cohesive_zone_length(law);
        let element = self.mesh.interface_element;
        if !(zone.is_finite() && zone > 0.0) {
            return Ok(Vec::new());
        }
        if element > zone {
            return Err(CzError::invalid(
                OWNER,
                "mesh.interface_element",
                element,
                format!(
                    "is longer than the law's cohesive zone (about {zone:.3} mm for E11 = {}, G_Ic = {}, strength {}): use at most {:.3} mm (three elements in the zone)",
                    self.material.e11,
                    law.fracture_energy()[0],
                    law.strength()[0],
                    zone / 3.0
                ),
            ));
        }
        Ok(if element > zone / 3.0 {
            vec![format!(
                "mesh.interface_element = {element} mm puts only {:.1} elements in the cohesive zone (about {zone:.3} mm): three or more resolve the softening; the peak load may be off",
                zone / element
            )]
        } else {
            Vec::new()
        })
    }

    /// The half model (small rotations, no compliance in series with the law) opens its
    /// interface without shearing it: its gaps' shear component and gradient are exact zeros, so
    /// the run takes from the law its response to pure opening and the window's elastic box.
    fn law_key(&self, law: &dyn CohesiveLaw) -> Option<Vec<u64>> {
        let plain = self.symmetry == Symmetry::Half && !self.effects.large_rotation;
        if !plain || !matches!(self.interface_law(law), Ok(None)) {
            return None;
        }
        let mut key = law.mode_one_key()?;
        key.extend(crate::fe::window::opening_key(law)?);
        Some(key)
    }

    fn simulate(&self, law: &dyn CohesiveLaw) -> std::result::Result<Record, SimulationFailure> {
        let fail = |error: CzError| SimulationFailure { error, partial: beamtest::new_record() };
        let series = self.interface_law(law).map_err(fail)?;
        let law = series.as_ref().map_or(law, |s| s as &dyn CohesiveLaw);
        let (p, scale) = self.problem().map_err(fail)?;
        let path = self.path(law, &scale);
        match beamtest::run(&p, law, &path, &RUN, &scale) {
            Ok((record, _)) => Ok(self.until_split(record, law).unwrap_or_else(|r| r)),
            // A run that fails once the crack has run through the specimen ended the test.
            Err(f) => self.until_split(f.partial.clone(), law).map_err(|_| f),
        }
    }
}

/// Runs `dcb` and also returns the engine's statistics (steps, iterations, factorisations).
pub fn simulate_with_stats(dcb: &Dcb, law: &dyn CohesiveLaw) -> Result<(Record, fe::RunStats)> {
    simulate_with_options(dcb, law, &RUN)
}

/// [`simulate_with_stats`] with the engine's run options `run` instead of the model's
/// ([`RUN_OPTIONS`]), e.g. to check one of its shortcuts against the run without it.
pub fn simulate_with_options(dcb: &Dcb, law: &dyn CohesiveLaw, run: &fe::RunOptions) -> Result<(Record, fe::RunStats)> {
    let series = dcb.interface_law(law)?;
    let law = series.as_ref().map_or(law, |s| s as &dyn CohesiveLaw);
    let (p, scale) = dcb.problem()?;
    let path = dcb.path(law, &scale);
    beamtest::run(&p, law, &path, run, &scale).map_err(|f| f.error)
}
