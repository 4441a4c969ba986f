//! Single-shear pull test of an FRP plate bonded to a concrete prism, on the beam/interface engine.
//!
//! # The test
//!
//! An FRP plate (width `b_f`, thickness `t_f`, modulus `E_f`) is bonded over a length `L` to a
//! concrete prism (width `b_c`, depth `h_c`, modulus `E_c`) and pulled at one end along its axis.
//! The prism bears against a restraint at the loaded end ("pull–push", the usual single-shear
//! arrangement), so it carries the load back in compression. The applied displacement is the
//! **loaded-end slip** `δ`, the plate's displacement relative to the concrete at the loaded end of
//! the bond, and the load is the plate force `P`.
//!
//! # Discretisation
//!
//! Axial coordinate `x` from the loaded end of the bond (`x = 0`) to its free end (`x = L`), one
//! uniform grid of `mesh.interface_element` elements. Zero-thickness interface points at the nodes
//! (trapezoidal weights, area `b_f ×` tributary length) carry any [`CohesiveLaw`] and join the plate
//! to the concrete.
//!
//! * **Plate**: an axial bar (two-node elements; deflection and rotation held), so the interface
//!   opening is identically zero and the law works in pure slip. Peeling from the eccentricity of
//!   the bond shear (`t_f/2` below the plate's axis) is neglected: the plate's bending stiffness is
//!   tiny (a check with the plate as a Timoshenko beam held by the grip moved the peak load of the
//!   paper's 1 mm plate by less than 0.02 %).
//! * **Concrete**: a linear elastic axial member of section `b_c × h_c` (uniform axial stress, the
//!   assumption of the closed-form solutions, e.g. Yuan et al. 2004), held at the loaded end; its
//!   bending is neglected (a deep prism clamped in the rig). Shear lag in the concrete below the
//!   bond line belongs to the bond law's initial stiffness (Lu et al.'s law is calibrated that
//!   way). With `concrete.rigid` the concrete does not deform at all: the assumption of
//!   [`BondedJoint`]'s closed forms.
//!
//! **How the concrete's compliance enters.** Nothing but the bond acts on the plate and the prism
//! beyond a cross-section at `x`, so the concrete's axial force is minus the plate's everywhere:
//! `N_c = −N_f`. The slip `s = u_f − u_c` then obeys `s' = N_f (1 + α)/(E_f A_f)` with
//! `α = b_f E_f t_f/(E_c b_c h_c)`: the test is exactly a plate of axial stiffness
//! `E_f A_f/(1 + α)` bonded to rigid concrete, whose axial displacement is the slip. The engine is
//! given that form (the plate's unknowns are the slips; the concrete layer below is fixed), with
//! identical load, slip, damage and energies (the concrete's strain energy `α` times the plate's is
//! inside the elastic energy). `models/tests/frp_pull.rs` checks it against a two-layer model with
//! an elastic concrete layer. (Carrying the concrete as its own layer would leave it with
//! round-off-level forces once the plate has fully debonded, and the engine's purely relative
//! residual test cannot converge to that zero-load state.) The bond equation is
//! `s'' = τ(s) (1 + α)/(E_f t_f)` ([`FrpPull::equivalent_joint`]) and a long bond carries
//! `P_max = b_f √(2 G_f E_f t_f/(1 + α))` ([`FrpPull::long_bond_strength`]).
//!
//! **Reference spring.** The loaded end is also tied to the ground by a linear spring of the
//! plate's own stiffness over the bond, `k = E_f A_f/((1 + α) L)`. Under displacement control it
//! changes nothing but the reaction (`P + k δ`); under the dissipation constraint it releases no
//! energy. Its force `k δ` and energy `½ k δ²` are taken out of the record exactly (the trapezoidal
//! work of a linear spring telescopes to `½ k δ²`). It is there because the engine's convergence
//! test is relative to the internal forces: as a bond fails completely the load, and with it the
//! tolerance, would go to zero while the round-off of the plate's stiffness terms does not, and the
//! run would stop just short of full separation.
//!
//! # Loading and path following
//!
//! The plate's axial displacement at the loaded end is prescribed (pulled towards `−x`; the record
//! gives the slip and the load as positive numbers). A long bond reaches `P_max` and keeps it while
//! the debonded zone runs along the bond (the slip grows by the stretch of the debonded plate);
//! when what is left is too short to carry `P_max`, the load drops and the loaded-end slip
//! *decreases* (snap-back: the debonded plate recovers its stretch) down to about the law's
//! separation slip at zero load. Short bonds (below about `L_e`) soften after their peak instead.
//!
//! * By default a run ends on the plateau, when the debonded zone has come within `2 L_e` of the
//!   free end, or at the law's separation slip for bonds shorter than `2 L_e`
//!   ([`FrpPull::default_slip`]): the range a test under slip control records before the joint
//!   fails.
//! * A larger `control.max_displacement` (up to [`FrpPull::full_range_slip`] and beyond) follows
//!   the final snap-back under the engine's dissipation constraint ([`crate::fe::path`]); the
//!   record then holds rows of decreasing slip, and the separated state (no load) is held up to
//!   the target. This works for laws with a finite softening branch (bilinear: checked to the
//!   final dissipation `b_f L G_f`). With Lu's law the remaining bond sits in the law's long
//!   exponential tail, nearly stress-free, and the engine's displacement control can converge
//!   straight onto the separated state (an equilibrium at any slip beyond `s_u`), skipping the
//!   snap-back; the rows after such a jump are equilibria, but the dissipated energy credited
//!   across it is not the law's (its final value exceeds `b_f L G_f`).
//!
//! # What is recorded
//!
//! The standard columns ([`czid_core::columns`]): `displacement` (loaded-end slip, mm), `load` (N),
//! `debonded_length`, `process_zone_length`, `crack_tip` (mm from the loaded end), and the energies
//! (N·mm; external work = elastic + dissipated).
//!
//! * **Debonded** means damage `D ≥ control.damage_threshold` (default `1 − 10⁻⁹`): the bond has
//!   lost all its stress transfer. For Lu et al.'s law ([`crate::laws::LuBondSlip`]) that is slip
//!   beyond the end of its tail `s_u` (0.485 mm for the paper's concrete), not the peak slip `s0`:
//!   its damage is the secant loss `1 − τ/(K0 s)`, already about 0.92 at the peak, so a threshold
//!   such as 0.9 would count the whole softening zone, and more, as debonded.
//! * **Process zone** is the engine's: points with `0 < D < threshold`. For a law with an elastic
//!   range (bilinear, ST-CZM) that is the softening zone; Lu et al.'s law has no elastic range
//!   (damage grows from the first slip), so there the column covers every stressed point ahead of
//!   the debonded zone. The softening zone proper (slip past the peak of the bond–slip curve) is
//!   reported by [`FrpPull::profiles`].
//! * **Strain along the plate** is not in the record (the engine reports global quantities per
//!   step): [`FrpPull::profiles`] returns the plate strain, slip, bond stress and damage along the
//!   bond at chosen loaded-end slips.
//!
//! ```
//! use czid_core::{columns, ForwardModel};
//! use czid_models::frp::pull::FrpPull;
//! use czid_models::laws::LuBondSlip;
//!
//! let law = LuBondSlip::from_concrete(47.0, 100.0, 200.0, 1000.0).unwrap();
//! let mut pull = FrpPull::paper(100.0).unwrap();
//! pull.mesh.interface_element = 5.0;
//! pull.control.max_displacement = Some(0.3);
//! pull.control.output_points = 10;
//! let record = pull.simulate(&law).unwrap();
//! let peak = record.column(columns::LOAD).unwrap().iter().cloned().fold(0.0, f64::max);
//! // A 100 mm bond (0.59 L_e) carries less than a long one.
//! assert!(peak > 0.7 * pull.long_bond_strength(&law) && peak < pull.long_bond_strength(&law));
//! ```

