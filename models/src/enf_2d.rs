//! End-notched flexure (ENF, mode II) on the continuum engine ([`crate::continuum`]): an
//! independent model of the test the beam model [`crate::enf`] describes.
//!
//! Both arms are meshed (plane-stress quadrilaterals), joined beyond the crack front by the
//! cohesive line and, on the pre-cracked faces, by frictionless contact points (a normal penalty,
//! by default the law's normal stiffness). Supports and load nose are **prescribed nodes**: the
//! lower arm's whole section at each support is held vertically, and both arms' sections under the
//! nose move down together by the applied deflection (the load is their summed reaction). Holding
//! sections rather than single surface nodes keeps the load introduction free of the point-load
//! indentation a single node would add to the compliance (it grows without bound as the mesh is
//! refined), and leaves the sections free to rotate.
//!
//! ```
//! use czid_core::{columns, ForwardModel};
//! use czid_models::enf_2d::Enf2d;
//! use czid_models::laws::Bilinear;
//! let mut enf = Enf2d::hartlen_enf03();
//! enf.mesh.interface_element = 1.0;
//! enf.control.max_displacement = Some(0.5);
//! enf.control.output_points = 5;
//! let law = Bilinear::bk(1e5, 60.0, 60.0, 0.8, 2.0, 2.0).unwrap();
//! let record = enf.simulate(&law).unwrap();
//! assert!(record.column(columns::LOAD).unwrap().last().unwrap() > &0.0);
//! ```

use czid_core::{CohesiveLaw, CzError, ForwardModel, Record, Result, SimulationFailure};
use serde::{Deserialize, Serialize};

use crate::beamtest::{self, ControlSettings, Material, RowScale};
use crate::continuum::grid::{graded_from_start, graded_rows, graded_towards_end, uniform, Grid};
use crate::continuum::interface::{self, Pair};
use crate::continuum::settings::record;
use crate::continuum::{elasticity, path, ContinuumEffects, ContinuumMesh, ContinuumProblem, PathSettings, SolverKind};
use crate::dcb_2d::critical_opening;
use crate::measurement::{recorded_control, LoadPoint};

/// Continuum ENF configuration: the beam model's specimen keys, a continuum mesh and a solver.
/// Lengths in mm, moduli in MPa.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Enf2d {
    /// Initial crack length from the left support to the crack front (mm).
    pub a0: f64,
    /// Half-span L between a support and the loading nose (mm).
    pub half_span: f64,
    /// Width b (mm).
    pub width: f64,
    /// Thickness of each arm h (mm).
    pub h: f64,
    /// Adherend constants (plane stress in the 1–3 plane).
    pub material: Material,
    /// Normal penalty of the contact on the cracked faces (MPa/mm); `None`: the law's normal
    /// initial stiffness.
    #[serde(default)]
    pub contact_stiffness: Option<f64>,
    /// Element sizes (`interface_element` from the crack front to the loading nose).
    #[serde(default)]
    pub mesh: ContinuumMesh,
    /// Loading and output; `control.max_displacement` is the final load-point deflection (mm),
    /// by default twice the beam-theory deflection at the onset of propagation.
    #[serde(default)]
    pub control: ControlSettings,
    /// Optional physics (`large_rotation` is not offered).
    #[serde(default)]
    pub effects: ContinuumEffects,
    /// Linear solver.
    #[serde(default)]
    pub solver: SolverKind,
}

const OWNER: &str = "model enf_2d";

impl Enf2d {
    /// Hartlen's ENF-03 specimen (h = 2.7 mm per arm, b = 25, L = 50, a0 = 34.7 mm; E_L = 19.3,
    /// E_T = 6.11, G_LT = 2.288 GPa).
    pub fn hartlen_enf03() -> Self {
        Enf2d {
            a0: 34.7,
            half_span: 50.0,
            width: 25.0,
            h: 2.7,
            material: Material { e11: 19_300.0, e22: 6_110.0, g13: 2_288.0, nu13: 0.0, plane: Default::default() },
            contact_stiffness: None,
            mesh: ContinuumMesh { interface_element: 0.2, ..Default::default() },
            control: ControlSettings::default(),
            effects: ContinuumEffects::default(),
            solver: SolverKind::default(),
        }
    }

