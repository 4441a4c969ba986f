//! The FRP-strengthened RC beam in four-point bending on the finite-element engine (forward model
//! `frp_beam`): intermediate-crack (IC) debonding of the soffit plate through any cohesive law.
//!
//! # The model
//!
//! * **Half beam.** The beam, its loads and supports are symmetric about mid-span, so the half
//!   `0 ≤ x ≤ L/2` (x from mid-span) is modelled with symmetry conditions at `x = 0` (no axial
//!   displacement and no rotation of the beam and of the plate). Both shear spans therefore
//!   debond together. In a test one side goes first (the two are never identical), the other
//!   then unloads with the falling load; the model's run to complete debonding of its half is that
//!   of the side that fails, with the other side assumed to follow it (energies and loads of the
//!   whole beam are twice the half's).
//! * **RC beam**: one fibre-section layer ([`crate::fe::fibre`]): `mesh.concrete_layers` concrete
//!   layers through the depth (Hognestad in compression, linear tension softening), the bars as
//!   steel fibres (elastic, yield, linear hardening) with the concrete they displace removed,
//!   plane sections and perfect bond of the bars. Transverse shear is linear elastic
//!   (`G_c = E_c/2.4`, ν = 0.2; the stirrups are taken to prevent shear failure).
//! * **Cracking: discrete cracks at a configurable spacing** (`cracks.spacing`, 150 mm; the
//!   first at `cracks.first`, by default half a spacing from mid-span, so the pattern is symmetric),
//!   taken as formed (a stabilised crack pattern): the cracking process itself is not modelled.
//!   Each crack is one element of length `l` (the interface element) holding the whole cracked
//!   segment of length `s` between two cracks: its fibres see the element strain times `l/s`
//!   (so its moment–rotation is the cracked section's moment–curvature over `s`, independent of
//!   `l`), its concrete carries no tension. Between cracks the concrete does not crack (linear in
//!   tension: the bond of the bars limits its tension), so the soffit's elongation concentrates
//!   at the cracks: the plate bridges a crack mouth that opens by the bars' elongation over the
//!   spacing, the slip concentrates on both sides of it and IC debonding starts there.
//! * **Plate**: a Timoshenko layer (axial, bending, shear) of `b_f × t_f` under the soffit,
//!   from mid-span to its end, joined to the beam by nodal interface points (trapezoidal weights,
//!   `b_f` × tributary length) carrying any [`CohesiveLaw`] in mixed mode: slip from the
//!   beam's soffit and the plate's top surface axial displacements, opening from their
//!   deflections. Once an interface point has failed the law's normal penalty is what keeps the
//!   plate out of the concrete. At mid-span a linear spring of 1 mm of the law's initial normal
//!   stiffness over the plate's width ties the plate's deflection to the beam's: without it a fully
//!   debonded plate would be free to translate transversely (a singular problem); it carries
//!   nothing else (the gap there is zero by symmetry while the plate is bonded).
//! * **Loading**: a point load `P/2` on the top of the half beam at `load_spacing/2` from
//!   mid-span, a roller at `span/2` under the soffit. The path is followed in the **soffit
//!   elongation** `c`, the axial displacement of the beam's bottom fibre at the plate end relative
//!   to mid-span (indirect displacement control, [`crate::fe::nonlinear`]): it grows monotonically
//!   as cracks open, bars yield and the plate debonds, so the run follows the load drops of
//!   debonding (and any snap-back in the deflection) that a test under displacement control jumps
//!   over.
//! * **Interface damage extrapolated within a step** ([`DamageUpdate::Extrapolated`], tolerance
//!   `control.damage_tolerance`): both sides of every crack soften at once, and with the law's
//!   own tangent Newton's method cannot settle which of them go on softening and which unload.
//!   With the damage held at its extrapolated value each step has a unique solution; the law
//!   updates the damage after it, and steps are halved (down to `control.min_step_fraction` of
//!   the output step) while the two differ by more than the tolerance. Where no state with a
//!   larger elongation is near (the debonded zone running to the plate end), steps of the
//!   smallest size cross the unstable stretch at nearly fixed elongation, as a test controlled by
//!   that elongation would jump. States are recorded every `control.elongation_step` and whenever
//!   another interface point fails.
//! * **Run end**: complete debonding of the modelled side (the failed stretch of the interface
//!   that ends at the plate end reaches back to where debonding started),
//!   crushing of the concrete (top fibre strain beyond `ε_cu` anywhere),
//!   `control.max_elongation`, or the mid-span deflection `control.max_deflection` if one is
//!   given (a test's last reading: the run need not go on beyond it), whichever comes first
//!   ([`RunEnd`]).
//!
//! Small rotations and small strains throughout (the deflections stay below span/40).
//!
//! # Record
//!
//! `displacement` is the **mid-span deflection** (mm, downward positive), `load` the total load `P`
//! on the beam (N). `debonded_length` is the length of the modelled side's interface with damage at
//! or above `control.damage_threshold` (default `1 − 10⁻⁹`: the bond has no stress left), its
//! fronts located inside the elements where the law, along the gaps interpolated between the last
//! failed point and the next, reaches that threshold (so the length is continuous in the state
//! and in the law's parameters instead of growing by whole points, [`crate::fe::crack`]), and
//! `process_zone_length` the length with `0 < D <` threshold; `crack_tip` the debonded front
//! farthest from mid-span (mm from mid-span). Energies are the whole beam's (N·mm): external work
//! = elastic + dissipated, where `dissipated_energy` is the interface's plus the concrete's and the
//! steel's, also given separately (`interface_dissipation`, `material_dissipation`). Extra columns:
//! `midspan_moment` (N·mm, `P/2 ×` shear span), `load_point_deflection` (mm) and
//! `soffit_elongation` (mm, the control).

