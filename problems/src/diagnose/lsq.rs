//! Bounded least squares on the unit cube (Levenberg–Marquardt with projected steps), with the
//! Jacobian's columns evaluated in parallel. Used for the base fit's polish and for the refits
//! with a candidate effect switched on; a step that would leave the cube is clipped to it, so a
//! parameter can sit on a bound (a null value often is one).

use czid_core::Result;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// Residual function of unit-cube coordinates.
pub type Residuals<'a> = dyn Fn(&[f64]) -> Result<Vec<f64>> + Sync + 'a;

/// Settings.
#[derive(Clone, Copy, Debug)]
pub struct LsOptions {
    /// Iterations (Jacobians) allowed.
    pub max_iterations: usize,
    /// Finite-difference step in unit-cube coordinates (≥ 1e-3: wider than the forward models'
    /// parameter ripple).
    pub step: f64,
    /// Stop when an iteration lowers the sum of squares by less than this fraction.
    pub tolerance: f64,
    /// Finite-difference Jacobians allowed after the first (when a start Jacobian is given, all
    /// of them): between them the Jacobian follows Broyden's rank-one updates, which costs one
    /// run per step instead of `2p` (refits start from the sensitivities the scores already hold).
    pub fd_jacobians: usize,
}

impl Default for LsOptions {
    fn default() -> Self {
        LsOptions { max_iterations: 25, step: 2e-3, tolerance: 1e-6, fd_jacobians: usize::MAX }
    }
}

/// Outcome of a fit.
#[derive(Clone, Debug)]
pub struct LsResult {
    /// Best point (unit-cube coordinates).
    pub u: Vec<f64>,
    /// Residuals there.
    pub r: Vec<f64>,
    /// Sum of squares there.
    pub rss: f64,
    /// Residual evaluations spent.
    pub evaluations: usize,
    /// Last Jacobian (free coordinates).
    pub jacobian: Option<DMatrix<f64>>,
}

