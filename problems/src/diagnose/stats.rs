//! χ² tail probabilities (regularised upper incomplete gamma function, Numerical Recipes §6.2),
//! and a test for structure left in residuals.

/// Readings per bin of [`structure_p`]: long enough to average white noise down, short enough
/// (30–50 bins on a curve of 300–500 readings) to follow a misfit that changes along the curve.
pub const STRUCTURE_BIN: usize = 10;

/// Probability that residuals `r` (noise units, white noise under the null), cut into
/// `ranges` (one per curve, readings in curve order), show at least the structure they show:
/// the sums of consecutive bins of [`STRUCTURE_BIN`] readings, squared and divided by the bin
/// length, are `χ²(1)` each under white noise, and a smooth misfit adds to every bin of its
/// stretch. A misfit spread thinly over many readings (χ²/dof of 1.1 over 700 readings, which the
/// χ² of all readings cannot tell from noise) is plain here: binning keeps the misfit and divides
/// the noise's share by the bin length. A tail bin shorter than half a bin is left out.
pub fn structure_p(r: &[f64], ranges: &[std::ops::Range<usize>]) -> f64 {
    structure_p_with_floor(r, ranges, &[])
}

/// Freedom of the floor's error to depart from its estimated shape, as a share of its size per
/// bin ([`structure_p_with_floor`]). Chosen on the clean and gain-error cases of gap-bench seed 41
/// (the smallest of 0, 0.3, 0.5 and 0.7 that calls none of its 20 clean tests structured: 0 calls
/// one) and scored on seed 43.
pub const FLOOR_SHAPE_FREEDOM: f64 = 0.3;

/// [`structure_p`] with a smooth error of the model-form floor on top of the noise: `floor` (noise
/// units, per reading, signed; empty: none) is the floor's estimated error `d`, the change its
/// reference's coarsened twin makes. The error is taken as `κ d + e`, `κ ~ N(0, 1)` an unknown
/// scale of that shape and `e` a shape-free part of [`FLOOR_SHAPE_FREEDOM`] times its size,
/// independent from bin to bin. With `S_b` a bin's residual sum, `D_b` its floor sum and `L_b`
/// its readings, the bin sums then have the covariance `V + D Dᵀ`, `V = diag(L_b + (ε D_b)²)`, and
/// `Sᵀ (V + D Dᵀ)⁻¹ S = Σ S²/v − (Σ S D/v)² / (1 + Σ D²/v)` is `χ²` with one degree per bin. A
/// misfit along the floor's own shape, of about its size, is not taken for structure; one of
/// another shape is, almost as surely as without a floor.
pub fn structure_p_with_floor(r: &[f64], ranges: &[std::ops::Range<usize>], floor: &[f64]) -> f64 {
    let (mut ss, mut sd, mut dd, mut bins) = (0.0, 0.0, 0.0, 0usize);
    for range in ranges {
        for (k, bin) in r[range.clone()].chunks(STRUCTURE_BIN).enumerate() {
            if 2 * bin.len() < STRUCTURE_BIN {
                continue;
            }
            let start = range.start + k * STRUCTURE_BIN;
            let d: f64 = floor.get(start..start + bin.len()).map_or(0.0, |f| f.iter().sum());
            let v = bin.len() as f64 + (FLOOR_SHAPE_FREEDOM * d).powi(2);
            let sum: f64 = bin.iter().sum();
            ss += sum * sum / v;
            sd += sum * d / v;
            dd += d * d / v;
            bins += 1;
        }
    }
    let stat = ss - sd * sd / (1.0 + dd);
    if bins == 0 {
        return 1.0;
    }
    chi2_survival(stat, bins as f64)
}

/// `P(X > x)` for `X ~ χ²(k)`.
pub fn chi2_survival(x: f64, k: f64) -> f64 {
    if x.is_nan() || x <= 0.0 {
        return 1.0;
    }
    gamma_q(0.5 * k, 0.5 * x)
}

/// `ln Γ(x)` for `x > 0`.
pub(crate) fn ln_gamma(x: f64) -> f64 {
    // Lanczos approximation (g = 7, n = 9), relative error below 1e-15 for x > 0.
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let t = x + 7.5;
    let s = C[1..].iter().enumerate().fold(C[0], |s, (i, c)| s + c / (x + i as f64 + 1.0));
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + s.ln()
}