use czid_core::error::require_positive;
use czid_core::{CohesiveLaw, CzError, ForwardModel, Record, Result, SimulationFailure};
use serde::{Deserialize, Serialize};

use super::beam_effects::BeamEffects;
use super::section::RcSection;
use super::spec::FrpBeamSpec;
use crate::fe::fibre::{Fibre, FibreMaterial, FibreSection};
use crate::fe::mesh::{graded, NONE};
use crate::fe::nonlinear::{self, ControlPath, DamageUpdate, FibreLayer, NonlinearProblem, NonlinearStats, Snapshot};
use crate::fe::{InterfacePoint, Layer, Mesh, NewtonSettings, PointKind, Section, Spring};
use crate::laws::StCzm;

const OWNER: &str = "model frp_beam";

/// Poisson's ratio of concrete, for its shear modulus.
const CONCRETE_POISSON: f64 = 0.2;
/// Transverse shear modulus of the plate over its axial modulus (a CFRP plate: about 5 GPa at
/// E_f = 200 GPa; a 1 mm plate's shear deformation is negligible either way).
const PLATE_SHEAR_RATIO: f64 = 0.025;

/// Element size and fibres.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BeamMesh {
    /// Largest element along the beam and the bond (mm). The bond's stress-transfer length is a
    /// few tens of mm (`√(E_f t_f/k_t)`, 20 mm for the paper's Table 8 law), its softening zone
    /// longer: 10 mm elements resolve the debonding load within 1 %.
    pub interface_element: f64,
    /// Concrete layers through the depth.
    pub concrete_layers: usize,
}

impl Default for BeamMesh {
    fn default() -> Self {
        BeamMesh { interface_element: 10.0, concrete_layers: 30 }
    }
}

/// Where the flexural cracks are.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BeamCracks {
    /// Distance between neighbouring discrete cracks (mm): the crack spacing of the beam, also
    /// the length over which the bars' elongation at a crack is collected.
    pub spacing: f64,
    /// Distance of the first crack from mid-span (mm); `None`: half the spacing (cracks placed
    /// symmetrically about mid-span, none on the symmetry plane).
    pub first: Option<f64>,
}

impl Default for BeamCracks {
    fn default() -> Self {
        BeamCracks { spacing: 150.0, first: None }
    }
}

