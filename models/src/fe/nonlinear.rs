//! Problems with materially nonlinear beams: fibre-section layers ([`super::fibre`]) beside the
//! linear Timoshenko layers and the cohesive interface, loaded by a force pattern whose magnitude
//! follows from an indirect displacement control.
//!
//! **Why indirect control.** A structure whose cohesive interface fails while its beams yield
//! (an FRP-plated RC beam losing its plate) can lose load while its load point moves back
//! (snap-back), and the dissipation constraint of [`super::path`] presumes elastic-damage
//! materials (its released energy `½(λ₀ Δc − Δλ c₀)` counts elastic unloading of a yielded bar as
//! released). Here the load is `P e` (`e` a fixed pattern) and the path is followed in a
//! quantity chosen to grow monotonically through the failure, a linear combination `c = a·q` of
//! the unknowns (for a plated beam: the elongation of the concrete soffit, which every crack
//! opening and every debonded length increases). Each step solves the bordered system
//! `f_int(q) = P e`, `a·q = c` by Newton's method (Crisfield's indirect displacement control):
//! `K x₁ = −r`, `K x₂ = e`, `ΔP = (c − a·q − a·x₁)/(a·x₂)`, `Δq = x₁ + ΔP x₂`.
//!
//! **Extrapolated damage.** When several softening stretches of the interface (both sides of
//! every crack of a plated beam) load at once, the path branches: some go on softening, the others
//! unload, and with the law's own tangent Newton's method cycles between such choices without
//! converging. With [`DamageUpdate::Extrapolated`] each step holds the interface's damage at its
//! value extrapolated from the last two states (Oliver, Huespe & Cante's implicit–explicit
//! integration), so that within a step the interface is linear with a positive stiffness and the
//! step has a unique solution; the law then updates the damage from the step's gaps, and the step
//! is repeated smaller while the two differ by more than a tolerance. The error is of the order of
//! the step and is measured by halving it (the book's FRP beam chapter). The normal status of a
//! damaged point (open, `(1 − D) k_n`; closed, `k_n`) is also taken from the start of the step
//! and corrected at most twice per step (`Solver::correct_status`). Energies are those of the
//! tractions in equilibrium (trapezoidal rule on each point's gap, `½ T·g` recoverable).
//!
//! **Interface in series with a compliance.** Each cohesive point may carry a linear compliance
//! `C = diag(c_n, c_t)` (mm/MPa) in series with the law (an adhesive layer): the law sees the gap
//! `g_l` solving `g_l + C T(g_l) = g` (a local Newton solve per point), and the point's stiffness
//! is `D (I + C D)⁻¹`. With `C = 0` this code path is not entered at all.
//!
//! **Energy.** External work `∫ P d(e·q)` (trapezoidal rule over steps); elastic energy: the
//! linear layers' exact strain energy, the fibres' recoverable energy and the interface's
//! (law plus compliance, `½ T·C T`); dissipated energy of the interface (work along each point's gap
//! path by `energy::path_work` minus its recoverable energy) and of the fibres (work by
//! [`fibre::FibreMaterial::step_work`] minus recoverable energy), each integrated point by point and
//! independently of the external work, so `W = U + D_interface + D_material` is a genuine check.
//!
//! **Initial strains** (shrinkage): if a fibre has one, the unloaded structure is first brought to
//! equilibrium at `P = 0`; energies are counted from that state.
//!
//! Small rotations and the nodal interface rule (each point with its tributary area).

use czid_core::{CohesiveLaw, CzError, Gap, LawEval, LawState, Tangent, Traction};

use super::assembly::{loading_tangent, strengths, Spring};
use super::banded::{BandError, BandMatrix, RowSparse, StiffnessBand};
use super::beam;
use super::crack::{self, CrackMeasures};
use super::energy::path_work;
use super::fibre::{self, FibreSection};
use super::interface::{self, InterfacePoint, PointKind, POINT_DOFS};
use super::mesh::{Mesh, NONE};
use super::newton::NewtonSettings;
use super::segment;
use super::symmetric_band::SymmetricBand;
use crate::materials::UniaxialState;

/// Fraction of the initial normal stiffness a failed interface point keeps in opening under
/// [`DamageUpdate::Extrapolated`] (its energy is recoverable and counted as elastic): 10⁻⁶ of
/// 477 MPa/mm over 10 × 100 mm is 0.5 N per mm of lift.
pub const RESIDUAL_OPENING_STIFFNESS: f64 = 1e-6;

/// A mesh layer whose axial force and moment come from a fibre section.
#[derive(Clone, Debug)]
pub struct FibreLayer {
    /// Index of the layer in the mesh. Its [`super::mesh::Section`] gives the shear stiffness only
    /// and must have a zero axial modulus `e`.
    pub layer: usize,
    /// The sections the elements use.
    pub sections: Vec<FibreSection>,
    /// Section of each element of the layer (index into `sections`), in order along the layer.
    pub element_section: Vec<usize>,
}

/// The discrete problem.
#[derive(Clone, Debug)]
pub struct NonlinearProblem {
    /// Nodes, layers, unknowns.
    pub mesh: Mesh,
    /// Cohesive interface points (nodal rule; small rotations).
    pub points: Vec<InterfacePoint>,
    /// Unknowns held at zero.
    pub fixed: Vec<usize>,
    /// Fibre-section layers.
    pub fibre_layers: Vec<FibreLayer>,
    /// Load pattern: the force on unknown `i` is `P × coefficient`. Its work-conjugate
    /// displacement is `Σ coefficient q_i`.
    pub load: Vec<(usize, f64)>,
    /// Control: `c = Σ coefficient q_i`, increased monotonically along the path.
    pub control: Vec<(usize, f64)>,
    /// Compliance in series with the law, `[normal, tangential]` (mm/MPa).
    pub compliance: [f64; 2],
    /// Linear springs (restraints); their energy is part of the elastic energy.
    pub springs: Vec<Spring>,
}

/// How far and how finely to follow the path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlPath {
    /// Spacing of the control values at which states are recorded (all hit exactly).
    pub spacing: f64,
    /// Largest control value.
    pub max_control: f64,
    /// Smallest step, as a fraction of the spacing, before the run gives up.
    pub min_step_fraction: f64,
    /// Damage at or above which a point counts as debonded.
    pub damage_threshold: f64,
    /// Newton settings.
    pub newton: NewtonSettings,
    /// How the interface's damage enters the equilibrium of a step.
    pub damage_update: DamageUpdate,
}

