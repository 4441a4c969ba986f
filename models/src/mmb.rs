//! Mixed-mode bending (MMB, ASTM D6671) on the beam/interface engine.
//!
//! A beam of two equal layers rests on supports under the lower layer at `x = 0` (the cracked
//! end, a hinge) and `x = 2L`. A lever loads it: hinged to the upper layer at `x = 0`, it bears on
//! the upper layer at mid-span `x = L` (the saddle) and is pushed down at `x = L + c`, a lever
//! length `c` beyond the saddle. By the lever's equilibrium the upper layer is pulled up at the
//! hinge by `P c/L` and pushed down at the saddle by `P (c + L)/L`: the superposition of a DCB
//! opening load `P_I = P (3c − L)/(4L)` and an ENF load `P_II = P (c + L)/L` (Reeder & Crews), so
//! the lever length sets the mode ratio, from pure mode II at `c = L/3` towards mode I as `c`
//! grows. A mid-plane crack runs from `x = 0` to `a0`; the cracked faces carry contact, frictionless
//! unless `effects.crack_face_friction` is set (as in [`crate::enf`]; here the ends do not press on
//! each other for any lever length, see `effects()`), the rest the cohesive law. The applied displacement is the lever's
//! load-point displacement (positive downwards) and the load the force `P` on the lever.
//!
//! **The lever in the mesh.** The lever couples the hinge and the saddle, nodes far apart, which
//! no band matrix holds, and a beam layer standing in for it would have to share the arms' 0.025 mm
//! elements, whose forces then cancel to the load with round-off above any useful tolerance (a
//! rigid beam's element stiffness grows as the inverse cube of the element length). A rigid lever
//! is two numbers, though: its deflection `t` at the hinge and `u` at its load point. A third layer
//! of the grid, from the hinge to the saddle, carries them from node to node (its two unknowns per
//! node, with no stiffness of its own) through stiff springs; a spring ties `t` to the upper arm at
//! the hinge, another ties the lever's deflection at the saddle, `(c t + L u)/(L + c)`, to the upper
//! arm there, and `u` at the saddle is the control unknown. The springs are statically determinate
//! (their forces follow from `P` alone), so their compliance `C_lever`
//! ([`Mmb::lever_compliance`]) is removed exactly from the recorded displacement and their energy
//! `½ C_lever P²` from the recorded energies: the record is that of a rigid lever. The lever's
//! weight (which ASTM D6671 corrects for) is not modelled: the recorded load is the applied force.

use czid_core::{CohesiveLaw, ForwardModel, Record, Result, SimulationFailure};
use serde::{Deserialize, Serialize};

use crate::beamtest::{self, ControlSettings, Material, MeshSettings, RowScale};
use crate::effects::Effects;
use crate::fe::mesh::graded;
use crate::fe::{self, FeProblem, Layer, Mesh, PathSettings, Section, Spring, StepRow};

/// MMB configuration. All lengths in mm, moduli in MPa.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mmb {
    /// Initial crack length from the hinge end (`x = 0`) to the crack front (mm).
    pub a0: f64,
    /// Half-span L between a support and the saddle (mm).
    pub half_span: f64,
    /// Lever length c from the saddle to the lever's load point (mm). The mode ratio of beam
    /// theory is `G_II/G = 1 / (1 + (4/3) ((3c − L)/(c + L))²)` ([`Mmb::beam_mode_ratio`]).
    pub lever: f64,
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
    /// Element sizes (`interface_element` from the crack front to the saddle, where the crack
    /// runs; `arm_element` elsewhere).
    #[serde(default)]
    pub mesh: MeshSettings,
    /// Loading and output; `control.max_displacement` is the final lever load-point displacement
    /// (mm), by default the one [`Mmb::max_displacement`] chooses from beam theory.
    #[serde(default)]
    pub control: ControlSettings,
    /// Optional physics (all off by default; `large_rotation` is not supported for MMB).
    #[serde(default)]
    pub effects: Effects,
}

const OWNER: &str = "model mmb";

/// What a run of the engine gives: the specimen's rows and the statistics, or the failure with
/// the rows that converged.
pub type EngineRun = std::result::Result<(Vec<StepRow>, fe::RunStats), fe::PathFailure>;

