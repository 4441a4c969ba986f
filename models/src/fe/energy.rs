//! Energy bookkeeping over converged steps.
//!
//! * External work `W = Σ ½(R_k + R_{k+1})(c_{k+1} − c_k)` (trapezoidal rule on the control
//!   unknown `c` and its reaction `R`).
//! * Elastic energy: exact strain energy of the beams and springs at the converged state plus the
//!   interface's recoverable energy `Σ A_i ψ(g_i, state_i)` ([`czid_core::CohesiveLaw::stored_energy`]).
//! * Dissipated energy: the work done on the interface points, `Σ_i A_i Σ_k ½(T_k + T_{k+1})·(g_{k+1} − g_k)`,
//!   minus their recoverable energy. It is computed point by point, independently of the external
//!   work, so that `W = elastic + dissipated` is a genuine check of equilibrium and of the step size
//!   (the trapezoidal rule is exact on linear pieces of a law, so its error comes only from steps
//!   that straddle a kink of a law). Contact points with friction are interface points like the
//!   others: the work done on them includes the friction's, and they store only their normal
//!   penalty's and stick spring's energy ([`super::interface::contact_stored`]), so the friction
//!   work is part of the dissipated energy.

use czid_core::{CohesiveLaw, Gap, LawEval, LawState, Traction};

use super::interface::{InterfacePoint, PointKind};
use super::segment::{Measure, ModeOne};

/// Running energy totals of the simulated part (N·mm).
#[derive(Clone, Debug, Default)]
pub struct Ledger {
    /// Work of the control reaction.
    pub external_work: f64,
    /// Work done on the interface points (recoverable + dissipated).
    pub interface_work: f64,
    /// The part of `interface_work` done by the tangential tractions on the slips (the rest is
    /// done by the normal tractions on the openings): the mode II share of the interface's work.
    pub shear_work: f64,
    /// Last committed tractions and gaps of the interface points.
    tractions: Vec<Traction>,
    gaps: Vec<Gap>,
}

impl Ledger {
    /// A ledger for `n` interface points, everything at zero.
    pub fn new(n: usize) -> Self {
        Ledger {
            external_work: 0.0,
            interface_work: 0.0,
            shear_work: 0.0,
            tractions: vec![Traction::zeros(); n],
            gaps: vec![Gap::zeros(); n],
        }
    }

    /// A ledger that goes on from a state reached elsewhere: the totals so far, and each point's
    /// committed traction and gap.
    pub(crate) fn resumed(external_work: f64, interface_work: f64, tractions: Vec<Traction>, gaps: Vec<Gap>) -> Self {
        Ledger { external_work, interface_work, shear_work: 0.0, tractions, gaps }
    }

    /// The committed tractions and gaps after the problem's points changed: `point_of[i]` is the
    /// old point the new point `i` was, or `None` for a point that `fresh(i)` gives. The totals keep
    /// the work done on every point, the removed ones included.
    pub(crate) fn remap_points(&mut self, point_of: &[Option<usize>], mut fresh: impl FnMut(usize) -> (Traction, Gap)) {
        let (mut tractions, mut gaps) = (Vec::with_capacity(point_of.len()), Vec::with_capacity(point_of.len()));
        for (i, o) in point_of.iter().enumerate() {
            let (t, g) = match o {
                Some(o) => (self.tractions[*o], self.gaps[*o]),
                None => fresh(i),
            };
            tractions.push(t);
            gaps.push(g);
        }
        self.tractions = tractions;
        self.gaps = gaps;
    }

    /// Adds the work of a converged step.
    pub fn commit(
        &mut self,
        points: &[InterfacePoint],
        trial: &[LawEval],
        gaps: &[Gap],
        dc: f64,
        r_old: f64,
        r_new: f64,
    ) {
        self.external_work += 0.5 * (r_old + r_new) * dc;
        let (mut w, mut ws) = (0.0, 0.0);
        for (ip, p) in points.iter().enumerate() {
            let t = trial[ip].traction;
            let g = gaps[ip];
            w += p.area * p.factor * 0.5 * (t + self.tractions[ip]).dot(&(g - self.gaps[ip]));
            ws += p.area * p.factor * 0.5 * (t[1] + self.tractions[ip][1]) * (g[1] - self.gaps[ip][1]);
            self.tractions[ip] = t;
            self.gaps[ip] = g;
        }
        self.interface_work += w;
        self.shear_work += ws;
    }