/// How the interface's damage enters the equilibrium of a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DamageUpdate {
    /// The law's own response (damage from the gaps of the step itself): exact, but Newton's
    /// method has to find which of many softening points load and which unload.
    Implicit,
    /// Damage extrapolated from the last two converged states (implicit–explicit integration,
    /// Oliver, Huespe & Cante 2008): within a step each point is linear with the damage
    /// `D_ex = D_n + (Δc/Δc_n)(D_n − D_{n−1})` (clamped to `[D_n, 1]`), so the step's problem
    /// has a positive interface stiffness and a unique solution; after convergence the law
    /// updates the damage from the step's gaps. The step is repeated at half the size while
    /// `max |D_{n+1} − D_ex|` exceeds `tolerance`, down to `min_fraction` of the output spacing
    /// (there the step is taken: the path crosses an unstable stretch at nearly fixed control,
    /// as a test under that control would). Needs a law that unloads along its secant,
    /// `T = (1 − D) K ⟨g⟩` (checked).
    Extrapolated {
        /// Largest accepted difference between the updated and the extrapolated damage.
        tolerance: f64,
        /// Smallest step, as a fraction of the output spacing.
        min_fraction: f64,
    },
}

/// One recorded state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NonlinearRow {
    /// Control value `c`.
    pub control: f64,
    /// Load factor `P`.
    pub load: f64,
    /// Work-conjugate displacement of the load pattern.
    pub displacement: f64,
    /// Work of the load (N·mm).
    pub external_work: f64,
    /// Recoverable energy of beams, fibres and interface (N·mm).
    pub elastic_energy: f64,
    /// Energy dissipated by the interface (N·mm).
    pub interface_dissipation: f64,
    /// Energy dissipated by the fibre materials (N·mm).
    pub material_dissipation: f64,
    /// Debonded length and process zone along the interface points.
    pub crack: CrackMeasures,
}

/// A converged state shown to the caller's observer.
pub struct Snapshot<'a> {
    /// The recorded row.
    pub row: &'a NonlinearRow,
    /// Unknowns.
    pub q: &'a [f64],
    /// Committed law states of the interface points.
    pub point_states: &'a [LawState],
    /// Gaps of the interface points (total, compliance included).
    pub gaps: &'a [Gap],
    /// Tractions of the interface points.
    pub tractions: &'a [Traction],
}

/// Statistics of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NonlinearStats {
    /// Converged steps.
    pub steps: usize,
    /// Assemblies.
    pub assemblies: usize,
    /// Factorisations.
    pub factorizations: usize,
    /// Steps cut after a failure.
    pub cuts: usize,
}

/// A failed run: the error and the rows recorded before it.
#[derive(Clone, Debug)]
pub struct NonlinearFailure {
    /// What went wrong.
    pub error: CzError,
    /// Rows recorded before.
    pub rows: Vec<NonlinearRow>,
}

struct Element {
    layer: usize,
    dofs: [usize; 6],
    len: f64,
}

struct FibreElement {
    fl: usize,
    section: usize,
    dofs: [usize; 6],
    len: f64,
    /// First fibre state of this element in the flat state arrays.
    first: usize,
}

/// The linear layers' and the fibres' part of an assembly: their forces `f` with secant
/// stiffnesses or not; `valid` while the committed history is that of the assembly and no fibre has
/// taken its unloading stiffness since, and `same_unknowns` when the next assembly is at the same
/// unknowns (Newton starting again after a correction of the normal statuses).
#[derive(Default)]
struct Base {
    valid: bool,
    secant: bool,
    ok: bool,
    same_unknowns: bool,
    f: Vec<f64>,
    /// The unknowns of the assembly, kept in debug builds to check `same_unknowns`.
    #[cfg(debug_assertions)]
    q: Vec<f64>,
}

/// Committed or trial state of everything with history.
#[derive(Clone)]
struct History {
    points: Vec<LawState>,
    law_gaps: Vec<Gap>,
    tractions: Vec<Traction>,
    gaps: Vec<Gap>,
    fibres: Vec<UniaxialState>,
    strains: Vec<f64>,
    stresses: Vec<f64>,
}

struct Solver<'a> {
    p: &'a NonlinearProblem,
    law: &'a dyn CohesiveLaw,
    elements: Vec<Element>,
    fibre_elements: Vec<FibreElement>,
    /// The fibres of each section of each fibre layer, their materials prepared.
    prepared: Vec<Vec<Vec<fibre::PreparedFibre>>>,
    linear: BandMatrix,
    /// The non-zero entries of `linear`, for its product with the unknowns.
    linear_rows: RowSparse,
    /// `linear`'s upper band, the start of a symmetric iteration matrix.
    linear_upper: SymmetricBand,
    /// The iteration matrix: general, or (with extrapolated damage, where every stiffness is
    /// symmetric) symmetric in half the storage and work; `symmetric` says which holds the
    /// factors of the last tangent.
    k: BandMatrix,
    ks: SymmetricBand,
    symmetric: bool,
    f: Vec<f64>,
    fixed_mask: Vec<bool>,
    strength: [f64; 2],
    /// Trial results of the last assembly.
    trial: History,
    iteration_tangents: Vec<Tangent>,
    /// Section tangents `∂[N, M]/∂[ε, κ]` of the fibre elements at the last assembly.
    section_tangents: Vec<[[f64; 2]; 2]>,
    /// The interface points' constant parts of their forces and stiffnesses ([`PointCouplings`]).
    couplings: PointCouplings,
    load: Vec<f64>,
    /// Work vectors of the Newton iterations.
    work: Vec<Vec<f64>>,
    /// The linear layers' and fibres' part of the last assembly.
    base: Base,
    settings: NewtonSettings,
    stats: NonlinearStats,
    with_compliance: bool,
    /// Secant iterations after a correction that increased the residual.
    secant_iterations: usize,
    /// Extrapolated damage of each point in this step (`None`: the law's own response).
    extrapolated: Option<Vec<f64>>,
    /// The law's initial stiffness `[k_n, k_t]` (MPa/mm).
    k0: [f64; 2],
    /// Per fibre in the current step: whether it was loading (history changed) at the last
    /// assembly, how often that has changed, and whether it now takes its unloading stiffness.
    fibre_loading: Vec<bool>,
    fibre_flips: Vec<u8>,
    fibre_unloading: Vec<bool>,
    /// Per interface point in the current step, with extrapolated damage: whether it is taken as
    /// open (`g_n > 0`) or closed (see `correct_status`).
    open: Vec<bool>,
}

/// What the interface points' forces and stiffnesses are made of that does not change along a run
/// (small rotations: the gap gradients `g_n`, `g_t` are constant), worked out once: point `i`'s
/// force on unknown `a` is `w (g_n,a T_n + g_t,a T_t)` and its stiffness between `a` and `b`
/// `w Σ_rs g_r,a D_rs g_s,b` (`w` its tributary area), here with `w` and the gradients' products
/// multiplied out and only the unknowns the point moves. An assembly then runs over these lists
/// instead of every pair of the point's unknowns.
#[derive(Default)]
struct PointCouplings {
    /// Per point, its entries in `forces` (`force_start[i]..force_start[i + 1]`) and in `pairs`.
    force_start: Vec<usize>,
    pair_start: Vec<usize>,
    /// Unknown and `[w g_n, w g_t]` at it.
    forces: Vec<(usize, [f64; 2])>,
    /// Unknowns `(a, b)` and `w [g_n,a g_n,b, g_n,a g_t,b, g_t,a g_n,b, g_t,a g_t,b]`.
    pairs: Vec<(usize, usize, [f64; 4])>,
    /// The pairs with `b ≥ a`, per point from `upper_start`: all that a symmetric band keeps.
    upper_start: Vec<usize>,
    upper: Vec<(usize, usize, [f64; 4])>,
}