/// Segment integration, records on the output grid, solved on the window around the crack front
/// (`fe::window`: the saddle's control ahead of the front, the open cracked faces behind it); a run
/// the window cannot take (faces that close) is solved on the whole mesh, and one it gives up part
/// way (a path that turns back) goes on there.
const RUN: fe::RunOptions = fe::RunOptions { window: true, ..fe::RunOptions::segments() };

/// Stiffness of the lever's ties relative to the specimen's beam-theory stiffness: their
/// compliance, removed exactly from the record, is then about 1 % of the specimen's, and the
/// round-off of their forces stays far below the residual tolerance.
const TIE_STIFFNESS: f64 = 1e3;

impl Mmb {
    /// An MMB of Hartlen's laminate and ENF geometry (h = 2.7 mm per arm, b = 25, L = 50,
    /// a0 = 34.7 mm; E_L = 19.3, E_T = 6.11, G_LT = 2.288 GPa) with a lever of length `c` (mm).
    pub fn hartlen(lever: f64) -> Self {
        let enf = crate::enf::Enf::hartlen_enf03();
        Mmb {
            a0: enf.a0,
            half_span: enf.half_span,
            lever,
            width: enf.width,
            h: enf.h,
            material: enf.material,
            contact_stiffness: None,
            mesh: enf.mesh,
            control: ControlSettings::default(),
            effects: Effects::default(),
        }
    }

    /// The MMB the book's *Mixed mode* speed figures and `benches/forward.rs` are measured on:
    /// [`Mmb::hartlen`] with a 43.722 mm lever (G_II/G = 0.5) to 7 mm, and a bilinear law of
    /// σ_n 25, σ_t 35 MPa, G_Ic 0.8, G_IIc 3 N/mm, η 2.2.
    pub fn hartlen_half_mode_two() -> (Self, crate::laws::Bilinear) {
        let mut mmb = Mmb::hartlen(43.722);
        mmb.control.max_displacement = Some(7.0);
        let law = crate::laws::Bilinear::bk(1e5, 25.0, 35.0, 0.8, 3.0, 2.2).expect("a valid law");
        (mmb, law)
    }

    /// The lever length that gives the mode ratio `G_II/G = psi` by beam theory (inverse of
    /// [`Mmb::beam_mode_ratio`], `0 < psi ≤ 1`; `psi = 1` gives `c = L/3`).
    pub fn lever_for_mode_ratio(half_span: f64, psi: f64) -> f64 {
        // (3c − L)/(c + L) = r with r = √(3 (1 − ψ)/(4 ψ)).
        let r = (0.75 * (1.0 - psi) / psi).sqrt();
        half_span * (1.0 + r) / (3.0 - r)
    }

    /// Checks the configuration, naming the first invalid field.
    pub fn validate(&self) -> Result<()> {
        beamtest::positive(OWNER, "a0", self.a0)?;
        beamtest::positive(OWNER, "half_span", self.half_span)?;
        beamtest::positive(OWNER, "lever", self.lever)?;
        beamtest::positive(OWNER, "width", self.width)?;
        beamtest::positive(OWNER, "h", self.h)?;
        if let Some(k) = self.contact_stiffness {
            beamtest::positive(OWNER, "contact_stiffness", k)?;
        }
        self.material.validate(OWNER)?;
        self.mesh.validate(OWNER)?;
        self.control.validate(OWNER)?;
        self.effects.validate(OWNER)?;
        beamtest::check_split_beam(OWNER, "MMB", &self.effects, self.a0, self.half_span)
    }

    /// Crack length the mesh uses: `a0 + effects.crack_length_offset` (mm).
    pub fn effective_crack_length(&self) -> f64 {
        self.a0 + self.effects.crack_length_offset
    }

    /// Opening load per unit lever load, `P_I/P = (3c − L)/(4L)`, and shear load per unit lever
    /// load, `P_II/P = (c + L)/L`.
    pub fn load_split(&self) -> (f64, f64) {
        let (c, l) = (self.lever, self.half_span);
        ((3.0 * c - l) / (4.0 * l), (c + l) / l)
    }