/// Path and output settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BeamControl {
    /// Soffit elongation between recorded states (mm).
    pub elongation_step: f64,
    /// Largest soffit elongation (mm); the run normally ends earlier, at complete debonding.
    pub max_elongation: f64,
    /// Damage at or above which the interface counts as debonded.
    pub damage_threshold: f64,
    /// Newton iterations per step before it is cut. The paper's beam needs 1 to 6 (measured with
    /// the Table 8 law on both the default path and the fixed schedule); the most go to the first
    /// step from rest, where the fibres of every cracked section sit at the concrete's kink (no
    /// tension at zero strain) and Newton settles which of them carry load.
    pub max_iterations: usize,
    /// Relative residual tolerance.
    pub tolerance: f64,
    /// Largest difference between the interface damage the law gives at the end of a step and
    /// the damage extrapolated for it ([`DamageUpdate::Extrapolated`]); a step that exceeds it is
    /// repeated at half the size.
    pub damage_tolerance: f64,
    /// Smallest step, as a fraction of `elongation_step`, to which a step is halved for the damage
    /// tolerance (a step of that size is taken whatever the difference: an unstable stretch of the
    /// path, crossed at nearly fixed elongation).
    pub min_step_fraction: f64,
    /// Mid-span deflection (mm, as recorded) at which the run ends, if it has not ended before: the state
    /// recorded where the deflection first reaches it is the last. A test that stopped at a
    /// known deflection need not be followed beyond it (the states after the first crossing are
    /// never compared with the test; the event "debonded length at the end of the test" reads
    /// the first crossing). `None`: the run goes on to complete debonding.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_deflection: Option<f64>,
}

impl BeamControl {
    /// A fixed step schedule of `elongation_step` (mm): no step is repeated smaller because the
    /// law's damage departs from the extrapolated one (a departure never exceeds 1). Every output
    /// then moves smoothly with the law's parameters, which finite-difference Jacobians need;
    /// the default halving decisions change with the parameters and make outputs jump (the path
    /// of `examples/frp-beam/identify.toml` and of `czid gap-bench --family beam`).
    pub fn set_fixed_schedule(&mut self, elongation_step: f64) {
        self.elongation_step = elongation_step;
        self.damage_tolerance = 1.0;
    }
}

impl Default for BeamControl {
    fn default() -> Self {
        BeamControl {
            elongation_step: 0.05,
            max_elongation: 40.0,
            damage_threshold: 1.0 - 1e-9,
            max_iterations: 60,
            tolerance: 1e-9,
            damage_tolerance: 0.05,
            min_step_fraction: 1.0 / 64.0,
            max_deflection: None,
        }
    }
}

/// Simply supported RC beam with a bonded soffit plate in symmetric four-point bending; see the
/// [module documentation](self). Lengths in mm; plate and loads centred on the span.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrpBeam {
    /// Overall length of the beam (mm).
    pub beam_length: f64,
    /// Distance between the supports (mm).
    pub span: f64,
    /// Distance between the two load points (mm).
    pub load_spacing: f64,
    /// Bonded length of the plate (mm).
    pub plate_length: f64,
    /// Cross-section: concrete, bars, plate (must have a plate).
    pub section: RcSection,
    /// Element size and fibres.
    #[serde(default)]
    pub mesh: BeamMesh,
    /// Discrete flexural cracks.
    #[serde(default)]
    pub cracks: BeamCracks,
    /// Path and output.
    #[serde(default)]
    pub control: BeamControl,
    /// Optional physics (all null by default).
    #[serde(default)]
    pub effects: BeamEffects,
}

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunEnd {
    /// The failed stretch of the interface that ends at the plate end reaches back to where
    /// debonding started: the plate is debonded from the first failed crack mouth to its end.
    CompleteDebonding,
    /// The concrete's top fibre passed its crushing strain.
    ConcreteCrushing,
    /// `control.max_elongation` was reached.
    MaxElongation,
    /// The mid-span deflection reached `control.max_deflection`.
    MaxDeflection,
}

/// Where the interface first failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DebondingStart {
    /// Nearest and farthest failed point from mid-span at the first recorded state with a failed
    /// point (mm).
    pub x: (f64, f64),
    /// Row of the record at which it happened.
    pub row: usize,
}

/// State along the plate at one recorded state.
#[derive(Clone, Debug, PartialEq)]
pub struct PlateProfile {
    /// Row of the record.
    pub row: usize,
    /// Node positions from mid-span (mm).
    pub x: Vec<f64>,
    /// Axial strain of the plate at the nodes (element values averaged onto nodes).
    pub plate_strain: Vec<f64>,
    /// Slip, concrete soffit minus plate (mm).
    pub slip: Vec<f64>,
    /// Bond shear stress (MPa).
    pub bond_stress: Vec<f64>,
    /// Interface damage.
    pub damage: Vec<f64>,
}

