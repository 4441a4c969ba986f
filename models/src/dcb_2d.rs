//! Double cantilever beam (DCB, mode I) on the continuum engine ([`crate::continuum`]): an
//! independent, higher-fidelity model of the test the beam model [`crate::dcb`] describes.
//!
//! One arm above the symmetry plane, meshed with plane-stress quadrilaterals (`thickness_elements`
//! through the arm, `interface_element` long along the crack path, growing to `arm_element` behind
//! the crack front), on a line of nodal cohesive points (opening twice the arm face's deflection).
//! The hinge is the arm's mid-thickness node at the load line: its deflection is driven (the
//! recorded opening is twice it) and it is held horizontally. With `effects.large_rotation` the
//! arm is total Lagrangian (the hinge force stays vertical).
//!
//! ```
//! use czid_core::{columns, ForwardModel};
//! use czid_models::dcb_2d::Dcb2d;
//! use czid_models::laws::Bilinear;
//! let mut dcb = Dcb2d::paper();
//! dcb.mesh.interface_element = 0.5;
//! dcb.control.max_displacement = Some(0.5);
//! dcb.control.output_points = 5;
//! let law = Bilinear::bk(1e5, 27.0, 27.0, 0.044, 0.1, 2.0).unwrap();
//! let record = dcb.simulate(&law).unwrap();
//! assert!(record.column(columns::LOAD).unwrap().last().unwrap() > &0.0);
//! ```

use czid_core::{CohesiveLaw, CzError, ForwardModel, Record, Result, SimulationFailure};
use serde::{Deserialize, Serialize};

use crate::beamtest::{self, ControlSettings, Material, RowScale};
use crate::continuum::grid::{graded_rows, graded_towards_end, uniform, Grid};
use crate::continuum::interface::{self, Pair};
use crate::continuum::settings::record;
use crate::continuum::{elasticity, path, ContinuumEffects, ContinuumMesh, ContinuumProblem, PathSettings, SolverKind};
use crate::measurement::{recorded_control, LoadPoint};

/// Continuum DCB configuration: the beam model's specimen keys, a continuum mesh and a solver.
/// Lengths in mm, moduli in MPa.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dcb2d {
    /// Initial crack length from the load line to the crack front (mm).
    pub a0: f64,
    /// Specimen length from the load line to the far end (mm).
    pub length: f64,
    /// Width b (mm).
    pub width: f64,
    /// Arm thickness h (mm).
    pub h: f64,
    /// Adherend constants (plane stress in the 1–3 plane: `e11`, `e22` through the thickness,
    /// `g13`, `nu13`).
    pub material: Material,
    /// Element sizes.
    #[serde(default)]
    pub mesh: ContinuumMesh,
    /// Loading and output; `control.max_displacement` is the final load-line opening (mm), by
    /// default the opening at which beam theory puts the crack 60 % of the way to the far end.
    #[serde(default)]
    pub control: ControlSettings,
    /// Optional physics (all off by default).
    #[serde(default)]
    pub effects: ContinuumEffects,
    /// Linear solver.
    #[serde(default)]
    pub solver: SolverKind,
}

const OWNER: &str = "model dcb_2d";

/// Largest crack advance of one dissipation-controlled step, in interface elements.
const ELEMENTS_PER_STEP: f64 = 4.0;

impl Dcb2d {
    /// The paper's DCB (Shi & Zhang: l = 180, b = 20, a0 = 50, 2h = 3.24 mm; E11 = 130,
    /// E22 = 6.5, G13 = 2.7 GPa), 0.1 mm elements along the crack path.
    pub fn paper() -> Self {
        Dcb2d {
            a0: 50.0,
            length: 180.0,
            width: 20.0,
            h: 1.62,
            material: Material { e11: 130_000.0, e22: 6_500.0, g13: 2_700.0, nu13: 0.26, plane: Default::default() },
            mesh: ContinuumMesh::default(),
            control: ControlSettings::default(),
            effects: ContinuumEffects::default(),
            solver: SolverKind::default(),
        }
    }

    /// Hartlen's specimen DCB-01 (b = 25, h = 2.7 per arm, L = 123, a0 = 37.64 mm; E_L = 19.3,
    /// E_T = 6.11, G_LT = 2.288 GPa), loaded to 30 mm opening.
    pub fn hartlen_dcb01() -> Self {
        Dcb2d {
            a0: 37.64,
            length: 123.0,
            width: 25.0,
            h: 2.7,
            material: Material { e11: 19_300.0, e22: 6_110.0, g13: 2_288.0, nu13: 0.0, plane: Default::default() },
            mesh: ContinuumMesh { interface_element: 0.2, ..Default::default() },
            control: ControlSettings { max_displacement: Some(30.0), ..Default::default() },
            effects: ContinuumEffects::default(),
            solver: SolverKind::default(),
        }
    }

