//! Measurement noise estimated from the data alone, so that a misfit can be compared with it
//! without trusting any model.
//!
//! Each interior reading is compared with the straight line through its two neighbours: for a
//! curve that is smooth on the scale of the sampling, the difference is noise, with variance
//! `σ² (1 + w² + (1 − w)²)` for the interpolation weight `w`. The largest 5 % of the normalised
//! squared differences are dropped (corners such as the peak of a load curve are not noise) and
//! the mean of the rest is corrected for the trimming of a Gaussian.

/// Share of the squared differences kept (the rest are corners, not noise).
const KEEP: f64 = 0.95;
/// `E[z² | z² below its 95 % quantile]` for a standard normal z: corrects the trimmed mean.
const TRIMMED_GAUSSIAN: f64 = 0.7589;
/// Floor of the estimate relative to the largest magnitude of the curve: a recording resolves
/// about a thousandth of its range, and a zero estimate would make every misfit infinitely
/// significant.
const FLOOR: f64 = 1e-3;

/// Noise standard deviation of `y(x)` (same unit as `y`). With `positive_only`, only readings
/// where the curve and its neighbours are above zero count (a debonded length is exactly zero
/// before the crack grows, which says nothing about its noise).
pub fn estimate(x: &[f64], y: &[f64], positive_only: bool) -> f64 {
    let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let floor = FLOOR * scale;
    let mut z2: Vec<f64> = Vec::new();
    for i in 1..x.len().saturating_sub(1) {
        if positive_only && (y[i - 1] <= 0.0 || y[i] <= 0.0 || y[i + 1] <= 0.0) {
            continue;
        }
        let span = x[i + 1] - x[i - 1];
        if span <= 0.0 {
            continue;
        }
        let w = (x[i + 1] - x[i]) / span;
        let e = y[i] - (w * y[i - 1] + (1.0 - w) * y[i + 1]);
        z2.push(e * e / (1.0 + w * w + (1.0 - w) * (1.0 - w)));
    }
    if z2.len() < 5 {
        return floor.max(f64::MIN_POSITIVE);
    }
    z2.sort_by(f64::total_cmp);
    let keep = ((z2.len() as f64 * KEEP).ceil() as usize).clamp(1, z2.len());
    let mean = z2[..keep].iter().sum::<f64>() / keep as f64;
    (mean / TRIMMED_GAUSSIAN).sqrt().max(floor).max(f64::MIN_POSITIVE)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in (0, 1) from a 64-bit linear congruential generator (core has no
    /// random-number dependency), turned into standard normals by Box–Muller.
    struct Normals(u64);
    impl Normals {
        fn uniform(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }
        fn next(&mut self) -> f64 {
            let (u1, u2) = (self.uniform(), self.uniform());
            (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
        }
    }

    #[test]
    fn recovers_the_spread_of_white_noise_on_a_smooth_curve_with_a_corner() {
        let mut rng = Normals(5);
        let x: Vec<f64> = (0..2000).map(|i| i as f64 * 0.01).collect();
        // A peaked curve (a corner at x = 8) plus noise of 0.3.
        let y: Vec<f64> = x.iter().map(|&v| 100.0 * if v < 8.0 { v / 8.0 } else { (8.0 / v).sqrt() }).collect();
        let noisy: Vec<f64> = y.iter().map(|v| v + 0.3 * rng.next()).collect();
        let s = estimate(&x, &noisy, false);
        assert!((s / 0.3 - 1.0).abs() < 0.06, "{s}");
    }

    #[test]
    fn a_noiseless_curve_gets_the_resolution_floor() {
        let x: Vec<f64> = (0..100).map(|i| i as f64).collect();
        let y: Vec<f64> = x.iter().map(|v| 2.0 * v).collect();
        assert_eq!(estimate(&x, &y, false), 1e-3 * 198.0);
    }
}
