//! Pieces shared by the beam test models (DCB, ENF): materials, mesh and control settings, and the
//! conversion of engine rows into a [`Record`].

use czid_core::error::{require_non_negative, require_positive};
use czid_core::{columns, CzError, Record, Result};
use serde::{Deserialize, Serialize};

use crate::fe::run_types::StepRow;

/// Which 2D idealisation the adherends follow.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Plane {
    /// Free to contract across the width: axial modulus E11 (narrow specimens; the default).
    #[default]
    Stress,
    /// Restrained across the width: axial modulus E11 / (1 − ν13 ν31), ν31 = ν13 E22 / E11.
    Strain,
}

/// Orthotropic adherend constants (MPa).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Axial (fibre-direction) Young's modulus E11 (MPa).
    pub e11: f64,
    /// Through-thickness Young's modulus E22 = E33 (MPa); used in plane strain and by reference
    /// formulas (corrected beam theory), not by the beams themselves.
    pub e22: f64,
    /// Transverse shear modulus G13 (MPa), resisting the beams' shear deformation.
    pub g13: f64,
    /// Poisson's ratio ν13 across the width (only used in plane strain).
    #[serde(default)]
    pub nu13: f64,
    /// Plane stress (default) or plane strain.
    #[serde(default)]
    pub plane: Plane,
}

impl Material {
    /// Checks the constants.
    pub fn validate(&self, owner: &str) -> Result<()> {
        require_positive(owner, "material.e11", self.e11)?;
        require_positive(owner, "material.e22", self.e22)?;
        require_positive(owner, "material.g13", self.g13)?;
        if !(self.nu13.is_finite() && (0.0..0.5).contains(&self.nu13)) {
            return Err(CzError::invalid(owner, "material.nu13", self.nu13, "must lie in [0, 0.5)"));
        }
        Ok(())
    }

    /// Axial modulus seen by the beams (MPa).
    pub fn axial_modulus(&self) -> f64 {
        match self.plane {
            Plane::Stress => self.e11,
            Plane::Strain => self.e11 / (1.0 - self.nu13 * self.nu13 * self.e22 / self.e11),
        }
    }
}

/// Smallest interface element accepted (mm): a thousandth of the finest cohesive zones met in
/// laminates; below it a specimen's mesh takes gigabytes for no gain.
pub const MIN_ELEMENT: f64 = 1e-3;
/// Memory of one beam element along the interface with its share of the solver's storage and the
/// run's records, measured on the DCB (bytes; 14 MB at 6 800 elements, 37 MB at 34 000).
pub const BYTES_PER_ELEMENT: f64 = 850.0;
/// Largest memory a mesh may need (bytes).
pub const MAX_MESH_BYTES: f64 = 4.0 * 1024.0 * 1024.0 * 1024.0;

/// Refuses a mesh of `elements` beam elements whose memory would exceed [`MAX_MESH_BYTES`],
/// before any of it is allocated.
pub fn check_memory(owner: &str, mesh: &MeshSettings, elements: f64) -> Result<()> {
    let bytes = elements * BYTES_PER_ELEMENT;
    if bytes > MAX_MESH_BYTES {
        return Err(CzError::invalid(
            owner,
            "mesh.interface_element",
            mesh.interface_element,
            format!(
                "gives {elements:.3e} beam elements, about {:.1} GB of memory (at most {:.0} GB): use a coarser interface_element or interface_subdivision",
                bytes / 1e9,
                MAX_MESH_BYTES / 1e9
            ),
        ));
    }
    Ok(())
}

/// Element sizes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MeshSettings {
    /// Largest element along the bonded interface, where the crack can run (mm). The paper uses
    /// 0.1 mm; the process zone should span at least ~5 elements.
    pub interface_element: f64,
    /// Largest element along the cracked arms (mm); they stay elastic, so they can be coarser.
    pub arm_element: f64,
    /// Beam elements per interface element where the crack can run (the models that integrate
    /// the interface between points by segments, see [`crate::fe::segment`]). Under a cohesive
    /// zone, Timoshenko arms deflect locally in shear over `√(κGA / k_f)` (k_f the interface
    /// stiffness per unit length), about 0.14 mm for the paper's DCB: elements of a quarter of
    /// that keep the load at a fixed opening a smooth function of the parameters (see the forward
    /// models chapter). 1: elements of `interface_element`.
    pub interface_subdivision: usize,
}

