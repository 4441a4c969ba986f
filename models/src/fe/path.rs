//! Path following: adaptive displacement control that lands exactly on an output grid, with a
//! dissipation-controlled detour through snap-backs.
//!
//! * **Displacement control.** The control unknown advances towards the next output abscissa in
//!   steps that double after fast convergence and halve after a failure. The predictor
//!   extrapolates the last increment; with the segment rule ([`RunOptions::interface`]) it also
//!   translates the solution near the crack front by the front's extrapolated advance
//!   (`shift_predictor`: a cohesive zone travels with its shape, which no linear extrapolation of
//!   the unknowns represents), so Newton starts within its quadratic basin even when the front
//!   crosses dozens of points in a step. Every output abscissa is hit exactly, so a response read
//!   at those abscissae is an equilibrium state, not an interpolation between adaptively placed
//!   steps: this keeps responses smooth in the parameters (finite-difference Jacobians).
//! * **Snap-back.** When displacement control cannot proceed even at the smallest step, the
//!   equilibrium path turns back in the control displacement. With the nodal rule a cohesive
//!   crack does this once per point; with segments only a genuinely unstable structure does. The
//!   solver then switches to the dissipation constraint (released energy per step prescribed,
//!   Gutiérrez 2004; Verhoosel, Remmers & Gutiérrez 2009), which follows snap-backs because
//!   dissipation only increases, with the released energy adapted to give control increments of
//!   about half an output spacing. With the nodal rule it stays there while the crack runs; with
//!   segments it returns to displacement control after every forward step. It ends on the target
//!   under displacement control; if the target lies inside an unstable stretch, or dissipation
//!   control itself stalls or creeps ([`CREEP_STEPS`] steps in a row that move neither the control
//!   nor the load), it jumps over the stretch under displacement control (the recorded states are
//!   still equilibria).
//! * **Window.** With [`RunOptions::window`] a problem that fits is solved by `fe::window`
//!   (displacement control on the unknowns around the crack front only); anything else, and any
//!   run the window gives up on, by the whole-mesh solver here, which goes on from the window's
//!   last committed state when the window gave up part way (and starts again from rest if it
//!   cannot go on from there: the window never fails a run the whole mesh completes).
//! * A run that still fails returns the error and every row that converged.

use std::rc::Rc;

use czid_core::{CohesiveLaw, CzError, Gap, LawEval, LawState, Traction};

use super::assembly::{FeProblem, InterfaceRule};
use super::crack::{self, CrackMeasures};
use super::energy::{self, Ledger};
use super::fine_zone::FineZone;
use super::interface::{PointKind, SIDE};
use super::newton::{Newton, StepFailure};
use super::run_types::{separated, FrontTrack, PathFailure, PathSettings, Resume, RunOptions, RunStats, StepRow};

struct State {
    q: Vec<f64>,
    states: Vec<LawState>,
    reaction: f64,
}

/// Runs problem `p` with `law` along the path described by `s` (nodal interface rule, every
/// converged step recorded).
pub fn run(p: &FeProblem, law: &dyn CohesiveLaw, s: &PathSettings) -> Result<(Vec<StepRow>, RunStats), PathFailure> {
    run_with(p, law, s, &RunOptions::default())
}

/// [`run`] with the choices of `o`: on the window around the crack front when asked and the
/// problem fits, else on the whole mesh (displacement control, with dissipation-controlled
/// detours through snap-backs).
pub fn run_with(
    p: &FeProblem,
    law: &dyn CohesiveLaw,
    s: &PathSettings,
    o: &RunOptions,
) -> Result<(Vec<StepRow>, RunStats), PathFailure> {
    run_tuned(p, law, s, o, true)
}

/// [`run_with`], the whole mesh's chord steps on or off ([`Newton::chord`]).
pub(crate) fn run_tuned(
    p: &FeProblem,
    law: &dyn CohesiveLaw,
    s: &PathSettings,
    o: &RunOptions,
    chord: bool,
) -> Result<(Vec<StepRow>, RunStats), PathFailure> {
    let (mut fallback, mut resume) = (None, None);
    if o.window && o.interface == InterfaceRule::Segments {
        match super::window::run(p, law, s) {
            Ok((rows, mut stats)) => {
                stats.windowed = true;
                return Ok((rows, stats));
            }
            Err((why, state)) => (fallback, resume) = (Some(why.reason()), state),
        }
    }
    let resumed = resume.is_some();
    match whole_mesh(p, law, s, o, chord, fallback, resume) {
        // Where the whole mesh cannot go on from the window's state (a path through a snap-back
        // that its own steps from rest would have taken otherwise), it starts again from rest: the
        // window never makes a run fail that the whole mesh completes.
        Err(_) if resumed => whole_mesh(p, law, s, o, chord, fallback, None),
        done => done,
    }
}

/// The whole-mesh solve of [`run_tuned`], from rest or from the state a windowed run reached.
fn whole_mesh(
    p: &FeProblem,
    law: &dyn CohesiveLaw,
    s: &PathSettings,
    o: &RunOptions,
    chord: bool,
    fallback: Option<&'static str>,
    resume: Option<Box<Resume>>,
) -> Result<(Vec<StepRow>, RunStats), PathFailure> {
    let mut run = WholeMesh::new(p, law, s, o, fallback);
    run.nw.chord = chord;
    if !(s.target.is_finite() && s.target != 0.0 && s.outputs > 0) {
        return Err(run.fail("the path needs a finite, non-zero target and at least one output".into()));
    }
    let mut path = Control::new(s);
    if let Some(state) = resume {
        run.resume(*state, &mut path);
    }
    while path.pos < path.target - path.eps && !run.separated {
        if run.stats.steps > path.max_steps {
            let msg = format!("gave up after {} steps at control {:.6}", run.stats.steps, path.dir * path.pos);
            return Err(run.fail(msg));
        }
        if path.dissipating {
            run.dissipation_step(&mut path)?;
        } else {
            run.displacement_step(&mut path)?;
        }
    }
    Ok(run.finish())
}

