//! What a path-following run is asked and what it returns, shared by the whole-mesh solver
//! ([`super::path`]) and the window solver (`super::window`): the settings of the path, the
//! recorded rows, the run's statistics and failure, and the tracking of the crack front that
//! both use to predict the next step. The types live apart from either solver so that neither
//! depends on the other's module (the whole-mesh solver calls the window; the window only needs
//! these types).

use czid_core::{CzError, LawState};

use super::assembly::InterfaceRule;
use super::crack::CrackMeasures;
use super::newton::NewtonSettings;
use super::segment::Segment;

/// How far and how finely to follow the path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSettings {
    /// Final value of the control unknown (either sign).
    pub target: f64,
    /// Number of equally spaced output abscissae between 0 and `target` (all are hit exactly).
    pub outputs: usize,
    /// Smallest displacement step, as a fraction of the output spacing, before switching to
    /// dissipation control.
    pub min_step_fraction: f64,
    /// Damage at or above which a point counts as fully debonded.
    pub damage_threshold: f64,
    /// The law's inner kink that marks the visible crack ([`czid_core::CohesiveLaw::visible_front_kink`]),
    /// for crack measures that can place a front there (the segment rule); the others use
    /// `damage_threshold`, the damage just beyond that kink ([`super::crack::visible_front_level`]).
    pub visible_kink: Option<usize>,
    /// Position of the initial crack front (reported as the tip until something debonds).
    pub crack_origin: f64,
    /// Newton settings.
    pub newton: NewtonSettings,
    /// End the run, successfully, at the first recorded state where the specimen has come apart
    /// ([`separated`]): a split DCB's arms spring back, and the states that follow describe no
    /// test (the dissipation constraint then drives the opening below zero, the arms pressed into
    /// each other with growing energy, until nothing converges). Off by default.
    pub end_at_separation: bool,
}

/// Share of the largest elastic energy so far below which a state whose crack has grown is one
/// where the specimen has come apart ([`separated`]).
pub const SEPARATED_ENERGY_SHARE: f64 = 0.01;

/// Whether a recorded state with stored elastic energy `elastic` and debonded length `debonded`,
/// after states whose largest elastic energy was `most`, is one where the specimen has come apart:
/// the crack has grown and the energy has fallen below [`SEPARATED_ENERGY_SHARE`] of `most` (the
/// arms have sprung back).
pub fn separated(elastic: f64, most: f64, debonded: f64) -> bool {
    debonded > 0.0 && elastic < SEPARATED_ENERGY_SHARE * most
}

impl PathSettings {
    /// A path to `target` with `outputs` equally spaced outputs, the crack starting at
    /// `crack_origin` (mm); the rest at their usual values (steps down to 10⁻³ of the output
    /// spacing before dissipation control, debonded meaning complete failure, default Newton
    /// settings). Change a field to depart from them.
    pub fn new(target: f64, outputs: usize, crack_origin: f64) -> Self {
        PathSettings {
            target,
            outputs,
            min_step_fraction: 1e-3,
            damage_threshold: 1.0 - 1e-9,
            visible_kink: None,
            crack_origin,
            newton: NewtonSettings::default(),
            end_at_separation: false,
        }
    }

    /// These settings with the debonded length at the law's visible front
    /// ([`czid_core::CohesiveLaw::visible_front_kink`], e.g. the matrix crack ahead of bridging
    /// fibres: what a camera sees) when that lies before complete failure, in a test of the mode
    /// `mode` (0: opening, 1: slip). A threshold below complete failure that the user chose stays.
    pub fn with_visible_front(mut self, law: &dyn czid_core::CohesiveLaw, mode: usize) -> Self {
        if self.damage_threshold >= super::crack::BELOW_FAILURE {
            if let Some(level) = super::crack::visible_front_level(law, mode) {
                self.damage_threshold = level;
                self.visible_kink = law.visible_front_kink();
            }
        }
        self
    }

    /// What the segment rule's crack measure counts as debonded.
    pub fn debonded(&self) -> super::crack::Debonded {
        match self.visible_kink {
            Some(k) => super::crack::Debonded::Kink(k),
            None => super::crack::Debonded::Damage(self.damage_threshold),
        }
    }
}