use czid_core::error::require_positive;
use czid_core::{CohesiveLaw, CzError, ForwardModel, Gap, LawState, Record, Result, SimulationFailure};
use serde::{Deserialize, Serialize};

use super::bond::BondedJoint;
use super::spec::FrpBeamSpec;
use crate::beamtest::{self, ControlSettings, RowScale};
use crate::fe::mesh::{graded, NONE};
use crate::fe::newton::Newton;
use crate::fe::run_types::StepRow;
use crate::fe::{
    self, FeProblem, InterfacePoint, Layer, Mesh, NewtonSettings, PathSettings, PointKind, Section, Spring,
};

const OWNER: &str = "model frp_pull";

/// Most elements a bond may be divided into (guards against a mistyped element size).
const MAX_ELEMENTS: f64 = 200_000.0;

/// The bonded plate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PullPlate {
    /// Width b_f (mm).
    pub width: f64,
    /// Thickness t_f (mm).
    pub thickness: f64,
    /// Axial modulus E_f (MPa).
    pub modulus: f64,
}

/// The concrete prism.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PullConcrete {
    /// Width b_c (mm) of the bonded face.
    pub width: f64,
    /// Depth h_c (mm) perpendicular to the bonded face; with the width, the section that carries
    /// the load back to the restraint.
    pub depth: f64,
    /// Cylinder strength f'c (MPa): gives the default modulus and Chen & Teng's effective bond
    /// length.
    pub fc_cylinder: f64,
    /// Young's modulus E_c (MPa); `None`: `4700 √f'c` (ACI 318).
    #[serde(default)]
    pub modulus: Option<f64>,
    /// Rigid concrete (no axial strain) instead of a linear elastic prism.
    #[serde(default)]
    pub rigid: bool,
}