    /// Mode ratio `G_II/G` of beam theory (Euler–Bernoulli arms clamped at the crack front):
    /// `G_I = 12 P_I² a²/(E b² h³)`, `G_II = 9 P_II² a²/(16 E b² h³)`.
    pub fn beam_mode_ratio(&self) -> f64 {
        let (pi, pii) = self.load_split();
        let (gi, gii) = (12.0 * pi * pi, 9.0 / 16.0 * pii * pii);
        gii / (gi + gii)
    }

    /// Beam-theory compliance of the lever load point with the arms' shear (mm/N):
    /// `C = (P_I/P)² C_DCB + (P_II/P)² C_ENF`, `C_DCB = 8a³/(E b h³) + 12a/(5 G13 b h)` (opening of
    /// two clamped Timoshenko arms), `C_ENF = (3a³ + 2L³)/(8 E b h³) + 3L/(10 G13 b h)`.
    pub fn beam_compliance(&self, a: f64) -> f64 {
        let g = self.effects.shear_modulus(self.material.g13);
        let (e, b, h) = (self.material.axial_modulus(), self.width, self.h);
        let c_dcb = 8.0 * a.powi(3) / (e * b * h.powi(3)) + 12.0 * a / (5.0 * g * b * h);
        let (pi, pii) = self.load_split();
        pi * pi * c_dcb + pii * pii * self.enf_part().beam_compliance(a)
    }

    /// The ENF the lever's shear part loads: the same specimen and crack without the lever.
    fn enf_part(&self) -> crate::enf::Enf {
        crate::enf::Enf {
            a0: self.a0,
            half_span: self.half_span,
            width: self.width,
            h: self.h,
            material: self.material.clone(),
            contact_stiffness: self.contact_stiffness,
            mesh: self.mesh.clone(),
            control: self.control.clone(),
            effects: self.effects.clone(),
        }
    }

    /// Final displacement: configured, or 1.1 times the larger beam-theory displacement on the
    /// propagation branch ([`Mmb::branch_displacement`]) at the initial crack and with the crack
    /// three quarters of the way to the saddle (a test is stopped before the crack reaches the
    /// saddle, where the loads no longer split as the lever ratio says).
    pub fn max_displacement(&self, law: &dyn CohesiveLaw) -> f64 {
        match self.control.max_displacement {
            Some(d) => d,
            None => {
                let a = self.effective_crack_length();
                let end = a + 0.75 * (self.half_span - a);
                1.1 * self.branch_displacement(law, a).max(self.branch_displacement(law, end))
            }
        }
    }

    /// Beam-theory lever load-point displacement (mm) at which a crack of length `a` (mm)
    /// propagates: `C(a) P_c(a)`.
    pub fn branch_displacement(&self, law: &dyn CohesiveLaw, a: f64) -> f64 {
        self.beam_compliance(a) * self.onset_load_at(law, a)
    }

    /// Beam-theory lever load at which the crack starts (N): `P_c = √(G_c / g)` with `G = g P²`
    /// and `G_c` interpolated linearly in the mode ratio between the law's `G_Ic` and `G_IIc`.
    pub fn onset_load(&self, law: &dyn CohesiveLaw) -> f64 {
        self.onset_load_at(law, self.effective_crack_length())
    }

    /// [`Mmb::onset_load`] for a crack of length `a` (mm).
    fn onset_load_at(&self, law: &dyn CohesiveLaw, a: f64) -> f64 {
        let (e, b, h) = (self.material.axial_modulus(), self.width, self.h);
        let (pi, pii) = self.load_split();
        let g_per_p2 = a * a / (e * b * b * h.powi(3)) * (12.0 * pi * pi + 9.0 / 16.0 * pii * pii);
        let [gi, gii] = law.fracture_energy();
        let psi = self.beam_mode_ratio();
        let gc = (gi + (gii - gi) * psi).max(1e-12);
        (gc / g_per_p2).sqrt()
    }

    fn arm_section(&self) -> Section {
        Section {
            e: self.material.axial_modulus(),
            g: self.effects.shear_modulus(self.material.g13),
            b: self.width,
            h: self.h,
        }
    }

    /// Stiffness of each of the two ties between the lever and the upper arm (N/mm), and of
    /// each spring carrying the lever's hinge deflection from one node to the next between the
    /// hinge and the saddle (`nodes` such springs in series: as compliant as a tie together).
    fn tie_stiffness(&self, nodes: usize) -> (f64, f64) {
        let k = TIE_STIFFNESS / self.beam_compliance(self.effective_crack_length());
        (k, k * nodes as f64)
    }

