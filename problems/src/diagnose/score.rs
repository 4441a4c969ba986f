//! Which effect: the score (Lagrange-multiplier) statistic of each candidate at the base fit.
//!
//! With `r` the residuals in noise units, `J_θ` the Jacobian of the fitted parameters and `J_e`
//! the sensitivity of the residuals to the effect at its null value, the part of the misfit the
//! fitted parameters cannot remove is `P⊥ r` (`P⊥` removes the span of `J_θ`), and the effect can
//! remove its projection onto `P⊥ J_e`:
//!
//! `S_e = rᵀ P⊥ J_e (J_eᵀ P⊥ J_e)⁻¹ J_eᵀ P⊥ r`,
//!
//! χ²-distributed with `dim e` degrees of freedom when the effect is absent and the noise is
//! white. `S_e / ||r||²` is the share of the misfit it explains to first order, with no refit. An
//! effect whose null value is a bound (a compliance cannot be negative) only counts in its
//! physical direction. The angle between `J_e` and the span of `J_θ` says how confounded the
//! effect is with the fitted parameters, and the regression of `J_e` on `J_θ` which fitted
//! parameter absorbs it (and how far it has moved to do so).

use crate::diagnose::candidate::{CandidateEffect, EffectParameter};
use crate::diagnose::gauge::{Gauge, Misfit};
use crate::diagnose::stats::chi2_survival;
use crate::identification::Setup;
use czid_core::{ParameterSpace, Result, Scale};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;

/// Finite-difference step of the effect sensitivities, in units of each parameter's range: as the
/// identifiability analysis, wide enough to average the crack-front ripple, small enough to stay
/// at the null.
pub const EFFECT_STEP: f64 = 1e-2;
/// A sensitivity column this much smaller than the largest is no sensitivity at all (e.g. the
/// tail length of a bridging law of zero strength).
const NEGLIGIBLE: f64 = 1e-9;
/// Family-wise significance level of the candidate scores (Bonferroni over the candidates).
pub const SIGNIFICANCE: f64 = 1e-3;

/// The base fit, linearised.
#[derive(Clone, Debug)]
pub struct Linearisation {
    /// Residuals (noise units).
    pub r: DVector<f64>,
    /// Jacobian of the fitted parameters (unit-cube coordinates).
    pub jac: DMatrix<f64>,
    /// Orthonormal basis of the span of `jac`.
    pub basis: DMatrix<f64>,
}

impl Linearisation {
    /// From residuals and the fitted parameters' Jacobian.
    pub fn new(r: &[f64], jac: DMatrix<f64>) -> Self {
        let basis = orthonormal_basis(&jac);
        Linearisation { r: DVector::from_column_slice(r), jac, basis }
    }

    /// `P⊥ x`.
    pub fn project_out(&self, x: &DMatrix<f64>) -> DMatrix<f64> {
        x - &self.basis * (self.basis.transpose() * x)
    }
}

/// Orthonormal basis of the column span (rank by singular values above 1e-10 of the largest).
pub fn orthonormal_basis(m: &DMatrix<f64>) -> DMatrix<f64> {
    if m.ncols() == 0 || m.nrows() == 0 {
        return DMatrix::zeros(m.nrows(), 0);
    }
    let svd = m.clone().svd(true, false);
    let smax = svd.singular_values.iter().cloned().fold(0.0, f64::max);
    let u = svd.u.expect("u requested");
    let keep: Vec<usize> = (0..svd.singular_values.len()).filter(|&i| svd.singular_values[i] > 1e-10 * smax).collect();
    DMatrix::from_fn(m.nrows(), keep.len(), |i, k| u[(i, keep[k])])
}

/// Cosine of the smallest principal angle between two column spans (1: a shared direction).
pub fn principal_cos(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    let (qa, qb) = (orthonormal_basis(a), orthonormal_basis(b));
    if qa.ncols() == 0 || qb.ncols() == 0 {
        return 0.0;
    }
    let m = qa.transpose() * qb;
    m.svd(false, false).singular_values.iter().cloned().fold(0.0, f64::max).min(1.0)
}