/// Element size along the bond.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PullMesh {
    /// Largest element along the bond (mm). The stress-transfer zone of an FRP-to-concrete bond
    /// is long (of the order of the effective bond length, ~100–200 mm), so a few mm suffice.
    pub interface_element: f64,
}

impl Default for PullMesh {
    fn default() -> Self {
        PullMesh { interface_element: 2.0 }
    }
}

/// Single-shear (pull–push) test of an FRP plate bonded to concrete; see the
/// [module documentation](self). Lengths in mm, moduli in MPa.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrpPull {
    /// Bonded length L (mm).
    pub bond_length: f64,
    /// The plate.
    pub plate: PullPlate,
    /// The concrete prism.
    pub concrete: PullConcrete,
    /// Element size.
    #[serde(default)]
    pub mesh: PullMesh,
    /// Loading and output; `control.max_displacement` is the final loaded-end slip (mm), by
    /// default [`FrpPull::default_slip`].
    #[serde(default)]
    pub control: ControlSettings,
}

/// Monotonic pure-slip response of a law (its bond–slip curve), probed from the virgin state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShearEnvelope {
    /// Largest bond stress (MPa).
    pub peak_stress: f64,
    /// Slip at the largest bond stress (mm).
    pub peak_slip: f64,
    /// Damage at the largest bond stress: points beyond it are softening.
    pub peak_damage: f64,
    /// Slip at which damage reaches the threshold, i.e. the bond is lost (mm).
    pub separation_slip: f64,
}

/// State along the bond at one loaded-end slip ([`FrpPull::profiles`]).
#[derive(Clone, Debug, PartialEq)]
pub struct BondProfile {
    /// Loaded-end slip (mm).
    pub slip: f64,
    /// Load (N).
    pub load: f64,
    /// Node positions from the loaded end (mm).
    pub x: Vec<f64>,
    /// Plate axial strain `N_f/(E_f A_f) = s'/(1 + α)` at the nodes (element values averaged onto
    /// the nodes; the end nodes take their element's value).
    pub plate_strain: Vec<f64>,
    /// Interface slip at the nodes (mm, positive when the plate moves towards the load).
    pub interface_slip: Vec<f64>,
    /// Bond (shear) stress at the nodes (MPa, positive resisting the pull).
    pub bond_stress: Vec<f64>,
    /// Damage at the nodes.
    pub damage: Vec<f64>,
    /// Length with `D ≥ threshold` (mm), as in the record.
    pub debonded_length: f64,
    /// Length past the peak of the bond–slip curve but not debonded (mm):
    /// `peak_damage ≤ D < threshold` ([`ShearEnvelope::peak_damage`]).
    pub softening_length: f64,
}

