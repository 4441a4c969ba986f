//! End-notched flexure (ENF, mode II) on the beam/interface engine.
//!
//! Three-point bending of a beam made of two equal layers: supports under the lower layer at
//! `x = 0` and `x = 2L`, the load on the upper layer at mid-span `x = L`. A mid-plane crack runs
//! from the left support to `x = a0`; beyond it the layers are joined by the cohesive law. On the
//! cracked faces a normal contact penalty keeps the arms from interpenetrating (the arms press on
//! each other there); its stiffness defaults to the law's normal penalty. The contact is
//! frictionless unless `effects.crack_face_friction` sets a Coulomb coefficient
//! ([`crate::fe::interface::frictional_contact`]). The
//! applied displacement is the load-point deflection (positive downwards) and the load the
//! force at the loading nose.
//!
//! ENF specimens with `a0 / L < 0.7` propagate unstably under displacement control: the path
//! follower then switches to dissipation control and records the snap-back.

use czid_core::{CohesiveLaw, CzError, ForwardModel, Record, Result, SimulationFailure};
use serde::{Deserialize, Serialize};

use crate::beamtest::{self, ControlSettings, Material, MeshSettings, RowScale};
use crate::effects::Effects;
use crate::fe::mesh::graded;
use crate::fe::{self, FeProblem, Layer, Mesh, PathSettings, Section};

/// ENF configuration. All lengths in mm, moduli in MPa.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Enf {
    /// Initial crack length from the left support to the crack front (mm).
    pub a0: f64,
    /// Half-span L between a support and the loading nose (mm).
    pub half_span: f64,
    /// Width b (mm).
    pub width: f64,
    /// Thickness of each arm h (mm) (the beam is 2h thick).
    pub h: f64,
    /// Adherend constants.
    pub material: Material,
    /// Normal penalty of the contact on the cracked faces (MPa/mm); `None`: the law's normal
    /// initial stiffness.
    #[serde(default)]
    pub contact_stiffness: Option<f64>,
    /// Element sizes (`interface_element` from the crack front to the loading nose, where the
    /// crack runs, and for two arm thicknesses past the nose; `arm_element` elsewhere).
    #[serde(default)]
    pub mesh: MeshSettings,
    /// Loading and output; `control.max_displacement` is the final load-point deflection (mm),
    /// by default twice the beam-theory deflection at the onset of propagation.
    #[serde(default)]
    pub control: ControlSettings,
    /// Optional physics (all off by default; `large_rotation` is not supported for ENF).
    #[serde(default)]
    pub effects: Effects,
}

const OWNER: &str = "model enf";

/// The engine's choices for ENF runs: segment integration of the interface and records on the
/// output grid (and along snap-backs); the whole mesh is solved: the window holds the cracked faces
/// open, and an ENF's press on each other (the book's *Mixed mode → Speed* says why a window that
/// carries the contact does not pay on this specimen).
const RUN: fe::RunOptions = fe::RunOptions::segments();

impl Enf {
    /// Hartlen's ENF-03 specimen (h = 2.7 mm per arm, b = 25, L = 50, a0 = 34.7 mm; E_L = 19.3,
    /// E_T = 6.11, G_LT = 2.288 GPa).
    pub fn hartlen_enf03() -> Self {
        Enf {
            a0: 34.7,
            half_span: 50.0,
            width: 25.0,
            h: 2.7,
            material: Material { e11: 19_300.0, e22: 6_110.0, g13: 2_288.0, nu13: 0.0, plane: Default::default() },
            contact_stiffness: None,
            mesh: MeshSettings { interface_element: 0.2, arm_element: 1.0, ..Default::default() },
            control: ControlSettings::default(),
            effects: Effects::default(),
        }
    }

