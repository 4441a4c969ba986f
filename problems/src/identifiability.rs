//! Which identified parameters the data actually determine.
//!
//! At the optimum, the Jacobian J of the weighted residual vector with respect to the parameters
//! (unit-cube coordinates, central differences) gives the Gauss–Newton covariance
//! `σ² (JᵀJ)⁻¹` with `σ² = ||r||² / (n − p)`. From it: standard errors, correlations, and a
//! plain verdict per parameter. A parameter the responses do not depend on at all (e.g. the
//! shear parameters of a symmetric DCB, whose interface never slips) has a zero Jacobian column:
//! it is reported as not determined, never as identified.

use crate::identification::Identification;
use czid_core::{ParameterSpace, Result, Scale};
use czid_optimizers::least_squares::{self, Differences, FiniteDifferences, Parallel};
use nalgebra::DMatrix;

/// Step of the central differences, in unit-cube coordinates: 1 % of each range, wide enough
/// to average over the small node-by-node ripple of a discretised crack front, narrow enough to
/// stay local.
const STEP: f64 = 1e-2;
/// A column this much smaller than the largest is treated as zero sensitivity.
const NEGLIGIBLE: f64 = 1e-6;
/// Standard error (unit-cube coordinates) above which a parameter is not pinned down.
const LOOSE: f64 = 0.25;
/// Correlation above which two parameters are reported as traded against each other.
const CORRELATED: f64 = 0.95;
/// Standard error (unit-cube coordinates) below which a parameter counts as determined even when
/// strongly correlated with another: the data pin both down despite the trade-off.
const TIGHT: f64 = 0.02;

/// The verdict on one parameter.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// Determined by the data.
    Determined,
    /// Strongly correlated with another parameter (index, correlation).
    CorrelatedWith(usize, f64),
    /// The data do not constrain it.
    NotDetermined,
    /// At its lower bound (the optimum may lie beyond).
    AtLowerBound,
    /// At its upper bound.
    AtUpperBound,
}

impl Verdict {
    /// Plain words, naming the other parameter where relevant.
    pub fn describe(&self, space: &ParameterSpace) -> String {
        match self {
            Verdict::Determined => "determined".into(),
            Verdict::CorrelatedWith(k, r) => {
                format!("correlated with {} (r = {r:.3})", space.parameters()[*k].path)
            }
            Verdict::NotDetermined => "not determined by these data".into(),
            Verdict::AtLowerBound => "at its lower bound".into(),
            Verdict::AtUpperBound => "at its upper bound".into(),
        }
    }
}

/// Identifiability at a point.
#[derive(Clone, Debug)]
pub struct Assessment {
    /// Verdict per parameter.
    pub verdicts: Vec<Verdict>,
    /// Standard error per parameter in physical units (None when not determined).
    pub standard_errors: Vec<Option<f64>>,
    /// Correlation matrix (row-major, p × p); NaN where undefined.
    pub correlations: Vec<f64>,
    /// Singular values of J (descending).
    pub singular_values: Vec<f64>,
    /// Sensitivity of the residuals to each parameter: the root mean square of its Jacobian
    /// column (residual units per unit of the parameter's range).
    pub sensitivities: Vec<f64>,
    /// Collinearity index of the sensitive parameters (Brun et al., Water Res. 35 (2001) 1483):
    /// `1/√λ_min` of the Gram matrix of the unit-normalised Jacobian columns. 1: orthogonal;
    /// above ~10–15 some combination of the parameters is poorly determined.
    pub collinearity_index: f64,
}

/// Step of the central differences of [`assess`], in unit-cube coordinates.
pub const FD_STEP: f64 = STEP;

/// Assesses the parameters at unit-cube point `u`.
pub fn assess(id: &Identification, u: &[f64]) -> Result<Assessment> {
    let residuals = |w: &[f64]| -> Result<Vec<f64>> { Ok(id.simulate(&id.space().from_unit(w))?.evaluation.residuals) };
    let r0 = residuals(u)?;
    let fd = FiniteDifferences { step: STEP, scheme: Differences::Central };
    let cube = vec![(0.0, 1.0); u.len()];
    let columns: Vec<usize> = (0..u.len()).collect();
    let jac = least_squares::jacobian(&Parallel(residuals), u, None, &fd, Some(&cube), &columns)?;
    Ok(assess_jacobian(id.space(), u, &r0, &jac))
}