/// A candidate's sensitivity at the base fit.
#[derive(Clone, Debug)]
pub struct Sensitivity {
    /// Candidate name.
    pub name: String,
    /// Its parameters.
    pub parameters: Vec<EffectParameter>,
    /// `∂r/∂u_e` (n × k, unit coordinates of each parameter's range; for a switch, on − off).
    pub columns: DMatrix<f64>,
    /// Null values in unit coordinates.
    pub null_u: Vec<f64>,
    /// Switch rather than size.
    pub discrete: bool,
}

/// One sensitivity run: parameter, unit value, residuals or why the run failed.
type Eval = (usize, f64, std::result::Result<Vec<f64>, String>);

/// The evaluation points a candidate needs for its sensitivity: `(parameter, unit value)`.
fn points(params: &[EffectParameter], discrete: bool, step: f64) -> Vec<(usize, f64)> {
    let mut out = Vec::new();
    for (j, p) in params.iter().enumerate() {
        let u = p.parameter.to_unit(p.null);
        if discrete {
            out.push((j, 1.0));
        } else if u <= 0.0 {
            out.push((j, u + step));
        } else if u >= 1.0 {
            out.push((j, u - step));
        } else {
            out.push((j, u - step));
            out.push((j, u + step));
        }
    }
    out
}

/// Sensitivities of `candidates` at the fitted setup (its residuals `r0` on `gauge`), every
/// simulation run in parallel, by differences of `step` (unit coordinates of each parameter's
/// range, normally [`EFFECT_STEP`]). A candidate whose runs fail gets the error instead.
pub fn sensitivities(
    gauge: &Gauge,
    fitted: &Setup,
    r0: &[f64],
    candidates: &[&dyn CandidateEffect],
    step: f64,
) -> Vec<std::result::Result<Sensitivity, String>> {
    let base_tree = serde_json::to_value(fitted).ok();
    // Every (candidate, parameter, value) job, its setup built first, then all simulated at once.
    struct Job {
        candidate: usize,
        param: usize,
        u: f64,
        run: bool,
        setup: Option<Setup>,
    }
    type Prepared = std::result::Result<(Vec<EffectParameter>, Vec<Job>), String>;
    let mut prepared: Vec<Prepared> = Vec::new();
    for (ci, c) in candidates.iter().enumerate() {
        let prep = (|| -> Result<(Vec<EffectParameter>, Vec<Job>)> {
            let params = c.parameters(fitted)?;
            let null: Vec<f64> = params.iter().map(|p| p.null).collect();
            let mut jobs = Vec::new();
            for (j, u) in points(&params, c.discrete(), step) {
                let mut values = null.clone();
                values[j] = params[j].parameter.from_unit(u);
                let setup = c.apply(fitted, &values)?;
                // A setup identical to the base has exactly zero sensitivity: no run needed.
                let same = base_tree.is_some() && serde_json::to_value(&setup).ok() == base_tree;
                jobs.push(Job { candidate: ci, param: j, u, run: !same, setup: (!same).then_some(setup) });
            }
            Ok((params, jobs))
        })();
        prepared.push(prep.map_err(|e| e.to_string()));
    }
    let setups: Vec<Setup> = prepared
        .iter_mut()
        .filter_map(|p| p.as_mut().ok())
        .flat_map(|(_, jobs)| jobs.iter_mut().filter_map(|j| j.setup.take()))
        .collect();
    let mut results = setups.par_iter().map(|s| Misfit::of(gauge, s)).collect::<Vec<_>>().into_iter();
    let n = r0.len();
    let mut out = Vec::new();
    for (ci, prep) in prepared.into_iter().enumerate() {
        let c = candidates[ci];
        let (params, jobs) = match prep {
            Ok(p) => p,
            Err(e) => {
                out.push(Err(e));
                continue;
            }
        };
        let null_u: Vec<f64> = params.iter().map(|p| p.parameter.to_unit(p.null)).collect();
        let mut evals: Vec<Eval> = Vec::new();
        for job in &jobs {
            debug_assert_eq!(job.candidate, ci);
            let r = match job.run {
                false => Ok(r0.to_vec()),
                true => match results.next() {
                    Some(Ok(m)) if m.failures.is_empty() => Ok(m.r),
                    Some(Ok(m)) => Err(m.failures.join("; ")),
                    Some(Err(e)) => Err(e.to_string()),
                    None => Err("internal: missing evaluation".into()),
                },
            };
            evals.push((job.param, job.u, r));
        }
        let mut columns = DMatrix::zeros(n, params.len());
        let mut failure = None;
        for j in 0..params.len() {
            let mine: Vec<&Eval> = evals.iter().filter(|e| e.0 == j).collect();
            let mut pts: Vec<(f64, &Vec<f64>)> = Vec::new();
            for e in &mine {
                match &e.2 {
                    Ok(r) => pts.push((e.1, r)),
                    Err(m) => failure = Some(m.clone()),
                }
            }
            if failure.is_some() {
                break;
            }
            let (ua, ra, ub, rb) = match pts.as_slice() {
                [(u1, r1), (u2, r2)] => (*u1, (*r1).clone(), *u2, (*r2).clone()),
                [(u1, r1)] => (null_u[j], r0.to_vec(), *u1, (*r1).clone()),
                _ => continue,
            };
            for i in 0..n {
                columns[(i, j)] = (rb[i] - ra[i]) / (ub - ua);
            }
        }
        match failure {
            Some(m) => out.push(Err(format!("the model with {} did not run: {m}", c.name()))),
            None => out.push(Ok(Sensitivity {
                name: c.name().into(),
                parameters: params,
                columns,
                null_u,
                discrete: c.discrete(),
            })),
        }
    }
    out
}

