//! A safeguarded Newton iteration for the scalar equations of the strength-model laws.
//!
//! The functions solved here are monotone on a known bracket, so Newton steps that leave the
//! bracket are replaced by bisection: the iteration always converges, and converges quadratically
//! once close. Nothing is allocated.

/// Iteration cap; reached only for pathological input, in which case the best bracketed estimate
/// is returned (never a panic).
const MAX_ITERATIONS: usize = 200;

/// Finds the root of `f` in `[lo, hi]`, where `f` is monotone with a sign change on the bracket.
///
/// `f` returns `(value, derivative)`; `increasing` says which way it goes; `start` is the first
/// iterate (clamped into the bracket). Stops once a step is below 1e-14 of the root (or the
/// bracket is that narrow).
pub(crate) fn solve_monotone(
    mut f: impl FnMut(f64) -> (f64, f64),
    mut lo: f64,
    mut hi: f64,
    start: f64,
    increasing: bool,
) -> f64 {
    let mut x = start.clamp(lo, hi);
    for _ in 0..MAX_ITERATIONS {
        let (value, slope) = f(x);
        if value == 0.0 {
            return x;
        }
        // Shrink the bracket to the side that still holds the root.
        if (value < 0.0) == increasing {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - value / slope;
        // 1e-14 relative: the residuals carry roundoff of a few ulps of their terms, so asking for
        // the last ulp would chase noise (and a noisy sign must not trigger a bisection step).
        let tolerance = 1e-14 * x.abs().max(f64::MIN_POSITIVE);
        if (newton - x).abs() <= tolerance {
            return newton.clamp(lo, hi);
        }
        let next = if newton.is_finite() && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if hi - lo <= tolerance {
            return next;
        }
        x = next;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::solve_monotone;

    #[test]
    fn finds_roots_of_increasing_and_decreasing_functions() {
        let r = solve_monotone(|x| (x * x - 2.0, 2.0 * x), 0.0, 2.0, 0.0, true);
        assert!((r - 2f64.sqrt()).abs() < 1e-15);
        let r = solve_monotone(|x| ((-x).exp() - 0.25, -(-x).exp()), 0.0, 10.0, 10.0, false);
        assert!((r - 4f64.ln()).abs() < 1e-14);
        // A function whose Newton steps overshoot: bisection keeps it bracketed.
        let r = solve_monotone(|x| (x.atan(), 1.0 / (1.0 + x * x)), -1.0, 20.0, 15.0, true);
        assert!(r.abs() < 1e-15);
    }
}