/// Everything a run produced.
#[derive(Clone, Debug)]
pub struct BeamRun {
    /// The record (see the [module documentation](self)).
    pub record: Record,
    /// Why it ended.
    pub end: RunEnd,
    /// Where debonding started, if it did.
    pub debonding_start: Option<DebondingStart>,
    /// Plate profiles at every row (only when asked for).
    pub profiles: Vec<PlateProfile>,
    /// Solver statistics.
    pub stats: NonlinearStats,
}

/// Node indices of the half-beam mesh.
#[derive(Clone, Copy, Debug)]
struct Layout {
    load: usize,
    support: usize,
    plate_end: usize,
}

/// Extra record columns.
pub mod beam_columns {
    /// Mid-span moment (N·mm).
    pub const MIDSPAN_MOMENT: &str = "midspan_moment";
    /// Deflection under the load points (mm).
    pub const LOAD_POINT_DEFLECTION: &str = "load_point_deflection";
    /// Soffit elongation, the path control (mm).
    pub const SOFFIT_ELONGATION: &str = "soffit_elongation";
    /// Energy dissipated by the interface (N·mm).
    pub const INTERFACE_DISSIPATION: &str = "interface_dissipation";
    /// Energy dissipated by concrete and steel (N·mm).
    pub const MATERIAL_DISSIPATION: &str = "material_dissipation";
}

impl FrpBeam {
    /// The paper's beam with the choices of [`FrpBeamSpec::paper`] (span 3600 mm, loads 1200 mm
    /// apart, 3 Ø16 bars, E_f = 200 GPa, 150 mm crack band) and default mesh and control.
    pub fn paper() -> Result<Self> {
        let spec = FrpBeamSpec::paper()?;
        let beam = FrpBeam {
            beam_length: spec.beam_length,
            span: spec.span,
            load_spacing: spec.load_spacing,
            plate_length: spec.plate_length,
            section: spec.section.clone(),
            mesh: BeamMesh::default(),
            cracks: BeamCracks { spacing: spec.section.concrete.crack_band, ..BeamCracks::default() },
            control: BeamControl::default(),
            effects: BeamEffects::default(),
        };
        beam.validate()?;
        Ok(beam)
    }

    /// The paper's identified interface law (Shi & Zhang, Table 8), an ST-CZM with sawtooth
    /// strength models: σ_n,c = 12 MPa, σ_t,c = 14 MPa, elastic ends 0.02513 / 0.02897 mm (the
    /// paper's Δu_f), failure openings 0.1457 / 0.1504 mm (its Δu_c).
    pub fn table8_law() -> Result<StCzm> {
        StCzm::sawtooth(12.0, 0.02513, 0.1457, 14.0, 0.02897, 0.1504)
    }