impl PointCouplings {
    fn new(points: &[InterfacePoint], kinematics: &[interface::GapKinematics]) -> Self {
        let mut c =
            PointCouplings { force_start: vec![0], pair_start: vec![0], upper_start: vec![0], ..Default::default() };
        for (pt, kin) in points.iter().zip(kinematics) {
            let w = pt.area * pt.factor;
            let g = &kin.grad;
            let moved: Vec<usize> =
                (0..POINT_DOFS).filter(|&a| kin.dofs[a] != NONE && (g[0][a] != 0.0 || g[1][a] != 0.0)).collect();
            for &a in &moved {
                c.forces.push((kin.dofs[a], [w * g[0][a], w * g[1][a]]));
                for &b in &moved {
                    let p = [g[0][a] * g[0][b], g[0][a] * g[1][b], g[1][a] * g[0][b], g[1][a] * g[1][b]];
                    let pair = (kin.dofs[a], kin.dofs[b], p.map(|v| w * v));
                    c.pairs.push(pair);
                    if pair.1 >= pair.0 {
                        c.upper.push(pair);
                    }
                }
            }
            c.force_start.push(c.forces.len());
            c.pair_start.push(c.pairs.len());
            c.upper_start.push(c.upper.len());
        }
        c
    }
}

#[inline]
fn get(q: &[f64], d: usize) -> f64 {
    if d == NONE {
        0.0
    } else {
        q[d]
    }
}

fn scatter<K: StiffnessBand>(k: &mut K, dofs: &[usize; 6], ke: &[[f64; 6]; 6]) {
    for (a, &da) in dofs.iter().enumerate() {
        if da == NONE {
            continue;
        }
        for (b, &db) in dofs.iter().enumerate() {
            if db != NONE && ke[a][b] != 0.0 {
                k.add(da, db, ke[a][b]);
            }
        }
    }
}

/// Checks the problem's consistency.
fn check(p: &NonlinearProblem) -> Result<(), CzError> {
    let n = p.mesh.n_dofs();
    for fl in &p.fibre_layers {
        let Some(layer) = p.mesh.layers.get(fl.layer) else {
            return Err(CzError::Simulation(format!("fibre layer {} is not a layer of the mesh", fl.layer)));
        };
        if layer.section.e != 0.0 {
            return Err(CzError::Simulation(format!(
                "fibre layer {}: its linear section must have a zero axial modulus (the fibres carry N and M)",
                fl.layer
            )));
        }
        if !layer.axial {
            return Err(CzError::Simulation(format!("fibre layer {} needs axial unknowns", fl.layer)));
        }
        if fl.element_section.len() != layer.last - layer.first
            || fl.element_section.iter().any(|&k| k >= fl.sections.len())
        {
            return Err(CzError::Simulation(format!(
                "fibre layer {}: needs one valid section index per element",
                fl.layer
            )));
        }
        if fl.sections.iter().any(|sec| sec.fibres.iter().any(|f| f.material >= sec.materials.len())) {
            return Err(CzError::Simulation(format!("fibre layer {}: a fibre names a missing material", fl.layer)));
        }
    }
    let bad = |d: &usize| *d >= n;
    if p.springs.iter().any(|sp| bad(&sp.i) || (sp.j != NONE && bad(&sp.j))) {
        return Err(CzError::Simulation("a spring names an unknown out of range".into()));
    }
    if p.fixed.iter().any(bad) || p.load.iter().any(|(d, _)| bad(d)) || p.control.iter().any(|(d, _)| bad(d)) {
        return Err(CzError::Simulation("an unknown of the problem is out of range".into()));
    }
    if p.load.is_empty() || p.control.is_empty() {
        return Err(CzError::Simulation("the problem needs a load pattern and a control".into()));
    }
    if p.points.iter().any(|pt| pt.kind != PointKind::Cohesive || pt.lower.is_none()) {
        return Err(CzError::Simulation("nonlinear problems take cohesive points between two layers only".into()));
    }
    if !(p.compliance.iter().all(|c| c.is_finite() && *c >= 0.0)) {
        return Err(CzError::Simulation("the interface compliance must be finite and non-negative".into()));
    }
    Ok(())
}

impl<'a> Solver<'a> {
    fn new(p: &'a NonlinearProblem, law: &'a dyn CohesiveLaw, settings: NewtonSettings) -> Self {
        let mesh = &p.mesh;
        let mut elements = Vec::new();
        for (k, layer) in mesh.layers.iter().enumerate() {
            for i in layer.first..layer.last {
                let (a, b) = (mesh.dofs(k, i), mesh.dofs(k, i + 1));
                elements.push(Element {
                    layer: k,
                    dofs: [a[0], a[1], a[2], b[0], b[1], b[2]],
                    len: mesh.x[i + 1] - mesh.x[i],
                });
            }
        }
        let n = mesh.n_dofs();
        let mut linear = BandMatrix::zeros(n, mesh.bandwidth());
        for e in &elements {
            scatter(&mut linear, &e.dofs, &beam::stiffness(&mesh.layers[e.layer].section, e.len));
        }
        for sp in &p.springs {
            linear.add(sp.i, sp.i, sp.k * sp.ci * sp.ci);
            if sp.j != NONE {
                linear.add(sp.j, sp.j, sp.k);
                linear.add(sp.i, sp.j, -sp.k * sp.ci);
                linear.add(sp.j, sp.i, -sp.k * sp.ci);
            }
        }
        let mut fibre_elements = Vec::new();
        let mut nfib = 0;
        for (ifl, fl) in p.fibre_layers.iter().enumerate() {
            let layer = &mesh.layers[fl.layer];
            for i in layer.first..layer.last {
                let (a, b) = (mesh.dofs(fl.layer, i), mesh.dofs(fl.layer, i + 1));
                let section = fl.element_section[i - layer.first];
                fibre_elements.push(FibreElement {
                    fl: ifl,
                    section,
                    dofs: [a[0], a[1], a[2], b[0], b[1], b[2]],
                    len: mesh.x[i + 1] - mesh.x[i],
                    first: nfib,
                });
                nfib += fl.sections[section].fibres.len();
            }
        }
        let np = p.points.len();
        let init = law.initial_state();
        let trial = History {
            points: vec![init; np],
            law_gaps: vec![Gap::zeros(); np],
            tractions: vec![Traction::zeros(); np],
            gaps: vec![Gap::zeros(); np],
            fibres: vec![UniaxialState::default(); nfib],
            strains: vec![0.0; nfib],
            stresses: vec![0.0; nfib],
        };
        let section_tangents = vec![[[0.0; 2]; 2]; fibre_elements.len()];
        let zero = vec![0.0; n];
        let mut hess = [[[0.0; POINT_DOFS]; POINT_DOFS]; 2];
        // Gap kinematics of the interface points (small rotations: `∂g/∂q` is constant).
        let kinematics: Vec<_> =
            p.points.iter().map(|pt| interface::kinematics(mesh, pt, &zero, false, &mut hess)).collect();
        let couplings = PointCouplings::new(&p.points, &kinematics);
        let mut fixed_mask = vec![false; n];
        for &d in &p.fixed {
            fixed_mask[d] = true;
        }
        let mut load = vec![0.0; n];
        for &(d, c) in &p.load {
            load[d] += c;
        }
        Solver {
            p,
            law,
            elements,
            fibre_elements,
            prepared: p.fibre_layers.iter().map(|fl| fl.sections.iter().map(|sec| sec.prepared()).collect()).collect(),
            k: BandMatrix::zeros(n, mesh.bandwidth()),
            ks: SymmetricBand::zeros(n, mesh.bandwidth()),
            symmetric: false,
            linear_rows: RowSparse::from_band(&linear),
            linear_upper: SymmetricBand::upper_of(&linear),
            linear,
            f: vec![0.0; n],
            fixed_mask,
            strength: strengths(law),
            trial,
            iteration_tangents: vec![Tangent::zeros(); np],
            section_tangents,
            couplings,
            load,
            work: Vec::new(),
            base: Base::default(),
            settings,
            stats: NonlinearStats::default(),
            with_compliance: p.compliance != [0.0, 0.0],
            secant_iterations: 4,
            extrapolated: None,
            k0: law.initial_stiffness(),
            fibre_loading: vec![false; nfib],
            fibre_flips: vec![0; nfib],
            fibre_unloading: vec![false; nfib],
            open: vec![false; np],
        }
    }