/// Where the path stands along the control unknown, and how the next step is chosen.
struct Control {
    /// Sign of the target.
    dir: f64,
    /// Output spacing (absolute control).
    spacing: f64,
    /// Smallest displacement step before switching to dissipation control.
    h_min: f64,
    /// `|target|`.
    target: f64,
    /// Tolerance on landing on an output abscissa.
    eps: f64,
    /// Step cap of the run.
    max_steps: usize,
    /// Signed progress along the control unknown.
    pos: f64,
    /// Next displacement step and the last one taken.
    h: f64,
    h_prev: f64,
    /// Index of the next output abscissa.
    k_out: usize,
    /// Following the path by dissipation (a snap-back) rather than by displacement.
    dissipating: bool,
    /// After a detour through dissipation control, one failed displacement step sends the path
    /// straight back (no step halving): the snap-backs of a propagating crack come one per node.
    quick_fallback: bool,
    /// Released energy per dissipation step.
    tau: f64,
    /// Load increment and released energy of the last dissipation step (its predictor).
    last: Option<(f64, f64)>,
    /// Control increment of the last dissipation step that moved forward (0: none).
    dc_last: f64,
    /// Dissipation steps retried because they would end beyond the target.
    overshoots: usize,
    /// Forward dissipation steps in a row that moved neither the control nor the load
    /// ([`CREEP_STEPS`]).
    creep: usize,
}

impl Control {
    fn new(s: &PathSettings) -> Self {
        let spacing = s.target.abs() / s.outputs as f64;
        Control {
            dir: s.target.signum(),
            spacing,
            h_min: spacing * s.min_step_fraction,
            target: s.target.abs(),
            eps: 1e-12 * spacing,
            max_steps: 200 * s.outputs + 20_000,
            pos: 0.0,
            h: spacing,
            h_prev: 0.0,
            k_out: 1,
            dissipating: false,
            quick_fallback: false,
            tau: 0.0,
            last: None,
            dc_last: 0.0,
            overshoots: 0,
            creep: 0,
        }
    }

    /// Back to displacement control after a forward dissipation step or a jump.
    fn resume_displacement(&mut self) {
        self.dissipating = false;
        self.quick_fallback = true;
        self.h = (0.5 * self.spacing).max(self.h_min);
        self.h_prev = 0.0;
    }
}

/// The problem a whole-mesh run solves: the one it was given, or that one coarse away from the
/// crack front (`fe::fine_zone`).
#[derive(Clone)]
enum Problem<'a> {
    Given(&'a FeProblem),
    Coarsened(Rc<FeProblem>),
}

impl std::ops::Deref for Problem<'_> {
    type Target = FeProblem;
    fn deref(&self) -> &FeProblem {
        match self {
            Problem::Given(p) => p,
            Problem::Coarsened(p) => p,
        }
    }
}

/// The whole-mesh solver's state: the problem, Newton, the committed solution and what has been
/// recorded of it.
struct WholeMesh<'a> {
    /// The problem the run was given, and the one it solves (with a fine zone, a part of it).
    base: &'a FeProblem,
    p: Problem<'a>,
    /// Under large rotations, the zone around the crack front where the mesh is fine.
    zone: Option<FineZone>,
    law: &'a dyn CohesiveLaw,
    s: &'a PathSettings,
    o: &'a RunOptions,
    nw: Newton,
    segments: bool,
    /// Steps double after convergence in at most `grow_below` iterations and halve from
    /// `shrink_above` on.
    grow_below: usize,
    shrink_above: usize,
    mode_one: Option<super::segment::ModeOne>,
    cur: State,
    prev_q: Vec<f64>,
    trial: Vec<f64>,
    ledger: Ledger,
    stats: RunStats,
    rows: Vec<StepRow>,
    measures: Measures,
    /// Dissipated energy at the last commit, and the last positive increment of it (the released
    /// energy a dissipation step starts from).
    last_diss: f64,
    tau_hint: f64,
    front: FrontTrack,
    /// Largest elastic energy recorded so far, and whether the specimen has come apart
    /// ([`PathSettings::end_at_separation`]).
    most_elastic: f64,
    separated: bool,
    /// Gone on from a windowed run's state ([`WholeMesh::resume`]): the rows carry no shear work
    /// (the window does not count it).
    resumed: bool,
    /// Under large rotations, the intact part far ahead of the crack front left out of the solve.
    cut: Option<Cut>,
}

/// Under large rotations the whole mesh is solved (the co-rotational arms cannot be condensed),
/// but the intact interface far ahead of the front carries next to nothing: on its elastic
/// foundation the arm's deflection decays over about `λ = (4 EI / (K₀ b))^{1/4}`. The nodes more
/// than [`CUT_DECAY_LENGTHS`] λ ahead of the onset front stay at rest and the structure is cut
/// there (a free end: the symmetry plane carries no shear, so the far part only translates along
/// the axis with the cut, which it is made to do). The cut moves on with the front, and the run
/// continues on the whole mesh once it reaches the far end. On Hartlen's DCB-01..03 the records
/// agree with the whole mesh's within 3 × 10⁻⁹ of the peak load (Newton's tolerance; with 20 λ
/// within 1.6 × 10⁻⁷, with 15 λ 1.1 × 10⁻⁵).
struct Cut {
    /// [`CUT_DECAY_LENGTHS`] decay lengths (mm).
    margin: f64,
    /// First node left out (`usize::MAX`: none).
    from_node: usize,
    /// The cut has reached the far end: the rest of the run is on the whole mesh.
    reached_end: bool,
    /// Every node from this one on has only unknowns numbered after the previous nodes', and no
    /// fixed, spring or control unknown, and its interface points are cohesive on a symmetry plane.
    first_allowed: usize,
    /// First unknown of each node.
    first_dof: Vec<usize>,
}

