//! Crack measures from the damage profile along an interface.
//!
//! Damage is known at the integration points only, and fully debonded points switch from
//! `D < threshold` to `D ≥ threshold` one at a time; counting whole tributary lengths would make
//! the debonded length a staircase in the applied displacement (and in every parameter, which
//! ruins finite-difference Jacobians). The fronts are therefore placed by extrapolating the
//! smoothly varying side of the profile: for the debonded front, the damage deficit `1 − D` of the
//! two process-zone points ahead is extrapolated linearly to `1 − threshold` (near complete failure
//! `1 − D` is linear in the opening deficit for the sawtooth and bilinear laws, so the front moves
//! continuously and reaches a point exactly when it fails); for the process-zone front, `D` of the
//! two damaged points behind it is extrapolated to zero. Fronts are clamped to the segment
//! between the last point inside and the first point outside.

use czid_core::{CohesiveLaw, Gap, LawState};

/// Lengths measured along one interface.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CrackMeasures {
    /// Length with `D ≥ threshold` (mm).
    pub debonded: f64,
    /// Length with `0 < D < threshold` (mm).
    pub process_zone: f64,
    /// Largest `x` of a debonded front, or the origin if nothing has debonded (mm).
    pub tip: f64,
}

/// Front of the run ending at `inside` (its neighbour `out1` is outside, `out2` beyond) where the
/// extrapolated value `v` reaches `level`, extrapolating from the outside points.
fn front_from_outside(x: &[f64], v: &[f64], inside: usize, out1: usize, out2: Option<usize>, level: f64) -> f64 {
    let (xi, xo) = (x[inside], x[out1]);
    if let Some(o2) = out2 {
        let slope = (v[o2] - v[out1]) / (x[o2] - xo);
        // v must move away from the level going outwards for the extrapolation to be meaningful.
        let dir = (xo - xi).signum();
        if slope * dir > 0.0 {
            let xf = xo + (level - v[out1]) / slope;
            return clamp_between(xf, xi, xo);
        }
    }
    xi
}

/// Front of the run ending at `inside` (its inner neighbour `in2`), extrapolating the inside
/// points to `level` towards the first outside point `out1`.
fn front_from_inside(x: &[f64], v: &[f64], inside: usize, in2: Option<usize>, out1: usize, level: f64) -> f64 {
    let (xi, xo) = (x[inside], x[out1]);
    if let Some(i2) = in2 {
        let slope = (v[inside] - v[i2]) / (xi - x[i2]);
        let dir = (xo - xi).signum();
        if slope * dir < 0.0 {
            let xf = xi + (level - v[inside]) / slope;
            return clamp_between(xf, xi, xo);
        }
    }
    xi
}

fn clamp_between(v: f64, a: f64, b: f64) -> f64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    v.clamp(lo, hi)
}

/// Length of `{D ≥ threshold}` plus fronts, for points at increasing `x` with damage `d`
/// (`deficit` is scratch space of the same length).
pub fn measure(x: &[f64], d: &[f64], threshold: f64, origin: f64, deficit: &mut [f64]) -> CrackMeasures {
    measure_located(x, d, threshold, origin, deficit, |_, _| None)
}

/// As [`measure`], with the debonded fronts placed by `located(inside, outside)`: the position
/// (mm) of the front between the debonded point `inside` and its neighbour `outside` (below the
/// threshold), e.g. where the law, evaluated along the gap interpolated between the two points,
/// reaches the threshold ([`super::segment::level_front`]). Such a front moves continuously with
/// the points' gaps: it leaves a point exactly when that point reaches the threshold and crosses
/// the element as the gaps grow, so the debonded length is a continuous function of the state
/// (and of the parameters) instead of growing by whole points. Where `located` gives `None` the
/// front is extrapolated as in [`measure`].
pub fn measure_located(
    x: &[f64],
    d: &[f64],
    threshold: f64,
    origin: f64,
    deficit: &mut [f64],
    located: impl Fn(usize, usize) -> Option<f64>,
) -> CrackMeasures {
    let n = x.len();
    let mut m = CrackMeasures { tip: origin, ..Default::default() };
    if n == 0 {
        return m;
    }
    for (e, di) in deficit.iter_mut().zip(d) {
        *e = 1.0 - di;
    }
    let et = 1.0 - threshold;
    let mut damaged = 0.0;
    let mut i = 0;
    while i < n {
        if d[i] < threshold {
            i += 1;
            continue;
        }
        let start = i;
        while i + 1 < n && d[i + 1] >= threshold {
            i += 1;
        }
        let end = i;
        let left = if start == 0 {
            x[0]
        } else {
            located(start, start - 1)
                .map(|f| clamp_between(f, x[start], x[start - 1]))
                .unwrap_or_else(|| front_from_outside(x, deficit, start, start - 1, start.checked_sub(2), et))
        };
        let right = if end + 1 == n {
            x[n - 1]
        } else {
            located(end, end + 1)
                .map(|f| clamp_between(f, x[end], x[end + 1]))
                .unwrap_or_else(|| front_from_outside(x, deficit, end, end + 1, (end + 2 < n).then_some(end + 2), et))
        };
        m.debonded += right - left;
        m.tip = m.tip.max(right);
        i += 1;
    }
    i = 0;
    while i < n {
        if d[i] <= 0.0 {
            i += 1;
            continue;
        }
        let start = i;
        while i + 1 < n && d[i + 1] > 0.0 {
            i += 1;
        }
        let end = i;
        let left = if start == 0 {
            x[0]
        } else {
            front_from_inside(x, d, start, (start < end).then_some(start + 1), start - 1, 0.0)
        };
        let right = if end + 1 == n {
            x[n - 1]
        } else {
            front_from_inside(x, d, end, (end > start).then(|| end - 1), end + 1, 0.0)
        };
        damaged += right - left;
        i += 1;
    }
    m.process_zone = (damaged - m.debonded).max(0.0);
    m
}