impl FrpPull {
    /// The paper's plate and concrete in a pull test of bond length `bond_length`: plate
    /// 100 × 0.999 mm with `E_f` from [`FrpBeamSpec::paper`] (200 GPa), concrete f'c = 47 MPa
    /// with `E_c = 4700 √f'c`, a 200 × 200 mm prism (the beam's width, so `b_f/b_c = 0.5` as on the
    /// beam; a square prism of that width), elastic: `α = 0.0155`.
    pub fn paper(bond_length: f64) -> Result<Self> {
        let spec = FrpBeamSpec::paper()?;
        let plate = spec
            .section
            .plate
            .as_ref()
            .ok_or_else(|| CzError::config(OWNER, "the paper's beam specification has no plate"))?;
        let pull = FrpPull {
            bond_length,
            plate: PullPlate {
                width: plate.width,
                thickness: plate.thickness,
                modulus: plate.material.elastic_modulus,
            },
            concrete: PullConcrete {
                width: spec.section.width,
                depth: spec.section.width,
                fc_cylinder: spec.section.concrete.compressive_strength,
                modulus: None,
                rigid: false,
            },
            mesh: PullMesh::default(),
            control: ControlSettings::default(),
        };
        pull.validate()?;
        Ok(pull)
    }

    /// Checks the configuration, naming the first invalid field.
    pub fn validate(&self) -> Result<()> {
        require_positive(OWNER, "bond_length", self.bond_length)?;
        require_positive(OWNER, "plate.width", self.plate.width)?;
        require_positive(OWNER, "plate.thickness", self.plate.thickness)?;
        require_positive(OWNER, "plate.modulus", self.plate.modulus)?;
        require_positive(OWNER, "concrete.width", self.concrete.width)?;
        require_positive(OWNER, "concrete.depth", self.concrete.depth)?;
        require_positive(OWNER, "concrete.fc_cylinder", self.concrete.fc_cylinder)?;
        if let Some(e) = self.concrete.modulus {
            require_positive(OWNER, "concrete.modulus", e)?;
        }
        if self.plate.width > self.concrete.width {
            return Err(CzError::invalid(
                OWNER,
                "plate.width",
                self.plate.width,
                format!("must not exceed the concrete width {} mm", self.concrete.width),
            ));
        }
        require_positive(OWNER, "mesh.interface_element", self.mesh.interface_element)?;
        if self.bond_length / self.mesh.interface_element > MAX_ELEMENTS {
            return Err(CzError::invalid(
                OWNER,
                "mesh.interface_element",
                self.mesh.interface_element,
                format!("gives more than {MAX_ELEMENTS} elements along the {} mm bond", self.bond_length),
            ));
        }
        self.control.validate(OWNER)
    }

    /// Concrete modulus E_c (MPa): the configured one or `4700 √f'c`.
    pub fn concrete_modulus(&self) -> f64 {
        self.concrete.modulus.unwrap_or_else(|| 4700.0 * self.concrete.fc_cylinder.sqrt())
    }

    /// Axial stiffness ratio `α = b_f E_f t_f/(E_c b_c h_c)` (0 for rigid concrete).
    pub fn stiffness_ratio(&self) -> f64 {
        if self.concrete.rigid {
            0.0
        } else {
            self.plate.width * self.plate.modulus * self.plate.thickness
                / (self.concrete_modulus() * self.concrete.width * self.concrete.depth)
        }
    }

    /// The joint as [`BondedJoint`] (closed forms of a rigid substrate, Chen & Teng's `L_e`).
    pub fn joint(&self) -> BondedJoint {
        BondedJoint {
            plate_width: self.plate.width,
            plate_thickness: self.plate.thickness,
            plate_modulus: self.plate.modulus,
            concrete_width: self.concrete.width,
            fc_cylinder: self.concrete.fc_cylinder,
            bond_length: self.bond_length,
        }
    }

    /// The rigid-substrate joint with the same bond equation: plate modulus `E_f/(1 + α)`.
    /// Its [`BondedJoint::strength_for_law`] is the exact peak load of this test for a law (the
    /// plate bar model), and its `long_bond_strength` the long-bond plateau.
    pub fn equivalent_joint(&self) -> BondedJoint {
        BondedJoint { plate_modulus: self.plate.modulus / (1.0 + self.stiffness_ratio()), ..self.joint() }
    }

