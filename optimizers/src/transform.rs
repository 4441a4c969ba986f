//! Bounds by transformation: local methods search an unconstrained `z ∈ Rⁿ`, mapped onto
//! the box by a smooth surjection, so every point they try is feasible.

use serde::{Deserialize, Serialize};

/// The map from `R` onto `[lo, hi]`, applied per variable.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BoundTransform {
    /// `x = lo + (hi − lo)(1 + sin z)/2`: periodic, reaches both bounds at finite `z`
    /// (so optima on a bound are attainable), and is nearly linear around the box centre.
    #[default]
    Sine,
    /// `x = lo + (hi − lo)/(1 + e^{−z})`: monotone; bounds only approached as `z → ±∞`.
    Logistic,
}

impl BoundTransform {
    /// `x = T(z)` into `x`.
    pub fn to_box(self, z: &[f64], bounds: &[(f64, f64)], x: &mut [f64]) {
        for ((xi, &zi), &(lo, hi)) in x.iter_mut().zip(z).zip(bounds) {
            let t = match self {
                BoundTransform::Sine => 0.5 * (1.0 + zi.sin()),
                BoundTransform::Logistic => 1.0 / (1.0 + (-zi).exp()),
            };
            *xi = (lo + (hi - lo) * t).clamp(lo, hi);
        }
    }

    /// A `z` with `T(z) = x` (the principal branch; `x` clamped into the box, and kept
    /// slightly inside for the logistic map, which never reaches the bounds).
    pub fn from_box(self, x: &[f64], bounds: &[(f64, f64)]) -> Vec<f64> {
        x.iter()
            .zip(bounds)
            .map(|(&xi, &(lo, hi))| {
                let t = if hi > lo { ((xi - lo) / (hi - lo)).clamp(0.0, 1.0) } else { 0.5 };
                match self {
                    BoundTransform::Sine => (2.0 * t - 1.0).asin(),
                    BoundTransform::Logistic => {
                        let t = t.clamp(1e-12, 1.0 - 1e-12);
                        (t / (1.0 - t)).ln()
                    }
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let b = [(-1.0, 3.0), (0.0, 1.0)];
        for t in [BoundTransform::Sine, BoundTransform::Logistic] {
            let x = [0.3, 0.9];
            let z = t.from_box(&x, &b);
            let mut y = [0.0; 2];
            t.to_box(&z, &b, &mut y);
            assert!((y[0] - x[0]).abs() < 1e-12 && (y[1] - x[1]).abs() < 1e-12);
        }
    }
}