    /// Checks the configuration, naming the first invalid field.
    pub fn validate(&self) -> Result<()> {
        require_positive(OWNER, "beam_length", self.beam_length)?;
        require_positive(OWNER, "span", self.span)?;
        require_positive(OWNER, "load_spacing", self.load_spacing)?;
        require_positive(OWNER, "plate_length", self.plate_length)?;
        if self.span > self.beam_length {
            return Err(CzError::invalid(OWNER, "span", self.span, "must not exceed the beam length"));
        }
        if self.load_spacing >= self.span {
            return Err(CzError::invalid(OWNER, "load_spacing", self.load_spacing, "must be shorter than the span"));
        }
        if self.plate_length > self.beam_length {
            return Err(CzError::invalid(OWNER, "plate_length", self.plate_length, "must not exceed the beam length"));
        }
        if self.plate_length <= self.load_spacing {
            return Err(CzError::invalid(
                OWNER,
                "plate_length",
                self.plate_length,
                "must reach past the load points into the shear spans",
            ));
        }
        self.section.validate()?;
        if self.section.plate.is_none() {
            return Err(CzError::config(format!("{OWNER}: section.plate"), "the strengthened beam needs a plate"));
        }
        require_positive(OWNER, "mesh.interface_element", self.mesh.interface_element)?;
        if self.beam_length / self.mesh.interface_element > 100_000.0 {
            return Err(CzError::invalid(
                OWNER,
                "mesh.interface_element",
                self.mesh.interface_element,
                "gives more than 100 000 elements",
            ));
        }
        if !(10..=2000).contains(&self.mesh.concrete_layers) {
            return Err(CzError::invalid(
                OWNER,
                "mesh.concrete_layers",
                self.mesh.concrete_layers as f64,
                "must be between 10 and 2000",
            ));
        }
        require_positive(OWNER, "cracks.spacing", self.cracks.spacing)?;
        if self.cracks.spacing < 2.0 * self.mesh.interface_element {
            return Err(CzError::invalid(
                OWNER,
                "cracks.spacing",
                self.cracks.spacing,
                format!("must be at least two elements ({} mm)", 2.0 * self.mesh.interface_element),
            ));
        }
        let first = self.first_crack();
        if !(first.is_finite() && first >= 0.5 * self.mesh.interface_element && first < 0.5 * self.span) {
            return Err(CzError::invalid(
                OWNER,
                "cracks.first",
                first,
                "must lie between half an element from mid-span and the support",
            ));
        }
        let c = &self.control;
        require_positive(OWNER, "control.elongation_step", c.elongation_step)?;
        require_positive(OWNER, "control.max_elongation", c.max_elongation)?;
        if c.max_elongation / c.elongation_step > 1e6 {
            return Err(CzError::invalid(OWNER, "control.elongation_step", c.elongation_step, "gives over 1e6 rows"));
        }
        if !(c.damage_threshold > 0.0 && c.damage_threshold <= 1.0) {
            return Err(CzError::invalid(OWNER, "control.damage_threshold", c.damage_threshold, "must lie in (0, 1]"));
        }
        if c.max_iterations == 0 {
            return Err(CzError::invalid(OWNER, "control.max_iterations", 0.0, "must be at least 1"));
        }
        require_positive(OWNER, "control.tolerance", c.tolerance)?;
        require_positive(OWNER, "control.damage_tolerance", c.damage_tolerance)?;
        if !(c.min_step_fraction > 0.0 && c.min_step_fraction <= 1.0) {
            return Err(CzError::invalid(
                OWNER,
                "control.min_step_fraction",
                c.min_step_fraction,
                "must lie in (0, 1]",
            ));
        }
        if let Some(d) = c.max_deflection {
            require_positive(OWNER, "control.max_deflection", d)?;
        }
        self.effects.validate(OWNER)?;
        // The effects must leave valid materials.
        self.materials().map(|_| ())
    }

    /// Distance from a support to the nearer load point (mm).
    pub fn shear_span(&self) -> f64 {
        0.5 * (self.span - self.load_spacing)
    }

    /// Concrete and steel with the effects applied (the nominal ones when they are null).
    fn materials(&self) -> Result<(crate::materials::Concrete, crate::materials::Steel)> {
        use crate::materials::UniaxialMaterial;
        let e = &self.effects;
        let concrete = self.section.concrete.clone();
        let mut steel = self.section.steel.clone();
        if e.steel_hardening_offset != 0.0 {
            steel.hardening_modulus += e.steel_hardening_offset;
        }
        steel.validate().map_err(|err| {
            CzError::config(format!("{OWNER}: effects.steel_hardening_offset"), format!("gives invalid steel: {err}"))
        })?;
        Ok((concrete, steel))
    }

    /// Position of the first crack from mid-span (mm).
    pub fn first_crack(&self) -> f64 {
        self.cracks.first.unwrap_or(0.5 * self.cracks.spacing)
    }

    /// Crack positions from mid-span up to the support (mm).
    pub fn crack_positions(&self) -> Vec<f64> {
        let mut xs = Vec::new();
        let mut x = self.first_crack();
        while x + 0.5 * self.mesh.interface_element < 0.5 * self.span {
            xs.push(x);
            x += self.cracks.spacing;
        }
        xs
    }

    /// The RC beam's fibre sections (heights from its centroid, mid-depth): `[between cracks,
    /// crack element]`. Between cracks the concrete does not crack; in a crack element of length
    /// `l` the concrete's tension softens over the element (crack band `l`: the crack dissipates
    /// `G_F`) and the bars see the element strain times `l/s` (their elongation over the crack
    /// spacing `s` lumped into the crack).
    fn fibre_sections(&self) -> Result<Vec<FibreSection>> {
        let (concrete, steel) = self.materials()?;
        let l = self.mesh.interface_element;
        let between = vec![FibreMaterial::UncrackedConcrete(concrete.clone()), FibreMaterial::Steel(steel.clone())];
        let crack = vec![
            FibreMaterial::CrackedConcrete { concrete, ratio: l / self.cracks.spacing },
            FibreMaterial::CrackSteel { steel, ratio: l / self.cracks.spacing },
        ];
        Ok(vec![self.fibres(between), self.fibres(crack)])
    }

