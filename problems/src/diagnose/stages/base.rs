//! The base fit: the subject's parameters polished on the misfit in noise units, its χ² against
//! the noise, and what the data say about each parameter.

use crate::diagnose::gauge::{Gauge, Misfit};
use crate::diagnose::run::{FittedParameter, Identifiability, Subject};
use crate::diagnose::score::Linearisation;
use crate::diagnose::stats::chi2_survival;
use crate::identifiability::{assess_jacobian, FD_STEP};
use crate::identification::Setup;
use czid_core::{ParameterSpace, Result};
use czid_optimizers::least_squares::{self, Differences, FiniteDifferences, LmOptions, Parallel};

/// Finite-difference step of the polish's Jacobians in unit-cube coordinates (wider than the
/// forward models' parameter ripple).
pub const POLISH_STEP: f64 = 2e-3;

/// The fitted base model and what the later stages need of it.
pub struct Base {
    /// The fitted parameters.
    pub space: ParameterSpace,
    /// The setup at its initial values.
    pub setup: Setup,
    /// The responses compared, with their noise.
    pub gauge: Gauge,
    /// The fit in unit-cube coordinates, and in physical values.
    pub u: Vec<f64>,
    /// Physical values of the fit.
    pub x: Vec<f64>,
    /// The setup at the fit.
    pub fitted: Setup,
    /// Its misfit.
    pub misfit: Misfit,
    /// `χ²` of the misfit (noise units), its degrees of freedom `n − p` and `P(χ²_{n−p} > χ²)`.
    pub chi2: f64,
    /// Degrees of freedom.
    pub dof: usize,
    /// Probability of a misfit this large from noise alone.
    pub p_noise: f64,
    /// Residual evaluations of the polish.
    pub evaluations: usize,
}

impl Base {
    /// Readings compared.
    pub fn readings(&self) -> usize {
        self.gauge.len()
    }

    /// The fitted model on the base setup, as a residual function of unit-cube coordinates on
    /// `gauge` (the whole data or a part of it).
    pub fn residuals<'a>(&'a self, gauge: &'a Gauge) -> impl Fn(&[f64]) -> Result<Vec<f64>> + Sync + 'a {
        move |u: &[f64]| Ok(Misfit::of(gauge, &self.space.apply(&self.setup, &self.space.from_unit(u))?)?.r)
    }
}

/// Distance to a bound (unit-cube coordinates) below which a fitted parameter sits at the bound.
const AT_BOUND: f64 = 1e-3;
/// Where a parameter found at a bound is started again (unit-cube coordinates).
pub const RESTARTS: [f64; 3] = [0.25, 0.5, 0.75];

/// Indices of the coordinates of `u` at a bound of the unit cube.
pub fn at_bound(u: &[f64]) -> Vec<usize> {
    (0..u.len()).filter(|&j| u[j] < AT_BOUND || u[j] > 1.0 - AT_BOUND).collect()
}

/// Polishes the subject's parameters from `u0` (unit cube) on the misfit in noise units. A fit
/// that ends with a parameter at a bound is started again with those parameters at a quarter,
/// the middle and three quarters of their range, and the best of the fits kept: a local method
/// stopped against a bound is more often lost than right, and a base fit that is wrong poisons
/// every later stage.
pub fn fit(subject: &Subject, u0: &[f64], gauge: Gauge) -> Result<Base> {
    let space = subject.space.clone();
    let setup = subject.setup.duplicate()?;
    let f = |u: &[f64]| -> Result<Vec<f64>> { Ok(Misfit::of(&gauge, &space.apply(&setup, &space.from_unit(u))?)?.r) };
    let lm = |start: &[f64]| {
        least_squares::minimize(&Parallel(f), start, &LmOptions::unit_cube(space.dim(), POLISH_STEP), None)
    };
    let mut polish = lm(u0)?;
    let mut evaluations = polish.evaluations;
    let stuck = at_bound(&polish.z);
    if !stuck.is_empty() {
        for w in RESTARTS {
            let mut start = polish.z.clone();
            for &j in &stuck {
                start[j] = w;
            }
            if let Ok(again) = lm(&start) {
                evaluations += again.evaluations;
                if again.cost < polish.cost {
                    polish = again;
                }
            }
        }
    }
    let u = polish.z;
    let x = space.from_unit(&u);
    let fitted = space.apply(&setup, &x)?;
    let misfit = Misfit::of(&gauge, &fitted)?;
    let chi2 = misfit.rss();
    let dof = gauge.len().saturating_sub(space.dim()).max(1);
    let p_noise = chi2_survival(chi2, dof as f64);
    Ok(Base { space, setup, gauge, u, x, fitted, misfit, chi2, dof, p_noise, evaluations })
}

/// What the data say about the fitted parameters: standard errors, sensitivities and verdicts,
/// the Jacobian's singular values and correlations, and the linearisation the scores use.
pub fn assess(base: &Base) -> Result<(Vec<FittedParameter>, Identifiability, Linearisation)> {
    let (space, p) = (&base.space, base.space.dim());
    let fd = FiniteDifferences { step: FD_STEP, scheme: Differences::Central };
    let cube = vec![(0.0, 1.0); p];
    let columns: Vec<usize> = (0..p).collect();
    let jac =
        least_squares::jacobian(&Parallel(base.residuals(&base.gauge)), &base.u, None, &fd, Some(&cube), &columns)?;
    let assessment = assess_jacobian(space, &base.u, &base.misfit.r, &jac);
    let parameters = space
        .parameters()
        .iter()
        .enumerate()
        .map(|(j, q)| FittedParameter {
            path: q.path.clone(),
            value: base.x[j],
            unit: q.unit.clone(),
            standard_error: assessment.standard_errors[j],
            sensitivity: assessment.sensitivities[j],
            verdict: assessment.verdicts[j].describe(space),
        })
        .collect();
    let identifiability = Identifiability {
        singular_values: assessment.singular_values.clone(),
        collinearity_index: assessment.collinearity_index,
        correlations: (0..p).map(|a| (0..p).map(|b| assessment.correlations[a * p + b]).collect()).collect(),
    };
    Ok((parameters, identifiability, Linearisation::new(&base.misfit.r, jac)))
}

/// Akaike and Bayesian information criteria `n ln(χ²/n) + 2k` and `n ln(χ²/n) + k ln n`.
pub fn aic_bic(chi2: f64, n: usize, k: usize) -> (f64, f64) {
    let n = n as f64;
    let l = n * (chi2.max(f64::MIN_POSITIVE) / n).ln();
    (l + 2.0 * k as f64, l + k as f64 * n.ln())
}
