//! Least squares on residual vectors: one finite-difference [`jacobian()`] and one
//! [`levenberg_marquardt::minimize`], shared by the registry's Levenberg–Marquardt (`czid
//! identify`), Gauss–Newton, the identifiability analysis and the diagnosis's base fit and refits.
//!
//! Both work on a [`ResidualSource`]: anything that returns the residual vectors of a batch of
//! points. The registry's methods evaluate through the optimizer's budget, tracker and observers;
//! [`Parallel`] turns a plain residual function into a source whose batches run on rayon's
//! threads (each point on its own, results in point order, so the outcome does not depend on the
//! number of threads).

pub mod jacobian;
pub mod levenberg_marquardt;

pub use jacobian::{jacobian, Differences, FiniteDifferences};
pub use levenberg_marquardt::{minimize, JacobianUpdates, LmOptions, Outcome, Termination};

use rayon::prelude::*;

/// The residuals of a batch of points.
pub trait ResidualSource {
    /// Why a point or the whole run failed.
    type Error;

    /// One result per point, in order: the residual vector, or why that point failed. `Err` as a
    /// whole stops the run (a budget spent, an observer's stop).
    #[allow(clippy::type_complexity)]
    fn residuals(&self, points: &[Vec<f64>]) -> Result<Vec<Result<Vec<f64>, Self::Error>>, Self::Error>;

    /// The residuals at one point; `Err` if that point failed.
    fn residuals_at(&self, point: &[f64]) -> Result<Vec<f64>, Self::Error> {
        self.residuals(std::slice::from_ref(&point.to_vec()))?.remove(0)
    }
}

/// A residual function as a [`ResidualSource`] whose batches are evaluated in parallel.
pub struct Parallel<F>(pub F);

impl<F, E> ResidualSource for Parallel<F>
where
    F: Fn(&[f64]) -> Result<Vec<f64>, E> + Sync,
    E: Send,
{
    type Error = E;

    fn residuals(&self, points: &[Vec<f64>]) -> Result<Vec<Result<Vec<f64>, E>>, E> {
        Ok(points.par_iter().map(|p| (self.0)(p)).collect())
    }
}