    /// The continuum ENF of the specimen a beam ENF describes, with the beam's effects carried
    /// over as [`crate::dcb_2d::Dcb2d::from_beam`] does (the extra compliances as the material
    /// change they stand for). The mesh keeps the beam's interface element.
    /// The continuum's contact is frictionless: a beam with `effects.crack_face_friction` has no
    /// continuum counterpart (an error).
    pub fn from_beam(beam: &crate::enf::Enf) -> Result<Enf2d> {
        let fx = &beam.effects;
        fx.reject_friction("model enf_2d (built from an enf)", "continuum ENF")?;
        let material = crate::dcb_2d::material_of_beam(&beam.material, fx, beam.h);
        let m = Enf2d {
            a0: beam.a0,
            half_span: beam.half_span,
            width: beam.width,
            h: beam.h,
            material,
            contact_stiffness: beam.contact_stiffness,
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
                large_rotation: false,
                load_offset: fx.load_offset,
                seating_toe: fx.seating_toe,
            },
            solver: SolverKind::default(),
        };
        m.validate()?;
        Ok(m)
    }

    /// Checks the configuration, naming the first invalid field.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("a0", self.a0), ("half_span", self.half_span), ("width", self.width), ("h", self.h)] {
            beamtest::positive(OWNER, name, v)?;
        }
        if let Some(k) = self.contact_stiffness {
            beamtest::positive(OWNER, "contact_stiffness", k)?;
        }
        self.material.validate(OWNER)?;
        elasticity::plane_stress(&self.material, OWNER)?;
        self.mesh.validate(OWNER)?;
        self.mesh.check_size(OWNER, 2.0 * self.half_span, 2)?;
        self.control.validate(OWNER)?;
        self.effects.validate(OWNER)?;
        if self.effects.large_rotation {
            return Err(CzError::invalid(OWNER, "effects.large_rotation", 1.0, "is not offered by the ENF model"));
        }
        let a = self.crack_length();
        if !(a > 0.0 && a < self.half_span) {
            return Err(CzError::invalid(
                OWNER,
                "a0",
                self.a0,
                format!("the crack front a0 + effects.crack_length_offset = {a} must lie in (0, half_span)"),
            ));
        }
        Ok(())
    }

    /// Crack length the mesh uses: `a0 + effects.crack_length_offset` (mm).
    pub fn crack_length(&self) -> f64 {
        self.a0 + self.effects.crack_length_offset
    }

    /// Beam-theory compliance with shear, `C = (3a³ + 2L³)/(8 E b h³) + 3L/(10 G13 b h)` (mm/N).
    pub fn beam_compliance(&self, a: f64) -> f64 {
        let (e, g, b, h, l) = (self.material.e11, self.material.g13, self.width, self.h, self.half_span);
        (3.0 * a.powi(3) + 2.0 * l.powi(3)) / (8.0 * e * b * h.powi(3)) + 3.0 * l / (10.0 * g * b * h)
    }

    /// Final deflection: configured, or twice the beam-theory deflection at which the crack starts.
    pub fn max_deflection(&self, law: &dyn CohesiveLaw) -> f64 {
        if let Some(d) = self.control.max_displacement {
            return d;
        }
        let a = self.crack_length();
        let pc = 4.0 * self.width / (3.0 * a)
            * (self.material.e11 * self.h.powi(3) * law.fracture_energy()[1].max(1e-12)).sqrt();
        2.0 * self.beam_compliance(a) * pc
    }

    /// The discrete problem and how its rows scale into the record.
    pub fn problem(&self, law: &dyn CohesiveLaw) -> Result<(ContinuumProblem, RowScale)> {
        self.validate()?;
        let (a, l, m) = (self.crack_length(), self.half_span, &self.mesh);
        let (fine, coarse) = (m.interface_element, m.arm_element.max(m.interface_element));
        let mut xs = graded_towards_end(0.0, a, fine, coarse, 1.2);
        xs.extend_from_slice(&uniform(a, l, fine)[1..]);
        xs.extend_from_slice(&graded_from_start(l, 2.0 * l, fine, coarse, 1.2)[1..]);
        let ny = m.thickness_elements;
        let g = m.thickness_grading;
        let arms = vec![graded_rows(0.0, self.h, ny, 1.0 / g), graded_rows(self.h, 2.0 * self.h, ny, g)];
        let grid = Grid::new(xs, arms, self.width);
        let nc = grid.xs.len();
        let at = |x: f64| grid.xs.iter().position(|&v| (v - x).abs() <= 1e-9 * l).unwrap_or(0);
        let (tip, mid) = (at(a), at(l));
        let pair = |c: usize| Pair { x: grid.xs[c], upper: grid.node(1, c, 0), lower: Some(grid.node(0, c, ny)) };
        let contact_pairs: Vec<Pair> = (0..=tip).map(pair).collect();
        let cohesive_pairs: Vec<Pair> = (tip..nc).map(pair).collect();
        let mut fixed = Vec::new();
        for c in [0, nc - 1] {
            fixed.extend((0..=ny).map(|r| 2 * grid.node(0, c, r) + 1));
        }
        fixed.push(2 * grid.node(0, nc - 1, ny / 2));
        // The nose pushes both arms' sections down: the control is positive downwards.
        let nose: Vec<usize> = (0..=ny).flat_map(|r| [grid.node(0, mid, r), grid.node(1, mid, r)]).collect();
        let load_point = LoadPoint { dof: 2 * nose[0] + 1, per_unit: 1.0, share: 1.0, at_first_node: false };
        let (_, scale) =
            recorded_control(self.effects.machine_compliance, self.effects.readout(), load_point, &mut Vec::new());
        let p = ContinuumProblem {
            stiffness: elasticity::plane_stress(&self.material, OWNER)?,
            large: false,
            cohesive: interface::line(&cohesive_pairs, self.width, m.interface_points),
            contact: interface::line(&contact_pairs, self.width, 0),
            contact_stiffness: self.contact_stiffness.unwrap_or(law.initial_stiffness()[0]),
            fixed,
            control: nose.iter().map(|&n| (2 * n + 1, -1.0)).collect(),
            solver: self.solver,
            grid,
        };
        Ok((p, scale))
    }

    fn settings(&self, law: &dyn CohesiveLaw, scale: &RowScale) -> PathSettings {
        let threshold = match crate::fe::crack::visible_front_level(law, 1) {
            Some(level) if self.control.damage_threshold >= crate::fe::crack::BELOW_FAILURE => level,
            _ => self.control.damage_threshold,
        };
        PathSettings {
            target: self.max_deflection(law) / scale.displacement,
            outputs: self.control.output_points,
            max_dissipation: law.fracture_energy()[1] * self.width * 4.0 * self.mesh.interface_element,
            max_opening_step: critical_opening(law),
            max_iterations: self.control.max_iterations,
            tolerance: self.control.tolerance.max(1e-8),
            damage_threshold: threshold,
            crack_origin: self.crack_length(),
            // The crack stops under the nose, where the arms are pressed together.
            stop_tip: self.half_span - 2.0 * self.mesh.interface_element,
        }
    }

    /// Runs the model and also returns the engine's statistics.
    pub fn simulate_with_stats(
        &self,
        law: &dyn CohesiveLaw,
    ) -> std::result::Result<(Record, path::Stats), SimulationFailure> {
        let fail = |error: CzError| SimulationFailure { error, partial: beamtest::new_record() };
        law.validate().map_err(fail)?;
        let (p, scale) = self.problem(law).map_err(fail)?;
        let settings = self.settings(law, &scale);
        match path::run(&p, law, &settings) {
            Ok((rows, stats)) => Ok((record(&rows, &scale), stats)),
            Err(f) => Err(SimulationFailure { error: f.error, partial: record(&f.rows, &scale) }),
        }
    }
}

#[typetag::serde(name = "enf_2d")]
impl ForwardModel for Enf2d {
    fn name(&self) -> &str {
        "enf_2d"
    }

    fn validate(&self) -> Result<()> {
        Enf2d::validate(self)
    }

    /// The ENF rule: the first peak, the unstable jump, the rise with the crack at the nose.
    fn regimes(&self) -> &'static dyn czid_core::RegimeRule {
        &crate::enf_regimes::EnfRegimes
    }

    fn effects(&self) -> Vec<czid_core::EffectDeclaration> {
        ContinuumEffects::declarations(false)
    }

    /// One element fewer through each arm ([`ContinuumMesh::coarsened`]).
    fn coarsened(&self) -> Option<Box<dyn ForwardModel>> {
        let mesh = self.mesh.coarsened()?;
        Some(Box::new(Enf2d { mesh, ..self.clone() }))
    }

    fn simulate(&self, law: &dyn CohesiveLaw) -> std::result::Result<Record, SimulationFailure> {
        self.simulate_with_stats(law).map(|(r, _)| r)
    }
}