    /// [`Ledger::commit`], with each cohesive point's work integrated along its straight gap path
    /// from its committed state `before` by the law itself: split where the point starts to
    /// damage and where it fails, Simpson's rule on each piece (exact for laws linear on each
    /// piece, and free of the error the trapezoidal rule makes on a step across a kink).
    #[allow(clippy::too_many_arguments)]
    pub fn commit_along(
        &mut self,
        points: &[InterfacePoint],
        law: &dyn CohesiveLaw,
        before: &[LawState],
        trial: &[LawEval],
        gaps: &[Gap],
        dc: f64,
        r_old: f64,
        r_new: f64,
        mode_one: Option<&ModeOne>,
    ) {
        self.external_work += 0.5 * (r_old + r_new) * dc;
        let (mut w, mut ws) = (0.0, 0.0);
        for (ip, p) in points.iter().enumerate() {
            let (t0, g0, t1, g1) = (self.tractions[ip], self.gaps[ip], trial[ip].traction, gaps[ip]);
            let (dw, dws) = if p.kind == PointKind::Cohesive && trial[ip].state != before[ip] {
                path_work_split(law, &before[ip], (g0, t0), (g1, t1), &trial[ip].state, mode_one)
            } else {
                (0.5 * (t0 + t1).dot(&(g1 - g0)), 0.5 * (t0[1] + t1[1]) * (g1[1] - g0[1]))
            };
            w += p.area * p.factor * dw;
            ws += p.area * p.factor * dws;
            self.tractions[ip] = t1;
            self.gaps[ip] = g1;
        }
        self.interface_work += w;
        self.shear_work += ws;
    }
}

/// Work per unit area of the law from state `s0` along the straight path from `(g0, t0)` to
/// `(g1, t1)` (`after`: the state reached).
pub(crate) fn path_work(
    law: &dyn CohesiveLaw,
    s0: &LawState,
    g0t0: (Gap, Traction),
    g1t1: (Gap, Traction),
    after: &LawState,
    mode_one: Option<&ModeOne>,
) -> f64 {
    path_work_split(law, s0, g0t0, g1t1, after, mode_one).0
}

/// [`path_work`] and the part of it done by the tangential traction on the slip, by the same
/// rule (the total is summed exactly as [`path_work`] always did).
pub(crate) fn path_work_split(
    law: &dyn CohesiveLaw,
    s0: &LawState,
    (g0, t0): (Gap, Traction),
    (g1, t1): (Gap, Traction),
    after: &LawState,
    mode_one: Option<&ModeOne>,
) -> (f64, f64) {
    let dg = g1 - g0;
    let at = |t: f64| g0 + dg * t;
    let traction = |t: f64| law.evaluate(&at(t), s0).traction;
    // Breakpoints: where damage starts (from a virgin state) and where it completes; each with
    // its traction where that is known without the law. A pure opening path crosses them at the
    // openings of `mode_one`, which holds the tractions there (the law is continuous at them).
    let mut bp: [Breakpoint; 4 + super::segment::MAX_INNER_KINKS] = [(1.0, None); 4 + super::segment::MAX_INNER_KINKS];
    bp[0] = (0.0, Some(t0));
    let mut n = 1;
    let pure = g0[1] == 0.0 && g1[1] == 0.0;
    let exact = if pure { mode_one } else { None };
    let openings = (g0[0], g1[0]);
    if s0.damage <= 0.0 && after.damage > 0.0 {
        let onset = mode_one.map(|m| m.onset);
        let eval = |t: f64| law.evaluate(&at(t), s0);
        // Measured beyond the onset: the damage, which starts from zero there.
        let measure: Measure = Some((&|e| e.state.damage, true));
        if let Some(t) = split(pure, openings, onset, eval, |e| e.state.damage > 0.0, measure) {
            bp[n] = (t, exact.map(|m| m.onset_traction));
            n += 1;
        }
    }
    if s0.damage < 1.0 && after.damage >= 1.0 {
        let failure = mode_one.and_then(|m| m.failure);
        let eval = |t: f64| law.evaluate(&at(t), s0);
        // Measured before failure: the intact fraction, which vanishes there.
        let measure: Measure = Some((&|e| 1.0 - e.state.damage, false));
        if let Some(t) = split(pure, openings, failure, eval, |e| e.state.damage >= 1.0, measure) {
            bp[n] = (t, exact.filter(|m| m.failure.is_some()).map(|m| m.failure_traction));
            n += 1;
        }
    }
    // The law's inner kinks (most laws have none: they pay for this test only).
    let inner_count =
        mode_one.map_or_else(|| law.inner_kinks().min(super::segment::MAX_INNER_KINKS), |m| m.inner_count);
    if inner_count > 0 {
        n = inner_kink_breakpoints(law, s0, after, (g0, g1), mode_one, inner_count, &mut bp, n);
    }
    bp[n] = (1.0, Some(t1));
    bp[1..n].sort_by(|x, y| x.0.total_cmp(&y.0));
    // Linear pieces need no sample between their ends: Simpson's rule with the mean of the ends
    // for the midpoint is the trapezoidal rule, exact on them.
    let linear = pure && law.opening_path_piecewise_linear();
    let (mut w, mut ws) = (0.0, 0.0);
    // The traction at the end of a piece is the next piece's start (evaluated once).
    let mut carried: Option<(f64, Traction)> = None;
    for k in 0..n {
        let ((a, known_a), (b, known_b)) = (bp[k], bp[k + 1]);
        if b <= a {
            continue;
        }
        let ta = match carried {
            Some((at, t)) if at == a => t,
            _ => known_a.unwrap_or_else(|| traction(a)),
        };
        let tb = known_b.unwrap_or_else(|| traction(b));
        carried = Some((b, tb));
        let tm = if linear { (ta + tb) * 0.5 } else { traction(0.5 * (a + b)) };
        let simpson = ta + tm * 4.0 + tb;
        w += (b - a) / 6.0 * simpson.dot(&dg);
        ws += (b - a) / 6.0 * simpson[1] * dg[1];
    }
    (w, ws)
}

