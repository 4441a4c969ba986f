//! The contract between search methods and what they minimise.

use crate::error::Result;
use serde::{Deserialize, Serialize};

/// The outcome of evaluating one candidate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Scalar value minimised by single-objective methods (the weighted composite `f`).
    pub value: f64,
    /// Separate objectives for multi-objective methods (e.g. `[||φ_F||², ||φ_L||²]`); empty
    /// when the problem has only `value`.
    pub objectives: Vec<f64>,
    /// Residual vector with `value = ||residuals||²`, for least-squares methods; empty when not
    /// available.
    pub residuals: Vec<f64>,
}

impl Evaluation {
    /// A scalar-only evaluation.
    pub fn scalar(value: f64) -> Self {
        Evaluation { value, objectives: Vec::new(), residuals: Vec::new() }
    }
}

/// A bounded minimisation problem.
///
/// `evaluate` may fail (e.g. a forward model that does not converge): optimizers count and
/// penalise failures, they never abort on them.
pub trait Problem: Sync {
    /// Number of variables.
    fn dim(&self) -> usize;
    /// Box bounds `(lower, upper)` per variable.
    fn bounds(&self) -> Vec<(f64, f64)>;
    /// Evaluates a candidate.
    fn evaluate(&self, x: &[f64]) -> Result<Evaluation>;
    /// Evaluates a batch of candidates; result `k` belongs to `xs[k]`. The default runs them on
    /// rayon's threads (one alone on the calling thread). Wrappers forward the batch to the
    /// problem they wrap, so that a [`BatchEvaluator`] at the bottom can send it elsewhere.
    fn evaluate_batch(&self, xs: &[Vec<f64>]) -> Vec<Result<Evaluation>> {
        use rayon::prelude::*;
        if xs.len() == 1 {
            vec![self.evaluate(&xs[0])]
        } else {
            xs.par_iter().map(|x| self.evaluate(x)).collect()
        }
    }
    /// Number of separate objectives in [`Evaluation::objectives`] (1 when only `value`).
    fn objectives(&self) -> usize {
        1
    }
}

/// Where the candidates of a batch are evaluated: on this process's threads, or spread over
/// processes that each hold an identical copy of the problem (MPI ranks). Result `k` must belong
/// to `xs[k]` whatever the spreading, so that optimizers stay deterministic.
pub trait BatchEvaluator: Send + Sync {
    /// Evaluates `xs` with `problem` or its copies.
    fn evaluate(&self, problem: &dyn Problem, xs: &[Vec<f64>]) -> Vec<Result<Evaluation>>;
}

/// A problem whose batches go through a [`BatchEvaluator`].
pub struct Batched<'a> {
    /// The problem.
    pub problem: &'a dyn Problem,
    /// Where its batches are evaluated.
    pub by: &'a dyn BatchEvaluator,
}

impl Problem for Batched<'_> {
    fn dim(&self) -> usize {
        self.problem.dim()
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        self.problem.bounds()
    }
    fn evaluate(&self, x: &[f64]) -> Result<Evaluation> {
        self.problem.evaluate(x)
    }
    fn evaluate_batch(&self, xs: &[Vec<f64>]) -> Vec<Result<Evaluation>> {
        self.by.evaluate(self.problem, xs)
    }
    fn objectives(&self) -> usize {
        self.problem.objectives()
    }
}

/// When to stop.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Budget {
    /// Maximum number of objective evaluations.
    pub evaluations: usize,
    /// Stop once the best value is at or below this.
    pub target: Option<f64>,
}

impl Budget {
    /// A budget of `evaluations` with no target.
    pub fn evaluations(evaluations: usize) -> Self {
        Budget { evaluations, target: None }
    }
}

/// Progress of a run, reported to [`Observer`]s after each iteration or generation.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress<'a> {
    /// Iteration or generation index (from 0).
    pub iteration: usize,
    /// Evaluations spent so far.
    pub evaluations: usize,
    /// Failed evaluations so far.
    pub failures: usize,
    /// Best value so far.
    pub best_value: f64,
    /// Best point so far.
    pub best_x: &'a [f64],
}

/// The resumable state of a run, serialised only when an observer asks for it (so runs that
/// are not checkpointed pay nothing).
pub trait Snapshot {
    /// The state as JSON, accepted back by [`Optimizer::resume`].
    fn to_json(&self) -> Result<String>;
}

/// Watches a run (progress bars, history files, checkpoints). Returning `false` asks the
/// optimizer to stop after the current iteration.
pub trait Observer {
    /// Called after each iteration.
    fn observe(&mut self, progress: &Progress<'_>) -> bool;

    /// Called after each iteration, before [`Observer::observe`], by optimizers that can resume:
    /// `state` resumes the run exactly where it stands. The default ignores it; a checkpoint
    /// writer saves it. An error (e.g. a full disk) stops the run.
    fn checkpoint(&mut self, progress: &Progress<'_>, state: &dyn Snapshot) -> Result<()> {
        let _ = (progress, state);
        Ok(())
    }
}

impl<T: Observer + ?Sized> Observer for &mut T {
    fn observe(&mut self, progress: &Progress<'_>) -> bool {
        (**self).observe(progress)
    }

    fn checkpoint(&mut self, progress: &Progress<'_>, state: &dyn Snapshot) -> Result<()> {
        (**self).checkpoint(progress, state)
    }
}

/// An observer that does nothing.
pub struct NoObserver;

impl Observer for NoObserver {
    fn observe(&mut self, _: &Progress<'_>) -> bool {
        true
    }
}

/// What an optimizer returns.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OptimizationResult {
    /// Best point found.
    pub best_x: Vec<f64>,
    /// Its evaluation.
    pub best: Evaluation,
    /// Evaluations spent.
    pub evaluations: usize,
    /// Evaluations that failed.
    pub failures: usize,
    /// Evaluations of a point evaluated before, answered from that evaluation instead of running
    /// the problem again (counted in `evaluations`; a genetic algorithm's child equal to a member).
    #[serde(default)]
    pub repeats: usize,
    /// Every improvement of the best value: `(evaluations so far, best value)`, where the
    /// count includes the evaluation that found it (so the best-so-far curve is exact per
    /// evaluation); the last entry is `(evaluations, best.value)`.
    pub history: Vec<(usize, f64)>,
    /// Non-dominated set for multi-objective methods: `(x, evaluation)`.
    pub pareto: Vec<(Vec<f64>, Evaluation)>,
}

/// A search method.
pub trait Optimizer {
    /// Short name, e.g. `"miga"`.
    fn name(&self) -> &str;
    /// Minimises `problem` within `budget`; the same `seed` gives the same result whatever the
    /// number of threads.
    fn minimize(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        seed: u64,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult>;

    /// Whether the method ends on its own convergence criterion (a local method, or a global
    /// search followed by a local polish), so that a run that spent its whole budget had not
    /// converged. Population methods that always spend their budget keep the default `false`.
    fn stops_when_converged(&self) -> bool {
        false
    }

    /// Refuses a budget the method cannot run with (e.g. smaller than its initial population),
    /// so that a caller can check every run before starting any. `minimize` checks it too.
    fn check_budget(&self, budget: &Budget) -> Result<()> {
        let _ = budget;
        Ok(())
    }

    /// Continues a run from a state saved through [`Observer::checkpoint`], with a possibly
    /// different budget; the final result equals that of an uninterrupted run. Optimizers that
    /// cannot resume keep this default, which says so.
    fn resume(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        state: &str,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        let _ = (problem, budget, state, observer);
        Err(crate::error::CzError::Optimizer(format!("optimizer `{}` cannot resume from a checkpoint", self.name())))
    }
}