    fn fibres(&self, materials: Vec<FibreMaterial>) -> FibreSection {
        let s = &self.section;
        let n = self.mesh.concrete_layers;
        let t = s.height / n as f64;
        let eps0 = self.effects.shrinkage_strain;
        let mut fibres: Vec<Fibre> = (0..n)
            .map(|i| Fibre {
                z: 0.5 * s.height - (i as f64 + 0.5) * t,
                area: s.width * t,
                material: 0,
                initial_strain: eps0,
            })
            .collect();
        for bar in &s.bars {
            let z = 0.5 * s.height - bar.depth;
            fibres.push(Fibre { z, area: bar.area, material: 1, initial_strain: 0.0 });
            // The concrete the bar displaces.
            fibres.push(Fibre { z, area: -bar.area, material: 0, initial_strain: eps0 });
        }
        FibreSection { materials, fibres }
    }

    /// Builds the discrete half-beam problem for `law`.
    fn problem(&self, law: &dyn CohesiveLaw) -> Result<(NonlinearProblem, Layout)> {
        self.validate()?;
        let plate = self.section.plate.as_ref().ok_or_else(|| CzError::config(OWNER, "section.plate is missing"))?;
        let half = |v: f64| 0.5 * v;
        let lc = self.mesh.interface_element;
        let cracks = self.crack_positions();
        let mut breaks =
            vec![0.0, half(self.load_spacing), half(self.span), half(self.plate_length), half(self.beam_length)];
        for &xc in &cracks {
            breaks.extend([xc - 0.5 * lc, xc + 0.5 * lc]);
        }
        breaks.sort_by(f64::total_cmp);
        breaks.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        let sizes = vec![self.mesh.interface_element; breaks.len() - 1];
        let x = graded(&breaks, &sizes);
        let node = |v: f64| {
            x.iter().enumerate().min_by(|a, b| (a.1 - v).abs().total_cmp(&(b.1 - v).abs())).map_or(0, |(i, _)| i)
        };
        let layout = Layout {
            load: node(half(self.load_spacing)),
            support: node(half(self.span)),
            plate_end: node(half(self.plate_length)),
        };
        let nn = x.len();
        let (h, tf) = (self.section.height, plate.thickness);
        let ec = self.section.concrete.elastic_modulus;
        let ef = plate.material.elastic_modulus;
        let rc = Layer {
            section: Section { e: 0.0, g: ec / (2.0 * (1.0 + CONCRETE_POISSON)), b: self.section.width, h },
            y: tf + 0.5 * h,
            axial: true,
            first: 0,
            last: nn - 1,
        };
        let frp = Layer {
            section: Section { e: ef, g: PLATE_SHEAR_RATIO * ef, b: plate.width, h: tf },
            y: 0.5 * tf,
            axial: true,
            first: 0,
            last: layout.plate_end,
        };
        let mesh = Mesh::new(x, vec![rc, frp], 0)?;
        let mut points = Vec::with_capacity(layout.plate_end + 1);
        for i in 0..=layout.plate_end {
            let left = if i > 0 { 0.5 * (mesh.x[i] - mesh.x[i - 1]) } else { 0.0 };
            let right = if i < layout.plate_end { 0.5 * (mesh.x[i + 1] - mesh.x[i]) } else { 0.0 };
            points.push(InterfacePoint {
                node: i,
                upper: 0,
                lower: Some(1),
                area: plate.width * (left + right),
                factor: 1.0,
                kind: PointKind::Cohesive,
            });
        }
        let (b0, p0) = (mesh.dofs(0, 0), mesh.dofs(1, 0));
        let fixed = vec![b0[0], b0[2], p0[0], p0[2], mesh.dofs(0, layout.support)[1]];
        let springs =
            vec![Spring { i: p0[1], j: b0[1], k: law.initial_stiffness()[0].abs() * plate.width * 1.0, ci: 1.0 }];
        let end = mesh.dofs(0, layout.plate_end);
        // Bottom fibre (z = −h/2) axial displacement u − zθ at the plate end.
        let control = vec![(end[0], 1.0), (end[2], 0.5 * h)];
        let load = vec![(mesh.dofs(0, layout.load)[1], -1.0)];
        let compliance = [self.effects.adhesive_normal_compliance, self.effects.adhesive_shear_compliance];
        let element_section = (0..nn - 1)
            .map(|i| {
                let mid = 0.5 * (mesh.x[i] + mesh.x[i + 1]);
                usize::from(cracks.iter().any(|&xc| (mid - xc).abs() < 0.5 * lc))
            })
            .collect();
        let fibre_layers = vec![FibreLayer { layer: 0, sections: self.fibre_sections()?, element_section }];
        let problem = NonlinearProblem { mesh, points, fixed, fibre_layers, load, control, compliance, springs };
        Ok((problem, layout))
    }