/// One converged state, in the units of the simulated part (not yet scaled by symmetry).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepRow {
    /// Control unknown.
    pub control: f64,
    /// Its reaction (work-conjugate generalised force).
    pub reaction: f64,
    /// Work of the reaction so far.
    pub external_work: f64,
    /// Strain energy of beams, springs and the interface's recoverable part.
    pub elastic_energy: f64,
    /// Energy dissipated by the interface so far.
    pub dissipated_energy: f64,
    /// Debonded length, process zone and tip along the cohesive points.
    pub crack: CrackMeasures,
    /// Work done so far by the interface's tangential tractions on the slips (the mode II part of
    /// the interface's work, recoverable energy included), when the solver tracks it: the
    /// whole-mesh solver does; the window solver does not (`None`).
    pub shear_work: Option<f64>,
}

/// Statistics of a run, for profiling and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunStats {
    /// Converged steps.
    pub steps: usize,
    /// Assemblies (Newton iterations including the final residual check).
    pub assemblies: usize,
    /// LU factorisations.
    pub factorizations: usize,
    /// Steps that had to be cut.
    pub cuts: usize,
    /// Dissipation-controlled steps.
    pub dissipation_steps: usize,
    /// Whether the run was solved on a window around the crack front ([`RunOptions::window`]).
    pub windowed: bool,
    /// Why a run asked to use the window was solved on the whole mesh instead.
    pub window_fallback: Option<&'static str>,
    /// Whether the whole mesh went on from the window's last committed state (rather than from
    /// rest) after the window gave up.
    pub resumed_from_window: bool,
}

/// A failed run: the error and the converged rows.
#[derive(Clone, Debug)]
pub struct PathFailure {
    /// What went wrong.
    pub error: CzError,
    /// Rows that converged before it.
    pub rows: Vec<StepRow>,
}

/// Choices of a run beyond the path itself.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunOptions {
    /// How the interface is integrated. With [`InterfaceRule::Segments`] the crack measures come
    /// from the segments' fronts and each point's work is integrated along its gap path by the law
    /// ([`super::energy::Ledger::commit_along`]).
    pub interface: InterfaceRule,
    /// Record only the output abscissae (and the states followed under the dissipation constraint,
    /// where the output grid cannot be followed) instead of every converged step. Then the rows'
    /// abscissae do not depend on the parameters, so a response interpolated between them is as
    /// smooth in the parameters as the states themselves.
    pub outputs_only: bool,
    /// Solve only a window around the crack front, the linear regions behind and ahead of it
    /// condensed exactly (`fe::window`), when the problem fits (small rotations, segments,
    /// one interface from near the loaded end to the far end, a law linear near the origin); any
    /// other problem, or a run whose checks fail, is solved on the whole mesh. Records the output
    /// abscissae only.
    pub window: bool,
    /// Under large rotations, leave the intact part far ahead of the crack front out of the
    /// whole-mesh solve (`fe::path`'s cut: 25 decay lengths of the arm on its interface ahead of
    /// the front, where the deflection has fallen to e⁻²⁵ of its value there).
    pub cut_far_field: bool,
    /// Under large rotations, keep the beam mesh fine only in a zone around the crack front that
    /// moves with it (`fe::fine_zone`): the free arm behind it in elements as long as the mesh's
    /// longest (a DCB's pre-crack arm), the intact part ahead in elements of half the arm's decay
    /// length on its interface, refined as the front approaches.
    pub fine_zone: bool,
}

impl RunOptions {
    /// Segment integration and records on the output grid, on the whole mesh, nothing left out or
    /// coarsened: the base that models change a field or two of.
    pub const fn segments() -> Self {
        RunOptions {
            interface: InterfaceRule::Segments,
            outputs_only: true,
            window: false,
            cut_far_field: false,
            fine_zone: false,
        }
    }
}

/// Largest share of the linear prediction of a front's advance that the parabola's curvature may
/// add or remove before the prediction falls back to the line ([`FrontTrack::advance`]).
const QUADRATIC_SHARE: f64 = 0.1;