    /// ENF-03 as `examples/hartlen-enf/enf03.toml` runs it (0.25 mm interface elements of one
    /// beam element each, to 5.58 mm), at the flexural modulus and the bilinear law that file
    /// identifies (σ_t 28.809 MPa, G_IIc 3.3386 N/mm, E11 34 106 MPa): the mode II run the speed
    /// figures of the book's *Mixed mode* chapter and `benches/forward.rs` are measured on.
    pub fn hartlen_enf03_identified() -> (Self, crate::laws::Bilinear) {
        let mut enf = Enf::hartlen_enf03();
        enf.mesh.interface_element = 0.25;
        enf.mesh.interface_subdivision = 1;
        enf.material.e11 = 34_106.0;
        enf.control.max_displacement = Some(5.58);
        let law = crate::laws::Bilinear::bk(1e5, 30.0, 28.809, 0.8, 3.3386, 2.0).expect("a valid law");
        (enf, law)
    }

    /// Checks the configuration, naming the first invalid field.
    pub fn validate(&self) -> Result<()> {
        beamtest::positive(OWNER, "a0", self.a0)?;
        beamtest::positive(OWNER, "half_span", self.half_span)?;
        beamtest::positive(OWNER, "width", self.width)?;
        beamtest::positive(OWNER, "h", self.h)?;
        if let Some(k) = self.contact_stiffness {
            beamtest::positive(OWNER, "contact_stiffness", k)?;
        }
        self.material.validate(OWNER)?;
        self.mesh.validate(OWNER)?;
        self.control.validate(OWNER)?;
        self.effects.validate(OWNER)?;
        beamtest::check_split_beam(OWNER, "ENF", &self.effects, self.a0, self.half_span)
    }

    /// Crack length the mesh uses: `a0 + effects.crack_length_offset` (mm).
    pub fn effective_crack_length(&self) -> f64 {
        self.a0 + self.effects.crack_length_offset
    }

    fn section(&self) -> Section {
        Section {
            e: self.material.axial_modulus(),
            g: self.effects.shear_modulus(self.material.g13),
            b: self.width,
            h: self.h,
        }
    }

    /// Beam-theory compliance with shear, `C = (3a³ + 2L³)/(8 E b h³) + 3L/(10 G13 b h)` (mm/N).
    pub fn beam_compliance(&self, a: f64) -> f64 {
        let g = self.effects.shear_modulus(self.material.g13);
        let (e, b, h, l) = (self.material.axial_modulus(), self.width, self.h, self.half_span);
        (3.0 * a.powi(3) + 2.0 * l.powi(3)) / (8.0 * e * b * h.powi(3)) + 3.0 * l / (10.0 * g * b * h)
    }

    /// Final deflection: configured, or twice the beam-theory deflection at which the crack
    /// starts, `P_c = (4b/(3a)) √(E h³ G_IIc)`.
    pub fn max_deflection(&self, law: &dyn CohesiveLaw) -> f64 {
        if let Some(d) = self.control.max_displacement {
            return d;
        }
        let a = self.effective_crack_length();
        let e = self.material.axial_modulus();
        let pc = 4.0 * self.width / (3.0 * a) * (e * self.h.powi(3) * law.fracture_energy()[1].max(1e-12)).sqrt();
        2.0 * self.beam_compliance(a) * pc
    }

