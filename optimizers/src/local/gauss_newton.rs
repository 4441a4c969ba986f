//! Gauss–Newton (argmin's `GaussNewton`) on finite-difference Jacobians of
//! [`czid_core::Evaluation::residuals`].

use super::{local_optimizer, Ctx, LocalSettings};
use crate::least_squares::{self, FiniteDifferences, ResidualSource};
use argmin::core::{Error, Executor, Jacobian, Operator};
use argmin_math::{ArgminDot, ArgminInv, ArgminTranspose};
use std::cell::RefCell;

/// Gauss–Newton (registry name `gauss-newton`); needs a problem with residuals.
#[derive(Clone, Debug)]
pub struct GaussNewton {
    settings: LocalSettings,
}

local_optimizer!(GaussNewton, "gauss-newton");

/// A small dense row-major matrix with the operations argmin's Gauss–Newton needs (argmin's
/// `Vec` backend has no inverse).
#[derive(Clone, Debug, PartialEq)]
pub struct Mat {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

impl Mat {
    /// A `rows × cols` matrix from row-major `data`.
    pub fn new(rows: usize, cols: usize, data: Vec<f64>) -> Self {
        debug_assert_eq!(data.len(), rows * cols);
        Mat { rows, cols, data }
    }

    fn at(&self, r: usize, c: usize) -> f64 {
        self.data[r * self.cols + c]
    }
}

impl ArgminTranspose<Mat> for Mat {
    fn t(self) -> Mat {
        let mut data = vec![0.0; self.data.len()];
        for r in 0..self.rows {
            for c in 0..self.cols {
                data[c * self.rows + r] = self.at(r, c);
            }
        }
        Mat { rows: self.cols, cols: self.rows, data }
    }
}

impl ArgminDot<Mat, Mat> for Mat {
    fn dot(&self, other: &Mat) -> Mat {
        let mut data = vec![0.0; self.rows * other.cols];
        for r in 0..self.rows {
            for k in 0..self.cols {
                let a = self.at(r, k);
                for c in 0..other.cols {
                    data[r * other.cols + c] += a * other.at(k, c);
                }
            }
        }
        Mat { rows: self.rows, cols: other.cols, data }
    }
}

impl ArgminDot<Vec<f64>, Vec<f64>> for Mat {
    fn dot(&self, v: &Vec<f64>) -> Vec<f64> {
        (0..self.rows)
            .map(|r| self.data[r * self.cols..(r + 1) * self.cols].iter().zip(v).map(|(a, b)| a * b).sum())
            .collect()
    }
}

impl ArgminInv<Mat> for Mat {
    /// Gauss–Jordan elimination with partial pivoting.
    fn inv(&self) -> std::result::Result<Mat, Error> {
        let n = self.rows;
        if n != self.cols {
            return Err(Error::msg("inverse of a non-square matrix"));
        }
        let mut a = self.data.clone();
        let mut inv = vec![0.0; n * n];
        (0..n).for_each(|i| inv[i * n + i] = 1.0);
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for col in 0..n {
            let piv = (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs())).unwrap_or(col);
            // Also catches NaN pivots.
            if a[piv * n + col].abs().partial_cmp(&(1e-14 * scale)) != Some(std::cmp::Ordering::Greater) {
                return Err(Error::msg("singular normal matrix JᵀJ"));
            }
            for c in 0..n {
                a.swap(col * n + c, piv * n + c);
                inv.swap(col * n + c, piv * n + c);
            }
            let d = a[col * n + col];
            for c in 0..n {
                a[col * n + c] /= d;
                inv[col * n + c] /= d;
            }
            for r in 0..n {
                if r != col {
                    let f = a[r * n + col];
                    if f != 0.0 {
                        for c in 0..n {
                            a[r * n + c] -= f * a[col * n + c];
                            inv[r * n + c] -= f * inv[col * n + c];
                        }
                    }
                }
            }
        }
        Ok(Mat { rows: n, cols: n, data: inv })
    }
}

/// Residual operator and its finite-difference Jacobian in `z`.
pub(crate) struct Residuals<'c, 'a> {
    pub ctx: &'c Ctx<'a>,
    pub last: RefCell<Option<(Vec<f64>, Vec<f64>)>>,
}

impl Residuals<'_, '_> {
    /// Jacobian `∂r/∂z` (rows: residuals) given `r(z)` when known.
    pub fn jacobian_at(&self, z: &[f64], r0: Option<&[f64]>) -> std::result::Result<Mat, Error> {
        let s = self.ctx.settings;
        let fd = FiniteDifferences { step: s.fd_step, scheme: s.differences };
        let columns: Vec<usize> = (0..z.len()).collect();
        let j = least_squares::jacobian(self, z, r0, &fd, None, &columns)?;
        Ok(Mat::new(j.nrows(), j.ncols(), j.transpose().as_slice().to_vec()))
    }
}

/// Evaluations through the run's budget and tracker; a failed point (no residuals) is an error.
impl ResidualSource for Residuals<'_, '_> {
    type Error = Error;

    fn residuals(&self, zs: &[Vec<f64>]) -> std::result::Result<Vec<std::result::Result<Vec<f64>, Error>>, Error> {
        Ok(self
            .ctx
            .eval(zs)?
            .into_iter()
            .map(|e| {
                if e.residuals.is_empty() {
                    Err(Error::msg("evaluation failed or has no residuals"))
                } else {
                    Ok(e.residuals)
                }
            })
            .collect())
    }
}

impl Operator for Residuals<'_, '_> {
    type Param = Vec<f64>;
    type Output = Vec<f64>;

    fn apply(&self, z: &Vec<f64>) -> std::result::Result<Vec<f64>, Error> {
        let r = self.residuals_at(z)?;
        *self.last.borrow_mut() = Some((z.clone(), r.clone()));
        Ok(r)
    }
}

impl Jacobian for Residuals<'_, '_> {
    type Param = Vec<f64>;
    type Jacobian = Mat;

    fn jacobian(&self, z: &Vec<f64>) -> std::result::Result<Mat, Error> {
        let cached = self.last.borrow().as_ref().filter(|(lz, _)| lz == z).map(|(_, r)| r.clone());
        self.jacobian_at(z, cached.as_deref())
    }
}

impl GaussNewton {
    fn polish(&self, ctx: &Ctx<'_>, z0: Vec<f64>) {
        let s = &self.settings;
        let Ok(solver) = argmin::solver::gaussnewton::GaussNewton::new().with_tolerance(s.tolerance) else {
            return;
        };
        let op = Residuals { ctx, last: RefCell::new(None) };
        // Errors mean a stop, a failed evaluation or a singular JᵀJ: the best point is kept.
        let _ = Executor::new(op, solver).configure(|st| st.param(z0).max_iters(s.max_iterations)).run();
    }
}