/// Damage thresholds at least this close to 1 count as complete failure with segments: the
/// debonded front is then the failure front the segment rule places anyway (for the bundled laws
/// it lies within 10⁻⁹ of the opening where the damage reaches `1 − 10⁻⁹`).
pub const FAILURE_LEVEL: f64 = 1.0 - 1e-6;

/// The highest damage level that still means a front before complete failure: a visible front's
/// level is kept at or below it, and a threshold at or above it is left to the visible front.
pub const BELOW_FAILURE: f64 = 1.0 - 1.0001e-6;

/// What a crack measure counts as debonded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Debonded {
    /// Damage at or above the level; levels from [`FAILURE_LEVEL`] on mean complete failure.
    Damage(f64),
    /// Material beyond the law's inner kink ([`CohesiveLaw::beyond_inner_kink`]), e.g. a matrix
    /// that has failed while fibres still bridge ([`CohesiveLaw::visible_front_kink`]).
    Kink(usize),
}

/// The damage level of the law's visible front ([`CohesiveLaw::visible_front_kink`]) for crack
/// measures that place fronts by damage alone: the damage just beyond the kink in the test's
/// mode (`mode` 0: opening, as in a DCB; 1: slip, as in an ENF), kept below [`FAILURE_LEVEL`] (a
/// level from there on means complete failure); `None` if the visible crack is complete failure.
pub fn visible_front_level(law: &dyn CohesiveLaw, mode: usize) -> Option<f64> {
    let k = law.visible_front_kink()?;
    super::segment::inner_kink_damage(law, k, mode).map(|d| d.min(BELOW_FAILURE))
}

/// Crack measures from the interface segments ([`super::segment`]) and the fronts the last
/// assembly found in them, `point(i)` the gap and committed state of point `i`.
///
/// A segment counts as debonded (damaged) from its debonded (damaged) end up to the debonded
/// (onset) front inside it, so the measures move continuously with the fronts. For
/// [`Debonded::Damage`] levels from [`FAILURE_LEVEL`] on, the front is the segment rule's failure
/// front; below, [`super::segment::level_front`] places it; for [`Debonded::Kink`],
/// [`super::segment::kink_front`]. Without a front between a debonded and an intact end (one
/// that could not be placed, e.g. after unloading) half the segment counts.
pub fn from_segments<'s>(
    segments: &[super::segment::Segment],
    fronts: &[[Option<f64>; 2]],
    law: &dyn CohesiveLaw,
    point: impl Fn(usize) -> (Gap, &'s LawState),
    origin: f64,
    debonded_by: Debonded,
) -> CrackMeasures {
    let mut m = CrackMeasures { tip: origin, ..Default::default() };
    let mut damaged = 0.0;
    let is_debonded = |st: &LawState| match debonded_by {
        Debonded::Damage(t) if t >= FAILURE_LEVEL => st.damage >= 1.0,
        Debonded::Damage(t) => st.damage >= t,
        Debonded::Kink(k) => law.beyond_inner_kink(st, k),
    };
    for (s, fr) in segments.iter().zip(fronts) {
        let ((ga, sa), (gb, sb)) = (point(s.a), point(s.b));
        let part = |ea: bool, eb: bool, front: &dyn Fn() -> Option<f64>| -> (f64, f64) {
            // Fraction of the segment on the side of the ends where the property holds, and the
            // right end of that part (fraction).
            match (ea, eb) {
                (true, true) => (1.0, 1.0),
                (false, false) => (0.0, 0.0),
                (true, false) => {
                    let e = front().unwrap_or(0.5);
                    (e, e)
                }
                (false, true) => (1.0 - front().unwrap_or(0.5), 1.0),
            }
        };
        let debond_front = || match debonded_by {
            Debonded::Damage(t) if t >= FAILURE_LEVEL => fr[1],
            Debonded::Damage(t) => super::segment::level_front(law, ga, gb, sa, sb, t),
            Debonded::Kink(k) => super::segment::kink_front(law, ga, gb, sa, sb, k),
        };
        let (debonded, right) = part(is_debonded(sa), is_debonded(sb), &debond_front);
        let (dmg, _) = part(sa.damage > 0.0, sb.damage > 0.0, &|| fr[0]);
        m.debonded += debonded * s.len;
        damaged += dmg * s.len;
        if debonded > 0.0 {
            m.tip = m.tip.max(s.x + right * s.len);
        }
    }
    m.process_zone = (damaged - m.debonded).max(0.0);
    m
}