/// Decay lengths `λ` of the arm on its elastic interface between the onset front and the cut.
const CUT_DECAY_LENGTHS: f64 = 25.0;

/// Forward dissipation steps in a row that move the control by less than [`CREEP_CONTROL`] of the
/// output spacing and the load by less than [`CREEP_LOAD`] of itself before the path jumps over
/// the stretch. Such steps release their energy at a standstill: where Newton cycles at a point
/// of the interface (a coarse point at its elastic limit), neither control converges on a longer
/// step, and one ENF run took 4600 of them (13 s, about 1.6 µm each) before the released energy
/// fell low enough for the jump. A snap-back moves the load in every step.
pub const CREEP_STEPS: usize = 20;
/// See [`CREEP_STEPS`].
pub const CREEP_CONTROL: f64 = 1e-3;
/// See [`CREEP_STEPS`].
pub const CREEP_LOAD: f64 = 1e-4;

impl Cut {
    /// The cut for `p` under `law`, if the problem has the structure it needs (large rotations,
    /// segments, one layer per node range numbered node by node, interface points on a symmetry
    /// plane).
    fn of(p: &FeProblem, law: &dyn CohesiveLaw, segments: bool) -> Option<Cut> {
        use super::mesh::NONE;
        if !p.large_rotation || !segments {
            return None;
        }
        let mesh = &p.mesh;
        let nn = mesh.x.len();
        let dofs = |j: usize| (0..mesh.layers.len()).flat_map(move |l| mesh.dofs(l, j)).filter(|&d| d != NONE);
        let first_dof: Vec<usize> = (0..nn).map(|j| dofs(j).min().unwrap_or(usize::MAX)).collect();
        let mut node_of = vec![0usize; mesh.n_dofs()];
        for j in 0..nn {
            for d in dofs(j) {
                node_of[d] = j;
            }
        }
        // The last node that must stay: numbering out of order, held or loaded unknowns, points
        // that are not cohesive on a symmetry plane.
        let mut last_needed = 0usize;
        for j in 0..nn.saturating_sub(1) {
            let last = dofs(j).max().unwrap_or(0);
            if first_dof[j + 1] == usize::MAX || last >= first_dof[j + 1] {
                last_needed = last_needed.max(j + 1);
            }
        }
        let node = |d: usize| if d == NONE || d >= node_of.len() { 0 } else { node_of[d] };
        for &d in p.fixed.iter().chain(std::iter::once(&p.control)) {
            last_needed = last_needed.max(node(d));
        }
        for sp in &p.springs {
            last_needed = last_needed.max(node(sp.i)).max(node(sp.j));
        }
        for pt in &p.points {
            if pt.kind != PointKind::Cohesive || pt.lower.is_some() {
                last_needed = last_needed.max(pt.node);
            }
        }
        let k0 = law.initial_stiffness()[0];
        let lambda =
            mesh.layers.iter().map(|l| (4.0 * l.section.ei() / (k0 * l.section.b)).powf(0.25)).fold(0.0f64, f64::max);
        if !(k0 > 0.0 && lambda.is_finite() && lambda > 0.0) {
            return None;
        }
        Some(Cut {
            margin: CUT_DECAY_LENGTHS * lambda,
            from_node: usize::MAX,
            reached_end: false,
            first_allowed: last_needed + 2,
            first_dof,
        })
    }
}

/// Work arrays of the crack measures.
struct Measures {
    cohesive: Vec<usize>,
    xs: Vec<f64>,
    dmg: Vec<f64>,
    point_stored: Vec<f64>,
    scratch: Vec<f64>,
}

impl Measures {
    fn of(p: &FeProblem) -> Self {
        let np = p.points.len();
        let cohesive: Vec<usize> = (0..np).filter(|&i| p.points[i].kind == PointKind::Cohesive).collect();
        let xs: Vec<f64> = cohesive.iter().map(|&i| p.mesh.x[p.points[i].node]).collect();
        Measures {
            dmg: vec![0.0; cohesive.len()],
            point_stored: vec![0.0; np],
            scratch: vec![0.0; cohesive.len()],
            cohesive,
            xs,
        }
    }
}

impl<'a> WholeMesh<'a> {
    fn new(
        base: &'a FeProblem,
        law: &'a dyn CohesiveLaw,
        s: &'a PathSettings,
        o: &'a RunOptions,
        fallback: Option<&'static str>,
    ) -> Self {
        let segments = o.interface == InterfaceRule::Segments;
        let (problem, zone) = match o.fine_zone && segments {
            true => match FineZone::of(base, law, s.crack_origin) {
                Some((zone, p)) => (Problem::Coarsened(Rc::new(p)), Some(zone)),
                None => (Problem::Given(base), None),
            },
            false => (Problem::Given(base), None),
        };
        let p = problem.clone();
        let p = &*p;
        let mut nw = Newton::with_rule(p, law, s.newton, o.interface);
        // With segments, forces are continuous and a good predictor leaves Newton in its basin: the
        // branch-cycling safeguard of the nodal rule only slows it down.
        nw.safeguard = o.interface == InterfaceRule::Nodal;
        // Steps double after convergence in at most this many iterations. With segments a crack front
        // crossing many points per step is normal work for Newton (typically 4-5 quadratically
        // converging iterations), not a sign that the step is too long.
        let (grow_below, shrink_above) = if segments { (5, 9) } else { (3, 7) };
        let mode_one = if segments { super::segment::ModeOne::of(law) } else { None };
        let n = nw.asm.n();
        let np = p.points.len();
        let measures = Measures::of(p);
        let init = law.initial_state();
        WholeMesh {
            base,
            p: problem,
            zone,
            law,
            s,
            o,
            nw,
            segments,
            grow_below,
            shrink_above,
            mode_one,
            cur: State { q: vec![0.0; n], states: vec![init; np], reaction: 0.0 },
            prev_q: vec![0.0; n],
            trial: vec![0.0; n],
            ledger: Ledger::new(np),
            stats: RunStats { window_fallback: fallback, ..Default::default() },
            rows: vec![StepRow {
                crack: CrackMeasures { tip: s.crack_origin, ..Default::default() },
                shear_work: Some(0.0),
                ..Default::default()
            }],
            measures,
            last_diss: 0.0,
            tau_hint: 0.0,
            front: FrontTrack::default(),
            most_elastic: 0.0,
            separated: false,
            resumed: false,
            cut: if o.cut_far_field { Cut::of(p, law, segments) } else { None },
        }
    }

