//! Interface segments: the cohesive interface between two neighbouring points, integrated exactly
//! over a traction field that is linear between the points and between the fronts where the law's
//! response has a kink.
//!
//! **Why.** With the nodal rule every point carries a whole tributary length, so a crack front
//! advances one point at a time. For laws whose dissipation rate switches on and off abruptly (a
//! linear elastic branch ending at the strength, softening that ends at complete failure: the
//! sawtooth and bilinear laws), the energy the interface absorbs per unit crack growth then
//! oscillates with the front's position between two points, by a fraction of the order of
//! (point spacing / process zone). A DCB loaded in displacement control is only stable if that
//! resistance varies slower than `4 G / a` per unit crack length: the oscillation is of the same
//! order in the spacing, so refining the mesh does not remove the resulting snap-backs, and the
//! load at a fixed opening becomes a discontinuous function of every parameter.
//!
//! **What.** Between points `a` and `b` the gap is interpolated linearly, `g(η) = (1 − η) g_a + η g_b`.
//! The traction is taken linear in `η` between the points' own tractions, except that it passes
//! through the law's values at the two fronts a segment may contain:
//!
//! * the *onset front*, where the gap leaves the initial elastic domain (one point damaged, the
//!   other intact), with the elastic traction there;
//! * the *failure front*, where the material reaches complete failure (one point failed, the
//!   other not), with the traction of failed material (zero in opening).
//!
//! For a law that is piecewise linear along the loading path (sawtooth, bilinear) and a linear gap,
//! this traction field is exact. The nodal forces `∫ N_i T dx` are integrated exactly over it (Simpson
//! per piece). A front moves continuously with the gaps, and when it reaches a point it becomes that
//! point's own kink: forces are continuous functions of the unknowns and the resistance to crack
//! growth no longer depends on where the front lies between points.
//!
//! **Where the fronts are.** In pure mode I (both points with exactly zero slip, a positive opening)
//! the fronts are at fixed openings, the law's elastic limit and failure opening, found once per run
//! ([`ModeOne`]); elsewhere along the segment by bisection on the law's damage. Material between
//! the points is assumed to have been loaded monotonically (the state of a front is the virgin
//! state for the onset, the intact neighbour's committed state for failure), which holds where
//! cracks grow.

use czid_core::{CohesiveLaw, Gap, LawState, Tangent, Traction};

use super::interface::{InterfacePoint, PointKind};
use super::mesh::Mesh;
use super::switch_point::switch_point;

/// The interface between two cohesive points of the same layers at neighbouring nodes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Left point (index into the problem's points).
    pub a: usize,
    /// Right point.
    pub b: usize,
    /// Axial coordinate of the left point (mm).
    pub x: f64,
    /// Length (mm).
    pub len: f64,
    /// Interface area of the segment times the energy share of the points (mm²).
    pub weight: f64,
}

/// The segments of `points`, and for each point whether a segment covers it (a covered point is
/// integrated through its segments only; the others keep the nodal rule).
///
/// Points of the same layers, kind and energy share at neighbouring nodes form a segment. The area
/// of a point is split between its two sides in proportion to their lengths (the nodal rule gives
/// each point half of each neighbouring element), so the segments carry exactly the points' areas.
pub fn segments(mesh: &Mesh, points: &[InterfacePoint]) -> (Vec<Segment>, Vec<bool>) {
    // Cohesive points by interface (layers and energy share) and node.
    let key = |p: &InterfacePoint| (p.upper, p.lower, p.factor.to_bits());
    let nn = mesh.x.len();
    let mut keys: Vec<(usize, Option<usize>, u64)> = Vec::new();
    let mut by_node: Vec<Vec<usize>> = Vec::new();
    let mut line = vec![usize::MAX; points.len()];
    for (i, p) in points.iter().enumerate() {
        if p.kind != PointKind::Cohesive {
            continue;
        }
        let k = key(p);
        let l = match keys.iter().position(|x| *x == k) {
            Some(l) => l,
            None => {
                keys.push(k);
                by_node.push(vec![usize::MAX; nn]);
                keys.len() - 1
            }
        };
        by_node[l][p.node] = i;
        line[i] = l;
    }
    let neighbour = |i: usize, right: bool| -> Option<usize> {
        let p = &points[i];
        if line[i] == usize::MAX {
            return None;
        }
        let node = if right { p.node + 1 } else { p.node.checked_sub(1)? };
        let j = *by_node[line[i]].get(node)?;
        (j != usize::MAX).then_some(j)
    };
    let len = |node: usize| mesh.x[node + 1] - mesh.x[node];
    let share = |i: usize, right: bool| -> f64 {
        let p = &points[i];
        let l = neighbour(i, false).map_or(0.0, |_| len(p.node - 1));
        let r = neighbour(i, true).map_or(0.0, |_| len(p.node));
        p.area * if right { r } else { l } / (l + r)
    };
    let mut out = Vec::new();
    let mut covered = vec![false; points.len()];
    for (i, p) in points.iter().enumerate() {
        if let Some(j) = neighbour(i, true) {
            out.push(Segment {
                a: i,
                b: j,
                x: mesh.x[p.node],
                len: len(p.node),
                weight: (share(i, true) + share(j, false)) * p.factor,
            });
            covered[i] = true;
            covered[j] = true;
        }
    }
    (out, covered)
}