    /// Compliance the lever's springs add at its load point (mm/N), with `nodes` carrying
    /// springs between the hinge and the saddle: by Castigliano's theorem from their forces, the
    /// hinge tie and the carrying springs `P c/L`, the saddle tie `P (c + L)/L`.
    fn tie_compliance(&self, nodes: usize) -> f64 {
        let (k, kr) = self.tie_stiffness(nodes);
        let (c, l) = (self.lever, self.half_span);
        (c / l).powi(2) * (1.0 / k + nodes as f64 / kr) + ((c + l) / l).powi(2) / k
    }

    /// Compliance of the lever's springs at its load point (mm/N) in the mesh this model builds
    /// (removed from the record).
    pub fn lever_compliance(&self) -> f64 {
        self.tie_compliance(self.saddle_node())
    }

    /// The grid: break points at the hinge, the crack front, the saddle and the far support.
    fn grid(&self) -> Vec<f64> {
        let (a, l) = (self.effective_crack_length(), self.half_span);
        let (fine, coarse) = (self.mesh.crack_element(), self.mesh.arm_element);
        let outer = coarse.min(4.0 * self.mesh.interface_element);
        graded(&[0.0, a, l, 2.0 * l], &[outer, fine, outer])
    }

    fn saddle_node(&self) -> usize {
        let l = self.half_span;
        self.grid().iter().position(|&xi| (xi - l).abs() <= 1e-9 * l).unwrap_or(0)
    }

    /// Builds the discrete problem and the scaling of its rows (built per run, like the DCB's).
    pub fn problem(&self, law: &dyn CohesiveLaw) -> Result<(FeProblem, RowScale)> {
        self.build(law).map(|(p, scale, _)| (p, scale))
    }

    /// [`Mmb::problem`] and the compliance of the lever's springs in it (mm/N).
    pub(crate) fn build(&self, law: &dyn CohesiveLaw) -> Result<(FeProblem, RowScale, f64)> {
        self.validate()?;
        let fx = &self.effects;
        let (a, l, c) = (self.effective_crack_length(), self.half_span, self.lever);
        let x = self.grid();
        let at = |v: f64| x.iter().position(|&xi| (xi - v).abs() <= 1e-9 * l).unwrap_or(0);
        let (tip, mid, end) = (at(a), at(l), at(2.0 * l));
        let s = self.arm_section();
        let lo = Layer { section: s, y: 0.5 * self.h, axial: true, first: 0, last: end };
        let up = Layer { section: s, y: 1.5 * self.h, axial: true, first: 0, last: end };
        // The lever's carrier: no stiffness of its own; at every node its "deflection" unknown is
        // the lever's deflection t at the hinge and its "rotation" unknown the deflection u of the
        // lever's load point.
        let none = Section { e: 0.0, g: 0.0, b: s.b, h: s.h };
        let lever = Layer { section: none, y: 3.0 * self.h, axial: false, first: 0, last: mid };
        let mesh = Mesh::new(x, vec![lo, up, lever], crate::measurement::extra_unknowns(fx.machine_compliance, false))?;
        let points = beamtest::cracked_arms_interface(&mesh, tip, end, self.width);
        let mut springs = Vec::new();
        let (k, kr) = self.tie_stiffness(mid);
        let t = |node: usize| mesh.dofs(2, node)[1];
        let u = |node: usize| mesh.dofs(2, node)[2];
        for node in 0..mid {
            springs.push(Spring { i: t(node), j: t(node + 1), k: kr, ci: 1.0 });
        }
        springs.push(Spring { i: t(0), j: mesh.dofs(1, 0)[1], k, ci: 1.0 });
        // The saddle tie, ½ k (α t + β u − w)² with α = c/(L + c), β = L/(L + c), assembled
        // exactly from two-point springs: ½ kα (t − w)² + ½ kβ (u − w)² − ½ kαβ (t − u)².
        let (alpha, beta) = (c / (l + c), l / (l + c));
        let w_saddle = mesh.dofs(1, mid)[1];
        springs.push(Spring { i: t(mid), j: w_saddle, k: k * alpha, ci: 1.0 });
        springs.push(Spring { i: u(mid), j: w_saddle, k: k * beta, ci: 1.0 });
        springs.push(Spring { i: t(mid), j: u(mid), k: -k * alpha * beta, ci: 1.0 });
        let mut fixed = vec![mesh.dofs(0, 0)[1], mesh.dofs(0, end)[1], mesh.dofs(0, end)[0]];
        // The load point's deflection is only needed at the saddle.
        fixed.extend((0..mid).map(u));
        // The lever's load point is pushed down: recorded displacement and load are positive.
        let load_point =
            crate::measurement::LoadPoint { dof: u(mid), per_unit: -1.0, share: 1.0, at_first_node: false };
        let (control, mut scale) =
            crate::measurement::recorded_control(fx.machine_compliance, fx.readout(), load_point, &mut springs);
        let lever_compliance = self.tie_compliance(mid);
        scale.compliance -= lever_compliance;
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
        Ok((p, scale, lever_compliance))
    }