    /// Moves the cut (large rotations) to the margin ahead of the front, never back; none in the
    /// first step, which sets every point's results on the whole mesh.
    fn place_cut(&mut self) {
        let Some(cut) = self.cut.as_mut() else { return };
        if self.stats.steps == 0 {
            return;
        }
        let front = if self.front.x.is_finite() { self.front.x.max(self.s.crack_origin) } else { self.s.crack_origin };
        let xs = &self.p.mesh.x;
        let node = xs.partition_point(|&x| x < front + cut.margin).max(cut.first_allowed);
        if cut.reached_end {
            return;
        }
        if node >= xs.len() {
            // The front has come within the margin of the far end: the whole mesh from now on.
            cut.reached_end = true;
            cut.from_node = usize::MAX;
        } else if cut.from_node == usize::MAX || node > cut.from_node {
            cut.from_node = node;
        }
        let (from, active) = match cut.from_node {
            usize::MAX => (usize::MAX, self.cur.q.len()),
            f => (f, cut.first_dof[f]),
        };
        self.nw.frozen_from_node = from;
        self.nw.active = active;
    }

    /// The part beyond the cut translates along the axis with the node before it (in `trial`,
    /// from the committed state).
    fn follow_cut(&mut self) {
        use super::mesh::NONE;
        let Some(cut) = self.cut.as_ref() else { return };
        let f = cut.from_node;
        if f == usize::MAX || f == 0 {
            return;
        }
        let mesh = &self.p.mesh;
        for layer in 0..mesh.layers.len() {
            let d = mesh.dofs(layer, f - 1)[0];
            if d == NONE {
                continue;
            }
            let du = self.trial[d] - self.cur.q[d];
            for j in f..mesh.x.len() {
                let dj = mesh.dofs(layer, j)[0];
                if dj != NONE {
                    self.trial[dj] = self.cur.q[dj] + du;
                }
            }
        }
    }

    /// Goes on from the state a windowed run reached before it gave up, instead of from rest: the
    /// window's rows and counters are kept, and the ledger starts from the whole mesh's own view of
    /// that state (its law results, gaps and stored energy there), so that the dissipated energy
    /// goes on from the window's. Where the window could not take even its smallest step, the path
    /// turns back, and the run goes on under the dissipation constraint at once. Left as it was
    /// if the whole mesh cannot evaluate the state.
    fn resume(&mut self, r: Resume, c: &mut Control) {
        let Problem::Given(p) = self.p.clone() else { return };
        let law = self.law;
        if r.q.len() != self.cur.q.len() || r.states.len() != p.points.len() {
            return;
        }
        if !self.nw.asm.assemble(p, law, &r.states, &r.q, Some(&mut self.nw.k), &mut self.nw.f, false) {
            return;
        }
        self.prev_q.copy_from_slice(&r.q);
        self.cur = State { q: r.q, states: r.states, reaction: r.reaction };
        let stored = self.segments_stored(p, law);
        let tractions = self.nw.asm.trial.iter().map(|ev| ev.traction).collect();
        self.ledger = Ledger::resumed(r.external_work, r.dissipated + stored, tractions, self.nw.asm.gaps.to_vec());
        self.most_elastic = r.rows.iter().map(|row| row.elastic_energy).fold(0.0, f64::max);
        self.rows = r.rows;
        self.last_diss = r.dissipated;
        self.tau_hint = r.dissipation_hint;
        self.front = r.front;
        self.stats =
            RunStats { window_fallback: Some(r.reason), windowed: false, resumed_from_window: true, ..r.stats };
        self.nw.counters = (r.stats.assemblies, r.stats.factorizations);
        self.resumed = true;
        c.pos = r.pos;
        c.h = r.h.min(c.spacing);
        c.h_prev = 0.0;
        c.k_out = r.k_out;
        if r.snap_back && self.tau_hint > 0.0 {
            c.dissipating = true;
            c.tau = self.tau_hint;
            c.last = None;
        }
    }

    /// The interface's recoverable energy at the last assembly with the committed states,
    /// integrated along the segments like the forces (the window's resume needs it as well as
    /// every commit).
    fn segments_stored(&mut self, p: &FeProblem, law: &dyn CohesiveLaw) -> f64 {
        for (i, v) in self.measures.point_stored.iter_mut().enumerate() {
            let g = &self.nw.asm.gaps[i];
            *v = match p.points[i].kind {
                PointKind::Cohesive => law.stored_energy(g, &self.cur.states[i]),
                PointKind::Contact => super::interface::contact_stored(&self.nw.asm.trial[i], g),
            };
        }
        self.nw.asm.interface_stored(p, &self.measures.point_stored)
    }

    /// The run's failure with every row recorded so far.
    fn fail(&mut self, msg: String) -> PathFailure {
        PathFailure { error: CzError::Simulation(msg), rows: std::mem::take(&mut self.rows) }
    }

    fn finish(mut self) -> (Vec<StepRow>, RunStats) {
        self.stats.assemblies = self.nw.counters.0;
        self.stats.factorizations = self.nw.counters.1;
        (self.rows, self.stats)
    }

