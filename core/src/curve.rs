//! Sampled curves y(x) and interpolation onto given abscissae.

use crate::error::{CzError, Result};
use serde::{Deserialize, Serialize};

/// A sampled curve: abscissae `x` (non-decreasing) and ordinates `y`.
///
/// ```
/// # use czid_core::Curve;
/// let c = Curve::new(vec![0.0, 1.0, 2.0], vec![0.0, 10.0, 5.0]).unwrap();
/// assert_eq!(c.sample(&[0.5, 1.5, 3.0]), vec![5.0, 7.5, 5.0]);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Curve {
    x: Vec<f64>,
    y: Vec<f64>,
}

impl Curve {
    /// A curve from samples; `x` must be non-decreasing, all values finite, lengths equal, and at
    /// least one point given.
    pub fn new(x: Vec<f64>, y: Vec<f64>) -> Result<Self> {
        if x.len() != y.len() {
            return Err(CzError::data("curve", format!("{} abscissae but {} ordinates", x.len(), y.len())));
        }
        if x.is_empty() {
            return Err(CzError::data("curve", "no points"));
        }
        if let Some(i) = x.iter().chain(y.iter()).position(|v| !v.is_finite()) {
            let row = i % x.len();
            return Err(CzError::data("curve", format!("non-finite value at point {row}")));
        }
        if let Some(i) = x.windows(2).position(|w| w[1] < w[0]) {
            return Err(CzError::data(
                "curve",
                format!("abscissa decreases at point {} ({} after {})", i + 1, x[i + 1], x[i]),
            ));
        }
        Ok(Curve { x, y })
    }

    /// A curve from a path whose abscissa may go back (snap-back under arc-length control).
    ///
    /// Keeps only the points that advance the abscissa beyond every earlier point: what a
    /// displacement-controlled test would record, where a snap-back shows as a sudden drop.
    pub fn from_path(x: &[f64], y: &[f64]) -> Result<Self> {
        let mut xs = Vec::with_capacity(x.len());
        let mut ys = Vec::with_capacity(y.len());
        let mut reach = f64::NEG_INFINITY;
        for (&xi, &yi) in x.iter().zip(y) {
            if xi > reach || xs.is_empty() {
                xs.push(xi);
                ys.push(yi);
                reach = xi;
            }
        }
        Curve::new(xs, ys)
    }

    /// Abscissae.
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// Ordinates.
    pub fn y(&self) -> &[f64] {
        &self.y
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Always false: a curve has at least one point.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Largest abscissa.
    pub fn x_max(&self) -> f64 {
        *self.x.last().expect("a curve has at least one point")
    }

    /// Linear interpolation at `xq`; outside the sampled range the end value is held.
    pub fn at(&self, xq: f64) -> f64 {
        let n = self.x.len();
        if xq <= self.x[0] {
            return self.y[0];
        }
        if xq >= self.x[n - 1] {
            return self.y[n - 1];
        }
        // First index with x > xq; xq lies in [x[i-1], x[i]).
        let i = self.x.partition_point(|&v| v <= xq);
        let (x0, x1, y0, y1) = (self.x[i - 1], self.x[i], self.y[i - 1], self.y[i]);
        if x1 == x0 {
            y1
        } else {
            y0 + (y1 - y0) * (xq - x0) / (x1 - x0)
        }
    }

    /// [`Curve::at`] for each abscissa in `xs`.
    pub fn sample(&self, xs: &[f64]) -> Vec<f64> {
        xs.iter().map(|&x| self.at(x)).collect()
    }

    /// The part of the curve with `lo ≤ x ≤ hi`.
    pub fn window(&self, lo: f64, hi: f64) -> Result<Self> {
        let (x, y): (Vec<f64>, Vec<f64>) =
            self.x.iter().zip(&self.y).filter(|(x, _)| **x >= lo && **x <= hi).map(|(a, b)| (*a, *b)).unzip();
        if x.is_empty() {
            return Err(CzError::data("curve", format!("no points with abscissa in [{lo}, {hi}]")));
        }
        Curve::new(x, y)
    }

    /// Euclidean norm of the ordinates, `||y||`.
    pub fn norm(&self) -> f64 {
        self.y.iter().map(|v| v * v).sum::<f64>().sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_decreasing_abscissa_and_names_the_point() {
        let e = Curve::new(vec![0.0, 2.0, 1.0], vec![0.0; 3]).unwrap_err();
        assert!(e.to_string().contains("point 2"), "{e}");
    }

    #[test]
    fn rejects_nan() {
        assert!(Curve::new(vec![0.0, f64::NAN], vec![0.0; 2]).is_err());
    }

    #[test]
    fn interpolates_linearly_and_holds_ends() {
        let c = Curve::new(vec![1.0, 2.0, 4.0], vec![2.0, 4.0, 0.0]).unwrap();
        assert_eq!(c.at(0.0), 2.0);
        assert_eq!(c.at(3.0), 2.0);
        assert_eq!(c.at(1.25), 2.5);
        assert_eq!(c.at(9.0), 0.0);
    }

    #[test]
    fn path_with_snap_back_becomes_a_drop() {
        let c = Curve::from_path(&[0.0, 1.0, 0.9, 0.8, 1.2], &[0.0, 10.0, 6.0, 3.0, 2.0]).unwrap();
        assert_eq!(c.x(), &[0.0, 1.0, 1.2]);
        assert_eq!(c.y(), &[0.0, 10.0, 2.0]);
    }
}