fn ss(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// Central-difference Jacobian at `u` (one-sided at a bound), columns evaluated in parallel.
pub fn jacobian(f: &Residuals<'_>, u: &[f64], step: f64) -> Result<DMatrix<f64>> {
    let p = u.len();
    let points: Vec<(usize, f64, f64)> = (0..p).map(|j| (j, (u[j] - step).max(0.0), (u[j] + step).min(1.0))).collect();
    let evals: Vec<Result<(Vec<f64>, Vec<f64>)>> = points
        .par_iter()
        .map(|&(j, lo, hi)| {
            let at = |v: f64| {
                let mut w = u.to_vec();
                w[j] = v;
                f(&w)
            };
            Ok((at(lo)?, at(hi)?))
        })
        .collect();
    let mut jac: Option<DMatrix<f64>> = None;
    for (&(j, lo, hi), e) in points.iter().zip(evals) {
        let (rl, rh) = e?;
        let m = jac.get_or_insert_with(|| DMatrix::zeros(rl.len(), p));
        for i in 0..rl.len() {
            m[(i, j)] = (rh[i] - rl[i]) / (hi - lo);
        }
    }
    Ok(jac.unwrap_or_else(|| DMatrix::zeros(0, 0)))
}

/// Minimises `||f(u)||²` over the unit cube from `u0`. Coordinates listed in `fixed` stay put.
pub fn minimize(f: &Residuals<'_>, u0: &[f64], fixed: &[usize], opts: &LsOptions) -> Result<LsResult> {
    minimize_from(f, u0, fixed, opts, None)
}

/// [`minimize`] starting from a known Jacobian of the free coordinates (rows as `f`'s).
pub fn minimize_from(
    f: &Residuals<'_>,
    u0: &[f64],
    fixed: &[usize],
    opts: &LsOptions,
    start_jacobian: Option<DMatrix<f64>>,
) -> Result<LsResult> {
    let free: Vec<usize> = (0..u0.len()).filter(|j| !fixed.contains(j)).collect();
    let mut u = u0.iter().map(|v| v.clamp(0.0, 1.0)).collect::<Vec<_>>();
    let mut r = f(&u)?;
    let mut cost = ss(&r);
    let mut evaluations = 1;
    if free.is_empty() {
        return Ok(LsResult { u, r, rss: cost, evaluations, jacobian: None });
    }
    let fd = |at: &[f64]| -> Result<DMatrix<f64>> {
        let w: Vec<f64> = free.iter().map(|&j| at[j]).collect();
        let sub = |v: &[f64]| -> Result<Vec<f64>> {
            let mut full = at.to_vec();
            for (k, &j) in free.iter().enumerate() {
                full[j] = v[k];
            }
            f(&full)
        };
        jacobian(&sub, &w, opts.step)
    };
    let mut fd_left = opts.fd_jacobians;
    let (mut jac, mut fresh) = match start_jacobian {
        Some(mut j) if j.nrows() == r.len() && j.ncols() == free.len() => {
            // A parameter with no sensitivity in the start Jacobian (e.g. a bridging tail's length
            // at zero strength) would never move: its column is differenced here.
            let zero: Vec<usize> = (0..free.len()).filter(|&k| j.column(k).norm() == 0.0).collect();
            if !zero.is_empty() {
                let w: Vec<f64> = zero.iter().map(|&k| u[free[k]]).collect();
                let sub = |v: &[f64]| -> Result<Vec<f64>> {
                    let mut full = u.clone();
                    for (c, &k) in zero.iter().enumerate() {
                        full[free[k]] = v[c];
                    }
                    f(&full)
                };
                let cols = jacobian(&sub, &w, opts.step)?;
                evaluations += 2 * zero.len();
                for (c, &k) in zero.iter().enumerate() {
                    j.set_column(k, &cols.column(c));
                }
            }
            (j, false)
        }
        _ => {
            evaluations += 2 * free.len();
            (fd(&u)?, true)
        }
    };
    let mut mu: Option<f64> = None;
    let mut iterations = 0;
    while iterations < opts.max_iterations {
        iterations += 1;
        let a = jac.transpose() * &jac;
        let g = jac.transpose() * DVector::from_column_slice(&r);
        let dmax = (0..free.len()).map(|i| a[(i, i)]).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        let m = mu.get_or_insert(1e-3 * dmax);
        let mut improved = None;
        // Two damping levels per round, run side by side (both always run, so the outcome does
        // not depend on the number of threads); the less damped one wins when both improve.
        'rounds: for _ in 0..4 {
            // Coordinates on a bound that the gradient pushes outwards stay there for this step
            // (the step of the others is solved without them).
            let moving: Vec<usize> = (0..free.len())
                .filter(|&k| {
                    let v = u[free[k]];
                    !((v <= 0.0 && g[k] > 0.0) || (v >= 1.0 && g[k] < 0.0))
                })
                .collect();
            let trial_at = |damping: f64| -> Option<Vec<f64>> {
                let q = moving.len();
                let mut lhs = DMatrix::from_fn(q, q, |i, j| a[(moving[i], moving[j])]);
                for i in 0..q {
                    lhs[(i, i)] += damping * a[(moving[i], moving[i])].max(1e-9 * dmax);
                }
                let rhs = DVector::from_fn(q, |i, _| -g[moving[i]]);
                let step = lhs.cholesky().map(|c| c.solve(&rhs))?;
                let mut trial = u.clone();
                for (c, &k) in moving.iter().enumerate() {
                    let j = free[k];
                    trial[j] = (u[j] + step[c]).clamp(0.0, 1.0);
                }
                (trial != u).then_some(trial)
            };
            let levels = [*m, 4.0 * *m];
            let trials: Vec<Option<Vec<f64>>> = levels.iter().map(|&d| trial_at(d)).collect();
            if trials.iter().all(|t| t.is_none()) {
                break;
            }
            let results: Vec<Option<Result<Vec<f64>>>> = trials.par_iter().map(|t| t.as_ref().map(|t| f(t))).collect();
            for (k, (trial, rt)) in trials.into_iter().zip(results).enumerate() {
                let (Some(trial), Some(rt)) = (trial, rt) else { continue };
                evaluations += 1;
                if let Ok(rt) = &rt {
                    // Broyden's update along the step actually taken (clipped at the bounds).
                    let du = DVector::from_iterator(free.len(), free.iter().map(|&j| trial[j] - u[j]));
                    let dr = DVector::from_iterator(r.len(), rt.iter().zip(&r).map(|(a, b)| a - b));
                    let d2 = du.norm_squared();
                    if d2 > 0.0 {
                        let miss = dr - &jac * &du;
                        jac += miss * du.transpose() / d2;
                        fresh = false;
                    }
                }
                if improved.is_none() {
                    if let Ok(rt) = rt {
                        if ss(&rt) < cost {
                            improved = Some((trial, rt));
                            *m = (levels[k] / 3.0).max(1e-12 * dmax);
                        }
                    }
                }
            }
            if improved.is_some() {
                break 'rounds;
            }
            *m *= 16.0;
        }
        let Some((trial, rt)) = improved else {
            // No progress: a fresh finite-difference Jacobian, if one is left, else stop.
            if !fresh && fd_left > 0 {
                fd_left -= 1;
                evaluations += 2 * free.len();
                jac = fd(&u)?;
                fresh = true;
                mu = None;
                continue;
            }
            break;
        };
        let new_cost = ss(&rt);
        let gain = (cost - new_cost) / cost.max(f64::MIN_POSITIVE);
        u = trial;
        r = rt;
        cost = new_cost;
        if gain < opts.tolerance {
            break;
        }
    }
    Ok(LsResult { u, r, rss: cost, evaluations, jacobian: Some(jac) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_a_curve_and_stops_on_a_bound() {
        // y = a x + b sampled; true a = 0.3, b = −0.2 lies outside b ∈ [0, 1]: b ends on 0.
        let xs: Vec<f64> = (0..20).map(|i| i as f64 / 19.0).collect();
        let f = |u: &[f64]| -> Result<Vec<f64>> { Ok(xs.iter().map(|x| u[0] * x + u[1] - (0.3 * x - 0.2)).collect()) };
        let res = minimize(&f, &[0.9, 0.9], &[], &LsOptions::default()).unwrap();
        assert_eq!(res.u[1], 0.0);
        // With b = 0 the best slope is the least-squares slope through the origin.
        let a_ref = xs.iter().map(|x| x * (0.3 * x - 0.2)).sum::<f64>() / xs.iter().map(|x| x * x).sum::<f64>();
        assert!((res.u[0] - a_ref).abs() < 1e-6, "{} vs {a_ref}", res.u[0]);
        // A fixed coordinate stays where it started.
        let res = minimize(&f, &[0.9, 0.5], &[1], &LsOptions::default()).unwrap();
        assert_eq!(res.u[1], 0.5);
    }
}