    /// One step under displacement control towards the next output abscissa; on failure, a
    /// shorter step or the switch to dissipation control.
    fn displacement_step(&mut self, c: &mut Control) -> Result<(), PathFailure> {
        self.place_cut();
        let (p, law, s, ic) = (self.p.clone(), self.law, self.s, self.p.control);
        let p = &*p;
        while c.k_out < s.outputs && c.spacing * c.k_out as f64 <= c.pos + c.eps {
            c.k_out += 1;
        }
        let next = if c.k_out >= s.outputs { c.target } else { c.spacing * c.k_out as f64 };
        let dh = c.h.min(next - c.pos);
        // Predictor: extrapolate the last increment.
        let alpha = if c.h_prev > 0.0 { dh / c.h_prev } else { 0.0 };
        for i in 0..self.trial.len() {
            self.trial[i] = self.cur.q[i] + alpha * (self.cur.q[i] - self.prev_q[i]);
        }
        if let Some(da) = self.front.advance(c.dir * dh) {
            shift_predictor(p, &self.cur.q, &mut self.trial, self.front.x, da, self.front.zone());
        }
        self.trial[ic] = c.dir * (c.pos + dh);
        if p.large_rotation {
            axial_predictor(p, &self.cur.q, &mut self.trial);
        }
        match self.nw.solve_displacement(p, law, &self.cur.states, &mut self.trial) {
            Ok(it) => {
                let reaction = self.nw.f[ic];
                let lands = (next - (c.pos + dh)).abs() <= c.eps;
                self.commit(reaction, !self.o.outputs_only || lands);
                c.pos = if (next - (c.pos + dh)).abs() <= c.eps { next } else { c.pos + dh };
                c.h_prev = dh;
                c.quick_fallback = false;
                c.creep = 0;
                if it <= self.grow_below {
                    c.h = (2.0 * c.h).min(c.spacing);
                } else if it >= self.shrink_above {
                    c.h *= 0.5;
                }
            }
            Err(e) => {
                self.stats.cuts += 1;
                c.h = 0.5 * dh;
                if c.h >= c.h_min && !c.quick_fallback {
                    return Ok(());
                }
                // Snap-back (or a genuinely hard step): follow the path by dissipation. That
                // needs a loaded, dissipating state; without one no snap-back is possible and
                // the failure is genuine.
                if !(self.tau_hint > 0.0 && self.cur.reaction != 0.0 && self.cur.q[ic] != 0.0) {
                    let msg = format!(
                        "no convergence at control {:.6} ({e:?}) even with steps of {:.3e}, and nothing has \
                         dissipated yet, so no snap-back to follow",
                        c.dir * (c.pos + dh),
                        dh
                    );
                    return Err(self.fail(msg));
                }
                c.dissipating = true;
                if c.tau <= 0.0 || !c.quick_fallback {
                    c.tau = self.tau_hint;
                }
                c.last = None;
            }
        }
        Ok(())
    }

    /// One step under the dissipation constraint (through a snap-back); when it cannot be met
    /// even with tiny increments, a jump over the unstable stretch.
    fn dissipation_step(&mut self, c: &mut Control) -> Result<(), PathFailure> {
        self.place_cut();
        let (p, law, ic) = (self.p.clone(), self.law, self.p.control);
        let p = &*p;
        let c0 = self.cur.q[ic];
        let l0 = self.cur.reaction;
        // Do not jump past the target: the run must end exactly on it.
        let tau_try = if c.dc_last > 0.0 && c.pos + c.dc_last * 1.5 > c.target {
            c.tau * (0.5 * (c.target - c.pos) / c.dc_last).clamp(0.05, 1.0)
        } else {
            c.tau
        };
        let mut lam = l0;
        self.trial.copy_from_slice(&self.cur.q);
        if let Some((dl_prev, tau_prev)) = c.last {
            let beta = tau_try / tau_prev;
            for i in 0..self.trial.len() {
                self.trial[i] += beta * (self.cur.q[i] - self.prev_q[i]);
            }
            lam += beta * dl_prev;
        }
        match self.nw.solve_dissipation(p, law, &self.cur.states, &mut self.trial, &mut lam, c0, l0, tau_try) {
            Ok(_) if c.dir * self.trial[ic] > c.target + c.eps && c.overshoots < 3 => {
                // Would end beyond the target: retry with a smaller increment so the run ends
                // on the target under displacement control. If the target lies inside a
                // snap-back no forward step can stop there; the run then ends just beyond it.
                c.tau *= 0.25;
                c.last = None;
                c.overshoots += 1;
                self.stats.cuts += 1;
            }
            Ok(it) => {
                // Weigh the step before accepting it: the constraint measures released energy by
                // the secant rule, exact for a linear-elastic unloading; a non-linear elastic
                // response (contact on the cracked faces of an ENF) meets it on a branch that
                // dissipates nothing, and unloading along it describes no test. Such a step is
                // refused and the unstable stretch jumped over instead.
                let mut ledger = self.ledger.clone();
                let energies = self.ledger_to_trial(&mut ledger, lam);
                if energies.0 - self.last_diss <= 0.01 * tau_try {
                    self.stats.cuts += 1;
                    return self.jump_over(c);
                }
                self.accept(lam, true, ledger, energies);
                self.stats.dissipation_steps += 1;
                c.last = Some((lam - l0, tau_try));
                let dc = (self.cur.q[ic] - c0).abs();
                c.dc_last = dc * tau_ratio_guard(c.dir * (self.cur.q[ic] - c0));
                c.pos = c.dir * self.cur.q[ic];
                let standstill = dc < CREEP_CONTROL * c.spacing && (lam - l0).abs() < CREEP_LOAD * l0.abs();
                c.creep = if standstill { c.creep + 1 } else { 0 };
                if c.creep >= CREEP_STEPS {
                    c.creep = 0;
                    return self.jump_over(c);
                }
                // Aim at steps of about half the output spacing in the control.
                if it <= 4 && dc > 0.0 {
                    c.tau *= (0.5 * c.spacing / dc).clamp(0.5, 2.0);
                } else if it >= self.shrink_above {
                    c.tau *= 0.6;
                }
                // Stay on dissipation control while the crack runs (each node that fails is a
                // small snap-back for displacement control); return to displacement control to
                // end exactly at the target, or when nothing dissipates any more.
                // With segments a snap-back is genuine, not one per point: go back to
                // displacement control after every forward step.
                let near_end = c.pos + c.spacing >= c.target;
                if c.dir * (self.cur.q[ic] - c0) > 0.0 && (near_end || self.segments) {
                    c.resume_displacement();
                }
            }
            Err(_) => {
                self.stats.cuts += 1;
                c.tau *= 0.5;
                c.last = None;
                if c.tau < 1e-12 * self.ledger.external_work.abs().max(1e-300) {
                    return self.jump_over(c);
                }
            }
        }
        Ok(())
    }