    /// The continuum model of the specimen a beam DCB describes, with the beam's effects carried
    /// over: the measurement's (machine compliance, displacement offset), the crack-length offset
    /// and large rotations as they are; the beam's extra compliances as the material change they
    /// stand for: `root_compliance c` lowers the through-thickness modulus so that the arm's
    /// compliance `h/(2 E22)` grows by `c`, `shear_compliance s` lowers `G13` to
    /// `1/(1/G13 + s)`. The mesh keeps the beam's interface element (4 Gauss points in each).
    pub fn from_beam(beam: &crate::dcb::Dcb) -> Result<Dcb2d> {
        const FROM: &str = "model dcb (as a continuum)";
        if beam.symmetry != crate::dcb::Symmetry::Half || beam.h_lower.is_some_and(|hl| hl != beam.h) {
            return Err(CzError::invalid(FROM, "symmetry", f64::NAN, "only equal arms have a continuum counterpart"));
        }
        let fx = &beam.effects;
        let material = material_of_beam(&beam.material, fx, beam.h);
        Ok(Dcb2d {
            a0: beam.a0,
            length: beam.length,
            width: beam.width,
            h: beam.h,
            material,
            mesh: ContinuumMesh {
                interface_element: beam.mesh.interface_element,
                arm_element: beam.mesh.arm_element.max(beam.mesh.interface_element),
                ..Default::default()
            },
            control: beam.control.clone(),
            effects: ContinuumEffects {
                machine_compliance: fx.machine_compliance,
                crack_length_offset: fx.crack_length_offset,
                displacement_offset: fx.displacement_offset,
                large_rotation: fx.large_rotation,
                load_offset: fx.load_offset,
                seating_toe: fx.seating_toe,
            },
            solver: SolverKind::default(),
        })
    }

    /// Checks the configuration, naming the first invalid field.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("a0", self.a0), ("length", self.length), ("width", self.width), ("h", self.h)] {
            beamtest::positive(OWNER, name, v)?;
        }
        self.material.validate(OWNER)?;
        elasticity::plane_stress(&self.material, OWNER)?;
        self.mesh.validate(OWNER)?;
        self.mesh.check_size(OWNER, self.length, 1)?;
        self.control.validate(OWNER)?;
        self.effects.validate(OWNER)?;
        let a = self.crack_length();
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

    /// Crack length the mesh uses: `a0 + effects.crack_length_offset` (mm).
    pub fn crack_length(&self) -> f64 {
        self.a0 + self.effects.crack_length_offset
    }

    /// Mode-I cohesive zone length of `law` (mm), Yang & Cox's slender-arm estimate
    /// `(E₁₁ G_Ic / σ_n²)^¼ h^¾`.
    pub fn cohesive_zone_length(&self, law: &dyn CohesiveLaw) -> f64 {
        let (gc, sigma) = (law.fracture_energy()[0], law.strength()[0]);
        (self.material.e11 * gc / (sigma * sigma)).powf(0.25) * self.h.powf(0.75)
    }

    /// Final opening: the configured one, or the simple-beam-theory opening at which the crack
    /// reaches 60 % of the bonded length.
    pub fn max_opening(&self, law: &dyn CohesiveLaw) -> f64 {
        if let Some(d) = self.control.max_displacement {
            return d;
        }
        let a = self.a0 + 0.6 * (self.length - self.a0);
        let ei = self.material.e11 * self.width * self.h.powi(3) / 12.0;
        2.0 * a * a / 3.0 * (self.width * law.fracture_energy()[0].max(1e-12) / ei).sqrt()
    }

    /// The discrete problem and how its rows scale into the record.
    pub fn problem(&self) -> Result<(ContinuumProblem, RowScale)> {
        self.validate()?;
        let (a, m) = (self.crack_length(), &self.mesh);
        let mut xs = graded_towards_end(0.0, a, m.interface_element, m.arm_element.max(m.interface_element), 1.2);
        xs.extend_from_slice(&uniform(a, self.length, m.interface_element)[1..]);
        let ny = m.thickness_elements;
        let grid = Grid::new(xs, vec![graded_rows(0.0, self.h, ny, m.thickness_grading)], self.width);
        let tip = grid.xs.iter().position(|&x| (x - a).abs() <= 1e-9 * self.length).unwrap_or(0);
        let nc = grid.xs.len();
        let pairs: Vec<Pair> =
            (tip..nc).map(|c| Pair { x: grid.xs[c], upper: grid.node(0, c, 0), lower: None }).collect();
        let cohesive = interface::line(&pairs, self.width, m.interface_points);
        let hinge = grid.node(0, 0, ny / 2);
        let load_point = LoadPoint { dof: 2 * hinge + 1, per_unit: 2.0, share: 0.5, at_first_node: false };
        let (control, scale) =
            recorded_control(self.effects.machine_compliance, self.effects.readout(), load_point, &mut Vec::new());
        let p = ContinuumProblem {
            grid,
            stiffness: elasticity::plane_stress(&self.material, OWNER)?,
            large: self.effects.large_rotation,
            cohesive,
            contact: Vec::new(),
            contact_stiffness: 0.0,
            fixed: vec![2 * hinge],
            control: vec![(control, 1.0)],
            solver: self.solver,
        };
        Ok((p, scale))
    }

    fn settings(&self, law: &dyn CohesiveLaw, scale: &RowScale) -> PathSettings {
        let zone = self.cohesive_zone_length(law);
        let margin = (2.0 * self.mesh.interface_element).max(if zone.is_finite() { zone } else { 0.0 });
        let threshold = match crate::fe::crack::visible_front_level(law, 0) {
            Some(level) if self.control.damage_threshold >= crate::fe::crack::BELOW_FAILURE => level,
            _ => self.control.damage_threshold,
        };
        PathSettings {
            target: self.max_opening(law) / scale.displacement,
            outputs: self.control.output_points,
            max_dissipation: law.fracture_energy()[0]
                * self.width
                * 0.5
                * ELEMENTS_PER_STEP
                * self.mesh.interface_element,
            max_opening_step: critical_opening(law),
            max_iterations: self.control.max_iterations,
            tolerance: self.control.tolerance.max(1e-8),
            damage_threshold: threshold,
            crack_origin: self.crack_length(),
            stop_tip: self.length - margin,
        }
    }

    /// Runs the model and also returns the engine's statistics.
    pub fn simulate_with_stats(
        &self,
        law: &dyn CohesiveLaw,
    ) -> std::result::Result<(Record, path::Stats), SimulationFailure> {
        let fail = |error: CzError| SimulationFailure { error, partial: beamtest::new_record() };
        law.validate().map_err(fail)?;
        let (p, scale) = self.problem().map_err(fail)?;
        let settings = self.settings(law, &scale);
        match path::run(&p, law, &settings) {
            Ok((rows, stats)) => Ok((record(&rows, &scale), stats)),
            Err(f) => Err(SimulationFailure { error: f.error, partial: record(&f.rows, &scale) }),
        }
    }
}