    /// Internal forces at `q` from the committed history `c`, with the trial history and the
    /// stiffnesses [`Solver::factorize_tangent`] assembles; `false` if something is not finite (or a
    /// series-compliance solve failed).
    fn assemble(&mut self, c: &History, q: &[f64], secant: bool) -> bool {
        self.stats.assemblies += 1;
        // Again at the unknowns of the last assembly (after a correction of the normal statuses):
        // the linear layers and the fibres give what they gave then.
        if std::mem::take(&mut self.base.same_unknowns) && self.base.valid && self.base.secant == secant {
            #[cfg(debug_assertions)]
            debug_assert!(self.base.q == q, "the unknowns moved since the assembly being reused");
            self.f.copy_from_slice(&self.base.f);
            return self.assemble_interface(c, q, secant, self.base.ok);
        }
        self.linear_rows.mul_vec(q, &mut self.f);
        let mut ok = true;
        let mut unloading_changed = false;
        for (ie, fe) in self.fibre_elements.iter().enumerate() {
            let fibres = &self.prepared[fe.fl][fe.section];
            let mut qe = [0.0; 6];
            for (v, &d) in qe.iter_mut().zip(&fe.dofs) {
                *v = get(q, d);
            }
            let e = fibre::strains(fe.len, &qe);
            let nf = fibres.len();
            let range = fe.first..fe.first + nf;
            let committed = &c.fibres[range.clone()];
            let trial = &mut self.trial.fibres[range.clone()];
            let stresses = &mut self.trial.stresses[range.clone()];
            let strains = &mut self.trial.strains[range.clone()];
            let loading_flags = &mut self.fibre_loading[range.clone()];
            let flips = &mut self.fibre_flips[range.clone()];
            let unloading = &mut self.fibre_unloading[range];
            // The section response and the fibres' bookkeeping in one pass over the fibres: with
            // `secant`, each fibre contributes its secant stiffness `σ/ε` (an iteration matrix that
            // cannot cycle between loading and unloading); a fibre flagged as unloading, its
            // unloading stiffness.
            let mut r = fibre::SectionResponse::default();
            for (k, f) in fibres.iter().enumerate() {
                let mat = &f.material;
                let mech = f.strain(e);
                let res = mat.respond(mech, &committed[k]);
                trial[k] = res.state;
                stresses[k] = res.stress;
                strains[k] = mech;
                let stiffness = if unloading[k] {
                    mat.unloading_stiffness(mech, res.stress)
                } else if secant && mech.abs() > 1e-12 {
                    (res.stress / mech).max(0.0)
                } else {
                    res.tangent
                };
                let (fa, ka) = (res.stress * f.area, stiffness * f.area);
                r.force[0] += fa;
                r.force[1] -= fa * f.z;
                r.tangent[0][0] += ka;
                r.tangent[0][1] -= ka * f.z;
                r.tangent[1][1] += ka * f.z * f.z;
                // A fibre that keeps switching between loading and unloading from one iteration
                // to the next (a bar at yield, concrete at its envelope) sits on its loading
                // surface in the solution, where Newton's tangents on either side send it across:
                // its unloading stiffness, stiffer than its tangent, makes the iterations contract
                // there (from the next assembly on).
                let loading = res.state != committed[k];
                if loading != loading_flags[k] {
                    loading_flags[k] = loading;
                    flips[k] = flips[k].saturating_add(1);
                    unloading_changed |= unloading[k] != (flips[k] >= 3);
                    unloading[k] = flips[k] >= 3;
                }
            }
            r.tangent[1][0] = r.tangent[0][1];
            ok &= fibre::element_forces(fe.len, &r, &fe.dofs, &mut self.f);
            self.section_tangents[ie] = r.tangent;
        }
        // A fibre that takes its unloading stiffness from now on changes the next tangent.
        let base = &mut self.base;
        base.valid = !unloading_changed;
        base.secant = secant;
        base.ok = ok;
        base.f.clear();
        base.f.extend_from_slice(&self.f);
        #[cfg(debug_assertions)]
        {
            base.q.clear();
            base.q.extend_from_slice(q);
        }
        self.assemble_interface(c, q, secant, ok)
    }

    /// The interface points' part of [`Solver::assemble`], `ok` from the rest.
    fn assemble_interface(&mut self, c: &History, q: &[f64], secant: bool, mut ok: bool) -> bool {
        let p = self.p;
        for (ip, pt) in p.points.iter().enumerate() {
            let [gn, gt] = interface::small_gap(&p.mesh, pt, q);
            let gap = Gap::new(gn, gt);
            let state = &c.points[ip];
            let (ev, d, gl) = if let Some(dex) = &self.extrapolated {
                // Open or closed as at the start of the step (see `correct_status`).
                self.with_damage(&gap, state, dex[ip], self.open[ip])
            } else if self.with_compliance {
                match self.series(&gap, state, c.law_gaps[ip], secant) {
                    Some(v) => v,
                    None => return false,
                }
            } else {
                let ev = self.law.evaluate(&gap, state);
                let d = if secant {
                    secant_stiffness(&gap, &ev)
                } else {
                    loading_tangent(self.law, &self.strength, &gap, state, &ev)
                };
                (ev, d, gap)
            };
            let t = ev.traction;
            if !(t[0].is_finite() && t[1].is_finite() && d.iter().all(|v| v.is_finite())) {
                ok = false;
            }
            self.trial.points[ip] = ev.state;
            self.trial.tractions[ip] = t;
            self.trial.gaps[ip] = gap;
            self.trial.law_gaps[ip] = gl;
            self.iteration_tangents[ip] = d;
            let cp = &self.couplings;
            for &(da, wg) in &cp.forces[cp.force_start[ip]..cp.force_start[ip + 1]] {
                self.f[da] += wg[0] * t[0] + wg[1] * t[1];
            }
        }
        ok
    }