impl Default for MeshSettings {
    fn default() -> Self {
        MeshSettings { interface_element: 0.1, arm_element: 0.5, interface_subdivision: 4 }
    }
}

impl MeshSettings {
    /// Checks the sizes.
    pub fn validate(&self, owner: &str) -> Result<()> {
        require_positive(owner, "mesh.interface_element", self.interface_element)?;
        require_positive(owner, "mesh.arm_element", self.arm_element)?;
        if self.interface_element < MIN_ELEMENT {
            return Err(CzError::invalid(
                owner,
                "mesh.interface_element",
                self.interface_element,
                format!("is below {MIN_ELEMENT} mm, far finer than any cohesive zone needs (0.05–0.5 mm)"),
            ));
        }
        if !(1..=1000).contains(&self.interface_subdivision) {
            return Err(CzError::invalid(
                owner,
                "mesh.interface_subdivision",
                self.interface_subdivision as f64,
                "must be between 1 and 1000",
            ));
        }
        Ok(())
    }

    /// Beam element size where the crack runs (mm).
    pub fn crack_element(&self) -> f64 {
        self.interface_element / self.interface_subdivision as f64
    }
}

/// How far to load and how often to record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlSettings {
    /// Final applied displacement (mm); `None` chooses one from the geometry and the law's
    /// toughness (see each model).
    pub max_displacement: Option<f64>,
    /// Number of equally spaced displacements at which a state is always recorded (more rows
    /// appear where steps were refined).
    pub output_points: usize,
    /// Damage at or above which the interface counts as debonded. Models integrating the
    /// interface by segments place the debonded front between points where the damage reaches it
    /// (from `1 − 10⁻⁶` on: where the law reports complete failure, see
    /// [`crate::fe::crack::FAILURE_LEVEL`]).
    pub damage_threshold: f64,
    /// Newton iterations allowed per step before it is cut.
    pub max_iterations: usize,
    /// Relative residual tolerance.
    pub tolerance: f64,
}

impl Default for ControlSettings {
    fn default() -> Self {
        ControlSettings {
            max_displacement: None,
            output_points: 100,
            damage_threshold: 1.0 - 1e-9,
            max_iterations: 20,
            tolerance: 1e-9,
        }
    }
}

impl ControlSettings {
    /// Checks the settings.
    pub fn validate(&self, owner: &str) -> Result<()> {
        if let Some(d) = self.max_displacement {
            require_positive(owner, "control.max_displacement", d)?;
        }
        if self.output_points == 0 || self.output_points > 1_000_000 {
            return Err(CzError::invalid(
                owner,
                "control.output_points",
                self.output_points as f64,
                "must be between 1 and 1e6",
            ));
        }
        if !(self.damage_threshold > 0.0 && self.damage_threshold <= 1.0) {
            return Err(CzError::invalid(
                owner,
                "control.damage_threshold",
                self.damage_threshold,
                "must lie in (0, 1]",
            ));
        }
        if self.max_iterations == 0 {
            return Err(CzError::invalid(owner, "control.max_iterations", 0.0, "must be at least 1"));
        }
        require_positive(owner, "control.tolerance", self.tolerance)
    }
}

/// The standard columns of a beam test record, with their units.
pub const COLUMNS: [(&str, &str); 8] = [
    (columns::DISPLACEMENT, "mm"),
    (columns::LOAD, "N"),
    (columns::DEBONDED_LENGTH, "mm"),
    (columns::PROCESS_ZONE_LENGTH, "mm"),
    (columns::CRACK_TIP, "mm"),
    (columns::EXTERNAL_WORK, "N·mm"),
    (columns::ELASTIC_ENERGY, "N·mm"),
    (columns::DISSIPATED_ENERGY, "N·mm"),
];

