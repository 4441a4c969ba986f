//! Levenberg–Marquardt with Marquardt's diagonal scaling and Nielsen's damping update (Madsen,
//! Nielsen & Tingleff, "Methods for non-linear least squares problems", 2004, Alg. 3.16), for
//! unbounded coordinates or a box (projected steps), with fixed coordinates, a start Jacobian and
//! Broyden's rank-one updates as options.
//!
//! * **Unbounded, fresh Jacobians** (`czid identify`'s `levenberg-marquardt`): the box is mapped
//!   onto `Rⁿ` by the optimizer; after every accepted step the Jacobian is differenced again.
//! * **Box, Broyden updates** (the diagnosis's base fit and refits, in unit-cube coordinates): a
//!   step that would leave the box is clipped to it and coordinates on a bound that the gradient
//!   pushes outwards stay there, so a parameter can sit on its bound (an effect's null value often
//!   is one); every trial updates the Jacobian along the step actually taken, which costs one run
//!   per step instead of `2p`, and a fresh difference is taken only when the steps stall.

use super::jacobian::{jacobian, FiniteDifferences};
use super::ResidualSource;
use nalgebra::DMatrix;

/// Initial damping (Nielsen's τ). The damping term is `μ diag(JᵀJ)` (Marquardt's scaling), which
/// already carries each coordinate's scale, so `μ` is a pure number and starts at τ. (Scaled once
/// more by the largest diagonal entry, as Levenberg's `μ I` is, the damping would grow with the
/// square of the misfit: a refit starting 10³ noise units from the data took first steps of
/// 10⁻⁸ of its range, below the forward model's own noise, and stalled there.)
const TAU: f64 = 1e-3;
/// With Broyden updates, rejected steps in a row after which the Jacobian is differenced afresh
/// (or the run ends when no fresh Jacobian is left).
const STALL: usize = 4;

/// How the Jacobian follows the iterates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JacobianUpdates {
    /// Differenced afresh after every accepted step.
    Fresh,
    /// Broyden's rank-one update after every trial; at most this many fresh differences (beyond
    /// the first when no start Jacobian is given) when the steps stall.
    Broyden {
        /// Fresh finite-difference Jacobians allowed.
        fresh: usize,
    },
}

/// Settings of one run.
#[derive(Clone, Debug, PartialEq)]
pub struct LmOptions {
    /// Trial steps allowed.
    pub max_iterations: u64,
    /// Stop when the projected gradient `‖Jᵀr‖∞` or the relative step falls below this.
    pub tolerance: f64,
    /// Stop when an accepted step lowers `‖r‖²` by less than this fraction (0: never).
    pub min_decrease: f64,
    /// Fresh or Broyden Jacobians.
    pub updates: JacobianUpdates,
    /// The finite differences.
    pub differences: FiniteDifferences,
    /// The box the iterates stay in (`None`: unbounded).
    pub bounds: Option<Vec<(f64, f64)>>,
    /// Coordinates that keep their starting value.
    pub fixed: Vec<usize>,
}

impl LmOptions {
    /// A run on the unit cube `[0, 1]^dim` with Broyden updates (a fresh Jacobian whenever the
    /// steps stall or seem converged on an updated one), central differences of `step`, up to 50
    /// trial steps, stopping when a step gains less than 1e-6 of `‖r‖²`; the fields are public to
    /// change.
    pub fn unit_cube(dim: usize, step: f64) -> Self {
        LmOptions {
            max_iterations: 50,
            tolerance: 1e-12,
            min_decrease: 1e-6,
            updates: JacobianUpdates::Broyden { fresh: usize::MAX },
            differences: FiniteDifferences { step, scheme: super::Differences::Central },
            bounds: Some(vec![(0.0, 1.0); dim]),
            fixed: Vec::new(),
        }
    }
}

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Termination {
    /// The projected gradient fell below the tolerance.
    Gradient,
    /// The step fell below the tolerance, or a projected step did not move.
    Step,
    /// An accepted step lowered the sum of squares by less than `min_decrease`.
    Decrease,
    /// The steps stalled and no fresh Jacobian was left.
    Stalled,
    /// The damping grew without bound.
    Damping,
    /// `max_iterations` trial steps were taken.
    Iterations,
    /// Nothing to fit: every coordinate is fixed.
    NothingFree,
}

/// The outcome of a run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Best point.
    pub z: Vec<f64>,
    /// Residuals there.
    pub r: Vec<f64>,
    /// Their sum of squares.
    pub cost: f64,
    /// Points evaluated.
    pub evaluations: usize,
    /// The last Jacobian of the free coordinates (`None` when nothing is free).
    pub jacobian: Option<DMatrix<f64>>,
    /// Why the run ended.
    pub termination: Termination,
}

