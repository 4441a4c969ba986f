//! Where a monotone yes/no property of a point along a segment switches, to round-off, in fewer
//! evaluations than bisection when a continuous measure of the distance to the switch is at hand.
//!
//! Fronts inside interface segments (where damage starts, where the material fails, where the
//! debonded length ends) are where a property of the law's state switches along the segment.
//! Bisection finds the switch to round-off in about fifty halvings, each a law evaluation. On one
//! side of the switch the law's state also carries a continuous measure that vanishes there (the
//! damage just beyond the onset, `1 − D` just before failure), and the secant through the two
//! nearest points of that side puts the switch within a small fraction of their distance. Each
//! estimate is probed a little on the other side of it, so the bracket closes from both sides.
//!
//! The result is what bisection gives: an argument where the property does not hold whose
//! neighbouring float holds it. For a property that switches once along the segment that argument
//! is unique, whichever points were evaluated on the way; where round-off makes the law's response
//! switch back and forth within a few units in the last place, the two may pick different ones of
//! those neighbours (the mixed-mode records then move by round-off, see the book's *Mixed mode →
//! Speed*).

/// How far past a secant estimate it is first probed, as a fraction of the estimate's distance from
/// the measured point it extrapolates from (the error assumed of it): the bracket then shrinks by
/// about this factor where the estimate is as good. Tightened tenfold when an estimate lands within
/// its probes, relaxed tenfold when one misses, between [`MIN_TRUST`] and [`MAX_TRUST`].
const FIRST_TRUST: f64 = 1e-2;
/// The tightest fraction: a secant on a nearly linear measure converges faster than this.
const MIN_TRUST: f64 = 1e-6;
/// The loosest: beyond it a probe gains little on halving.
const MAX_TRUST: f64 = 0.25;

/// The switch of `at(s).0` from false (at `lo`) to true (at `hi`): a float where it is false whose
/// neighbour is true. `at(s).1` is the continuous measure that vanishes at the switch, on
/// the side `measured_beyond` says (true: where the property holds); `ends` are the measures at
/// `lo` and `hi` (ignored on the side without one). The search falls back on halving the bracket
/// whenever an estimate does not help (the measure not finite, not changing, or the bracket not
/// halved in two evaluations), so it takes at most three evaluations per halving.
pub(crate) fn switch_point(
    mut lo: f64,
    mut hi: f64,
    measured_beyond: bool,
    ends: [f64; 2],
    at: impl Fn(f64) -> (bool, f64),
) -> f64 {
    // The measured side's two points nearest the switch, nearest first.
    let mut near = if measured_beyond { (hi, ends[1]) } else { (lo, ends[0]) };
    let mut far: Option<(f64, f64)> = None;
    // Towards the side without a measure.
    let across = if measured_beyond { -1.0 } else { 1.0 };
    // Whether the last probe of the current estimate landed across it: the estimate is then
    // probed on the measured side, for a measured point next to the switch.
    let mut landed_across = false;
    // How close the estimates are taken to be, as a fraction of their distance from the nearest
    // measured point: tightened while they land within it, relaxed when they miss.
    let mut trust = FIRST_TRUST;
    let mut width = hi - lo;
    let mut slow = 0;
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            return lo;
        }
        let mut x = mid;
        if let Some((s0, q0)) = far.filter(|_| slow < 2) {
            let (s1, q1) = near;
            if q0 != q1 && q0.is_finite() && q1.is_finite() {
                let root = s1 - q1 * (s1 - s0) / (q1 - q0);
                let side = if landed_across { -across } else { across };
                // At least a few units in the last place, so that the last probes still straddle
                // the switch once the estimate is that close.
                let offset = (trust * (root - s1).abs()).max(4.0 * f64::EPSILON * root.abs());
                let mut probe = root + side * offset;
                // Beyond the bracket's end that way: halfway from the estimate to that end.
                let end = if side > 0.0 { hi } else { lo };
                if (probe - end) * side >= 0.0 {
                    probe = 0.5 * (root + end);
                }
                if probe > lo && probe < hi {
                    x = probe;
                }
            }
        }
        let (holds, measure) = at(x);
        if holds {
            hi = x;
        } else {
            lo = x;
        }
        let was_probe = x != mid;
        let on_measured_side = holds == measured_beyond;
        if was_probe {
            // A probe past the estimate that stays on the measured side, or one short of it that
            // lands across, missed: the estimate was farther from the switch than assumed.
            let missed = on_measured_side != landed_across;
            trust = if missed {
                (trust * 10.0).min(MAX_TRUST)
            } else if landed_across {
                (trust * 0.1).max(MIN_TRUST)
            } else {
                trust
            };
        }
        if on_measured_side {
            far = Some(near);
            near = (x, measure);
            landed_across = false;
        } else {
            landed_across = was_probe;
        }
        if hi - lo <= 0.5 * width {
            width = hi - lo;
            slow = 0;
        } else {
            slow += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    /// Bisection to round-off, as the fronts were located before.
    fn bisect(mut lo: f64, mut hi: f64, beyond: impl Fn(f64) -> bool) -> f64 {
        loop {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                return lo;
            }
            if beyond(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
    }

    /// Switches of smooth measures on either side, some with a kink at the switch or a flat
    /// stretch: the same float as bisection, in fewer evaluations.
    #[test]
    fn the_switch_is_bisections_in_fewer_evaluations() {
        let (mut worst, mut total, mut bisections, mut cases) = (0usize, 0usize, 0usize, 0usize);
        for k in 0..200 {
            let root = (k as f64 * 0.618_033_988_749_895).fract() * 0.98 + 0.01;
            let curvature = (k % 7) as f64 - 3.0;
            for measured_beyond in [false, true] {
                // Vanishes at the root, positive on the measured side; quadratic there.
                let measure = |s: f64| {
                    let d = if measured_beyond { s - root } else { root - s };
                    d * (1.0 + curvature * d).max(0.05)
                };
                let beyond = |s: f64| s > root;
                let count = Cell::new(0usize);
                let found = switch_point(0.0, 1.0, measured_beyond, [measure(0.0), measure(1.0)], |s| {
                    count.set(count.get() + 1);
                    (beyond(s), measure(s))
                });
                let b = Cell::new(0usize);
                let expected = bisect(0.0, 1.0, |s| {
                    b.set(b.get() + 1);
                    beyond(s)
                });
                assert_eq!(found.to_bits(), expected.to_bits(), "root {root}, measured beyond {measured_beyond}");
                worst = worst.max(count.get());
                total += count.get();
                bisections += b.get();
                cases += 1;
            }
        }
        assert!(worst <= 3 * 56, "worst {worst} evaluations");
        // Under half of bisection's evaluations on these smooth measures.
        assert!(2 * total < bisections, "{total} evaluations against bisection's {bisections} over {cases} cases");
    }

    /// A measure of no use (constant, or not finite) leaves bisection's halvings, and its result.
    #[test]
    fn a_useless_measure_falls_back_on_halving() {
        for measure in [0.0, f64::NAN] {
            let root = 0.3217;
            let count = Cell::new(0usize);
            let found = switch_point(0.0, 1.0, false, [measure; 2], |s| {
                count.set(count.get() + 1);
                (s > root, measure)
            });
            assert_eq!(found.to_bits(), bisect(0.0, 1.0, |s| s > root).to_bits());
            assert!(count.get() <= 60, "{} evaluations", count.get());
        }
    }
}