    /// Factorises the tangent at the last assembly, the prescribed unknowns' rows and columns
    /// replaced by the identity's: symmetric with extrapolated damage (the interface's iteration
    /// stiffness is then `diag((1 − D) k)`, and the layers' and fibres' are symmetric), else
    /// general (a law's own tangent need not be symmetric).
    fn factorize_tangent(&mut self) -> Result<(), BandError> {
        self.stats.factorizations += 1;
        self.symmetric = self.extrapolated.is_some();
        // `with_damage` gives every point a diagonal stiffness. Were one not symmetric, the
        // iteration matrix would be wrong, not the solution (the residual is exact): Newton would
        // only converge more slowly.
        debug_assert!(!self.symmetric || self.iteration_tangents.iter().all(|d| d[(0, 1)] == d[(1, 0)]));
        if self.symmetric {
            let mut k = std::mem::take(&mut self.ks);
            k.copy_from(&self.linear_upper);
            self.add_tangent(&mut k);
            self.ks = k;
            self.ks.factorize()
        } else {
            let mut k = std::mem::take(&mut self.k);
            k.copy_from(&self.linear);
            self.add_tangent(&mut k);
            self.k = k;
            self.k.factorize()
        }
    }

    /// Adds the fibre elements' tangents (from their section tangents) and the interface points'
    /// (from their iteration stiffnesses) at the last assembly to `k`, then replaces the
    /// prescribed unknowns' rows and columns by the identity's.
    fn add_tangent<K: StiffnessBand>(&self, k: &mut K) {
        for (fe, st) in self.fibre_elements.iter().zip(&self.section_tangents) {
            fibre::scatter_tangent(fe.len, st, &fe.dofs, k);
        }
        let cp = &self.couplings;
        // A symmetric band drops the entries below its diagonal: only the pairs it keeps.
        let (pairs, start) = if K::UPPER_ONLY { (&cp.upper, &cp.upper_start) } else { (&cp.pairs, &cp.pair_start) };
        for (ip, d) in self.iteration_tangents.iter().enumerate() {
            let dd = [d[(0, 0)], d[(0, 1)], d[(1, 0)], d[(1, 1)]];
            for &(da, db, p) in &pairs[start[ip]..start[ip + 1]] {
                k.add(da, db, dd[0] * p[0] + dd[1] * p[1] + dd[2] * p[2] + dd[3] * p[3]);
            }
        }
        for &d in &self.p.fixed {
            k.set_identity_row_col(d);
        }
    }

    /// Solves with the last factorised tangent.
    fn solve_factored(&self, b: &mut [f64]) {
        if self.symmetric {
            self.ks.solve_in_place(b);
        } else {
            self.k.solve_in_place(b);
        }
    }

    /// Solves for two right-hand sides with the last factorised tangent.
    fn solve2_factored(&self, b1: &mut [f64], b2: &mut [f64]) {
        if self.symmetric {
            self.ks.solve2_in_place(b1, b2);
        } else {
            self.k.solve2_in_place(b1, b2);
        }
    }

    /// A point with the fixed damage `dex` (secant `(1 − D) K` in slip and opening, `K` in
    /// closure), in series with the compliance: its traction and stiffness, and its committed
    /// `state` unchanged (the state the law reaches at the converged law gap, the implicit update,
    /// is worked out once the step has converged: [`Solver::update_extrapolated_states`]).
    /// `open` selects the normal branch (see `correct_status`).
    fn with_damage(&self, gap: &Gap, state: &LawState, dex: f64, open: bool) -> (LawEval, Tangent, Gap) {
        let c = self.p.compliance;
        let intact = 1.0 - dex;
        let series = |k: f64, c: f64| k / (1.0 + c * k);
        // Open, a failed point keeps `RESIDUAL_OPENING_STIFFNESS` of its normal stiffness: a plate
        // that has lifted off everywhere then still follows the beam's deflection instead of
        // leaving the tangent singular (its bending stiffness alone is some 10⁻¹⁴ of the beam's).
        let kn = series(if open { intact.max(RESIDUAL_OPENING_STIFFNESS) * self.k0[0] } else { self.k0[0] }, c[0]);
        let kt = series(intact * self.k0[1], c[1]);
        let t = Traction::new(kn * gap[0], kt * gap[1]);
        let gl = Gap::new(gap[0] - c[0] * t[0], gap[1] - c[1] * t[1]);
        let d = Tangent::new(kn, 0.0, 0.0, kt);
        (LawEval { traction: t, tangent: d, state: *state }, d, gl)
    }

    /// With extrapolated damage, after convergence: the states the law reaches at the trial law
    /// gaps from the committed states `c` (within the iterations the law is not needed, the
    /// damage being held, so it is evaluated once per step instead of at every assembly).
    fn update_extrapolated_states(&mut self, c: &History) {
        for ((st, g), old) in self.trial.points.iter_mut().zip(&self.trial.law_gaps).zip(&c.points) {
            *st = self.law.evaluate(g, old).state;
        }
    }

    /// Corrects the normal status (open or closed) of the points whose converged state contradicts
    /// it by a force above the tolerance `tol`; `true` if any was corrected.
    ///
    /// With extrapolated damage a damaged point's normal stiffness is `(1 − D) k_n` open and `k_n`
    /// closed: a kink at zero opening, where a debonded plate lying on the soffit has many points.
    /// Newton's method cycles between contact states there, so the status of every point is taken
    /// from the start of the step and held through the iterations (the step's problem is then
    /// smooth in the interface); a converged state that contradicts it is corrected and solved
    /// again (an active-set iteration).
    fn correct_status(&mut self, tol: f64) -> bool {
        let Some(dex) = &self.extrapolated else {
            return false;
        };
        let mut any = false;
        for (ip, pt) in self.p.points.iter().enumerate() {
            let g = self.trial.gaps[ip][0];
            let open = self.open[ip];
            if open == (g > 0.0) {
                continue;
            }
            // Force the wrong branch puts on the point: its stiffness difference times the gap.
            let error = pt.area * pt.factor * dex[ip].min(1.0 - RESIDUAL_OPENING_STIFFNESS) * self.k0[0] * g.abs();
            if error > tol {
                self.open[ip] = !open;
                any = true;
            }
        }
        any
    }

