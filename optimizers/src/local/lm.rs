//! Levenberg–Marquardt on [`czid_core::Evaluation::residuals`] (ours: argmin 0.11 has none),
//! with Marquardt's diagonal scaling and Nielsen's damping update (Madsen, Nielsen &
//! Tingleff, "Methods for non-linear least squares problems", 2004, Alg. 3.16).

use super::gauss_newton::Residuals;
use super::{local_optimizer, Ctx, LocalSettings};
use std::cell::RefCell;

/// Levenberg–Marquardt (registry name `levenberg-marquardt`, alias `lm`); needs residuals.
#[derive(Clone, Debug)]
pub struct LevenbergMarquardt {
    settings: LocalSettings,
}

local_optimizer!(LevenbergMarquardt, "levenberg-marquardt");

/// Initial damping relative to the largest diagonal entry of JᵀJ (Nielsen's τ).
const TAU: f64 = 1e-3;

impl LevenbergMarquardt {
    fn polish(&self, ctx: &Ctx<'_>, z0: Vec<f64>) {
        let op = Residuals { ctx, last: RefCell::new(None) };
        let _ = solve(&op, z0, self.settings.tolerance, self.settings.max_iterations);
    }
}

/// One LM run from `z`; returns early (with an error) when the run must stop.
fn solve(
    op: &Residuals<'_, '_>,
    mut z: Vec<f64>,
    tol: f64,
    max_iterations: u64,
) -> std::result::Result<(), argmin::core::Error> {
    let n = z.len();
    let mut r = op.batch(std::slice::from_ref(&z))?.remove(0);
    let mut cost: f64 = r.iter().map(|v| v * v).sum();
    let (mut a, mut g) = normal_equations(&op.jacobian_at(&z, Some(&r))?, &r);
    let mut mu = TAU * (0..n).map(|i| a[i * n + i]).fold(0.0, f64::max);
    let mut nu = 2.0;
    let mut m = vec![0.0; n * n];
    for _ in 0..max_iterations {
        if g.iter().fold(0.0f64, |s, v| s.max(v.abs())) <= tol {
            return Ok(());
        }
        // Marquardt scaling D = diag(JᵀJ), floored so that insensitive variables still move.
        let dmax = (0..n).map(|i| a[i * n + i]).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        m.copy_from_slice(&a);
        for i in 0..n {
            m[i * n + i] += mu * a[i * n + i].max(1e-12 * dmax);
        }
        let Some(step) = cholesky_solve(&mut m, &g, n) else {
            mu *= nu;
            nu *= 2.0;
            continue;
        };
        let norm_z = z.iter().map(|v| v * v).sum::<f64>().sqrt();
        let norm_h = step.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm_h <= tol * (norm_z + tol) {
            return Ok(());
        }
        let trial: Vec<f64> = z.iter().zip(&step).map(|(a, b)| a - b).collect();
        let trial_r = op.ctx.eval(std::slice::from_ref(&trial))?.remove(0).residuals;
        let trial_cost: f64 = if trial_r.is_empty() { f64::INFINITY } else { trial_r.iter().map(|v| v * v).sum() };
        // Gain ratio: actual over predicted decrease of ½‖r‖², with h = −step:
        // L(0) − L(h) = ½ hᵀ(μ D h − g) = ½ stepᵀ(μ D step + g).
        let predicted: f64 = (0..n).map(|i| step[i] * (mu * a[i * n + i].max(1e-12 * dmax) * step[i] + g[i])).sum();
        let rho = if predicted > 0.0 { (cost - trial_cost) / predicted } else { -1.0 };
        if rho > 0.0 {
            z = trial;
            r = trial_r;
            cost = trial_cost;
            (a, g) = normal_equations(&op.jacobian_at(&z, Some(&r))?, &r);
            mu *= (1.0f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
            nu = 2.0;
        } else {
            mu *= nu;
            nu *= 2.0;
        }
        if !mu.is_finite() {
            return Ok(());
        }
    }
    Ok(())
}

/// `(JᵀJ, Jᵀr)`, row-major.
fn normal_equations(j: &super::gauss_newton::Mat, r: &[f64]) -> (Vec<f64>, Vec<f64>) {
    use argmin_math::{ArgminDot, ArgminTranspose};
    let jt = j.clone().t();
    let a: super::gauss_newton::Mat = jt.dot(j);
    let g: Vec<f64> = jt.dot(&r.to_vec());
    (a.into_data(), g)
}

/// Solves `M x = b` for symmetric positive definite `M` (overwritten by its Cholesky factor);
/// `None` if `M` is not positive definite.
fn cholesky_solve(m: &mut [f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    for j in 0..n {
        let mut d = m[j * n + j];
        for k in 0..j {
            d -= m[j * n + k] * m[j * n + k];
        }
        if d.is_nan() || d <= 0.0 || !d.is_finite() {
            return None;
        }
        let d = d.sqrt();
        m[j * n + j] = d;
        for i in j + 1..n {
            let mut s = m[i * n + j];
            for k in 0..j {
                s -= m[i * n + k] * m[j * n + k];
            }
            m[i * n + j] = s / d;
        }
    }
    let mut y = b.to_vec();
    for i in 0..n {
        for k in 0..i {
            y[i] -= m[i * n + k] * y[k];
        }
        y[i] /= m[i * n + i];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            y[i] -= m[k * n + i] * y[k];
        }
        y[i] /= m[i * n + i];
    }
    Some(y)
}