/// Minimises `‖r(z)‖²` from `z0`; `start_jacobian` (rows as `r`, one column per free coordinate)
/// saves the first finite differences. `Err` when the source stops the run or a Jacobian cannot be
/// evaluated; a failed trial point is a rejected step.
pub fn minimize<S: ResidualSource>(
    src: &S,
    z0: &[f64],
    opts: &LmOptions,
    start_jacobian: Option<DMatrix<f64>>,
) -> Result<Outcome, S::Error> {
    let free: Vec<usize> = (0..z0.len()).filter(|j| !opts.fixed.contains(j)).collect();
    let bounds = opts.bounds.as_deref();
    let z: Vec<f64> = match bounds {
        Some(b) => z0.iter().zip(b).map(|(v, &(lo, hi))| v.clamp(lo, hi)).collect(),
        None => z0.to_vec(),
    };
    let r = src.residuals_at(&z)?;
    if free.is_empty() {
        let cost = sum_of_squares(&r);
        return Ok(Outcome { z, r, cost, evaluations: 1, jacobian: None, termination: Termination::NothingFree });
    }
    let mut lm = Run::start(src, opts, free, z, r, start_jacobian)?;
    let termination = lm.iterate()?;
    let Run { z, r, cost, evaluations, jac, .. } = lm;
    Ok(Outcome { z, r, cost, evaluations, jacobian: Some(jac), termination })
}

/// One run's state.
struct Run<'a, S: ResidualSource> {
    src: &'a S,
    opts: &'a LmOptions,
    free: Vec<usize>,
    z: Vec<f64>,
    r: Vec<f64>,
    cost: f64,
    evaluations: usize,
    jac: DMatrix<f64>,
    /// `JᵀJ` (row-major) and `Jᵀr` of the current Jacobian.
    a: Vec<f64>,
    g: Vec<f64>,
    mu: f64,
    nu: f64,
    /// Whether `jac` was differenced at `z` (not updated since).
    fresh: bool,
    fresh_left: usize,
    rejected: usize,
}

impl<'a, S: ResidualSource> Run<'a, S> {
    fn start(
        src: &'a S,
        opts: &'a LmOptions,
        free: Vec<usize>,
        z: Vec<f64>,
        r: Vec<f64>,
        start_jacobian: Option<DMatrix<f64>>,
    ) -> Result<Self, S::Error> {
        let fresh_left = match opts.updates {
            JacobianUpdates::Fresh => 0,
            JacobianUpdates::Broyden { fresh } => fresh,
        };
        let cost = sum_of_squares(&r);
        let mut run = Run {
            src,
            opts,
            free,
            z,
            r,
            cost,
            evaluations: 1,
            jac: DMatrix::zeros(0, 0),
            a: Vec::new(),
            g: Vec::new(),
            mu: 0.0,
            nu: 2.0,
            fresh: false,
            fresh_left,
            rejected: 0,
        };
        match start_jacobian {
            Some(j) if j.nrows() == run.r.len() && j.ncols() == run.free.len() => {
                run.jac = j;
                // A coordinate without sensitivity in the start Jacobian (e.g. a bridging tail's
                // length at zero strength) would never move: its column is differenced.
                let zero: Vec<usize> = (0..run.free.len()).filter(|&k| run.jac.column(k).norm() == 0.0).collect();
                if !zero.is_empty() {
                    let cols: Vec<usize> = zero.iter().map(|&k| run.free[k]).collect();
                    let d = run.difference(&cols)?;
                    for (c, &k) in zero.iter().enumerate() {
                        run.jac.set_column(k, &d.column(c));
                    }
                }
            }
            _ => {
                run.jac = run.difference(&run.free.clone())?;
                run.fresh = true;
            }
        }
        run.normalise();
        run.reset_damping();
        Ok(run)
    }