/// Opening at which a triangular law of the same strength and toughness fails, `2 G_c / σ` (the
/// larger of the two modes, mm): the scale of a crack-front opening step.
pub(crate) fn critical_opening(law: &dyn CohesiveLaw) -> f64 {
    let (g, s) = (law.fracture_energy(), law.strength());
    (2.0 * g[0] / s[0]).max(2.0 * g[1] / s[1])
}

#[typetag::serde(name = "dcb_2d")]
impl ForwardModel for Dcb2d {
    fn name(&self) -> &str {
        "dcb_2d"
    }

    fn validate(&self) -> Result<()> {
        Dcb2d::validate(self)
    }

    fn effects(&self) -> Vec<czid_core::EffectDeclaration> {
        ContinuumEffects::declarations(true)
    }

    /// Elements longer than the cohesive zone are refused (the crack would jump point by point).
    fn check_law(&self, law: &dyn CohesiveLaw) -> Result<Vec<String>> {
        let zone = self.cohesive_zone_length(law);
        let element = self.mesh.interface_element;
        if zone.is_finite() && zone > 0.0 && element > zone {
            return Err(CzError::invalid(
                OWNER,
                "mesh.interface_element",
                element,
                format!(
                    "is longer than the law's cohesive zone (about {zone:.3} mm): use at most {:.3} mm",
                    zone / 3.0
                ),
            ));
        }
        Ok(Vec::new())
    }

    /// One element fewer through each arm ([`ContinuumMesh::coarsened`]).
    fn coarsened(&self) -> Option<Box<dyn ForwardModel>> {
        let mesh = self.mesh.coarsened()?;
        Some(Box::new(Dcb2d { mesh, ..self.clone() }))
    }

    fn simulate(&self, law: &dyn CohesiveLaw) -> std::result::Result<Record, SimulationFailure> {
        self.simulate_with_stats(law).map(|(r, _)| r)
    }
}

/// The arms' material of the continuum counterpart of a beam model whose arms are `h` thick: the
/// beam's extra compliances as the material change they stand for (`root_compliance c` lowers
/// E22 so that `h/(2 E22)` grows by `c`; `shear_compliance s` lowers G13 to `1/(1/G13 + s)`).
/// Switched off, an effect leaves the material as it is, bit for bit.
pub(crate) fn material_of_beam(material: &Material, fx: &crate::effects::Effects, h: f64) -> Material {
    let mut m = material.clone();
    if fx.root_compliance > 0.0 {
        m.e22 = 1.0 / (1.0 / m.e22 + 2.0 * fx.root_compliance / h);
    }
    m.g13 = fx.shear_modulus(m.g13);
    m
}