/// Assesses the parameters of `space` at unit-cube point `u` from the residuals `r0` there and
/// their Jacobian `jac` (n × p, unit-cube coordinates).
pub fn assess_jacobian(space: &ParameterSpace, u: &[f64], r0: &[f64], jac: &DMatrix<f64>) -> Assessment {
    let p = u.len();
    let n = r0.len();
    let norms: Vec<f64> = (0..p).map(|j| jac.column(j).norm()).collect();
    let largest = norms.iter().cloned().fold(0.0, f64::max);
    let insensitive: Vec<bool> = norms.iter().map(|&s| s <= NEGLIGIBLE * largest || s == 0.0).collect();

    let sigma2 = if n > p { r0.iter().map(|v| v * v).sum::<f64>() / (n - p) as f64 } else { f64::NAN };
    let svd = jac.clone().svd(false, false);
    let singular_values = svd.singular_values.iter().cloned().collect();
    // Covariance over the sensitive parameters only: the insensitive ones would make JᵀJ singular.
    let keep: Vec<usize> = (0..p).filter(|&j| !insensitive[j]).collect();
    let mut cov = DMatrix::<f64>::from_element(p, p, f64::NAN);
    if !keep.is_empty() {
        let jk = DMatrix::from_fn(n, keep.len(), |i, a| jac[(i, keep[a])]);
        if let Some(inv) = (jk.transpose() * &jk).try_inverse() {
            for (a, &ja) in keep.iter().enumerate() {
                for (b, &jb) in keep.iter().enumerate() {
                    cov[(ja, jb)] = sigma2 * inv[(a, b)];
                }
            }
        }
    }
    let mut correlations = vec![f64::NAN; p * p];
    for a in 0..p {
        for b in 0..p {
            correlations[a * p + b] = cov[(a, b)] / (cov[(a, a)] * cov[(b, b)]).sqrt();
        }
    }
    let params = space.parameters();
    let mut verdicts = Vec::with_capacity(p);
    let mut standard_errors = Vec::with_capacity(p);
    for j in 0..p {
        let se_u = cov[(j, j)].sqrt();
        let verdict = if insensitive[j] || se_u > LOOSE {
            Verdict::NotDetermined
        } else if u[j] <= STEP {
            Verdict::AtLowerBound
        } else if u[j] >= 1.0 - STEP {
            Verdict::AtUpperBound
        } else {
            let partner = (0..p)
                .filter(|&k| k != j && correlations[j * p + k].abs() > CORRELATED)
                .max_by(|&a, &b| correlations[j * p + a].abs().total_cmp(&correlations[j * p + b].abs()));
            match partner {
                Some(k) if se_u > TIGHT => Verdict::CorrelatedWith(k, correlations[j * p + k]),
                _ => Verdict::Determined,
            }
        };
        let x = params[j].from_unit(u[j]);
        let dx_du = match params[j].scale {
            Scale::Linear => params[j].upper - params[j].lower,
            Scale::Log => x * (params[j].upper / params[j].lower).ln(),
        };
        standard_errors.push(if verdict == Verdict::NotDetermined || !se_u.is_finite() {
            None
        } else {
            Some(se_u * dx_du)
        });
        verdicts.push(verdict);
    }
    let sensitivities = norms.iter().map(|s| s / (n.max(1) as f64).sqrt()).collect();
    let collinearity_index = if keep.is_empty() {
        f64::NAN
    } else {
        let normalised = DMatrix::from_fn(n, keep.len(), |i, a| jac[(i, keep[a])] / norms[keep[a]]);
        let gram = normalised.transpose() * &normalised;
        let lmin = gram.symmetric_eigenvalues().iter().cloned().fold(f64::INFINITY, f64::min);
        if lmin > 0.0 {
            1.0 / lmin.sqrt()
        } else {
            f64::INFINITY
        }
    };
    Assessment { verdicts, standard_errors, correlations, singular_values, sensitivities, collinearity_index }
}