    /// Trial steps until a stopping rule holds.
    fn iterate(&mut self) -> Result<Termination, S::Error> {
        let (n, bounds) = (self.free.len(), self.opts.bounds.as_deref());
        for _ in 0..self.opts.max_iterations {
            // Coordinates on a bound that the gradient pushes outwards stay there for this step.
            let moving: Vec<usize> =
                (0..n).filter(|&k| !pushed_out(bounds, self.free[k], self.z[self.free[k]], self.g[k])).collect();
            if moving.iter().fold(0.0f64, |s, &k| s.max(self.g[k].abs())) <= self.opts.tolerance {
                match self.refresh_or(Termination::Gradient)? {
                    Some(end) => return Ok(end),
                    None => continue,
                }
            }
            let Some(step) = damped_step(&self.a, &self.g, n, &moving, self.mu) else {
                self.mu *= self.nu;
                self.nu *= 2.0;
                continue;
            };
            let norm_z = self.z.iter().map(|v| v * v).sum::<f64>().sqrt();
            let norm_h = step.iter().map(|v| v * v).sum::<f64>().sqrt();
            let (trial, clipped) = self.trial_point(&moving, &step);
            if norm_h <= self.opts.tolerance * (norm_z + self.opts.tolerance) || (bounds.is_some() && trial == self.z) {
                match self.refresh_or(Termination::Step)? {
                    Some(end) => return Ok(end),
                    None => continue,
                }
            }
            if let Some(end) = self.try_step(trial, clipped, &moving, &step)? {
                return Ok(end);
            }
            if !self.mu.is_finite() {
                return Ok(Termination::Damping);
            }
        }
        Ok(Termination::Iterations)
    }

    /// `z − step` over the moving coordinates, projected onto the box; whether it was clipped.
    fn trial_point(&self, moving: &[usize], step: &[f64]) -> (Vec<f64>, bool) {
        let bounds = self.opts.bounds.as_deref();
        let mut trial = self.z.clone();
        let mut clipped = false;
        for (c, &k) in moving.iter().enumerate() {
            let j = self.free[k];
            let v = self.z[j] - step[c];
            trial[j] = bounds.map_or(v, |b| v.clamp(b[j].0, b[j].1));
            clipped |= trial[j] != v;
        }
        (trial, clipped)
    }