    /// Last resort when the dissipation constraint cannot be met: jump over the unstable stretch
    /// under displacement control (the states recorded are still equilibria; the skipped part is
    /// not).
    fn jump_over(&mut self, c: &mut Control) -> Result<(), PathFailure> {
        let (p, law, ic) = (self.p.clone(), self.law, self.p.control);
        let p = &*p;
        for k in 1..=4 {
            // (may end beyond the target when it lies inside the unstable stretch)
            let dh = 0.5 * c.spacing * k as f64;
            self.trial.copy_from_slice(&self.cur.q);
            self.trial[ic] = c.dir * (c.pos + dh);
            if self.nw.solve_displacement(p, law, &self.cur.states, &mut self.trial).is_ok() {
                let reaction = self.nw.f[ic];
                self.commit(reaction, true);
                c.pos += dh;
                c.resume_displacement();
                c.tau = self.tau_hint.max(c.tau);
                return Ok(());
            }
        }
        let msg = format!(
            "no convergence at control {:.6}: displacement control failed and the dissipation \
             constraint could not be met with increments down to {:.3e} N·mm",
            c.dir * c.pos,
            c.tau
        );
        Err(self.fail(msg))
    }

    /// Brings `ledger` from the committed state to the trial solution with load `reaction` and
    /// returns the interface's energies there: dissipated (the work done on it less what it
    /// stores) and stored, point by point. The committed state is not touched, so a trial can be
    /// weighed before it is accepted.
    fn ledger_to_trial(&self, ledger: &mut Ledger, reaction: f64) -> (f64, f64) {
        let (p, law, ic) = (self.p.clone(), self.law, self.p.control);
        let p = &*p;
        let (t, g) = (&self.nw.asm.trial, &self.nw.asm.gaps);
        let (dc, r_old) = (self.trial[ic] - self.cur.q[ic], self.cur.reaction);
        if self.segments {
            ledger.commit_along(&p.points, law, &self.cur.states, t, g, dc, r_old, reaction, self.mode_one.as_ref());
        } else {
            ledger.commit(&p.points, t, g, dc, r_old, reaction);
        }
        let stored = energy::interface_stored(&p.points, law, t, g);
        (ledger.interface_work - stored, stored)
    }

    /// Accepts the trial solution with `reaction` as its load: law states, energy ledger and
    /// front track move on; with `record`, a row is written.
    fn commit(&mut self, reaction: f64, record: bool) {
        let mut ledger = std::mem::take(&mut self.ledger);
        let energies = self.ledger_to_trial(&mut ledger, reaction);
        self.accept(reaction, record, ledger, energies);
    }

    /// [`WholeMesh::commit`] with the ledger already brought to the trial solution.
    fn accept(&mut self, reaction: f64, record: bool, ledger: Ledger, (dissipated, stored): (f64, f64)) {
        let (p, law, ic) = (self.p.clone(), self.law, self.p.control);
        let p = &*p;
        self.follow_cut();
        self.ledger = ledger;
        self.prev_q.copy_from_slice(&self.cur.q);
        self.cur.q.copy_from_slice(&self.trial);
        for (st, ev) in self.cur.states.iter_mut().zip(&self.nw.asm.trial) {
            *st = ev.state;
        }
        self.cur.reaction = reaction;
        // With segments the recoverable energy is integrated like the forces (the dissipation
        // stays point by point, where the work is integrated).
        let stored = if self.segments { self.segments_stored(p, law) } else { stored };
        if dissipated - self.last_diss > 0.0 {
            self.tau_hint = dissipated - self.last_diss;
        }
        self.last_diss = dissipated;
        self.stats.steps += 1;
        if self.segments {
            self.front.commit(self.cur.q[ic], &self.nw.asm.segments, &self.nw.asm.fronts);
        }
        if record {
            let structural = self.nw.asm.structural_energy(p, &self.cur.q);
            let crack = self.crack_measures();
            let elastic = structural + stored;
            self.separated = self.s.end_at_separation && separated(elastic, self.most_elastic, crack.debonded);
            self.most_elastic = self.most_elastic.max(elastic);
            self.rows.push(StepRow {
                control: self.cur.q[ic],
                reaction,
                external_work: self.ledger.external_work,
                elastic_energy: elastic,
                dissipated_energy: dissipated,
                crack,
                shear_work: (!self.resumed).then_some(self.ledger.shear_work),
            });
        }
        self.follow_front();
    }