/// An empty record with the standard columns of a beam test.
pub fn new_record() -> Record {
    Record::new(&COLUMNS)
}

/// How engine rows map to the specimen's record.
#[derive(Clone, Copy, Debug)]
pub struct RowScale {
    /// Recorded displacement per unit of the control unknown.
    pub displacement: f64,
    /// Added to the recorded displacement per unit recorded load (mm/N): a compliant machine
    /// whose load train is not part of the mesh (see [`crate::measurement::recorded_control`]).
    pub compliance: f64,
    /// Recorded load per unit reaction.
    pub load: f64,
    /// Whole-specimen energy per unit energy of the simulated part (2 for a half model).
    pub energy: f64,
    /// How the instruments read the specimen's displacement and load (offsets, a seating toe).
    pub readout: crate::measurement::Readout,
}

impl RowScale {
    /// The specimen's displacement and load in a state of control value `control` and reaction
    /// `reaction`, a compliant machine's share included, before the instruments read them.
    pub fn specimen(&self, control: f64, reaction: f64) -> (f64, f64) {
        let p = self.load * reaction;
        // Without a compliance the sum is the one the base model always recorded, bit for bit.
        let delta = if self.compliance == 0.0 {
            self.displacement * control
        } else {
            self.displacement * control + self.compliance * p
        };
        (delta, p)
    }

    /// The recorded displacement and load of every state `(control, reaction)`, an unloaded first
    /// reading first when the readout has a displacement offset (the sharp toe).
    pub fn readings(&self, states: impl Iterator<Item = (f64, f64)> + Clone) -> Vec<[f64; 2]> {
        let specimen = states.map(|(c, r)| self.specimen(c, r));
        let c0 = crate::measurement::initial_compliance(specimen.clone());
        let mut out = Vec::new();
        if let Some(first) = self.readout.unloaded() {
            out.push(first);
        }
        out.extend(specimen.map(|(d, p)| {
            let (d, p) = self.readout.read(d, p, c0);
            [d, p]
        }));
        out
    }
}

/// One converged state of a test engine (beam or continuum), as the record needs it.
#[derive(Clone, Copy, Debug)]
pub struct EngineState {
    /// Control value.
    pub control: f64,
    /// Its reaction.
    pub reaction: f64,
    /// Debonded length, process-zone length and crack tip (mm).
    pub crack: [f64; 3],
    /// External work, elastic and dissipated energy of the simulated part (N·mm).
    pub energies: [f64; 3],
}

impl From<&StepRow> for EngineState {
    fn from(r: &StepRow) -> Self {
        EngineState {
            control: r.control,
            reaction: r.reaction,
            crack: [r.crack.debonded, r.crack.process_zone, r.crack.tip],
            energies: [r.external_work, r.elastic_energy, r.dissipated_energy],
        }
    }
}

/// The record of engine states scaled into the specimen's displacement, load and energies, read
/// through the instruments (every beam-test engine records this way).
pub fn record_states(states: &[EngineState], s: &RowScale) -> Record {
    let mut rec = new_record();
    let readings = s.readings(states.iter().map(|r| (r.control, r.reaction)));
    let unloaded = readings.len() > states.len();
    if unloaded {
        // The seating toe: the load stays at its zero until the offset is taken up.
        let tip = states.first().map_or(0.0, |r| r.crack[2]);
        rec.push(&[readings[0][0], readings[0][1], 0.0, 0.0, tip, 0.0, 0.0, 0.0]);
    }
    for (r, [delta, p]) in states.iter().zip(&readings[usize::from(unloaded)..]) {
        let [debonded, zone, tip] = r.crack;
        let [work, elastic, dissipated] = r.energies.map(|e| s.energy * e);
        rec.push(&[*delta, *p, debonded, zone, tip, work, elastic, dissipated]);
    }
    rec
}