    /// The path in the control unknown, which also moves with the lever's own compliance: to
    /// record the specimen up to `max_displacement` it runs further by `C_lever P_c` (`P_c` the
    /// beam-theory onset load), so the record ends at, or a little beyond, `max_displacement`.
    pub(crate) fn path(&self, law: &dyn CohesiveLaw, scale: &RowScale, lever_compliance: f64) -> PathSettings {
        let a = self.effective_crack_length();
        let lever = lever_compliance * self.onset_load(law);
        // Mixed mode: the segment rule places the visible front at the law's kink whatever the
        // mode; the opening's damage level serves only measures by damage alone.
        self.control.path((self.max_displacement(law) + lever) / scale.displacement, a).with_visible_front(law, 0)
    }

    /// Engine rows with the lever's stored energy `½ C_lever P²` taken out of the external work and
    /// the elastic energy (the specimen's energies).
    fn specimen_rows(rows: &[StepRow], cl: f64) -> Vec<StepRow> {
        rows.iter()
            .map(|r| {
                let lever = 0.5 * cl * r.reaction * r.reaction;
                StepRow { external_work: r.external_work - lever, elastic_energy: r.elastic_energy - lever, ..*r }
            })
            .collect()
    }

    /// Runs the model as [`ForwardModel::simulate`] does and returns the engine's rows (the
    /// specimen's energies, the control unknown being the lever's load point in the mesh's sign
    /// convention) and statistics.
    pub fn run_rows(&self, law: &dyn CohesiveLaw) -> EngineRun {
        self.run(law, &RUN).1
    }

    /// [`Mmb::run_rows`] on the whole mesh, whose rows also carry the interface's work by mode
    /// ([`StepRow::shear_work`]; the window does not count it): for checks of the mode partition.
    /// Its states are the window's to the Newton tolerance.
    pub fn run_rows_whole_mesh(&self, law: &dyn CohesiveLaw) -> EngineRun {
        self.run(law, &fe::RunOptions { window: false, ..RUN }).1
    }

    /// Builds the problem once and runs it: the scaling of its rows (`None` when the problem could
    /// not be built), and the specimen's rows and statistics, or on failure its converged rows.
    fn run(&self, law: &dyn CohesiveLaw, options: &fe::RunOptions) -> (Option<RowScale>, EngineRun) {
        let built =
            law.validate().and_then(|_| self.build(law)).and_then(|b| Ok((b, self.effects.interface_law(law)?)));
        let ((p, scale, cl), series) = match built {
            Ok(b) => b,
            Err(error) => return (None, Err(fe::PathFailure { error, rows: Vec::new() })),
        };
        let law = series.as_ref().map_or(law, |s| s as &dyn CohesiveLaw);
        let path = self.path(law, &scale, cl);
        let run = match fe::run_with(&p, law, &path, options) {
            Ok((rows, stats)) => Ok((Self::specimen_rows(&rows, cl), stats)),
            Err(f) => Err(fe::PathFailure { error: f.error, rows: Self::specimen_rows(&f.rows, cl) }),
        };
        (Some(scale), run)
    }
}

#[typetag::serde(name = "mmb")]
impl ForwardModel for Mmb {
    fn name(&self) -> &str {
        "mmb"
    }