    /// Runs the beam with `law`; with `profiles`, also the state along the plate at every row.
    pub fn run(&self, law: &dyn CohesiveLaw, profiles: bool) -> std::result::Result<BeamRun, SimulationFailure> {
        let fail = |error: CzError| SimulationFailure { error, partial: new_record() };
        law.validate().map_err(fail)?;
        let (p, layout) = self.problem(law).map_err(fail)?;
        let c = &self.control;
        let path = ControlPath {
            spacing: c.elongation_step,
            max_control: c.max_elongation,
            min_step_fraction: 1e-4,
            damage_threshold: c.damage_threshold,
            newton: NewtonSettings { max_iterations: c.max_iterations, tolerance: c.tolerance },
            damage_update: DamageUpdate::Extrapolated {
                tolerance: c.damage_tolerance,
                min_fraction: c.min_step_fraction,
            },
        };
        let eps_cu = self.section.concrete.crushing_strain;
        let z_top = 0.5 * self.section.height;
        let ratio = self.mesh.interface_element / self.cracks.spacing;
        let mut extra: Vec<[f64; 2]> = Vec::new();
        let mut end = RunEnd::MaxElongation;
        let mut start = None;
        let mut debonded_before = false;
        let mut kept = Vec::new();
        let threshold = c.damage_threshold;
        let mut observe = |s: &Snapshot| -> bool {
            let row = extra.len();
            let w = |node: usize| -s.q[p.mesh.dofs(0, node)[1]];
            extra.push([w(0), w(layout.load)]);
            let failed: Vec<f64> = p
                .points
                .iter()
                .zip(s.point_states)
                .filter(|(_, st)| st.damage >= threshold)
                .map(|(pt, _)| p.mesh.x[pt.node])
                .collect();
            if start.is_none() && !failed.is_empty() {
                start = Some(DebondingStart { x: (failed[0], failed[failed.len() - 1]), row });
            }
            if profiles {
                kept.push(profile(&p, s, row));
            }
            // Complete debonding: the failed stretch that ends at the plate end reaches back to
            // where debonding started (IC debonding has run through to the plate end; the plate
            // beyond the first debonded crack carries nothing).
            // The run ends at the state recorded after the one where this first holds: the
            // equilibrium of a step holds the damage extrapolated from the states before it, so
            // the state where the last point fails still carries some of the plate's force, the
            // next one no longer does.
            let from_end = s.point_states.iter().rev().take_while(|st| st.damage >= threshold).count();
            if let (Some(st), true) = (start, from_end > 0) {
                let first = p.points.len() - from_end;
                if p.mesh.x[p.points[first].node] <= st.x.0 {
                    if debonded_before {
                        end = RunEnd::CompleteDebonding;
                        return true;
                    }
                    debonded_before = true;
                }
            }
            // The deflection as recorded (with a measurement offset, if one is planted).
            if c.max_deflection.is_some_and(|d| w(0) + self.effects.deflection_offset >= d) {
                end = RunEnd::MaxDeflection;
                return true;
            }
            let crushed = (0..layout.support).any(|i| {
                let (a, b) = (p.mesh.dofs(0, i), p.mesh.dofs(0, i + 1));
                let l = p.mesh.x[i + 1] - p.mesh.x[i];
                let (eps, kappa) = ((s.q[b[0]] - s.q[a[0]]) / l, (s.q[b[2]] - s.q[a[2]]) / l);
                // A crack element's strains are its segment's over the ratio l/s.
                let scale = if p.fibre_layers[0].element_section[i] == 1 { ratio } else { 1.0 };
                (eps - z_top * kappa) * scale < -eps_cu
            });
            if crushed {
                end = RunEnd::ConcreteCrushing;
                return true;
            }
            false
        };
        let result = nonlinear::run(&p, law, &path, &mut observe);
        let to_record = |rows: &[nonlinear::NonlinearRow]| self.to_record(rows, &extra);
        match result {
            Ok((rows, stats)) => {
                Ok(BeamRun { record: to_record(&rows), end, debonding_start: start, profiles: kept, stats })
            }
            Err(f) => Err(SimulationFailure { error: f.error, partial: to_record(&f.rows) }),
        }
    }