    /// Evaluates `trial` and accepts or rejects it (Nielsen's damping update); `Some` when the run
    /// ends here.
    fn try_step(
        &mut self,
        trial: Vec<f64>,
        clipped: bool,
        moving: &[usize],
        step: &[f64],
    ) -> Result<Option<Termination>, S::Error> {
        let n = self.free.len();
        let trial_r = self.src.residuals(std::slice::from_ref(&trial))?.remove(0);
        self.evaluations += 1;
        let trial_cost = match &trial_r {
            Ok(t) if !t.is_empty() => sum_of_squares(t),
            _ => f64::INFINITY,
        };
        let predicted = if clipped {
            let h: Vec<f64> = self.free.iter().map(|&j| trial[j] - self.z[j]).collect();
            predicted_decrease(&self.a, &self.g, n, &h)
        } else {
            // L(0) − L(h) of ‖r‖²'s linear model with h = −step solving (A + μD) step = g.
            let a = &self.a;
            let dmax = (0..n).map(|i| a[i * n + i]).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
            moving
                .iter()
                .enumerate()
                .map(|(c, &k)| step[c] * (self.mu * a[k * n + k].max(1e-12 * dmax) * step[c] + self.g[k]))
                .sum()
        };
        let rho = if predicted > 0.0 { (self.cost - trial_cost) / predicted } else { -1.0 };
        let broyden_updates = matches!(self.opts.updates, JacobianUpdates::Broyden { .. });
        if let (true, Ok(t)) = (broyden_updates, &trial_r) {
            broyden(&mut self.jac, &self.free, &self.z, &trial, &self.r, t);
            self.fresh = false;
        }
        if rho > 0.0 {
            let gain = (self.cost - trial_cost) / self.cost.max(f64::MIN_POSITIVE);
            self.z = trial;
            self.r = trial_r.unwrap_or_default();
            self.cost = trial_cost;
            self.rejected = 0;
            if !broyden_updates {
                self.jac = self.difference(&self.free.clone())?;
            }
            self.normalise();
            self.mu *= (1.0f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
            self.nu = 2.0;
            // A small gain ends the run even on an updated Jacobian: refreshing it here costs `2p`
            // runs per stop and, measured on the bundled diagnoses, buys nothing.
            return Ok((gain < self.opts.min_decrease).then_some(Termination::Decrease));
        }
        self.mu *= self.nu;
        self.nu *= 2.0;
        self.rejected += 1;
        if !broyden_updates {
            return Ok(None);
        }
        if self.rejected < STALL {
            self.normalise();
            return Ok(None);
        }
        self.refresh_or(Termination::Stalled)
    }

    /// With Broyden updates, a run that seems to have converged (or stalled) on an updated
    /// Jacobian gets a fresh one, if one is left, and goes on (`None`); otherwise it ends with
    /// `why`. Only a differenced Jacobian is trusted to say that the run is done.
    fn refresh_or(&mut self, why: Termination) -> Result<Option<Termination>, S::Error> {
        if self.opts.updates == JacobianUpdates::Fresh || self.fresh || self.fresh_left == 0 {
            return Ok(Some(why));
        }
        self.fresh_left -= 1;
        self.jac = self.difference(&self.free.clone())?;
        self.fresh = true;
        self.rejected = 0;
        self.normalise();
        self.reset_damping();
        Ok(None)
    }

    /// The finite-difference Jacobian at `z` for coordinates `cols`.
    fn difference(&mut self, cols: &[usize]) -> Result<DMatrix<f64>, S::Error> {
        let fd = &self.opts.differences;
        self.evaluations += fd.points(cols.len(), true);
        jacobian(self.src, &self.z, Some(&self.r), fd, self.opts.bounds.as_deref(), cols)
    }

    fn normalise(&mut self) {
        (self.a, self.g) = normal_equations(&self.jac, &self.r);
    }

    fn reset_damping(&mut self) {
        self.mu = TAU;
        self.nu = 2.0;
    }
}

fn sum_of_squares(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// Whether coordinate `j`, at `v` with gradient component `g`, sits on a bound the descent
/// direction `−g` points out of.
fn pushed_out(bounds: Option<&[(f64, f64)]>, j: usize, v: f64, g: f64) -> bool {
    bounds.is_some_and(|b| (v <= b[j].0 && g > 0.0) || (v >= b[j].1 && g < 0.0))
}

/// The step of the `moving` coordinates: `(A + μD) step = g` over them, `D = diag(A)` floored so
/// that insensitive coordinates still move (Marquardt's scaling); `None` if not positive definite.
fn damped_step(a: &[f64], g: &[f64], n: usize, moving: &[usize], mu: f64) -> Option<Vec<f64>> {
    let dmax = (0..n).map(|i| a[i * n + i]).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let q = moving.len();
    let mut m = vec![0.0; q * q];
    for (r, &i) in moving.iter().enumerate() {
        for (c, &j) in moving.iter().enumerate() {
            m[r * q + c] = a[i * n + j];
        }
        m[r * q + r] += mu * a[i * n + i].max(1e-12 * dmax);
    }
    let rhs: Vec<f64> = moving.iter().map(|&i| g[i]).collect();
    cholesky_solve(&mut m, &rhs, q)
}

/// The decrease of `‖r‖²`'s linear model along the step `h` taken: `−2gᵀh − hᵀAh`.
fn predicted_decrease(a: &[f64], g: &[f64], n: usize, h: &[f64]) -> f64 {
    let mut s = 0.0;
    for i in 0..n {
        let ah: f64 = (0..n).map(|j| a[i * n + j] * h[j]).sum();
        s -= 2.0 * g[i] * h[i] + h[i] * ah;
    }
    s
}

/// Broyden's rank-one update of the Jacobian along the step from `z` to `trial` (free
/// coordinates), residuals `r` → `rt`: `J += (Δr − J Δz) Δzᵀ / ‖Δz‖²`.
fn broyden(jac: &mut DMatrix<f64>, free: &[usize], z: &[f64], trial: &[f64], r: &[f64], rt: &[f64]) {
    let du: Vec<f64> = free.iter().map(|&j| trial[j] - z[j]).collect();
    let d2: f64 = du.iter().map(|v| v * v).sum();
    if d2 == 0.0 || rt.len() != r.len() {
        return;
    }
    for k in 0..r.len() {
        let predicted: f64 = (0..du.len()).map(|c| jac[(k, c)] * du[c]).sum();
        let miss = (rt[k] - r[k]) - predicted;
        for (c, d) in du.iter().enumerate() {
            jac[(k, c)] += miss * d / d2;
        }
    }
}

/// `(JᵀJ, Jᵀr)`, row-major, summed in row order.
fn normal_equations(j: &DMatrix<f64>, r: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let (m, n) = (j.nrows(), j.ncols());
    let mut a = vec![0.0; n * n];
    for row in 0..n {
        for k in 0..m {
            let v = j[(k, row)];
            for col in 0..n {
                a[row * n + col] += v * j[(k, col)];
            }
        }
    }
    let g = (0..n).map(|row| (0..m).map(|k| j[(k, row)]).zip(r).map(|(a, b)| a * b).sum()).collect();
    (a, g)
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

#[cfg(test)]
mod tests {
    use super::super::{Differences, Parallel};
    use super::*;

    fn boxed(fixed: Vec<usize>) -> LmOptions {
        LmOptions {
            max_iterations: 200,
            tolerance: 1e-14,
            min_decrease: 0.0,
            updates: JacobianUpdates::Broyden { fresh: 5 },
            differences: FiniteDifferences { step: 1e-4, scheme: Differences::Central },
            bounds: Some(vec![(0.0, 1.0); 2]),
            fixed,
        }
    }

    #[test]
    fn fits_a_line_and_stops_on_a_bound() {
        // y = a x + b sampled; the true b = −0.2 lies outside b ∈ [0, 1]: b ends on 0.
        let xs: Vec<f64> = (0..20).map(|i| i as f64 / 19.0).collect();
        let f = Parallel(|u: &[f64]| -> Result<Vec<f64>, ()> {
            Ok(xs.iter().map(|x| u[0] * x + u[1] - (0.3 * x - 0.2)).collect())
        });
        let res = minimize(&f, &[0.9, 0.9], &boxed(vec![]), None).unwrap();
        assert_eq!(res.z[1], 0.0);
        // With b = 0 the best slope is the least-squares slope through the origin.
        let a_ref = xs.iter().map(|x| x * (0.3 * x - 0.2)).sum::<f64>() / xs.iter().map(|x| x * x).sum::<f64>();
        assert!((res.z[0] - a_ref).abs() < 1e-6, "{} vs {a_ref}", res.z[0]);
        // A fixed coordinate keeps its value.
        let res = minimize(&f, &[0.9, 0.5], &boxed(vec![1]), None).unwrap();
        assert_eq!(res.z[1], 0.5);
    }

    #[test]
    fn fresh_jacobians_solve_rosenbrock_as_least_squares() {
        // r = (10 (y − x²), 1 − x): minimum at (1, 1).
        let f = Parallel(|z: &[f64]| -> Result<Vec<f64>, ()> { Ok(vec![10.0 * (z[1] - z[0] * z[0]), 1.0 - z[0]]) });
        let opts = LmOptions {
            max_iterations: 500,
            tolerance: 1e-12,
            min_decrease: 0.0,
            updates: JacobianUpdates::Fresh,
            differences: FiniteDifferences { step: 1e-7, scheme: Differences::Central },
            bounds: None,
            fixed: vec![],
        };
        let res = minimize(&f, &[-1.2, 1.0], &opts, None).unwrap();
        assert!((res.z[0] - 1.0).abs() < 1e-6 && (res.z[1] - 1.0).abs() < 1e-6, "{:?}", res.z);
        assert!(res.cost < 1e-12, "{}", res.cost);
    }

    #[test]
    fn the_steps_do_not_depend_on_the_units_of_the_residuals() {
        // Residuals in noise units can be 10⁴ times those of the same fit normalised by the data:
        // the points evaluated must be the same. (With the damping started at τ max diag(JᵀJ),
        // the fit in the larger units took first steps 10⁸ times shorter.)
        // The points are recorded in the order the method asks for them (a batch evaluated in
        // parallel would record them in the order its threads finish).
        struct Recorded {
            scale: f64,
            seen: std::cell::RefCell<Vec<Vec<f64>>>,
        }
        impl ResidualSource for Recorded {
            type Error = ();
            fn residuals(&self, points: &[Vec<f64>]) -> Result<Vec<Result<Vec<f64>, ()>>, ()> {
                self.seen.borrow_mut().extend(points.iter().cloned());
                let s = self.scale;
                let r = |z: &Vec<f64>| {
                    let (x, y) = (z[0], z[1]);
                    Ok(vec![s * 10.0 * (y - x * x), s * (1.0 - x), s * 0.1 * (x + y - 1.5)])
                };
                Ok(points.iter().map(r).collect())
            }
        }
        let points = |scale: f64| {
            let f = Recorded { scale, seen: Default::default() };
            let res = minimize(&f, &[0.05, 0.9], &boxed(vec![]), None).unwrap();
            assert!(res.evaluations > 20, "{}", res.evaluations);
            f.seen.into_inner()
        };
        let (small, large) = (points(1.0), points(1e4));
        // The first thirty (near the optimum, rounding in the differences tells the two apart).
        for (k, (a, b)) in small.iter().zip(&large).take(30).enumerate() {
            for (u, v) in a.iter().zip(b) {
                assert!((u - v).abs() < 1e-9, "evaluation {k}: {a:?} against {b:?}");
            }
        }
    }

    #[test]
    fn a_failed_trial_is_a_rejected_step() {
        // The model fails for x > 0.8; the minimum of (x − 0.7)² lies below it.
        let f = Parallel(|z: &[f64]| if z[0] > 0.8 { Err("failed") } else { Ok(vec![z[0] - 0.7, 0.0]) });
        let res = minimize(&f, &[0.0, 0.5], &boxed(vec![1]), None).unwrap();
        assert!((res.z[0] - 0.7).abs() < 1e-8, "{:?}", res.z);
    }
}