/// Converts engine rows to a record.
pub fn to_record(rows: &[StepRow], s: &RowScale) -> Record {
    record_states(&rows.iter().map(EngineState::from).collect::<Vec<_>>(), s)
}

/// The interface of two arms (layer 0 below, layer 1 above) on nodes `0..=last`, cracked up to
/// node `tip`: contact points (frictionless unless the problem sets `contact_friction`) on the
/// cracked faces, and cohesive points from the crack front on (the front node carries both, each
/// with its side's tributary length).
pub fn cracked_arms_interface(
    mesh: &crate::fe::Mesh,
    tip: usize,
    last: usize,
    width: f64,
) -> Vec<crate::fe::InterfacePoint> {
    use crate::fe::{InterfacePoint, PointKind};
    let mut points = Vec::with_capacity(last + 2);
    for i in 0..=last {
        let left = if i > 0 { 0.5 * (mesh.x[i] - mesh.x[i - 1]) } else { 0.0 };
        let right = if i < last { 0.5 * (mesh.x[i + 1] - mesh.x[i]) } else { 0.0 };
        let pt = |area: f64, kind| InterfacePoint { node: i, upper: 1, lower: Some(0), area, factor: 1.0, kind };
        if i < tip {
            points.push(pt(width * (left + right), PointKind::Contact));
        } else if i == tip {
            points.push(pt(width * left, PointKind::Contact));
            points.push(pt(width * right, PointKind::Cohesive));
        } else {
            points.push(pt(width * (left + right), PointKind::Cohesive));
        }
    }
    points
}

/// Checks what the split beams on two supports (ENF, MMB) share: no large rotations, and the
/// crack front `a0 + effects.crack_length_offset` inside the first half-span.
pub fn check_split_beam(
    owner: &str,
    model: &str,
    effects: &crate::effects::Effects,
    a0: f64,
    half_span: f64,
) -> Result<()> {
    if effects.large_rotation {
        return Err(CzError::invalid(
            owner,
            "effects.large_rotation",
            1.0,
            format!("is not supported by the {model} model"),
        ));
    }
    let a = a0 + effects.crack_length_offset;
    if !(a > 0.0 && a < half_span) {
        return Err(CzError::invalid(
            owner,
            "a0",
            a0,
            format!("the crack front a0 + effects.crack_length_offset = {a} must lie in (0, half_span)"),
        ));
    }
    Ok(())
}

/// Checks a length is positive.
pub fn positive(owner: &str, name: &str, v: f64) -> Result<()> {
    require_positive(owner, name, v)
}

/// Checks a value is not negative.
pub fn non_negative(owner: &str, name: &str, v: f64) -> Result<()> {
    require_non_negative(owner, name, v)
}

impl ControlSettings {
    /// Path-following settings to `target` (control unknown) with these output and Newton settings.
    pub fn path(&self, target: f64, crack_origin: f64) -> crate::fe::PathSettings {
        crate::fe::PathSettings {
            target,
            outputs: self.output_points,
            min_step_fraction: 1e-3,
            damage_threshold: self.damage_threshold,
            visible_kink: None,
            crack_origin,
            newton: crate::fe::NewtonSettings { max_iterations: self.max_iterations, tolerance: self.tolerance },
            end_at_separation: false,
        }
    }
}

/// Runs an engine problem and converts its rows to a record, keeping the converged rows of a run
/// that fails part way; also returns the engine's statistics on success.
pub fn run(
    p: &crate::fe::FeProblem,
    law: &dyn czid_core::CohesiveLaw,
    path: &crate::fe::PathSettings,
    options: &crate::fe::RunOptions,
    scale: &RowScale,
) -> std::result::Result<(Record, crate::fe::RunStats), czid_core::SimulationFailure> {
    match crate::fe::run_with(p, law, path, options) {
        Ok((rows, stats)) => Ok((to_record(&rows, scale), stats)),
        Err(f) => Err(czid_core::SimulationFailure { error: f.error, partial: to_record(&f.rows, scale) }),
    }
}
