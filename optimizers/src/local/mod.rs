//! Local methods on the box through a [`BoundTransform`]: Nelder–Mead, L-BFGS and
//! Gauss–Newton from argmin (given plain `Vec<f64>`), and the shared Levenberg–Marquardt of
//! [`crate::least_squares`].
//!
//! They search `z ∈ Rⁿ` with `x = T(z)`; derivatives are finite differences in `z`, their
//! `2n` (central) or `n` (forward) points evaluated as one parallel batch. They draw no
//! random numbers, so the seed does not matter. A run ends when the method converges (then
//! it may restart from its best point, see [`LocalSettings::restarts`]), when the budget or
//! target is reached, or when an observer asks; failed evaluations are penalised and counted.

mod gauss_newton;
mod lbfgs;
mod lm;
mod nelder_mead;

pub use gauss_newton::GaussNewton;
pub use lbfgs::Lbfgs;
pub use lm::LevenbergMarquardt;
pub use nelder_mead::NelderMead;

use crate::eval::{self, check, evaluate_batch, Tracker, DEFAULT_FAILED_VALUE};
use crate::transform::BoundTransform;
use czid_core::{Budget, CzError, Evaluation, Observer, OptimizationResult, Optimizer, Problem, Result};
use serde::{Deserialize, Serialize};
use std::cell::RefCell;

pub use crate::least_squares::Differences;

/// Settings shared by the local methods.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LocalSettings {
    /// Starting point in the box (default: the box centre).
    pub start: Option<Vec<f64>>,
    /// Map from `Rⁿ` onto the box (default `sine`).
    pub transform: BoundTransform,
    /// Convergence tolerance (default 1e-20, small on purpose: these methods polish and the
    /// budget is their real limit; raise it to stop earlier): Nelder–Mead, standard deviation of the simplex
    /// values; L-BFGS, gradient norm; Gauss–Newton, change of `‖r‖`; Levenberg–Marquardt,
    /// gradient `‖Jᵀr‖∞` and relative step.
    pub tolerance: f64,
    /// Edge of Nelder–Mead's initial simplex in `z` (default 0.5; `z` is in radians for the
    /// sine map, whose period is 2π).
    pub initial_step: f64,
    /// Relative finite-difference step: `h = fd_step · max(1, |z_i|)` (default 1e-7).
    pub fd_step: f64,
    /// Finite-difference scheme (default central).
    pub differences: Differences,
    /// L-BFGS memory (default 7).
    pub memory: usize,
    /// Fresh starts from the best point after convergence while budget remains (default 2):
    /// cheap insurance against Nelder–Mead's collapsed simplices and stale quasi-Newton memory.
    pub restarts: usize,
    /// Iteration cap per start (default 100000).
    pub max_iterations: u64,
    /// Value given to failed evaluations (default 1e30).
    pub failed_value: f64,
}

impl Default for LocalSettings {
    fn default() -> Self {
        LocalSettings {
            start: None,
            transform: BoundTransform::Sine,
            tolerance: 1e-20,
            initial_step: 0.5,
            fd_step: 1e-7,
            differences: Differences::Central,
            memory: 7,
            restarts: 2,
            max_iterations: 100_000,
            failed_value: DEFAULT_FAILED_VALUE,
        }
    }
}

impl LocalSettings {
    /// Checks every setting; `owner` names the method in errors.
    pub fn validate(&self, owner: &str) -> Result<()> {
        let o = format!("optimizer {owner}");
        if let Some(s) = &self.start {
            if let Some(v) = s.iter().find(|v| !v.is_finite()) {
                return Err(CzError::invalid(&o, "start", *v, "must be finite"));
            }
        }
        if !(self.tolerance >= 0.0 && self.tolerance.is_finite()) {
            return Err(CzError::invalid(&o, "tolerance", self.tolerance, "must be finite and not negative"));
        }
        check::positive(&o, "initial_step", self.initial_step)?;
        check::positive(&o, "fd_step", self.fd_step)?;
        check::at_least(&o, "memory", self.memory, 1)?;
        check::finite(&o, "failed_value", self.failed_value)
    }
}

/// A method that polishes from a given point (used by [`crate::hybrid::Hybrid`]).
pub trait LocalOptimizer: Optimizer {
    /// Minimises from `start` (a point of the box).
    fn minimize_from(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        start: &[f64],
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult>;
}

/// Why a local run stopped early (argmin is aborted through an error carrying this).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stop {
    Budget,
    Target,
    Observer,
    Error,
}

struct CtxState<'a> {
    tracker: Tracker,
    observer: &'a mut dyn Observer,
    iteration: usize,
    stop: Option<Stop>,
    error: Option<CzError>,
}

/// What argmin's problem wrappers share: the transformed, counted, budgeted evaluation.
pub(crate) struct Ctx<'a> {
    problem: &'a dyn Problem,
    bounds: Vec<(f64, f64)>,
    settings: &'a LocalSettings,
    budget: &'a Budget,
    state: RefCell<CtxState<'a>>,
}

impl<'a> Ctx<'a> {
    fn new(
        problem: &'a dyn Problem,
        settings: &'a LocalSettings,
        budget: &'a Budget,
        observer: &'a mut dyn Observer,
    ) -> Result<Self> {
        let bounds = eval::checked_bounds(problem)?;
        let state = CtxState { tracker: Tracker::default(), observer, iteration: 0, stop: None, error: None };
        Ok(Ctx { problem, bounds, settings, budget, state: RefCell::new(state) })
    }

    fn dim(&self) -> usize {
        self.bounds.len()
    }