/// A candidate's score at the base fit.
#[derive(Clone, Debug, Serialize)]
pub struct Score {
    /// Candidate name.
    pub name: String,
    /// Degrees of freedom (sensitive parameters).
    pub dof: usize,
    /// Score statistic `S_e` (χ² units).
    pub statistic: f64,
    /// `P(χ²_dof > S_e)`: small when the effect is present.
    pub p_value: f64,
    /// Significant at the family-wise level [`SIGNIFICANCE`].
    pub significant: bool,
    /// Share of the base misfit it removes to first order, with the fitted parameters
    /// re-adjusted (no refit).
    pub explained: f64,
    /// The effect size the data ask for (first order), per parameter: (name, value, unit).
    pub predicted: Vec<(String, f64, String)>,
    /// Angle between its sensitivity and the span of the fitted parameters' (degrees): near 0,
    /// fully confounded; 90, independent.
    pub angle_deg: f64,
    /// The fitted parameter that absorbs most of it in the base fit.
    pub absorbed_by: Option<String>,
    /// How far adding the effect at the predicted size would move that parameter (its unit).
    pub absorbed_shift: Option<f64>,
    /// First-order move of every fitted parameter (unit-cube coordinates) when the effect is
    /// added at the predicted size: where a refit starts.
    #[serde(skip)]
    pub fitted_shift: Vec<f64>,
}

/// Least squares `min ||s + A δ||²` with `δ_j ≥ 0` where `one_sided[j]` (active set).
fn constrained(a: &DMatrix<f64>, s: &DVector<f64>, one_sided: &[bool]) -> DVector<f64> {
    let k = a.ncols();
    let mut free: Vec<usize> = (0..k).collect();
    loop {
        let mut delta = DVector::zeros(k);
        if free.is_empty() {
            return delta;
        }
        let af = DMatrix::from_fn(a.nrows(), free.len(), |i, c| a[(i, free[c])]);
        let sol = af.clone().svd(true, true).solve(&(-s), 1e-12).unwrap_or_else(|_| DVector::zeros(free.len()));
        for (c, &j) in free.iter().enumerate() {
            delta[j] = sol[c];
        }
        let worst = free
            .iter()
            .copied()
            .filter(|&j| one_sided[j] && delta[j] < 0.0)
            .min_by(|&x, &y| delta[x].total_cmp(&delta[y]));
        match worst {
            Some(j) => free.retain(|&f| f != j),
            None => return delta,
        }
    }
}