/// The last committed state of a windowed run that gave up, for the whole mesh to go on from
/// instead of starting again from rest (`fe::window` builds it, `fe::path` resumes it).
#[derive(Debug)]
pub(crate) struct Resume {
    /// Why the window gave up.
    pub(crate) reason: &'static str,
    /// The window could not take even its smallest step: the path turns back (a snap-back), so
    /// the whole mesh goes on under the dissipation constraint.
    pub(crate) snap_back: bool,
    /// Every unknown of the problem, the control one included.
    pub(crate) q: Vec<f64>,
    /// Every interface point's law state.
    pub(crate) states: Vec<LawState>,
    /// Load on the control unknown.
    pub(crate) reaction: f64,
    /// Work of the load, and energy the interface has dissipated (N·mm).
    pub(crate) external_work: f64,
    pub(crate) dissipated: f64,
    /// Energy the interface dissipated in the last step that dissipated, for the dissipation
    /// constraint to start from.
    pub(crate) dissipation_hint: f64,
    /// Rows recorded so far, and the run's counters.
    pub(crate) rows: Vec<StepRow>,
    pub(crate) stats: RunStats,
    /// Where the path stands: position along the control, next step, next output abscissa.
    pub(crate) pos: f64,
    pub(crate) h: f64,
    pub(crate) k_out: usize,
    /// The front's recent positions.
    pub(crate) front: FrontTrack,
}

/// The most advanced onset front of the segment rule over the last three commits, for predicting
/// how far it moves in the next step.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct FrontTrack {
    /// Control and front position at the last three commits, oldest first (NaN: no front).
    hist: [(f64, f64); 3],
    /// Front position at the last commit.
    pub(crate) x: f64,
    /// Distance between the onset and the failure front (or the crack origin) at the last commit.
    zone_length: f64,
    /// Length of the segment holding the front.
    element: f64,
    known: usize,
}

impl FrontTrack {
    pub(crate) fn commit(&mut self, control: f64, segments: &[Segment], fronts: &[[Option<f64>; 2]]) {
        let (mut onset, mut failure, mut element) = (f64::NAN, f64::NAN, 0.0);
        for (sg, fr) in segments.iter().zip(fronts) {
            if let Some(e) = fr[0] {
                onset = sg.x + e * sg.len;
                element = sg.len;
            }
            if let Some(e) = fr[1] {
                failure = sg.x + e * sg.len;
            }
        }
        self.hist = [self.hist[1], self.hist[2], (control, onset)];
        self.known = if onset.is_finite() { (self.known + 1).min(3) } else { 0 };
        self.x = onset;
        self.element = element;
        self.zone_length = if failure.is_finite() { (onset - failure).abs() } else { 0.0 };
    }

    /// Front advance over a control increment `dc`, extrapolated from the last commits: along
    /// the parabola through the last three where its curvature is a small correction
    /// ([`QUADRATIC_SHARE`]), else along the line through the last two.
    ///
    /// A DCB's crack grows as the square root of the opening, so the line overshoots by a share of
    /// the step that the parabola removes: the first residual of a step is then mostly the process
    /// zone's own change, and Newton needs one iteration fewer in about every second step (the
    /// paper's DCB: 411 assemblies against 502). Where the front jumps (unstable growth in an ENF)
    /// a parabola through the jump overshoots, and the line is kept.
    pub(crate) fn advance(&self, dc: f64) -> Option<f64> {
        let [(cm, xm), (c0, x0), (c1, x1)] = self.hist;
        if self.known < 2 || c1 == c0 {
            return None;
        }
        let slope = (x1 - x0) / (c1 - c0);
        let line = slope * dc;
        if self.known == 3 && cm != c0 && cm != c1 {
            let curvature = (slope - (x0 - xm) / (c0 - cm)) / (c1 - cm);
            let bend = curvature * dc * (c1 + dc - c0);
            if bend.abs() <= QUADRATIC_SHARE * line.abs() {
                return Some(line + bend);
            }
        }
        Some(line)
    }

    /// Half-width of the region that travels with the front: the process zone and the elastic
    /// region ahead of it where the gaps are still large (a few process zones), at least a few
    /// elements.
    pub(crate) fn zone(&self) -> f64 {
        (4.0 * self.zone_length).max(20.0 * self.element)
    }
}