/// Where along a step (a fraction of it) a point crosses a level of its path: at the law's
/// opening `level` when the path is pure opening (exact), else where `beyond` switches for the
/// law's response `eval` along the step (to round-off with a `measure` of the distance to it,
/// [`super::switch_point`]; by 60 halvings without); `None` if the step does not cross it.
#[inline]
fn split(
    pure: bool,
    (a, b): (f64, f64),
    level: Option<f64>,
    eval: impl Fn(f64) -> LawEval,
    beyond: impl Fn(&LawEval) -> bool,
    measure: Measure,
) -> Option<f64> {
    if let (true, Some(g)) = (pure, level) {
        if (a - g) * (b - g) < 0.0 {
            return Some((g - a) / (b - a));
        }
        return None;
    }
    let e0 = eval(0.0);
    if beyond(&e0) {
        return None;
    }
    let e1 = eval(1.0);
    if !beyond(&e1) {
        return None;
    }
    Some(if measure.is_some() {
        super::segment::switch_along(&e0, &e1, eval, beyond, measure)
    } else {
        super::segment::bisect_halvings(0.0, 1.0, 60, |t| beyond(&eval(t)))
    })
}

/// Adds to the breakpoints `bp[..n]` of [`path_work_split`] the law's first `count` inner kinks
/// that the step crosses; returns the new count. Kept out of line: most laws have no inner kink.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn inner_kink_breakpoints(
    law: &dyn CohesiveLaw,
    s0: &LawState,
    after: &LawState,
    (g0, g1): (Gap, Gap),
    mode_one: Option<&ModeOne>,
    count: usize,
    bp: &mut [Breakpoint],
    mut n: usize,
) -> usize {
    let dg = g1 - g0;
    let pure = g0[1] == 0.0 && g1[1] == 0.0;
    let openings = (g0[0], g1[0]);
    for k in 0..count {
        if !law.beyond_inner_kink(s0, k) && law.beyond_inner_kink(after, k) {
            let kink = mode_one.and_then(|m| m.inner[k]);
            let eval = |t: f64| law.evaluate(&(g0 + dg * t), s0);
            let beyond = |e: &LawEval| law.beyond_inner_kink(&e.state, k);
            if let Some(t) = split(pure, openings, kink.map(|(g, _, _)| g), eval, beyond, None) {
                bp[n] = (t, kink.filter(|_| pure).map(|(_, traction, _)| traction));
                n += 1;
            }
        }
    }
    n
}

/// A breakpoint of a step's gap path (a fraction of the step) and its traction, where known
/// without evaluating the law.
type Breakpoint = (f64, Option<Traction>);

/// Recoverable energy of the interface points (N·mm) in the states of the evaluations `trial` at `gaps`.
pub fn interface_stored(points: &[InterfacePoint], law: &dyn CohesiveLaw, trial: &[LawEval], gaps: &[Gap]) -> f64 {
    let mut e = 0.0;
    for (ip, p) in points.iter().enumerate() {
        let psi = match p.kind {
            PointKind::Cohesive => law.stored_energy(&gaps[ip], &trial[ip].state),
            // The normal penalty and, with friction, the stick spring (½ T·g without friction).
            PointKind::Contact => super::interface::contact_stored(&trial[ip], &gaps[ip]),
        };
        e += p.area * p.factor * psi;
    }
    e
}