/// A law's fronts on the pure mode I opening path from the virgin state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeOne {
    /// Largest opening at which the virgin law is still undamaged (mm).
    pub onset: f64,
    /// Its traction and tangent.
    pub onset_traction: Traction,
    pub onset_tangent: Tangent,
    /// Smallest opening at which the law reports complete failure (mm), if any.
    pub failure: Option<f64>,
    /// Traction and tangent of failed material at that opening.
    pub failure_traction: Traction,
    pub failure_tangent: Tangent,
    /// The law's inner kinks ([`CohesiveLaw::inner_kinks`], at most [`MAX_INNER_KINKS`]): the
    /// smallest opening beyond each, and the traction and tangent just beyond it.
    pub inner: [Option<(f64, Traction, Tangent)>; MAX_INNER_KINKS],
    /// How many inner kinks the law has (kept here so that integration asks the law once a run).
    pub inner_count: usize,
}

/// Inner kinks of a law that the segments place fronts at (further ones are not resolved).
pub const MAX_INNER_KINKS: usize = 2;

impl ModeOne {
    /// Finds the fronts by bisection to round-off; `None` if the law damages from the first
    /// opening on (no elastic domain, hence no onset kink).
    pub fn of(law: &dyn CohesiveLaw) -> Option<ModeOne> {
        let init = law.initial_state();
        let damage = |g: f64| law.evaluate(&Gap::new(g, 0.0), &init).state.damage;
        let [k, _] = law.initial_stiffness();
        let [s, _] = law.strength();
        let mut hi = if k > 0.0 && s > 0.0 { s / k } else { 1e-6 };
        let mut doublings = 0;
        while damage(hi) <= 0.0 {
            hi *= 2.0;
            doublings += 1;
            if doublings > 80 {
                return None;
            }
        }
        let onset = bisect(0.0, hi, |g| damage(g) > 0.0);
        if onset <= 0.0 || onset.is_nan() {
            return None;
        }
        let at_onset = law.evaluate(&Gap::new(onset, 0.0), &init);
        let gc = law.fracture_energy()[0];
        let hi = if gc > 0.0 && s > 0.0 { (2.0 * gc / s).max(2.0 * onset) } else { 2.0 * onset };
        let failure = bracket_and_bisect(onset, hi, |g| damage(g) >= 1.0);
        // Failed side of the front (the bisection returns the last opening below it).
        let at_failure = failure.map(|g| law.evaluate(&Gap::new(next_up(g), 0.0), &init));
        let inner_count = law.inner_kinks().min(MAX_INNER_KINKS);
        let mut inner = [None; MAX_INNER_KINKS];
        for (k, slot) in inner.iter_mut().enumerate().take(inner_count) {
            let beyond = |g: f64| law.beyond_inner_kink(&law.evaluate(&Gap::new(g, 0.0), &init).state, k);
            *slot = bracket_and_bisect(onset, 2.0 * onset, beyond).map(|g| {
                let e = law.evaluate(&Gap::new(next_up(g), 0.0), &init);
                (g, e.traction, e.tangent)
            });
        }
        Some(ModeOne {
            onset,
            onset_traction: at_onset.traction,
            onset_tangent: at_onset.tangent,
            failure,
            failure_traction: at_failure.map_or(Traction::zeros(), |e| e.traction),
            failure_tangent: at_failure.map_or(Tangent::zeros(), |e| e.tangent),
            inner,
            inner_count,
        })
    }
}