    /// The law behind the series compliance: solves `g_l + C T(g_l) = g` from the guess `g0`;
    /// returns the law's evaluation at `g_l`, the point's iteration stiffness `D (I + C D)⁻¹` and
    /// `g_l`.
    fn series(&self, gap: &Gap, state: &LawState, g0: Gap, secant: bool) -> Option<(LawEval, Tangent, Gap)> {
        let c = self.p.compliance;
        let cm = Tangent::new(c[0], 0.0, 0.0, c[1]);
        let id = Tangent::identity();
        let mut gl = g0;
        let scale = gap.norm().max(1e-12);
        for _ in 0..60 {
            let ev = self.law.evaluate(&gl, state);
            let r = gl + cm * ev.traction - gap;
            if r.norm() <= 1e-13 * scale {
                let d = if secant {
                    secant_stiffness(&gl, &ev)
                } else {
                    loading_tangent(self.law, &self.strength, &gl, state, &ev)
                };
                let eff = d * (id + cm * d).try_inverse()?;
                return Some((ev, eff, gl));
            }
            let j = id + cm * ev.tangent;
            let step = j.try_inverse()? * r;
            gl -= step;
        }
        None
    }

    fn scale(&self) -> f64 {
        self.f.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300)
    }

    /// Newton's method at control `c_target` (`None`: at zero load, no control) from the predictor
    /// `q`, `load`; returns the iterations on success.
    fn solve(&mut self, c: &History, q: &mut [f64], load: &mut f64, c_target: Option<f64>) -> Option<usize> {
        // The work vectors are kept from one step to the next.
        // A new committed history (or a new step from it).
        self.base.valid = false;
        self.base.same_unknowns = false;
        let mut work = std::mem::take(&mut self.work);
        work.resize_with(3, Vec::new);
        for v in work.iter_mut() {
            v.clear();
            v.resize(q.len(), 0.0);
        }
        let [r, b, dq] = &mut work[..] else { unreachable!() };
        let result = self.newton(c, q, load, c_target, r, b, dq);
        self.work = work;
        if result.is_some() && self.extrapolated.is_some() {
            self.update_extrapolated_states(c);
        }
        result
    }

    /// [`Solver::solve`] with the work vectors `r`, `b`, `dq` (zeros of the length of `q`).
    #[allow(clippy::too_many_arguments)]
    fn newton(
        &mut self,
        c: &History,
        q: &mut [f64],
        load: &mut f64,
        c_target: Option<f64>,
        r: &mut [f64],
        b: &mut [f64],
        dq: &mut [f64],
    ) -> Option<usize> {
        let n = q.len();
        let mut dload = 0.0;
        // Safeguard against branch cycling (a cracking fibre or a softening interface point
        // flipping between loading and unloading from one iteration to the next): a correction
        // that increased the residual is halved, and the next iterations use secant stiffnesses (a
        // fixed-point iteration that settles the active set) before Newton resumes; with
        // extrapolated damage the halving goes further instead (a line search), see below.
        // Normal statuses start from the committed gaps, fibres with no flips.
        self.open.iter_mut().zip(&c.gaps).for_each(|(o, g)| *o = g[0] > 0.0);
        let mut corrections = 0usize;
        self.fibre_loading.iter_mut().for_each(|v| *v = false);
        self.fibre_flips.iter_mut().for_each(|v| *v = 0);
        self.fibre_unloading.iter_mut().for_each(|v| *v = false);
        let mut r_prev = f64::INFINITY;
        let mut alpha = 1.0f64;
        let mut secant_left = 0usize;
        let mut it = 0usize;
        let max_it = self.settings.max_iterations;
        while it <= max_it {
            if !self.assemble(c, q, secant_left > 0) {
                return None;
            }
            let tol = self.settings.tolerance * self.scale();
            let mut rmax = 0.0f64;
            for i in 0..n {
                let v = if self.fixed_mask[i] { 0.0 } else { self.f[i] - *load * self.load[i] };
                r[i] = -v;
                rmax = rmax.max(v.abs());
            }
            if !rmax.is_finite() {
                return None;
            }
            let ctl: f64 = self.p.control.iter().map(|&(d, a)| a * q[d]).sum();
            let cres = c_target.map_or(0.0, |t| t - ctl);
            if rmax <= tol && cres.abs() <= 1e-12 * ctl.abs().max(1e-9) {
                // At most two corrections of the normal statuses per step: beyond, a debonded
                // plate lying on the soffit keeps switching points between touching and lifting by
                // fractions of a micrometre; the statuses then stay as they are for this step
                // (explicit, like the damage) and are taken from the converged gaps for the next.
                if corrections >= 2 || !self.correct_status(tol) {
                    return Some(it);
                }
                // A new start for the iterations with the corrected statuses.
                corrections += 1;
                self.base.same_unknowns = true;
                r_prev = f64::INFINITY;
                it = 0;
                continue;
            }
            // With extrapolated damage the interface is linear within a step; what is left are the
            // kinks of the fibres (a bar at yield, cracked concrete at zero strain): a
            // backtracking line search on the correction (down to 1/32 of it) instead of the
            // secant iterations.
            let (min_alpha, secant_after) =
                if self.extrapolated.is_some() { (1.0 / 32.0, 0) } else { (0.3, self.secant_iterations) };
            if rmax > r_prev && alpha > min_alpha {
                alpha *= 0.5;
                for (qi, di) in q.iter_mut().zip(dq.iter()) {
                    *qi -= alpha * di;
                }
                *load -= alpha * dload;
                secant_left = secant_after;
                it += 1;
                continue;
            }
            if it >= max_it {
                break;
            }
            it += 1;
            secant_left = secant_left.saturating_sub(1);
            // The line search compares force residuals of iterates that meet the control
            // constraint (which a full correction does exactly, the constraint being linear). An
            // iterate that misses it, such as a step's predictor, has no comparable residual: at
            // the first step from rest the force residual is zero and every correction would be
            // halved back towards it, spending the iterations on a point that cannot be right.
            r_prev = if cres.abs() <= 1e-9 * ctl.abs().max(1e-9) { rmax } else { f64::INFINITY };
            alpha = 1.0;
            self.factorize_tangent().ok()?;
            if c_target.is_some() {
                for i in 0..n {
                    b[i] = if self.fixed_mask[i] { 0.0 } else { self.load[i] };
                }
                self.solve2_factored(r, b);
                let a1: f64 = self.p.control.iter().map(|&(d, a)| a * r[d]).sum();
                let a2: f64 = self.p.control.iter().map(|&(d, a)| a * b[d]).sum();
                if a2 == 0.0 || !a2.is_finite() {
                    return None;
                }
                dload = (cres - a1) / a2;
                for i in 0..n {
                    dq[i] = r[i] + dload * b[i];
                    q[i] += dq[i];
                }
                *load += dload;
            } else {
                self.solve_factored(r);
                dload = 0.0;
                dq.copy_from_slice(r);
                for (qi, ri) in q.iter_mut().zip(r.iter()) {
                    *qi += ri;
                }
            }
        }
        None
    }
}

/// Secant stiffness `diag(T_n/g_n, T_t/g_t)` of a damage law, non-negative (the tangent's diagonal
/// at a zero gap component).
fn secant_stiffness(gap: &Gap, ev: &LawEval) -> Tangent {
    let mut d = Tangent::zeros();
    for i in 0..2 {
        let v = if gap[i].abs() > 1e-14 { ev.traction[i] / gap[i] } else { ev.tangent[(i, i)] };
        d[(i, i)] = v.max(0.0);
    }
    d
}