    /// Builds the discrete problem (built per run, like the DCB's).
    pub fn problem(&self, law: &dyn CohesiveLaw) -> Result<(FeProblem, RowScale)> {
        self.validate()?;
        let fx = &self.effects;
        let a = self.effective_crack_length();
        let l = self.half_span;
        let (fine, coarse) = (self.mesh.crack_element(), self.mesh.arm_element);
        let outer = coarse.min(4.0 * self.mesh.interface_element);
        // Under the loading nose the interface carries the load's local stresses, which decay over
        // about a millimetre (the arm on its elastic interface). Two arm thicknesses past the nose
        // keep interface elements: a point reaching its strength there must not be one of the
        // arms' coarse ones, at which Newton cycles and the path creeps.
        let past = l + 2.0 * self.h;
        let x = if past + outer < 2.0 * l {
            graded(&[0.0, a, l, past, 2.0 * l], &[outer, fine, self.mesh.interface_element.min(outer), outer])
        } else {
            graded(&[0.0, a, l, 2.0 * l], &[outer, fine, outer])
        };
        let nn = x.len();
        let tip = x.iter().position(|&v| (v - a).abs() <= 1e-9 * l).unwrap_or(0);
        let mid = x.iter().position(|&v| (v - l).abs() <= 1e-9 * l).unwrap_or(nn / 2);
        let s = self.section();
        let lo = Layer { section: s, y: 0.5 * self.h, axial: true, first: 0, last: nn - 1 };
        let up = Layer { section: s, y: 1.5 * self.h, axial: true, first: 0, last: nn - 1 };
        let mesh = Mesh::new(x, vec![lo, up], crate::measurement::extra_unknowns(fx.machine_compliance, false))?;
        let points = beamtest::cracked_arms_interface(&mesh, tip, nn - 1, self.width);
        let mut springs = Vec::new();
        let fixed = vec![mesh.dofs(0, 0)[1], mesh.dofs(0, nn - 1)[1], mesh.dofs(0, nn - 1)[0]];
        let w_load = mesh.dofs(1, mid)[1];
        // The load nose pushes the upper arm down: recorded deflection and load are positive.
        let load_point =
            crate::measurement::LoadPoint { dof: w_load, per_unit: -1.0, share: 1.0, at_first_node: false };
        let (control, scale) =
            crate::measurement::recorded_control(fx.machine_compliance, fx.readout(), load_point, &mut springs);
        let contact_stiffness = self.contact_stiffness.unwrap_or(law.initial_stiffness()[0]);
        let contact_friction = fx.crack_face_friction;
        let p = FeProblem {
            mesh,
            points,
            springs,
            fixed,
            control,
            large_rotation: false,
            contact_stiffness,
            contact_friction,
        };
        Ok((p, scale))
    }

    pub(crate) fn path(&self, law: &dyn CohesiveLaw, scale: &RowScale) -> PathSettings {
        self.control
            .path(self.max_deflection(law) / scale.displacement, self.effective_crack_length())
            .with_visible_front(law, 1)
    }
}

#[typetag::serde(name = "enf")]
impl ForwardModel for Enf {
    fn name(&self) -> &str {
        "enf"
    }

    fn validate(&self) -> Result<()> {
        Enf::validate(self)
    }

    /// The ENF rule: the first peak, the unstable jump, the rise with the crack at the nose.
    fn regimes(&self) -> &'static dyn czid_core::RegimeRule {
        &crate::enf_regimes::EnfRegimes
    }

    fn effects(&self) -> Vec<czid_core::EffectDeclaration> {
        // The ENF model has no large-rotation option (it refuses `effects.large_rotation`); its
        // cracked faces touch, so friction on them is a candidate.
        crate::effects::Effects::declarations_with_contact()
    }

    /// The continuum ENF of the same specimen ([`crate::enf_2d::Enf2d::from_beam`]).
    fn reference(&self) -> Option<Box<dyn ForwardModel>> {
        crate::enf_2d::Enf2d::from_beam(self).ok().map(|m| Box::new(m) as Box<dyn ForwardModel>)
    }

    fn simulate(&self, law: &dyn CohesiveLaw) -> std::result::Result<Record, SimulationFailure> {
        let fail = |error: CzError| SimulationFailure { error, partial: beamtest::new_record() };
        law.validate().map_err(fail)?;
        let (p, scale) = self.problem(law).map_err(fail)?;
        let series = self.effects.interface_law(law).map_err(fail)?;
        let law = series.as_ref().map_or(law, |s| s as &dyn CohesiveLaw);
        let path = self.path(law, &scale);
        beamtest::run(&p, law, &path, &RUN, &scale).map(|(record, _)| record)
    }
}

/// Runs `enf` and also returns the engine's statistics.
pub fn simulate_with_stats(enf: &Enf, law: &dyn CohesiveLaw) -> Result<(Record, fe::RunStats)> {
    law.validate()?;
    let (p, scale) = enf.problem(law)?;
    let series = enf.effects.interface_law(law)?;
    let law = series.as_ref().map_or(law, |s| s as &dyn CohesiveLaw);
    let path = enf.path(law, &scale);
    beamtest::run(&p, law, &path, &RUN, &scale).map_err(|f| f.error)
}
