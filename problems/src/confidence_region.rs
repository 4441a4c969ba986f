//! Which of several fits the data cannot tell from the best one.
//!
//! The standard errors of an identification ([`crate::identifiability`]) linearise the objective
//! at the fit's end point. Runs that end in other minima show what the linearisation cannot: a
//! second point, far from the first, that fits as well. Beale's confidence region of nonlinear
//! least squares, `f(θ) ≤ f_min (1 + p/(n − p) F_{p, n−p}(1 − α))` for `n` residuals and `p`
//! parameters (Beale 1960; Bates & Watts, *Nonlinear Regression Analysis*, §6.1), is the region
//! those standard errors are the linear approximation of (the same `σ² = f/(n − p)`): every run
//! that ends inside it is a fit the data do not reject at level `α`, and the spread of a
//! parameter over those runs is a lower bound on how well the data determine it.

use crate::diagnose::stats::ln_gamma;

/// Level of the region: the 95 % confidence region.
pub const LEVEL: f64 = 0.95;

/// The fits inside the region around the best one.
#[derive(Clone, Debug, PartialEq)]
pub struct EquivalentFits {
    /// The region's bound on the objective.
    pub threshold: f64,
    /// Indices of the runs inside it (the best one included).
    pub inside: Vec<usize>,
    /// Per parameter, the smallest and largest value over those runs.
    pub ranges: Vec<(f64, f64)>,
}

/// The runs (objective values `f`, identified values `x`) inside the 95 % region of the best
/// one, for `n` residuals; `None` without a finite best value or when `n ≤ p`.
pub fn equivalent_fits(f: &[f64], x: &[Vec<f64>], n: usize) -> Option<EquivalentFits> {
    let best = f.iter().copied().filter(|v| v.is_finite()).fold(f64::INFINITY, f64::min);
    let p = x.first()?.len();
    if !best.is_finite() || n <= p || p == 0 {
        return None;
    }
    let (d1, d2) = (p as f64, (n - p) as f64);
    let threshold = best * (1.0 + d1 / d2 * f_quantile(LEVEL, d1, d2));
    let inside: Vec<usize> = (0..f.len()).filter(|&k| f[k] <= threshold).collect();
    let ranges = (0..p)
        .map(|j| {
            inside.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &k| (lo.min(x[k][j]), hi.max(x[k][j])))
        })
        .collect();
    Some(EquivalentFits { threshold, inside, ranges })
}

/// The `q` quantile of Fisher's F distribution with `d1` and `d2` degrees of freedom.
pub fn f_quantile(q: f64, d1: f64, d2: f64) -> f64 {
    // The distribution function rises monotonically from 0: bracket, then bisect.
    let (mut lo, mut hi) = (0.0, 1.0);
    while f_cdf(hi, d1, d2) < q {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f_cdf(mid, d1, d2) < q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// `P(X ≤ x)` for `X ~ F(d1, d2)`: `I_{d1 x/(d1 x + d2)}(d1/2, d2/2)`.
fn f_cdf(x: f64, d1: f64, d2: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    incomplete_beta(d1 * x / (d1 * x + d2), 0.5 * d1, 0.5 * d2)
}

/// The regularised incomplete beta function `I_x(a, b)` (continued fraction by the modified
/// Lentz method, Numerical Recipes §6.4).
fn incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front = (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    // The fraction converges fast for x below the mean; above it, by symmetry.
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_fraction(x, a, b) / a
    } else {
        1.0 - front * beta_fraction(1.0 - x, b, a) / b
    }
}

fn beta_fraction(x: f64, a: f64, b: f64) -> f64 {
    let tiny = 1e-300;
    let clamp = |v: f64| if v.abs() < tiny { tiny } else { v };
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 / clamp(1.0 - qab * x / qap);
    let mut h = d;
    for m in 1..1000 {
        let m = m as f64;
        let m2 = 2.0 * m;
        let even = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 / clamp(1.0 + even * d);
        c = clamp(1.0 + even / c);
        h *= d * c;
        let odd = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 / clamp(1.0 + odd * d);
        c = clamp(1.0 + odd / c);
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-16 {
            break;
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f_quantiles_match_the_tables() {
        // Standard F tables (upper 5 % and 1 % points).
        for (q, d1, d2, table) in [
            (0.95, 1.0, 10.0, 4.965),
            (0.95, 5.0, 10.0, 3.326),
            (0.95, 6.0, 120.0, 2.175),
            (0.99, 3.0, 20.0, 4.938),
            (0.95, 2.0, 30.0, 3.316),
        ] {
            let v = f_quantile(q, d1, d2);
            assert!((v / table - 1.0).abs() < 1e-3, "F({q}; {d1}, {d2}) = {v}, table {table}");
        }
        // Closed forms: F(1, d) is Student's t squared (t_{0.975}(10) = 2.228139); for two
        // numerator degrees of freedom the distribution function is 1 − (1 + 2x/d)^(−d/2).
        assert!((f_quantile(0.95, 1.0, 10.0).sqrt() - 2.228139).abs() < 1e-5);
        let x = f_quantile(0.9, 2.0, 7.0);
        assert!((1.0 - (1.0 + 2.0 * x / 7.0).powf(-3.5) - 0.9).abs() < 1e-12);
    }

    #[test]
    fn the_region_keeps_the_runs_within_its_bound_and_spans_their_values() {
        // Six parameters and 202 residuals, as a beam with a curve and two events: the bound is
        // f_min (1 + 6/196 F(0.95; 6, 196)), F about 2.14, so about 6.5 % above the best value.
        let f = [0.3305, 0.3414, 0.3671, 0.4923];
        let x: Vec<Vec<f64>> = [13.2, 14.1, 12.8, 12.5].iter().map(|&s| vec![s, 0.0, 0.0, 0.0, 0.0, 0.0]).collect();
        let e = equivalent_fits(&f, &x, 202).unwrap();
        let factor = e.threshold / 0.3305 - 1.0;
        assert!((factor - 6.0 / 196.0 * f_quantile(0.95, 6.0, 196.0)).abs() < 1e-12);
        assert!((0.064..0.067).contains(&factor), "{factor}");
        assert_eq!(e.inside, [0, 1]);
        assert_eq!(e.ranges[0], (13.2, 14.1));
        // Nothing to say without residuals beyond the parameters, or without a finite value.
        assert!(equivalent_fits(&f, &x, 6).is_none());
        assert!(equivalent_fits(&[f64::NAN], &x[..1], 202).is_none());
    }
}