/// Running energy totals.
#[derive(Clone, Copy, Default)]
struct Totals {
    external: f64,
    interface_work: f64,
    material_work: f64,
}

/// Follows the path of `p` with `law` under the indirect control `path`. `observe` sees every
/// recorded state and returns `true` to end the run there (e.g. once the interface has failed).
pub fn run(
    p: &NonlinearProblem,
    law: &dyn CohesiveLaw,
    path: &ControlPath,
    observe: &mut dyn FnMut(&Snapshot) -> bool,
) -> Result<(Vec<NonlinearRow>, NonlinearStats), NonlinearFailure> {
    let fail = |rows: Vec<NonlinearRow>, msg: String| NonlinearFailure { error: CzError::Simulation(msg), rows };
    if let Err(e) = check(p) {
        return Err(NonlinearFailure { error: e, rows: Vec::new() });
    }
    if !(path.spacing > 0.0 && path.max_control > 0.0 && path.spacing.is_finite() && path.max_control.is_finite()) {
        return Err(fail(Vec::new(), "the control path needs a positive spacing and end".into()));
    }
    let explicit = match path.damage_update {
        DamageUpdate::Implicit => None,
        DamageUpdate::Extrapolated { tolerance, min_fraction } => {
            if !(tolerance > 0.0 && min_fraction > 0.0 && min_fraction <= 1.0) {
                return Err(fail(
                    Vec::new(),
                    "extrapolated damage needs a positive tolerance and a step fraction in (0, 1]".into(),
                ));
            }
            if let Err(msg) = check_secant_unloading(law) {
                return Err(fail(Vec::new(), msg));
            }
            Some((tolerance, min_fraction))
        }
    };
    let mut s = Solver::new(p, law, path.newton);
    let n = p.mesh.n_dofs();
    let mut committed = s.trial.clone();
    let mut q = vec![0.0; n];
    let mut load = 0.0;
    let mut rows = Vec::new();
    let xs: Vec<f64> = p.points.iter().map(|pt| p.mesh.x[pt.node]).collect();
    let mut dmg = vec![0.0; p.points.len()];
    let mut scratch = vec![0.0; p.points.len()];
    let displacement = |q: &[f64]| -> f64 { p.load.iter().map(|&(d, a)| a * q[d]).sum() };
    let control = |q: &[f64]| -> f64 { p.control.iter().map(|&(d, a)| a * q[d]).sum() };

    // Energies at a committed state: (elastic, interface stored, fibre stored).
    let stored = |s: &Solver, h: &History, q: &[f64]| -> (f64, f64, f64) {
        let mut lin = 0.0;
        for e in &s.elements {
            let mut qe = [0.0; 6];
            for (v, &d) in qe.iter_mut().zip(&e.dofs) {
                *v = get(q, d);
            }
            lin += beam::energy(&p.mesh.layers[e.layer].section, e.len, &qe);
        }
        for sp in &p.springs {
            let d = sp.ci * q[sp.i] - get(q, sp.j);
            lin += 0.5 * sp.k * d * d;
        }
        let mut fib = 0.0;
        for fe in &s.fibre_elements {
            let sec = &p.fibre_layers[fe.fl].sections[fe.section];
            for (k, f) in sec.fibres.iter().enumerate() {
                let i = fe.first + k;
                fib += f.area * fe.len * sec.materials[f.material].stored_energy(h.strains[i], h.stresses[i]);
            }
        }
        let c = p.compliance;
        let mut int = 0.0;
        for (ip, pt) in p.points.iter().enumerate() {
            let t = h.tractions[ip];
            int += pt.area
                * pt.factor
                * if explicit.is_some() {
                    // Linear within the step, law and compliance together: ½ T·g.
                    0.5 * t.dot(&h.gaps[ip])
                } else {
                    law.stored_energy(&h.law_gaps[ip], &h.points[ip]) + 0.5 * (c[0] * t[0] * t[0] + c[1] * t[1] * t[1])
                };
        }
        (lin + fib + int, int, fib)
    };

    // Initial strains: equilibrium at zero load first.
    let initial = p
        .fibre_layers
        .iter()
        .any(|fl| fl.sections.iter().any(|sec| sec.fibres.iter().any(|f| f.initial_strain != 0.0)));
    if initial {
        if s.solve(&committed, &mut q, &mut load, None).is_none() {
            return Err(fail(rows, "no equilibrium under the initial strains".into()));
        }
        committed = s.trial.clone();
    }
    let (u0, i0, f0) = stored(&s, &committed, &q);
    // Work done before the path (by initial strains) is outside the balance: start from here.
    let mut totals = Totals { external: 0.0, interface_work: i0, material_work: f0 };
    let elastic0 = u0;
    let c0 = control(&q);
    let mut record = |s: &Solver,
                      h: &History,
                      q: &[f64],
                      load: f64,
                      totals: &Totals,
                      rows: &mut Vec<NonlinearRow>,
                      observe: &mut dyn FnMut(&Snapshot) -> bool|
     -> bool {
        let (u, int, fib) = stored(s, h, q);
        for (d, st) in dmg.iter_mut().zip(&h.points) {
            *d = st.damage;
        }
        // Debonded fronts inside the elements, where the law along the gap interpolated between
        // a debonded point and its neighbour reaches the threshold (see `crack::measure_located`).
        // Where it does not reach it even at the debonded point (that point has unloaded since it
        // failed), the front is at the point: the located front slides there continuously as the
        // point unloads.
        let located = |inside: usize, outside: usize| {
            let (gi, go) = (h.law_gaps[inside], h.law_gaps[outside]);
            let (si, so) = (&h.points[inside], &h.points[outside]);
            let eta = segment::level_front(law, gi, go, si, so, path.damage_threshold).unwrap_or(0.0);
            Some(xs[inside] + eta * (xs[outside] - xs[inside]))
        };
        let origin = xs.first().copied().unwrap_or(0.0);
        let crack = crack::measure_located(&xs, &dmg, path.damage_threshold, origin, &mut scratch, located);
        let row = NonlinearRow {
            control: control(q) - c0,
            load,
            displacement: displacement(q),
            external_work: totals.external,
            elastic_energy: u - elastic0,
            interface_dissipation: totals.interface_work - int,
            material_dissipation: totals.material_work - fib,
            crack,
        };
        rows.push(row);
        let snap = Snapshot { row: &row, q, point_states: &h.points, gaps: &h.gaps, tractions: &h.tractions };
        observe(&snap)
    };
    if record(&s, &committed, &q, load, &totals, &mut rows, observe) {
        return Ok((rows, s.stats));
    }

    let spacing = path.spacing;
    let h_min = spacing * path.min_step_fraction;
    let target = path.max_control;
    let eps = 1e-12 * spacing;
    let mut pos = 0.0f64;
    let mut h = spacing;
    let mut k_out = 1usize;
    let mut prev_q = q.clone();
    let mut prev_load = load;
    let mut h_prev = 0.0f64;
    let mut trial_q = vec![0.0; n];
    let np = p.points.len();
    // Damage of the points at the last two committed states, for the extrapolation.
    let mut d_prev = vec![0.0; np];
    let mut d_ex = vec![0.0; np];
    let mut failed = 0usize;
    let max_steps = 200 * ((target / spacing).ceil() as usize) + 20_000;
    while pos < target - eps {
        if s.stats.steps > max_steps {
            return Err(fail(rows, format!("gave up after {} steps at control {pos:.6}", s.stats.steps)));
        }
        let next = (spacing * k_out as f64).min(target);
        let dh = h.min(next - pos);
        let alpha = if h_prev > 0.0 { dh / h_prev } else { 0.0 };
        for i in 0..n {
            trial_q[i] = q[i] + alpha * (q[i] - prev_q[i]);
        }
        let mut trial_load = load + alpha * (load - prev_load);
        if explicit.is_some() {
            for (ip, d) in d_ex.iter_mut().enumerate() {
                let dn = committed.points[ip].damage;
                *d = (dn + alpha * (dn - d_prev[ip])).clamp(dn, 1.0);
            }
            s.extrapolated = Some(std::mem::take(&mut d_ex));
        }
        let solved = s.solve(&committed, &mut trial_q, &mut trial_load, Some(c0 + pos + dh));
        if let Some(v) = s.extrapolated.take() {
            d_ex = v;
        }
        // With extrapolated damage: how far the law's update departs from the damage used.
        let departure = match (solved, explicit) {
            (Some(_), Some(_)) => {
                s.trial.points.iter().zip(&d_ex).map(|(st, d)| (st.damage - d).abs()).fold(0.0, f64::max)
            }
            _ => 0.0,
        };
        if let (Some(_), Some((tolerance, min_fraction))) = (solved, explicit) {
            let floor = (spacing * min_fraction).max(h_min);
            if departure > tolerance && dh > floor * (1.0 + 1e-9) {
                s.stats.cuts += 1;
                h = (0.5 * dh).max(floor);
                continue;
            }
        }
        match solved {
            Some(it) => {
                // Energies of the step, point by point.
                let d_old = displacement(&q);
                let d_new = displacement(&trial_q);
                totals.external += 0.5 * (load + trial_load) * (d_new - d_old);
                let c = p.compliance;
                for (ip, pt) in p.points.iter().enumerate() {
                    let w = if explicit.is_some() {
                        // Linear within the step: the trapezoidal rule on the total gap.
                        let (g0, t0) = (committed.gaps[ip], committed.tractions[ip]);
                        let (g1, t1) = (s.trial.gaps[ip], s.trial.tractions[ip]);
                        0.5 * (t0 + t1).dot(&(g1 - g0))
                    } else {
                        let (g0, t0) = (committed.law_gaps[ip], committed.tractions[ip]);
                        let (g1, t1) = (s.trial.law_gaps[ip], s.trial.tractions[ip]);
                        let before = &committed.points[ip];
                        let after = &s.trial.points[ip];
                        let mut w = if after != before {
                            path_work(law, before, (g0, t0), (g1, t1), after, None)
                        } else {
                            0.5 * (t0 + t1).dot(&(g1 - g0))
                        };
                        if s.with_compliance {
                            w +=
                                0.5 * (c[0] * (t1[0] * t1[0] - t0[0] * t0[0]) + c[1] * (t1[1] * t1[1] - t0[1] * t0[1]));
                        }
                        w
                    };
                    totals.interface_work += pt.area * pt.factor * w;
                }
                for fe in &s.fibre_elements {
                    for (k, f) in s.prepared[fe.fl][fe.section].iter().enumerate() {
                        let i = fe.first + k;
                        let w = f.material.step_work(
                            &committed.fibres[i],
                            (committed.strains[i], committed.stresses[i]),
                            (s.trial.strains[i], s.trial.stresses[i]),
                        );
                        totals.material_work += f.area * fe.len * w;
                    }
                }
                for (d, st) in d_prev.iter_mut().zip(&committed.points) {
                    *d = st.damage;
                }
                prev_q.copy_from_slice(&q);
                prev_load = load;
                q.copy_from_slice(&trial_q);
                load = trial_load;
                // The trial history becomes the committed one; the old committed vectors are the
                // next step's trial, which the step's first assembly overwrites in full.
                std::mem::swap(&mut committed, &mut s.trial);
                s.stats.steps += 1;
                pos += dh;
                h_prev = dh;
                let easy = explicit.is_none_or(|(tolerance, _)| departure <= 0.25 * tolerance);
                if it <= 4 && easy {
                    h = (2.0 * h).min(spacing);
                } else if it >= 8 {
                    h = (0.5 * h).max(h_min);
                }
                // States are recorded on the output grid and, in between, whenever another point
                // has failed (the debonding front's progress through a load drop).
                let now_failed = committed.points.iter().filter(|st| st.damage >= path.damage_threshold).count();
                let on_grid = (next - pos).abs() <= eps;
                if on_grid {
                    pos = next;
                    k_out += 1;
                }
                if on_grid || now_failed != failed {
                    failed = now_failed;
                    if record(&s, &committed, &q, load, &totals, &mut rows, observe) {
                        break;
                    }
                }
            }
            None => {
                s.stats.cuts += 1;
                if dh <= h_min * (1.0 + 1e-9) {
                    return Err(fail(
                        rows,
                        format!("no convergence at control {:.6} with steps down to {h_min:.3e}", pos + dh),
                    ));
                }
                h = (0.5 * dh).max(h_min);
                h_prev = 0.0;
            }
        }
    }
    s.stats.assemblies = s.stats.assemblies.max(1);
    Ok((rows, s.stats))
}