    /// Under large rotations, moves the fine zone with the crack front when it has moved far
    /// enough (`fe::fine_zone`), carrying the committed state over to the new problem.
    fn follow_front(&mut self) {
        let Some(zone) = self.zone.as_mut() else { return };
        let onset = if self.front.x.is_finite() { self.front.x } else { self.s.crack_origin };
        let (states, evals, gaps) = (&self.cur.states, &self.nw.asm.trial, &self.nw.asm.gaps);
        let Some(m) = zone.follow(self.base, &self.p, states, evals, gaps, onset) else { return };
        let (kept, base_x) = (&zone.kept, &self.base.mesh.x);
        self.cur.q = m.carry(kept, base_x, &self.cur.q);
        self.prev_q = m.carry(kept, base_x, &self.prev_q);
        self.trial = m.carry(kept, base_x, &self.trial);
        // Inserted points: the law's state at their gap, reached from the virgin state (ahead of
        // the front they have been loaded monotonically).
        let p = &m.problem;
        let law = self.law;
        let mut hess = [[[0.0; super::interface::POINT_DOFS]; super::interface::POINT_DOFS]; 2];
        let fresh: Vec<Option<(LawEval, Gap)>> = m
            .point_of
            .iter()
            .enumerate()
            .map(|(i, o)| {
                o.is_none().then(|| {
                    let k = super::interface::kinematics(&p.mesh, &p.points[i], &self.cur.q, true, &mut hess);
                    let g = Gap::new(k.gap[0], k.gap[1]);
                    (law.evaluate(&g, &law.initial_state()), g)
                })
            })
            .collect();
        let old_states = std::mem::take(&mut self.cur.states);
        self.cur.states = m
            .point_of
            .iter()
            .zip(&fresh)
            .map(|(o, f)| match (o, f) {
                (Some(o), _) => old_states[*o],
                (None, Some((ev, _))) => ev.state,
                (None, None) => law.initial_state(),
            })
            .collect();
        self.ledger.remap_points(&m.point_of, |i| {
            fresh[i].map_or((Traction::zeros(), Gap::zeros()), |(ev, g)| (ev.traction, g))
        });
        let (counters, safeguard, chord) = (self.nw.counters, self.nw.safeguard, self.nw.chord);
        self.nw = Newton::with_rule(p, law, self.s.newton, self.o.interface);
        self.nw.counters = counters;
        self.nw.safeguard = safeguard;
        self.nw.chord = chord;
        self.measures = Measures::of(p);
        if let Some(old) = self.cut.take() {
            // The same cut on the new numbering (it only moves on).
            self.cut = Cut::of(p, law, self.segments).map(|mut cut| {
                cut.reached_end = old.reached_end;
                cut.from_node = match old.from_node {
                    usize::MAX => usize::MAX,
                    f => m.node(&zone.kept, f),
                };
                cut
            });
        }
        self.p = Problem::Coarsened(Rc::new(m.problem));
    }

    /// Debonded length, process zone and tip of the committed state: from the segments' fronts
    /// (segment rule) or from the points' damage (nodal rule).
    fn crack_measures(&mut self) -> CrackMeasures {
        let (law, s, m) = (self.law, self.s, &mut self.measures);
        if self.segments {
            let (segs, gaps, st) = (&self.nw.asm.segments, &self.nw.asm.gaps, &self.cur.states);
            crack::from_segments(segs, &self.nw.asm.fronts, law, |i| (gaps[i], &st[i]), s.crack_origin, s.debonded())
        } else {
            for (d, &i) in m.dmg.iter_mut().zip(&m.cohesive) {
                *d = self.cur.states[i].damage;
            }
            crack::measure(&m.xs, &m.dmg, s.damage_threshold, s.crack_origin, &mut m.scratch)
        }
    }
}

/// Predictor for a propagating crack: near the front a cohesive zone travels along the interface
/// with its shape nearly unchanged, which extrapolating the unknowns linearly cannot represent (it
/// superposes two fronts). Unknowns of nodes within `zone` of the front at `x` are replaced by the
/// current solution translated by the predicted advance `da` (interpolated linearly between
/// nodes); Newton then only corrects the shape.
///
/// Under large rotations the axial displacements are left to the extrapolation: there an arm's
/// axial displacement carries the shortening of its rotated length, which accumulates along the
/// arm instead of travelling with the front, and translating it put jumps at the zone's edges that
/// the axial stiffness turned into residuals as large as the internal forces (two wasted Newton
/// iterations per step, and steps cut to an eighth of the output spacing).
fn shift_predictor(p: &FeProblem, cur: &[f64], trial: &mut [f64], x: f64, da: f64, zone: f64) {
    use super::mesh::NONE;
    let xs = &p.mesh.x;
    let nn = xs.len();
    // Per node [u, w, θ]: the axial displacement only under small rotations (see above).
    let first = usize::from(p.large_rotation);
    let pair = p.large_rotation && p.mesh.layers.len() == 2;
    for i in 0..nn {
        if (xs[i] - x).abs() > zone {
            continue;
        }
        let xt = xs[i] - da;
        let j = xs.partition_point(|v| *v <= xt).clamp(1, nn - 1) - 1;
        let t = ((xt - xs[j]) / (xs[j + 1] - xs[j])).clamp(0.0, 1.0);
        if pair {
            // Two arms (a DCB with both meshed): what travels with the front is the opening, half
            // the arms' difference. Their mean is the body's motion: the specimen tilts as one arm
            // is pulled and the other held, and translating the tilt tore the arms at the zone's
            // edges, which under large rotations cost Newton its basin (about 65,000 assemblies
            // for DCB-01 to 30 mm at 60 outputs). The mean is left to the extrapolation.
            let at = |layer: usize, node: usize| p.mesh.dofs(layer, node);
            let (lo, up) = ((at(0, i), at(0, j), at(0, j + 1)), (at(1, i), at(1, j), at(1, j + 1)));
            for c in first..SIDE {
                let ds = [lo.0[c], lo.1[c], lo.2[c], up.0[c], up.1[c], up.2[c]];
                if ds.contains(&NONE) || lo.0[c] == p.control || up.0[c] == p.control {
                    continue;
                }
                let mean = 0.5 * (trial[up.0[c]] + trial[lo.0[c]]);
                let half = 0.5 * ((1.0 - t) * (cur[up.1[c]] - cur[lo.1[c]]) + t * (cur[up.2[c]] - cur[lo.2[c]]));
                trial[up.0[c]] = mean + half;
                trial[lo.0[c]] = mean - half;
            }
            continue;
        }
        for layer in 0..p.mesh.layers.len() {
            let (di, dj, dk) = (p.mesh.dofs(layer, i), p.mesh.dofs(layer, j), p.mesh.dofs(layer, j + 1));
            for c in first..SIDE {
                if di[c] != NONE && dj[c] != NONE && dk[c] != NONE && di[c] != p.control {
                    trial[di[c]] = (1.0 - t) * cur[dj[c]] + t * cur[dk[c]];
                }
            }
        }
    }
}