    /// Long-bond strength `b_f √(2 G_f E_f t_f/(1 + α))` (N) with the law's mode II fracture
    /// energy as `G_f`.
    pub fn long_bond_strength(&self, law: &dyn CohesiveLaw) -> f64 {
        self.equivalent_joint().long_bond_strength(law.fracture_energy()[1].max(0.0))
    }

    /// Loaded-end slip (mm) at which a long bond has debonded over `debonded` mm on its plateau:
    /// `s_sep + P_max a (1 + α)/(b_f E_f t_f)` (the separation slip `s_sep` of the law
    /// ([`shear_envelope`]) at the loaded end plus the stretch of the debonded plate at `P_max`).
    fn plateau_slip(&self, law: &dyn CohesiveLaw, debonded: f64) -> f64 {
        let separation = shear_envelope(law, self.control.damage_threshold).map_or(0.0, |e| e.separation_slip);
        let joint = self.equivalent_joint();
        let stretch = self.long_bond_strength(law) * debonded / (joint.plate_width * joint.plate_stiffness());
        let slip = separation + stretch;
        if slip.is_finite() && slip > 0.0 {
            slip
        } else {
            // A law without fracture energy or finite separation: a plate strain of 1 % along the
            // bond, far beyond any bond failure.
            0.01 * self.bond_length
        }
    }

    /// Default final slip (mm): the loaded-end slip at which the debonded zone of a long bond has
    /// run to within `2 L_e` of the free end (Chen & Teng's `L_e`), still on the plateau (with
    /// Lu's law the load starts to fall with about 1.6–1.9 `L_e` of bond left); the law's
    /// separation slip for bonds shorter than `2 L_e`, where the load has fallen to (nearly)
    /// nothing. The final collapse of a long bond is left out: see [`FrpPull::full_range_slip`].
    pub fn default_slip(&self, law: &dyn CohesiveLaw) -> f64 {
        let debonded = (self.bond_length - 2.0 * self.joint().effective_bond_length()).max(0.0);
        self.plateau_slip(law, debonded)
    }

    /// The loaded-end slip at which a long bond would have debonded completely on its plateau
    /// (mm). A run to it passes the end of the plateau, where the load drops and the slip snaps
    /// back to about the separation slip, and then the complete separation (zero load), held to the
    /// end. Dissipation control follows that snap-back for laws with a finite softening branch
    /// (bilinear); for Lu's law, whose long exponential tail leaves the remaining bond nearly
    /// stress-free, the engine's displacement control can land straight on the separated state
    /// (an equilibrium at any slip beyond `s_u`), skipping the snap-back, and its dissipated energy
    /// past that jump is then not the law's (the final value should be `b_f L G_f`).
    pub fn full_range_slip(&self, law: &dyn CohesiveLaw) -> f64 {
        self.plateau_slip(law, self.bond_length)
    }

    /// Final loaded-end slip of a run (mm): configured, or [`FrpPull::default_slip`].
    pub fn max_slip(&self, law: &dyn CohesiveLaw) -> f64 {
        self.control.max_displacement.unwrap_or_else(|| self.default_slip(law))
    }