/// Scores a sensitivity against the linearised base fit. `space` and `u` are the fitted
/// parameters (for the absorbing parameter's shift); `tests` is the number of candidates scored
/// (for the family-wise significance level).
pub fn score(lin: &Linearisation, sens: &Sensitivity, space: &ParameterSpace, u: &[f64], tests: usize) -> Score {
    let norms: Vec<f64> = (0..sens.columns.ncols()).map(|j| sens.columns.column(j).norm()).collect();
    let largest = norms.iter().cloned().fold(0.0, f64::max);
    let keep: Vec<usize> = (0..norms.len()).filter(|&j| norms[j] > NEGLIGIBLE * largest && norms[j] > 0.0).collect();
    let je = DMatrix::from_fn(sens.columns.nrows(), keep.len(), |i, c| sens.columns[(i, keep[c])]);
    let a = lin.project_out(&je);
    let s = {
        let rm = DMatrix::from_column_slice(lin.r.len(), 1, lin.r.as_slice());
        let p = lin.project_out(&rm);
        DVector::from_column_slice(p.as_slice())
    };
    // Sizes must move away from a null that is a bound; a switch can only be turned on.
    let one_sided: Vec<bool> =
        keep.iter().map(|&j| sens.discrete || sens.null_u[j] <= 0.0 || sens.null_u[j] >= 1.0).collect();
    let sign: Vec<f64> =
        keep.iter().map(|&j| if !sens.discrete && sens.null_u[j] >= 1.0 { -1.0 } else { 1.0 }).collect();
    let a_signed = DMatrix::from_fn(a.nrows(), a.ncols(), |i, c| a[(i, c)] * sign[c]);
    let delta_signed = constrained(&a_signed, &s, &one_sided);
    let delta = DVector::from_fn(keep.len(), |c, _| delta_signed[c] * sign[c]);
    let fitted = &s + &a * &delta;
    let statistic = (s.norm_squared() - fitted.norm_squared()).max(0.0);
    let total = lin.r.norm_squared().max(f64::MIN_POSITIVE);
    let dof = keep.len();
    let p_value = if dof == 0 { 1.0 } else { chi2_survival(statistic, dof as f64) };
    let predicted = sens
        .parameters
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let du = keep.iter().position(|&k| k == j).map_or(0.0, |c| delta[c]);
            let value = if sens.discrete {
                if du > 0.0 {
                    1.0
                } else {
                    0.0
                }
            } else {
                p.parameter.from_unit(sens.null_u[j] + du)
            };
            (p.parameter.path.clone(), value, p.parameter.unit.clone())
        })
        .collect();
    let angle_deg = if dof == 0 { f64::NAN } else { principal_cos(&je, &lin.jac).acos().to_degrees() };
    // The fitted parameters' mimicry of the effect: J_θ c ≈ J_e δ.
    let (mut absorbed_by, mut absorbed_shift) = (None, None);
    let mut fitted_shift = vec![0.0; lin.jac.ncols()];
    if dof > 0 && lin.jac.ncols() > 0 && statistic > 0.0 {
        let target = &je * &delta;
        if let Ok(c) = lin.jac.clone().svd(true, true).solve(&target, 1e-12) {
            fitted_shift = c.iter().map(|v| -v).collect();
            let contribution: Vec<f64> = (0..c.len()).map(|j| (lin.jac.column(j) * c[j]).norm()).collect();
            if let Some(j) = (0..c.len()).max_by(|&x, &y| contribution[x].total_cmp(&contribution[y])) {
                if contribution[j] > 0.0 {
                    let p = &space.parameters()[j];
                    let dx_du = match p.scale {
                        Scale::Linear => p.upper - p.lower,
                        Scale::Log => p.from_unit(u[j]) * (p.upper / p.lower).ln(),
                    };
                    absorbed_by = Some(p.path.clone());
                    absorbed_shift = Some(-c[j] * dx_du);
                }
            }
        }
    }
    Score {
        name: sens.name.clone(),
        dof,
        statistic,
        p_value,
        significant: dof > 0 && p_value < SIGNIFICANCE / tests.max(1) as f64,
        explained: statistic / total,
        predicted,
        angle_deg,
        absorbed_by,
        absorbed_shift,
        fitted_shift,
    }
}

/// Cosine between two candidates' sensitivities once the fitted parameters' span is removed
/// (1: the data cannot tell them apart).
pub fn confusability(lin: &Linearisation, a: &Sensitivity, b: &Sensitivity) -> f64 {
    principal_cos(&lin.project_out(&a.columns), &lin.project_out(&b.columns))
}