fn gamma_q(a: f64, x: f64) -> f64 {
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // Series for P, then Q = 1 − P.
        let (mut sum, mut term, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..1000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * front).max(0.0)
    } else {
        // Continued fraction (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (front * h).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
// One curve is a list of one range of readings, not a range of values.
#[allow(clippy::single_range_in_vec_init)]
mod tests {
    use super::*;

    #[test]
    fn matches_tabulated_quantiles() {
        // Standard χ² table: P(X > q) for the 5 %, 1 % and 0.1 % quantiles.
        for (k, q, p) in
            [(1.0, 3.841, 0.05), (1.0, 10.828, 0.001), (2.0, 5.991, 0.05), (2.0, 13.816, 0.001), (10.0, 23.209, 0.01)]
        {
            let s = chi2_survival(q, k);
            assert!((s / p - 1.0).abs() < 2e-3, "k = {k}: {s} vs {p}");
        }
        // Closed form for two degrees of freedom: exp(−x/2).
        assert!((chi2_survival(7.0, 2.0) - (-3.5f64).exp()).abs() < 1e-14);
    }

    use rand::{Rng, SeedableRng};

    /// Unit white noise (Box–Muller).
    fn white(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let (u, v): (f64, f64) = (1.0 - rng.random::<f64>(), rng.random());
                (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
            })
            .collect()
    }

    #[test]
    fn white_noise_shows_no_structure_and_a_thin_smooth_misfit_does() {
        let n = 700;
        // Under the null the p-value is uniform: over 200 draws about a fifth falls below 0.2.
        let below: usize = (0..200).filter(|&s| structure_p(&white(n, s), &[0..n]) < 0.2).count();
        assert!((25..=55).contains(&below), "{below} of 200 white-noise draws below p = 0.2");
        // A smooth misfit of 0.45 noise units amplitude over the whole curve (χ²/dof about 1.1):
        // the χ² of all readings flags it at 1e-3 in a few draws, the bins in (nearly) all.
        let (mut by_chi2, mut by_bins) = (0, 0);
        for seed in 0..20 {
            let r: Vec<f64> =
                white(n, 1000 + seed).iter().enumerate().map(|(i, e)| e + 0.45 * (i as f64 / 120.0).sin()).collect();
            let chi2: f64 = r.iter().map(|x| x * x).sum();
            by_chi2 += usize::from(chi2_survival(chi2, n as f64) <= 1e-3);
            by_bins += usize::from(structure_p(&r, &[0..n]) <= 1e-3);
        }
        assert!(by_chi2 <= 8 && by_bins >= 19, "flagged by χ² {by_chi2}/20, by the bins {by_bins}/20");
    }

    #[test]
    fn a_misfit_along_the_floors_error_is_not_structure_and_one_of_another_shape_is() {
        let n = 450;
        // The floor's estimated error: smooth, 0.6 noise units.
        let d: Vec<f64> = (0..n).map(|i| 0.6 * (i as f64 / 90.0).sin()).collect();
        let (mut along, mut scaled, mut other, mut plain) = (0, 0, 0, 0);
        for seed in 0..20 {
            let e = white(n, 2000 + seed);
            let with = |k: f64| -> Vec<f64> { e.iter().zip(&d).map(|(v, f)| v + k * f).collect() };
            let r = with(1.0);
            along += usize::from(structure_p_with_floor(&r, &[0..n], &d) <= 1e-3);
            plain += usize::from(structure_p(&r, &[0..n]) <= 1e-3);
            // Twice the estimated size: the scale of the floor's error is not known.
            scaled += usize::from(structure_p_with_floor(&with(2.0), &[0..n], &d) <= 1e-3);
            // An effect of another shape, rising to 1.5 noise units, on top of the floor's error.
            let ramp: Vec<f64> = r.iter().enumerate().map(|(i, v)| v + 1.5 * i as f64 / n as f64).collect();
            other += usize::from(structure_p_with_floor(&ramp, &[0..n], &d) <= 1e-3);
        }
        assert!(plain >= 17, "without the floor its error is structure in only {plain}/20");
        assert!(
            along <= 1 && scaled <= 1,
            "the floor's own error flagged in {along}/20 and {scaled}/20 at twice its size"
        );
        assert!(other >= 19, "an effect of another shape flagged in only {other}/20");
        // No floor is the plain test.
        let e = white(n, 7);
        assert_eq!(structure_p_with_floor(&e, &[0..n], &[]), structure_p(&e, &[0..n]));
    }

    #[test]
    fn bins_stay_inside_their_curve() {
        // Two curves of opposite constant misfit: bins across the boundary would cancel.
        let r: Vec<f64> = (0..40).map(|i| if i < 20 { 1.0 } else { -1.0 }).collect();
        let p_split = structure_p(&r, &[0..20, 20..40]);
        assert!(p_split < 1e-6, "{p_split}");
        assert_eq!(structure_p(&[], &[]), 1.0);
    }
}