    /// Builds the discrete problem: layer 0 is the (fixed) concrete surface, layer 1 the plate as
    /// a bar of axial stiffness `E_f A_f/(1 + α)` whose axial displacement is the slip (see the
    /// [module documentation](self)); node 0 sits at the loaded end.
    pub fn problem(&self) -> Result<FeProblem> {
        self.validate()?;
        let x = graded(&[0.0, self.bond_length], &[self.mesh.interface_element]);
        let nn = x.len();
        let (hc, tf) = (self.concrete.depth, self.plate.thickness);
        let equivalent = self.equivalent_joint();
        // Deflections and rotations are held everywhere, so the shear moduli never act; the beam
        // element still needs positive ones.
        let concrete = Layer {
            section: Section { e: self.concrete_modulus(), g: self.concrete_modulus(), b: self.concrete.width, h: hc },
            y: 0.5 * hc,
            axial: false,
            first: 0,
            last: nn - 1,
        };
        let plate = Layer {
            section: Section { e: equivalent.plate_modulus, g: equivalent.plate_modulus, b: self.plate.width, h: tf },
            y: hc + 0.5 * tf,
            axial: true,
            first: 0,
            last: nn - 1,
        };
        let mesh = Mesh::new(x, vec![concrete, plate], 0)?;
        let mut points = Vec::with_capacity(nn);
        let mut fixed = Vec::with_capacity(4 * nn);
        for i in 0..nn {
            let left = if i > 0 { 0.5 * (mesh.x[i] - mesh.x[i - 1]) } else { 0.0 };
            let right = if i + 1 < nn { 0.5 * (mesh.x[i + 1] - mesh.x[i]) } else { 0.0 };
            points.push(InterfacePoint {
                node: i,
                upper: 1,
                lower: Some(0),
                area: self.plate.width * (left + right),
                factor: 1.0,
                kind: PointKind::Cohesive,
            });
            let (c, p) = (mesh.dofs(0, i), mesh.dofs(1, i));
            fixed.extend([c[1], c[2], p[1], p[2]]);
        }
        let control = mesh.dofs(1, 0)[0];
        let springs = vec![Spring { i: control, j: NONE, k: self.reference_stiffness(), ci: 1.0 }];
        Ok(FeProblem {
            mesh,
            points,
            springs,
            fixed,
            control,
            large_rotation: false,
            contact_stiffness: 0.0,
            contact_friction: 0.0,
        })
    }

    /// Stiffness of the reference spring at the loaded end, `E_f A_f/((1 + α) L)` (N/mm); see the
    /// [module documentation](self).
    pub fn reference_stiffness(&self) -> f64 {
        let joint = self.equivalent_joint();
        joint.plate_width * joint.plate_stiffness() / self.bond_length
    }

    /// Engine rows to the record: the reference spring's force and energy removed, signs turned
    /// so the slip and the load are positive.
    fn to_record(&self, rows: &[StepRow]) -> Record {
        let k = self.reference_stiffness();
        let rows: Vec<StepRow> = rows
            .iter()
            .map(|r| {
                let spring = 0.5 * k * r.control * r.control;
                StepRow {
                    reaction: r.reaction - k * r.control,
                    external_work: r.external_work - spring,
                    elastic_energy: r.elastic_energy - spring,
                    ..*r
                }
            })
            .collect();
        beamtest::to_record(
            &rows,
            &RowScale { displacement: -1.0, compliance: 0.0, load: -1.0, energy: 1.0, readout: Default::default() },
        )
    }

    fn path(&self, law: &dyn CohesiveLaw) -> PathSettings {
        PathSettings {
            target: -self.max_slip(law),
            outputs: self.control.output_points,
            min_step_fraction: 1e-3,
            damage_threshold: self.control.damage_threshold,
            visible_kink: None,
            crack_origin: 0.0,
            newton: self.newton(),
            end_at_separation: false,
        }
    }

    fn newton(&self) -> NewtonSettings {
        NewtonSettings { max_iterations: self.control.max_iterations, tolerance: self.control.tolerance }
    }
}

#[typetag::serde(name = "frp_pull")]
impl ForwardModel for FrpPull {
    fn name(&self) -> &str {
        "frp_pull"
    }

    fn validate(&self) -> Result<()> {
        FrpPull::validate(self)
    }

    fn simulate(&self, law: &dyn CohesiveLaw) -> std::result::Result<Record, SimulationFailure> {
        let fail = |error: CzError| SimulationFailure { error, partial: beamtest::new_record() };
        law.validate().map_err(fail)?;
        let p = self.problem().map_err(fail)?;
        let path = self.path(law);
        match fe::run(&p, law, &path) {
            Ok((rows, _)) => Ok(self.to_record(&rows)),
            Err(f) => Err(SimulationFailure { error: f.error, partial: self.to_record(&f.rows) }),
        }
    }
}

/// Runs `pull` and also returns the engine's statistics (steps, iterations, factorisations).
pub fn simulate_with_stats(pull: &FrpPull, law: &dyn CohesiveLaw) -> Result<(Record, fe::RunStats)> {
    law.validate()?;
    let p = pull.problem()?;
    let (rows, stats) = fe::run(&p, law, &pull.path(law)).map_err(|f| f.error)?;
    Ok((pull.to_record(&rows), stats))
}