/// Checks that `law` unloads along its secant, `T = (1 − D) K ⟨g⟩` with its initial stiffness
/// `K` (what [`DamageUpdate::Extrapolated`] assumes), at a few damaged mixed-mode states.
fn check_secant_unloading(law: &dyn CohesiveLaw) -> Result<(), String> {
    let [kn, kt] = law.initial_stiffness();
    let [sn, st] = strengths(law);
    let init = law.initial_state();
    for (a, b) in [(1.5, 0.0), (0.0, 1.5), (1.2, 1.2), (0.0, 3.0), (-1.0, 2.0)] {
        let g = Gap::new(a * sn / kn, b * st / kt);
        let ev = law.evaluate(&g, &init);
        let intact = 1.0 - ev.state.damage;
        let expected = Traction::new(if g[0] > 0.0 { intact * kn } else { kn } * g[0], intact * kt * g[1]);
        let back = law.evaluate(&(g * 0.5), &ev.state);
        let unloaded = expected * 0.5;
        let scale = expected.norm().max(1e-9 * (sn + st));
        if (ev.traction - expected).norm() > 1e-6 * scale || (back.traction - unloaded).norm() > 1e-6 * scale {
            return Err(format!(
                "extrapolated damage needs a law that unloads along its secant T = (1 − D) K g; this one does not \
                 (at the gap ({:.4e}, {:.4e}) mm)",
                g[0], g[1]
            ));
        }
    }
    Ok(())
}