    fn validate(&self) -> Result<()> {
        Mmb::validate(self)
    }

    fn effects(&self) -> Vec<czid_core::EffectDeclaration> {
        // No large-rotation option (the model refuses `effects.large_rotation`). Friction on the
        // cracked faces is honoured but not declared: the lever's hinge pulls the cracked ends
        // apart by at least what the ENF part of the load presses them with (beam theory: they
        // press with P (L − 3c)/(4L) ≤ 0 for c ≥ L/3), so it has nothing to act on.
        crate::effects::Effects::declarations(false)
    }

    fn simulate(&self, law: &dyn CohesiveLaw) -> std::result::Result<Record, SimulationFailure> {
        let (scale, run) = self.run(law, &RUN);
        // Without a built problem there are no rows: the record is empty either way.
        let record =
            |rows: &[StepRow]| scale.as_ref().map_or_else(beamtest::new_record, |s| beamtest::to_record(rows, s));
        match run {
            Ok((rows, _)) => Ok(record(&rows)),
            Err(f) => Err(SimulationFailure { partial: record(&f.rows), error: f.error }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `m` at `law` on the whole mesh and with the window asked for: rows and statistics of each.
    fn both_runs(m: &Mmb, law: &dyn CohesiveLaw) -> (EngineOk, EngineOk) {
        let (p, scale, cl) = m.build(law).unwrap();
        let path = m.path(law, &scale, cl);
        let run = |window: bool| fe::run_with(&p, law, &path, &fe::RunOptions { window, ..RUN }).unwrap();
        (run(false), run(true))
    }

    type EngineOk = (Vec<StepRow>, fe::RunStats);

    /// The largest load difference between two records of the same outputs, of the first's peak.
    fn load_difference(a: &[StepRow], b: &[StepRow]) -> f64 {
        let peak = a.iter().map(|r| r.reaction.abs()).fold(0.0, f64::max);
        a.iter().zip(b).map(|(x, y)| (x.reaction - y.reaction).abs() / peak).fold(0.0, f64::max)
    }

    /// The window around the crack front against the whole mesh on the same problem and path:
    /// the condensed regions are exact, so the two differ by the Newton tolerance only. Three
    /// mode ratios (G_II/G = 0.2, 0.5 and 0.8 by beam theory), the saddle ahead of the front.
    #[test]
    fn the_windowed_run_is_the_whole_mesh_run() {
        for psi in [0.2, 0.5, 0.8] {
            let (mut m, law) = Mmb::hartlen_half_mode_two();
            m.lever = Mmb::lever_for_mode_ratio(m.half_span, psi);
            m.control.max_displacement = None;
            let ((whole, sw), (win, sv)) = both_runs(&m, &law);
            println!("G_II/G {psi}: whole mesh {sw:?}\n           window     {sv:?}");
            assert!(sv.windowed && !sw.windowed, "{sv:?}");
            assert_eq!(whole.len(), win.len());
            let peak = whole.iter().map(|r| r.reaction.abs()).fold(0.0, f64::max);
            let work = whole.last().unwrap().external_work;
            let mut worst = [0.0f64; 4];
            let end = whole.last().unwrap().control.abs();
            for (a, b) in whole.iter().zip(&win) {
                // The same output grid, reached through other cuts (sums of other increments).
                assert!((a.control - b.control).abs() <= 1e-12 * end, "{} against {}", a.control, b.control);
                worst[0] = worst[0].max((a.reaction - b.reaction).abs() / peak);
                worst[1] = worst[1].max((a.elastic_energy - b.elastic_energy).abs() / work);
                worst[2] = worst[2].max((a.dissipated_energy - b.dissipated_energy).abs() / work);
                worst[3] = worst[3].max((a.crack.debonded - b.crack.debonded).abs());
            }
            let balance = |rows: &[StepRow]| {
                rows.iter()
                    .map(|r| (r.external_work - r.elastic_energy - r.dissipated_energy).abs() / work)
                    .fold(0.0, f64::max)
            };
            println!(
                "           energy balance: whole mesh {:.1e}, window {:.1e} (of W)",
                balance(&whole),
                balance(&win)
            );
            let grown = whole.last().unwrap().crack.debonded;
            println!(
                "           worst differences: load {:.1e} (of the peak), elastic {:.1e}, dissipated {:.1e} (of W), debonded {:.1e} mm; crack grown {grown:.2} mm",
                worst[0], worst[1], worst[2], worst[3]
            );
            // The states converge to the Newton tolerance (1e-9 of the internal forces). The
            // dissipated energy is each point's work along its gap path, integrated step by step
            // along a mixed-mode path that curves, and the two runs cut their steps differently:
            // it differs by less than either run's own energy balance (W − U − D, whose error is
            // that of the external work's trapezoidal rule over the steps).
            assert!(worst[0] < 1e-7 && worst[1] < 1e-7 && worst[3] < 1e-5, "{worst:?}");
            let (bw, bv) = (balance(&whole), balance(&win));
            assert!(bw < 5e-3 && bv < 5e-3, "energy balance {bw:.1e}, {bv:.1e}");
            assert!(worst[2] < bw.min(bv), "dissipated {:.1e} against balances {bw:.1e}, {bv:.1e}", worst[2]);
            assert!(grown > 1.0, "the crack ran");
        }
    }

    /// A weak shear branch (σ_t 6.4 MPa) grows a process zone over the whole ligament: the window
    /// hands its state to the whole mesh once it spans three quarters of the interface, and the
    /// run goes on there under the same control (on the snap-back at the peak, where the window's
    /// Newton could not converge, the whole mesh took thirty times as long going on from the
    /// window's state as from rest).
    #[test]
    fn a_window_over_most_of_the_interface_hands_the_run_to_the_whole_mesh() {
        let (m, _) = Mmb::hartlen_half_mode_two();
        let law = crate::laws::Bilinear::bk(1e5, 21.527, 6.3613, 0.74535, 2.7863, 1.6521).unwrap();
        let ((whole, sw), (handed, sh)) = both_runs(&m, &law);
        assert!(sh.resumed_from_window, "{sh:?}");
        assert_eq!(sh.window_fallback, Some("the window spans most of the interface"), "{sh:?}");
        // About as many steps as from rest: not the creeping continuation along the snap-back.
        assert!(sh.steps < 2 * sw.steps, "{sh:?} against {sw:?}");
        assert_eq!(whole.len(), handed.len());
        let worst = load_difference(&whole, &handed);
        assert!(worst < 1e-7, "loads differ by {worst:.1e} of the peak");
    }

    /// At pure mode II (the lever at L/3) the window cannot take its smallest step at the peak,
    /// and the whole mesh cannot go on from the window's state along the snap-back: it starts again
    /// from rest, and the record is the whole mesh's own, bit for bit.
    #[test]
    fn a_whole_mesh_that_cannot_go_on_from_the_windows_state_starts_from_rest() {
        let mut m = Mmb::hartlen(Mmb::lever_for_mode_ratio(50.0, 1.0));
        m.control.output_points = 100;
        let law = crate::laws::Bilinear::bk(1e6, 30.0, 30.0, 1.0, 1.0, 2.0).unwrap();
        let ((whole, sw), (again, sa)) = both_runs(&m, &law);
        assert_eq!(sa.window_fallback, Some("no convergence even with the smallest step"), "{sa:?}");
        assert!(!sa.resumed_from_window, "{sa:?}");
        assert_eq!((sa.steps, sa.assemblies), (sw.steps, sw.assemblies));
        assert_eq!(whole, again);
    }

    /// An ENF's cracked faces press on each other: the window, which holds them open, sees them
    /// close and leaves the run to the whole mesh, whose record it then is.
    #[test]
    fn closing_faces_leave_the_run_to_the_whole_mesh() {
        let (e, law) = crate::enf::Enf::hartlen_enf03_identified();
        let (p, scale) = e.problem(&law).unwrap();
        let path = e.path(&law, &scale);
        let run = |window: bool| fe::run_with(&p, &law, &path, &fe::RunOptions { window, ..RUN }).unwrap();
        let ((whole, sw), (tried, st)) = (run(false), run(true));
        assert!(!st.windowed && !st.resumed_from_window, "{st:?}");
        assert_eq!(st.window_fallback, Some("a failed point behind the window closed"), "{st:?}");
        assert_eq!(whole, tried, "the whole mesh's record, bit for bit ({sw:?})");
    }
}