/// Bond stress (MPa) of `law` on its monotonic pure-slip curve at slip `slip` (mm): the law
/// evaluated from the virgin state, which for damage laws driven by the largest slip reached (all
/// bundled laws) is the loading envelope. The bond–slip curve to give
/// [`BondedJoint::strength_for_law`].
pub fn envelope_stress(law: &dyn CohesiveLaw, slip: f64) -> f64 {
    law.evaluate(&Gap::new(0.0, slip), &LawState::default()).traction[1]
}

/// Peak and separation of `law`'s bond–slip curve, `threshold` the damage that counts as
/// separated. The separation slip is found by bisection to round-off, so it varies continuously
/// with the law's parameters; the peak by a scan and golden-section refinement.
pub fn shear_envelope(law: &dyn CohesiveLaw, threshold: f64) -> Result<ShearEnvelope> {
    let damage = |s: f64| law.evaluate(&Gap::new(0.0, s), &LawState::default()).state.damage;
    let stress = |s: f64| envelope_stress(law, s);
    let strength = law.strength()[1].abs();
    let energy = law.fracture_energy()[1].abs();
    let mut scale = 2.0 * energy / strength;
    if !(scale.is_finite() && scale > 0.0) {
        scale = 1.0;
    }
    // Bracket the separation: double until damage reaches the threshold or the stress is gone
    // for good (a law whose damage never quite reaches 1).
    let mut hi = scale;
    let mut found = false;
    for _ in 0..60 {
        if damage(hi) >= threshold || (hi > 4.0 * scale && stress(hi).abs() <= 1e-9 * strength) {
            found = true;
            break;
        }
        hi *= 2.0;
    }
    if !found {
        return Err(CzError::Simulation(format!(
            "{OWNER}: the law's bond stress does not vanish in pure slip up to {hi:e} mm"
        )));
    }
    let separated = |s: f64| damage(s) >= threshold || (s > 4.0 * scale && stress(s).abs() <= 1e-9 * strength);
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if separated(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let separation = hi;
    // Peak: scan, then golden-section search around the best sample.
    let samples = 400;
    let at = |i: usize| separation * i as f64 / samples as f64;
    let best = (1..samples).max_by(|&i, &j| stress(at(i)).total_cmp(&stress(at(j)))).unwrap_or(1);
    let (mut a, mut b) = (at(best - 1), at(best + 1));
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..80 {
        let (c, d) = (b - ratio * (b - a), a + ratio * (b - a));
        if stress(c) > stress(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let peak_slip = 0.5 * (a + b);
    Ok(ShearEnvelope {
        peak_stress: stress(peak_slip),
        peak_slip,
        peak_damage: damage(peak_slip),
        separation_slip: separation,
    })
}

impl FrpPull {
    /// The state along the bond at each loaded-end slip of `slips` (increasing, mm).
    ///
    /// The engine's path follower reports global quantities only, so this follows the loading
    /// path itself under displacement control (adaptive steps on the engine's Newton solver,
    /// without the path follower's extrapolating predictor) and reads the plate strain and the
    /// interface state at the requested slips. It reaches every state of the rising branch, of the
    /// softening branch of a short bond and of the debonding plateau of a long one (every point
    /// loads monotonically there, so the state does not depend on the step sequence and equals the
    /// record's at the same slip). A slip past the end of the plateau, where the path turns back
    /// and slip control has no neighbouring state, is an error.
    pub fn profiles(&self, law: &dyn CohesiveLaw, slips: &[f64]) -> Result<Vec<BondProfile>> {
        law.validate()?;
        let p = self.problem()?;
        if let Some(w) = slips.windows(2).find(|w| w[1] < w[0]) {
            return Err(CzError::invalid(OWNER, "profile slips", w[1], "must be increasing"));
        }
        if let Some(&s) = slips.iter().find(|s| !(s.is_finite() && **s >= 0.0)) {
            return Err(CzError::invalid(OWNER, "profile slips", s, "must be finite and non-negative"));
        }
        let threshold = self.control.damage_threshold;
        let envelope = shear_envelope(law, threshold)?;
        let mut nw = Newton::new(&p, law, self.newton());
        let n = p.mesh.n_dofs();
        let np = p.points.len();
        let mut q = vec![0.0; n];
        let mut states = vec![law.initial_state(); np];
        let mut trial = vec![0.0; n];
        let mut reaction = 0.0;
        let mut out = Vec::with_capacity(slips.len());
        // Steps of at most 1 % of the separation slip, cut down to 1e-6 of it before giving up.
        let h_max = 0.01 * envelope.separation_slip;
        let h_min = 1e-6 * envelope.separation_slip;
        let mut pos = 0.0f64;
        let mut h = h_max;
        for &target in slips {
            while pos < target {
                let dh = h.min(target - pos);
                trial.copy_from_slice(&q);
                trial[p.control] = -(pos + dh);
                match nw.solve_displacement(&p, law, &states, &mut trial) {
                    Ok(it) => {
                        q.copy_from_slice(&trial);
                        for (st, ev) in states.iter_mut().zip(&nw.asm.trial) {
                            *st = ev.state;
                        }
                        reaction = nw.f[p.control] - self.reference_stiffness() * q[p.control];
                        pos = if target - (pos + dh) <= 1e-12 * target { target } else { pos + dh };
                        if it <= 4 {
                            h = (2.0 * h).min(h_max);
                        }
                    }
                    Err(e) => {
                        h = 0.5 * dh;
                        if h < h_min {
                            return Err(CzError::Simulation(format!(
                                "{OWNER}: displacement control cannot follow the path past a loaded-end slip of \
                                 {pos:.6} mm towards {target} mm ({e:?}): the state lies beyond a snap-back"
                            )));
                        }
                    }
                }
            }
            out.push(self.profile_at(&p, law, &q, &states, -reaction, pos, &envelope));
        }
        Ok(out)
    }

    #[allow(clippy::too_many_arguments)]
    fn profile_at(
        &self,
        p: &FeProblem,
        law: &dyn CohesiveLaw,
        q: &[f64],
        states: &[LawState],
        load: f64,
        slip: f64,
        envelope: &ShearEnvelope,
    ) -> BondProfile {
        let mesh = &p.mesh;
        let nn = mesh.x.len();
        // The plate layer's axial displacement is minus the slip (see `problem`).
        let interface_slip: Vec<f64> = (0..nn).map(|i| -q[mesh.dofs(1, i)[0]]).collect();
        let to_strain = 1.0 / (1.0 + self.stiffness_ratio());
        let strains: Vec<f64> = (0..nn - 1)
            .map(|i| -to_strain * (interface_slip[i + 1] - interface_slip[i]) / (mesh.x[i + 1] - mesh.x[i]))
            .collect();
        let plate_strain = (0..nn)
            .map(|i| match i {
                0 => strains[0],
                _ if i == nn - 1 => strains[nn - 2],
                _ => 0.5 * (strains[i - 1] + strains[i]),
            })
            .collect();
        // Committed states already hold these slips' history: evaluating them again returns the
        // committed tractions.
        let bond_stress = interface_slip
            .iter()
            .zip(states)
            .map(|(&s, st)| -law.evaluate(&Gap::new(0.0, -s), st).traction[1])
            .collect();
        let damage: Vec<f64> = states.iter().map(|s| s.damage).collect();
        let mut scratch = vec![0.0; nn];
        let debonded = fe::crack::measure(&mesh.x, &damage, self.control.damage_threshold, 0.0, &mut scratch);
        // Length past the peak: the debonded measure at the peak's damage level, minus the debonded.
        let past_peak = if envelope.peak_damage > 0.0 {
            fe::crack::measure(&mesh.x, &damage, envelope.peak_damage, 0.0, &mut scratch).debonded
        } else {
            debonded.debonded + debonded.process_zone
        };
        BondProfile {
            slip,
            load,
            x: mesh.x.clone(),
            plate_strain,
            interface_slip,
            bond_stress,
            damage,
            debonded_length: debonded.debonded,
            softening_length: (past_peak - debonded.debonded).max(0.0),
        }
    }
}