/// [`bisect`] on `[lo, hi]` after doubling `hi` (up to 80 times) until `beyond(hi)`; `None` if
/// it never is.
fn bracket_and_bisect(lo: f64, mut hi: f64, beyond: impl Fn(f64) -> bool) -> Option<f64> {
    for _ in 0..80 {
        if beyond(hi) {
            return Some(bisect(lo, hi, beyond));
        }
        hi *= 2.0;
    }
    None
}

/// The point of `[lo, hi]` where `beyond` switches from false (at `lo`) to true (at `hi`), to
/// round-off: the last value for which it is false.
fn bisect(lo: f64, hi: f64, beyond: impl Fn(f64) -> bool) -> f64 {
    bisect_halvings(lo, hi, 200, beyond)
}

/// [`bisect`] with at most `halvings` halvings (it stops earlier once `lo` and `hi` are
/// neighbouring numbers, where a further halving would evaluate `beyond` and change nothing).
pub(crate) fn bisect_halvings(mut lo: f64, mut hi: f64, halvings: usize, beyond: impl Fn(f64) -> bool) -> f64 {
    for _ in 0..halvings {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if beyond(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

fn next_up(v: f64) -> f64 {
    f64::from_bits(v.to_bits() + 1)
}

/// A front inside a segment: its position and the traction there, with their derivatives with
/// respect to the two end gaps.
#[derive(Clone, Copy, Debug)]
struct Front {
    eta: f64,
    t: Traction,
    /// `∂η/∂g_a`, `∂η/∂g_b`.
    deta: [[f64; 2]; 2],
    /// `∂T/∂g_a`, `∂T/∂g_b`.
    dt: [Tangent; 2],
}

/// What a segment contributes: forces on its end gaps (the work-conjugates of `g_a`, `g_b`) and
/// their Jacobian with respect to the end gaps.
#[derive(Clone, Copy, Debug)]
pub struct SegmentForces {
    /// Force on `g_a` and on `g_b` (N).
    pub f: [Traction; 2],
    /// `∂f_i/∂g_j` (N/mm).
    pub jac: [[Tangent; 2]; 2],
    /// Position (fraction from `a`) of the onset front and of the failure front, if inside.
    pub fronts: [Option<f64>; 2],
    /// `∫ ½ T·g` over the segment (N·mm): its recoverable energy for laws that unload along the
    /// secant (the default of [`CohesiveLaw::stored_energy`]).
    pub stored: f64,
}

/// One end of a segment as the assembly sees it.
#[derive(Clone, Copy, Debug)]
pub struct End<'a> {
    /// Gap.
    pub gap: Gap,
    /// Trial traction.
    pub t: Traction,
    /// Iteration tangent.
    pub d: Tangent,
    /// Trial state.
    pub trial: &'a LawState,
    /// Committed state.
    pub state: &'a LawState,
}

/// Forces of segment `s` with ends `a`, `b` (see the module documentation).
pub fn integrate(s: &Segment, a: &End, b: &End, law: &dyn CohesiveLaw, mode_one: Option<&ModeOne>) -> SegmentForces {
    let w = s.weight;
    let mut fronts = [None, None];
    let mut kinks: [Option<Front>; 2] = [None, None];
    let pure_one = a.gap[1] == 0.0 && b.gap[1] == 0.0 && a.gap[0] > 0.0 && b.gap[0] > 0.0;
    // Onset front: one end damaged, the other never damaged.
    let (da, db) = (a.trial.damage > 0.0, b.trial.damage > 0.0);
    if da != db {
        let intact = if da { b } else { a };
        if intact.state.damage <= 0.0 {
            kinks[0] = match (pure_one, mode_one) {
                (true, Some(m)) => fixed_opening(a, b, m.onset, m.onset_traction, &m.onset_tangent),
                _ => {
                    let init = law.initial_state();
                    // Measured beyond the onset: the damage, which starts from zero there.
                    let measure: Measure = Some((&|e| e.state.damage, true));
                    located(a, b, &|g| law.evaluate(g, &init), |e| e.state.damage > 0.0, measure, !da, true)
                }
            };
        }
    }
    // Failure front: one end failed, the other not.
    let (fa, fb) = (a.trial.damage >= 1.0, b.trial.damage >= 1.0);
    if fa != fb {
        let other = if fa { b } else { a };
        kinks[1] = match (pure_one, mode_one.and_then(|m| m.failure.map(|g| (g, m)))) {
            (true, Some((g, m))) => fixed_opening(a, b, g, m.failure_traction, &m.failure_tangent),
            _ => {
                // Measured before failure: the intact fraction, which vanishes there.
                let measure: Measure = Some((&|e| 1.0 - e.state.damage, false));
                located(a, b, &|g| law.evaluate(g, other.state), |e| e.state.damage >= 1.0, measure, !fa, false)
            }
        };
    }
    // The law's inner kinks, where it has any (most laws have none: no work for them here).
    let inner_kinks = mode_one.map_or_else(|| law.inner_kinks(), |m| m.inner_count);
    let smooth = kinks[0].is_none() && kinks[1].is_none();
    if smooth && inner_kinks == 0 {
        return linear_segment(a, b, w);
    }
    let inner_fronts = if inner_kinks > 0 { inner_fronts(a, b, law, mode_one, pure_one, inner_kinks) } else { None };
    if smooth && inner_fronts.is_none() {
        return linear_segment(a, b, w);
    }
    for (slot, k) in fronts.iter_mut().zip(&kinks) {
        *slot = k.map(|k| k.eta);
    }
    // Breakpoints along η: the ends and the fronts, in order (at most four fronts, so they are
    // kept on the stack and sorted by insertion).
    let mut found = [None; 2 + MAX_INNER_KINKS];
    let mut count = 0;
    for fr in kinks.iter().chain(inner_fronts.iter().flatten()).flatten() {
        let mut k = count;
        while k > 0 && found[k - 1].is_some_and(|p: Front| p.eta > fr.eta) {
            found[k] = found[k - 1];
            k -= 1;
        }
        found[k] = Some(*fr);
        count += 1;
    }
    let inner = &found[..count];
    let n = count + 2;
    let mut xs = [0.0; 4 + MAX_INNER_KINKS];
    let mut ts = [Traction::zeros(); 4 + MAX_INNER_KINKS];
    xs[0] = 0.0;
    ts[0] = a.t;
    for (k, fr) in inner.iter().flatten().enumerate() {
        xs[k + 1] = fr.eta;
        ts[k + 1] = fr.t;
    }
    xs[n - 1] = 1.0;
    ts[n - 1] = b.t;
    // f_a = w Σ ∫ (1 − η) T dη, f_b = w Σ ∫ η T dη over pieces with linear T; and the
    // coefficients of each breakpoint's traction and position.
    let mut f = [Traction::zeros(); 2];
    let mut ct = [[0.0; 4 + MAX_INNER_KINKS]; 2]; // ∂f_i/∂T_k (scalar, per component)
    let mut cx = [[Traction::zeros(); 4 + MAX_INNER_KINKS]; 2]; // ∂f_i/∂x_k
    for p in 0..n - 1 {
        let (x0, x1, t0, t1) = (xs[p], xs[p + 1], ts[p], ts[p + 1]);
        let l = x1 - x0;
        for (i, (n0, n1)) in [(1.0 - x0, 1.0 - x1), (x0, x1)].into_iter().enumerate() {
            // ∫ N T over the piece, N and T linear: l/6 [2 N0 T0 + N0 T1 + N1 T0 + 2 N1 T1].
            let bracket = t0 * (2.0 * n0 + n1) + t1 * (n0 + 2.0 * n1);
            f[i] += bracket * (l / 6.0);
            ct[i][p] += l / 6.0 * (2.0 * n0 + n1);
            ct[i][p + 1] += l / 6.0 * (n0 + 2.0 * n1);
            // dN/dx = −1 for f_a, +1 for f_b.
            let dn = if i == 0 { -1.0 } else { 1.0 };
            cx[i][p] += -bracket / 6.0 + (t0 * 2.0 + t1) * (dn * l / 6.0);
            cx[i][p + 1] += bracket / 6.0 + (t0 + t1 * 2.0) * (dn * l / 6.0);
        }
    }
    let dg = b.gap - a.gap;
    let stored: f64 = (0..n - 1)
        .map(|p| half_product(xs[p + 1] - xs[p], ts[p], ts[p + 1], a.gap + dg * xs[p], a.gap + dg * xs[p + 1]))
        .sum();
    let mut jac = [[Tangent::zeros(); 2]; 2];
    for i in 0..2 {
        jac[i][0] = a.d * ct[i][0];
        jac[i][1] = b.d * ct[i][n - 1];
        for (k, fr) in inner.iter().flatten().enumerate() {
            for j in 0..2 {
                jac[i][j] += fr.dt[j] * ct[i][k + 1];
                let c = cx[i][k + 1];
                for r in 0..2 {
                    for col in 0..2 {
                        jac[i][j][(r, col)] += c[r] * fr.deta[j][col];
                    }
                }
            }
        }
    }
    SegmentForces {
        f: [f[0] * w, f[1] * w],
        jac: [[jac[0][0] * w, jac[0][1] * w], [jac[1][0] * w, jac[1][1] * w]],
        fronts,
        stored: stored * w,
    }
}

/// Forces of a segment with no front inside: the traction is linear along it.
#[inline]
fn linear_segment(a: &End, b: &End, w: f64) -> SegmentForces {
    let (ta, tb) = (a.t, b.t);
    SegmentForces {
        f: [(ta * 2.0 + tb) * (w / 6.0), (ta + tb * 2.0) * (w / 6.0)],
        jac: [[a.d * (w / 3.0), b.d * (w / 6.0)], [a.d * (w / 6.0), b.d * (w / 3.0)]],
        fronts: [None, None],
        stored: half_product(1.0, ta, tb, a.gap, b.gap) * w,
    }
}

/// Fronts at the law's first `count` inner kinks (at most [`MAX_INNER_KINKS`]) where one end is
/// beyond the kink and the other not; `None` if there is none.
fn inner_fronts(
    a: &End,
    b: &End,
    law: &dyn CohesiveLaw,
    mode_one: Option<&ModeOne>,
    pure_one: bool,
    count: usize,
) -> Option<[Option<Front>; MAX_INNER_KINKS]> {
    let mut fronts = [None; MAX_INNER_KINKS];
    for (k, slot) in fronts.iter_mut().enumerate().take(count) {
        let (ka, kb) = (law.beyond_inner_kink(a.trial, k), law.beyond_inner_kink(b.trial, k));
        if ka == kb {
            continue;
        }
        let other = if ka { b } else { a };
        *slot = match (pure_one, mode_one.and_then(|m| m.inner[k])) {
            (true, Some((g, t, d))) => fixed_opening(a, b, g, t, &d),
            _ => located(
                a,
                b,
                &|g| law.evaluate(g, other.state),
                |e| law.beyond_inner_kink(&e.state, k),
                None,
                !ka,
                false,
            ),
        };
    }
    fronts.iter().any(Option::is_some).then_some(fronts)
}

/// `∫ ½ T·g` over a piece of length `l` (fraction of the segment) on which `T` and `g` are linear.
fn half_product(l: f64, t0: Traction, t1: Traction, g0: Gap, g1: Gap) -> f64 {
    l / 12.0 * (2.0 * t0.dot(&g0) + t0.dot(&g1) + t1.dot(&g0) + 2.0 * t1.dot(&g1))
}

/// A front at the fixed opening `g` on a pure mode I segment, if it lies strictly between the ends;
/// `t`, `k` the traction and tangent there.
fn fixed_opening(a: &End, b: &End, g: f64, t: Traction, k: &Tangent) -> Option<Front> {
    let (ga, gb) = (a.gap[0], b.gap[0]);
    if (ga - g) * (gb - g) >= 0.0 || ga.is_nan() || gb.is_nan() {
        return None;
    }
    let d = ga - gb;
    let eta = (ga - g) / d;
    let deta = [[(g - gb) / (d * d), 0.0], [(ga - g) / (d * d), 0.0]];
    Some(Front { eta, t, deta, dt: front_tangents(k, eta, b.gap - a.gap, &deta) })
}

/// `∂T/∂g_j` of a front's traction, the law's tangent `k` times `∂g(η)/∂g_j = c_j I + Δg ⊗ ∂η/∂g_j`.
fn front_tangents(k: &Tangent, eta: f64, dg: Gap, deta: &[[f64; 2]; 2]) -> [Tangent; 2] {
    let mut dt = [Tangent::zeros(); 2];
    for (j, c) in [1.0 - eta, eta].into_iter().enumerate() {
        let mut dgj = Tangent::identity() * c;
        for r in 0..2 {
            for col in 0..2 {
                dgj[(r, col)] += dg[r] * deta[j][col];
            }
        }
        dt[j] = k * dgj;
    }
    dt
}

/// A continuous measure of the law's response that vanishes at a front, and whether it is taken
/// beyond the front (else before it): it lets [`switch_point`] find the front in fewer evaluations
/// than bisection, at the same place where the response switches once along the way. `None`:
/// bisection.
pub(crate) type Measure<'a> = Option<(&'a dyn Fn(&czid_core::LawEval) -> f64, bool)>;

/// The front where `beyond` switches along `s` in `[0, 1]`, false at 0 and true at 1, from the
/// responses `e0`, `e1` there: [`switch_point`] with the measure, else bisection.
pub(crate) fn switch_along(
    e0: &czid_core::LawEval,
    e1: &czid_core::LawEval,
    eval_at: impl Fn(f64) -> czid_core::LawEval,
    beyond: impl Fn(&czid_core::LawEval) -> bool,
    measure: Measure,
) -> f64 {
    match measure {
        Some((m, measured_beyond)) => switch_point(0.0, 1.0, measured_beyond, [m(e0), m(e1)], |s| {
            let e = eval_at(s);
            (beyond(&e), m(&e))
        }),
        None => bisect(0.0, 1.0, |s| beyond(&eval_at(s))),
    }
}

/// A front located along the segment: `beyond` holds for the law's response at the
/// end `a` (if `from_a` is false, at `b`) and not at the other. Its derivatives need the normal to
/// the front in gap space: the gradient of the damage on the side where it varies (`grows_beyond`:
/// beyond the front for the onset, before it for failure), by central differences; the radial
/// direction if that gradient vanishes.
fn located(
    a: &End,
    b: &End,
    eval: &dyn Fn(&Gap) -> czid_core::LawEval,
    beyond: impl Fn(&czid_core::LawEval) -> bool,
    measure: Measure,
    from_a: bool,
    grows_beyond: bool,
) -> Option<Front> {
    let gap = |eta: f64| a.gap * (1.0 - eta) + b.gap * eta;
    // Orient the search so that `beyond` is false at 0 and true at 1 in `s`.
    let to_eta = |s: f64| if from_a { s } else { 1.0 - s };
    let e0 = eval(&gap(to_eta(0.0)));
    if beyond(&e0) {
        return None;
    }
    let e1 = eval(&gap(to_eta(1.0)));
    if !beyond(&e1) {
        return None;
    }
    let s = switch_along(&e0, &e1, |s| eval(&gap(to_eta(s))), &beyond, measure);
    let eta = to_eta(s);
    if !(eta > 0.0 && eta < 1.0) {
        return None;
    }
    let g = gap(eta);
    let at = eval(&g);
    let norm = g.norm();
    let dg = b.gap - a.gap;
    let mut deta = [[0.0; 2]; 2];
    let mut dt = [Tangent::zeros(); 2];
    if norm > 0.0 {
        // A point a little on the side where the damage varies, and the damage's gradient there.
        let h = 1e-6 * norm;
        let side = if grows_beyond == from_a { 1.0 } else { -1.0 };
        let toward = dg * (side / dg.norm().max(1e-300));
        let probe = g + toward * (4.0 * h);
        let dmg = |x: Gap| eval(&x).state.damage;
        let grad = Gap::new(
            dmg(probe + Gap::new(h, 0.0)) - dmg(probe - Gap::new(h, 0.0)),
            dmg(probe + Gap::new(0.0, h)) - dmg(probe - Gap::new(0.0, h)),
        );
        let nrm = if grad.norm() > 0.0 && grad.iter().all(|v| v.is_finite()) { grad / grad.norm() } else { g / norm };
        let den = nrm.dot(&dg);
        if den != 0.0 {
            for (j, c) in [1.0 - eta, eta].into_iter().enumerate() {
                for r in 0..2 {
                    deta[j][r] = -c * nrm[r] / den;
                }
            }
            dt = front_tangents(&at.tangent, eta, dg, &deta);
        }
    }
    Some(Front { eta, t: at.traction, deta, dt })
}

/// Where along the segment between points with gaps `ga`, `gb` and committed states `sa`, `sb`
/// the damage reaches `level` (a fraction from `a`), if one end is at or above it and the other
/// below: located on the law evaluated from the less damaged end's state (the material between
/// loaded monotonically, as for the failure front), by a secant search on how far the damage is
/// from the level.
pub fn level_front(law: &dyn CohesiveLaw, ga: Gap, gb: Gap, sa: &LawState, sb: &LawState, level: f64) -> Option<f64> {
    // Measured before the front: how far the damage is from the level.
    front_where(law, ga, gb, sa, sb, |st| st.damage >= level, Some(&|e: &czid_core::LawEval| level - e.state.damage))
}

/// As [`level_front`], where the law passes its inner kink `k` ([`CohesiveLaw::beyond_inner_kink`]).
pub fn kink_front(law: &dyn CohesiveLaw, ga: Gap, gb: Gap, sa: &LawState, sb: &LawState, k: usize) -> Option<f64> {
    front_where(law, ga, gb, sa, sb, |st| law.beyond_inner_kink(st, k), None)
}

/// Where along the segment the state reached from the end that is not `beyond` becomes so.
fn front_where(
    law: &dyn CohesiveLaw,
    ga: Gap,
    gb: Gap,
    sa: &LawState,
    sb: &LawState,
    beyond_at: impl Fn(&LawState) -> bool,
    before: Option<&dyn Fn(&czid_core::LawEval) -> f64>,
) -> Option<f64> {
    let (ea, eb) = (law.evaluate(&ga, sa), law.evaluate(&gb, sb));
    let (ba, bb) = (beyond_at(&ea.state), beyond_at(&eb.state));
    if ba == bb {
        return None;
    }
    let (from, state, e0) = if !ba { (0.0, sa, ea) } else { (1.0, sb, eb) };
    let gap = |eta: f64| ga * (1.0 - eta) + gb * eta;
    let eval_at = |s: f64| {
        let eta = if from == 0.0 { s } else { 1.0 - s };
        law.evaluate(&gap(eta), state)
    };
    let e1 = eval_at(1.0);
    if !beyond_at(&e1.state) {
        return None;
    }
    let s = switch_along(&e0, &e1, eval_at, |e| beyond_at(&e.state), before.map(|m| (m, false)));
    Some(if from == 0.0 { s } else { 1.0 - s })
}

/// Damage just beyond the law's inner kink `k` along a pure-mode path (`mode` 0: opening, 1:
/// slip): the level at which models that measure a crack by damage alone place a front at that
/// kink (`None` if the path never passes it).
pub fn inner_kink_damage(law: &dyn CohesiveLaw, k: usize, mode: usize) -> Option<f64> {
    let init = law.initial_state();
    let at = |g: f64| law.evaluate(&if mode == 0 { Gap::new(g, 0.0) } else { Gap::new(0.0, g) }, &init);
    let beyond = |g: f64| law.beyond_inner_kink(&at(g).state, k);
    let [kn, kt] = law.initial_stiffness();
    let (stiffness, strength) = (if mode == 0 { kn } else { kt }, law.strength()[mode.min(1)]);
    // From the elastic limit (or a micrometre) on.
    let hi = if stiffness > 0.0 && strength > 0.0 { strength / stiffness } else { 1e-3 };
    bracket_and_bisect(0.0, hi, beyond).map(|g| at(next_up(g)).state.damage)
}