/// Under large rotations: the axial displacements of each layer set so that every element keeps
/// the chord stretch it has in `cur` at the predicted transverse displacements, walking from the
/// end whose axial displacement is held. A rotating arm shortens along its axis by the
/// accumulated `l (1 − cos θ)` of its elements; extrapolated, those axial displacements missed it
/// and the axial stiffness turned the difference into residuals of a hundred times the load, which
/// cost a Newton iteration in most steps (431 assemblies instead of 494 on Hartlen's DCB-01 to
/// 30 mm).
fn axial_predictor(p: &FeProblem, cur: &[f64], trial: &mut [f64]) {
    use super::mesh::NONE;
    let xs = &p.mesh.x;
    let at = |q: &[f64], d: usize| if d == NONE { 0.0 } else { q[d] };
    for (layer, l) in p.mesh.layers.iter().enumerate() {
        if !l.axial {
            continue;
        }
        // From the end whose axial displacement is held (the load point of a DCB), else from the
        // far end.
        let held = |node: usize| {
            let d = p.mesh.dofs(layer, node)[0];
            d == NONE || p.fixed.contains(&d)
        };
        let forward = held(l.first);
        let elements: Box<dyn Iterator<Item = usize>> =
            if forward { Box::new(l.first..l.last) } else { Box::new((l.first..l.last).rev()) };
        for i in elements {
            let (a, b) = (p.mesh.dofs(layer, i), p.mesh.dofs(layer, i + 1));
            let l0 = xs[i + 1] - xs[i];
            let (dx0, dy0) = (l0 + at(cur, b[0]) - at(cur, a[0]), at(cur, b[1]) - at(cur, a[1]));
            let ln = (dx0 * dx0 + dy0 * dy0).sqrt();
            let dy = at(trial, b[1]) - at(trial, a[1]);
            if dy.abs() >= ln {
                continue;
            }
            let dx = (ln * ln - dy * dy).sqrt();
            let (set, from, sign) = if forward { (b[0], a[0], 1.0) } else { (a[0], b[0], -1.0) };
            if set == NONE || set == p.control || p.fixed.contains(&set) {
                continue;
            }
            trial[set] = at(trial, from) + sign * (dx - l0);
        }
    }
}

/// A backward dissipation step (snap-back) says nothing about the forward reach of the next one.
fn tau_ratio_guard(forward: f64) -> f64 {
    if forward > 0.0 {
        1.0
    } else {
        0.0
    }
}

impl From<StepFailure> for CzError {
    fn from(e: StepFailure) -> Self {
        CzError::Simulation(format!("{e:?}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dcb::{self, Dcb};
    use crate::enf::Enf;
    use crate::laws::Bilinear;
    use crate::mmb::Mmb;

    /// Chord steps on the whole mesh (the last factorisation reused once the residual is below
    /// `CHORD_BELOW` of the forces) reach the states of full Newton steps, with fewer
    /// factorisations: Hartlen's ENF-03 at its identified law, an MMB at G_II/G = 0.5 (the runs of
    /// `benches/forward.rs`) and Hartlen's DCB-01 with large rotations to 15 mm.
    #[test]
    fn chord_steps_on_the_whole_mesh_reach_the_states_of_full_newton_steps() {
        let (enf, enf_law) = Enf::hartlen_enf03_identified();
        let (p, scale) = enf.problem(&enf_law).unwrap();
        let enf_run = (p, enf.path(&enf_law, &scale), RunOptions::segments());

        let (mmb, mmb_law) = Mmb::hartlen_half_mode_two();
        let (p, scale, lever) = mmb.build(&mmb_law).unwrap();
        let mmb_run = (p, mmb.path(&mmb_law, &scale, lever), RunOptions::segments());

        let mut d = Dcb::hartlen_dcb01();
        d.effects.large_rotation = true;
        d.control.max_displacement = Some(15.0);
        let dcb_law = Bilinear::bk(1e5, 30.0, 40.0, 0.8, 1.6, 2.0).unwrap();
        let (p, scale) = d.problem().unwrap();
        let dcb_run = (p, d.path(&dcb_law, &scale), dcb::RUN_OPTIONS);

        for (name, (p, path, options), law) in
            [("ENF-03", enf_run, &enf_law), ("MMB", mmb_run, &mmb_law), ("DCB-01, large rotations", dcb_run, &dcb_law)]
        {
            let (newton, s_newton) = run_tuned(&p, law, &path, &options, false).unwrap();
            let (chord, s_chord) = run_tuned(&p, law, &path, &options, true).unwrap();
            assert!(!s_chord.windowed, "{name}: solved on the window");
            assert_eq!(chord.len(), newton.len(), "{name}");
            let peak = newton.iter().fold(0.0f64, |m, r| m.max(r.reaction.abs()));
            let work = newton.iter().fold(0.0f64, |m, r| m.max(r.external_work.abs()));
            let (mut load, mut energy) = (0.0f64, 0.0f64);
            for (a, b) in chord.iter().zip(&newton) {
                assert_eq!(a.control, b.control, "{name}");
                load = load.max((a.reaction - b.reaction).abs() / peak);
                energy = energy.max((a.elastic_energy - b.elastic_energy).abs() / work);
                energy = energy.max((a.dissipated_energy - b.dissipated_energy).abs() / work);
                energy = energy.max((a.external_work - b.external_work).abs() / work);
            }
            println!("{name}: loads within {load:.1e} of the peak, energies {energy:.1e} of the work; {s_chord:?} against {s_newton:?}");
            assert!(load <= 1e-9, "{name}: loads differ by {load:e} of the peak");
            assert!(energy <= 1e-9, "{name}: energies differ by {energy:e} of the work");
            assert!(s_chord.factorizations < s_newton.factorizations, "{name}: {s_chord:?} against {s_newton:?}");
        }
    }
}