    fn to_z(&self, x: &[f64]) -> Vec<f64> {
        self.settings.transform.from_box(x, &self.bounds)
    }

    fn stopped(&self) -> bool {
        self.state.borrow().stop.is_some()
    }

    fn best_x(&self) -> Vec<f64> {
        self.state.borrow().tracker.best_x.clone()
    }

    /// Evaluates the points `zs` (one parallel batch), or refuses with an argmin error once the
    /// run must stop.
    fn eval(&self, zs: &[Vec<f64>]) -> std::result::Result<Vec<Evaluation>, argmin::core::Error> {
        let mut st = self.state.borrow_mut();
        if let Some(stop) = st.stop {
            return Err(argmin::core::Error::msg(format!("{stop:?}")));
        }
        if st.tracker.evaluations + zs.len() > self.budget.evaluations {
            st.stop = Some(Stop::Budget);
            return Err(argmin::core::Error::msg("budget"));
        }
        let xs: Vec<Vec<f64>> = zs
            .iter()
            .map(|z| {
                let mut x = vec![0.0; z.len()];
                self.settings.transform.to_box(z, &self.bounds, &mut x);
                x
            })
            .collect();
        let st = &mut *st;
        let out = evaluate_batch(self.problem, &xs, self.settings.failed_value, &mut st.tracker);
        st.iteration += 1;
        match eval::report(st.observer, st.iteration, &st.tracker, None) {
            Ok(true) => {}
            Ok(false) => st.stop = Some(Stop::Observer),
            Err(e) => {
                st.error = Some(e);
                st.stop = Some(Stop::Error);
            }
        }
        if st.stop.is_none() && st.tracker.target_reached(self.budget) {
            st.stop = Some(Stop::Target);
        }
        Ok(out)
    }

    /// Points `z ± h e_i` (central) or `z + h e_i` (forward) and their steps.
    fn fd_points(&self, z: &[f64]) -> (Vec<Vec<f64>>, Vec<f64>) {
        let h: Vec<f64> = z.iter().map(|v| self.settings.fd_step * v.abs().max(1.0)).collect();
        let mut pts = Vec::with_capacity(2 * z.len());
        for i in 0..z.len() {
            let mut p = z.to_vec();
            p[i] += h[i];
            pts.push(p);
            if self.settings.differences == Differences::Central {
                let mut m = z.to_vec();
                m[i] -= h[i];
                pts.push(m);
            }
        }
        (pts, h)
    }

    fn finish(self) -> Result<OptimizationResult> {
        let st = self.state.into_inner();
        if let Some(e) = st.error {
            return Err(e);
        }
        Ok(st.tracker.result(self.bounds.len(), Vec::new()))
    }
}

/// Runs `once` from `start`, then again from the best point while restarts and budget remain.
fn with_restarts(ctx: &Ctx<'_>, start: &[f64], mut once: impl FnMut(Vec<f64>)) {
    once(ctx.to_z(start));
    for _ in 0..ctx.settings.restarts {
        if ctx.stopped() {
            break;
        }
        once(ctx.to_z(&ctx.best_x()));
    }
}

fn start_point(settings: &LocalSettings, problem: &dyn Problem, owner: &str) -> Result<Vec<f64>> {
    let bounds = eval::checked_bounds(problem)?;
    match &settings.start {
        Some(s) if s.len() != bounds.len() => Err(CzError::config(
            format!("optimizer {owner}"),
            format!("`start` has {} values, the problem has {} variables", s.len(), bounds.len()),
        )),
        Some(s) => Ok(s.clone()),
        None => Ok(bounds.iter().map(|&(lo, hi)| 0.5 * (lo + hi)).collect()),
    }
}

/// Implements [`Optimizer`] and [`LocalOptimizer`] for a local method from its inherent
/// `fn polish(&self, ctx: &Ctx<'_>, z0: Vec<f64>)`: one run from `z0` (unbounded coordinates)
/// that evaluates through `ctx` and may stop at any evaluation `ctx` refuses.
macro_rules! local_optimizer {
    ($ty:ty, $name:literal) => {
        impl czid_core::Optimizer for $ty {
            fn name(&self) -> &str {
                $name
            }

            fn stops_when_converged(&self) -> bool {
                true
            }

            fn minimize(
                &self,
                problem: &dyn czid_core::Problem,
                budget: &czid_core::Budget,
                _seed: u64,
                observer: &mut dyn czid_core::Observer,
            ) -> czid_core::Result<czid_core::OptimizationResult> {
                let start = super::start_point(&self.settings, problem, $name)?;
                super::LocalOptimizer::minimize_from(self, problem, budget, &start, observer)
            }
        }

        impl super::LocalOptimizer for $ty {
            fn minimize_from(
                &self,
                problem: &dyn czid_core::Problem,
                budget: &czid_core::Budget,
                start: &[f64],
                observer: &mut dyn czid_core::Observer,
            ) -> czid_core::Result<czid_core::OptimizationResult> {
                let ctx = super::Ctx::new(problem, &self.settings, budget, observer)?;
                super::with_restarts(&ctx, start, |z0| self.polish(&ctx, z0));
                ctx.finish()
            }
        }

        impl $ty {
            /// The method with validated settings.
            pub fn new(settings: super::LocalSettings) -> czid_core::Result<Self> {
                settings.validate($name)?;
                Ok(Self { settings })
            }

            /// The settings.
            pub fn settings(&self) -> &super::LocalSettings {
                &self.settings
            }
        }
    };
}
use local_optimizer;