    fn to_record(&self, rows: &[nonlinear::NonlinearRow], extra: &[[f64; 2]]) -> Record {
        let mut rec = new_record();
        let offset = self.effects.deflection_offset;
        if offset != 0.0 {
            let tip = rows.first().map_or(0.0, |r| r.crack.tip);
            rec.push(&[0.0, 0.0, 0.0, 0.0, tip, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        }
        // Whole beam: two halves.
        for (r, e) in rows.iter().zip(extra) {
            let load = 2.0 * r.load;
            rec.push(&[
                e[0] + offset,
                load,
                r.crack.debonded,
                r.crack.process_zone,
                r.crack.tip,
                2.0 * r.external_work,
                2.0 * r.elastic_energy,
                2.0 * (r.interface_dissipation + r.material_dissipation),
                0.5 * load * self.shear_span(),
                e[1] + offset,
                r.control,
                2.0 * r.interface_dissipation,
                2.0 * r.material_dissipation,
            ]);
        }
        rec
    }
}

fn new_record() -> Record {
    let mut columns = crate::beamtest::COLUMNS.to_vec();
    columns.extend([
        (beam_columns::MIDSPAN_MOMENT, "N·mm"),
        (beam_columns::LOAD_POINT_DEFLECTION, "mm"),
        (beam_columns::SOFFIT_ELONGATION, "mm"),
        (beam_columns::INTERFACE_DISSIPATION, "N·mm"),
        (beam_columns::MATERIAL_DISSIPATION, "N·mm"),
    ]);
    Record::new(&columns)
}

/// The plate's state at a snapshot.
fn profile(p: &NonlinearProblem, s: &Snapshot, row: usize) -> PlateProfile {
    let np = p.points.len();
    let x: Vec<f64> = p.points.iter().map(|pt| p.mesh.x[pt.node]).collect();
    let u = |i: usize| {
        let d = p.mesh.dofs(1, i)[0];
        if d == NONE {
            0.0
        } else {
            s.q[d]
        }
    };
    let element: Vec<f64> = (0..np - 1).map(|i| (u(i + 1) - u(i)) / (x[i + 1] - x[i])).collect();
    let plate_strain = (0..np)
        .map(|i| match (i.checked_sub(1).map(|k| element[k]), element.get(i)) {
            (Some(a), Some(b)) => 0.5 * (a + b),
            (Some(a), None) => a,
            (None, Some(b)) => *b,
            (None, None) => 0.0,
        })
        .collect();
    PlateProfile {
        row,
        x,
        plate_strain,
        slip: s.gaps.iter().map(|g| g[1]).collect(),
        bond_stress: s.tractions.iter().map(|t| t[1]).collect(),
        damage: s.point_states.iter().map(|st| st.damage).collect(),
    }
}

#[typetag::serde(name = "frp_beam")]
impl ForwardModel for FrpBeam {
    fn name(&self) -> &str {
        "frp_beam"
    }

    fn validate(&self) -> Result<()> {
        FrpBeam::validate(self)
    }

    fn effects(&self) -> Vec<czid_core::EffectDeclaration> {
        super::beam_effects::BeamEffects::declarations()
    }

    fn regimes(&self) -> &'static dyn czid_core::RegimeRule {
        &super::regimes::BeamRegimes
    }

    fn simulate(&self, law: &dyn CohesiveLaw) -> std::result::Result<Record, SimulationFailure> {
        self.run(law, false).map(|r| r.record)
    }
}
