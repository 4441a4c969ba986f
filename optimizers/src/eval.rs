//! Population evaluation shared by every optimizer: parallel over the batch, penalised
//! failures, exact best-so-far bookkeeping.

use czid_core::{Evaluation, Problem, Result};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// Isight's default "failed run objective value": what a failed evaluation scores.
pub const DEFAULT_FAILED_VALUE: f64 = 1e30;

/// Counters and the best point of a run; part of every checkpoint.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Tracker {
    /// Evaluations spent.
    pub evaluations: usize,
    /// Evaluations that failed (error or non-finite value).
    pub failures: usize,
    /// Evaluations answered from an earlier evaluation of the same point ([`evaluate_batch_reusing`]).
    #[serde(default)]
    pub repeats: usize,
    /// Best point so far (empty before the first evaluation).
    pub best_x: Vec<f64>,
    /// Its evaluation.
    pub best: Option<Evaluation>,
    /// Every improvement: `(evaluations including the improving one, value)`.
    pub history: Vec<(usize, f64)>,
}

impl Tracker {
    /// Best value so far (`+∞` before the first evaluation).
    pub fn best_value(&self) -> f64 {
        self.best.as_ref().map_or(f64::INFINITY, |e| e.value)
    }

    /// Records one evaluation, in the order the optimizer generated it.
    pub fn record(&mut self, x: &[f64], evaluation: &Evaluation, failed: bool) {
        self.evaluations += 1;
        if failed {
            self.failures += 1;
        }
        if evaluation.value < self.best_value() {
            self.best_x.clear();
            self.best_x.extend_from_slice(x);
            self.best = Some(evaluation.clone());
            self.history.push((self.evaluations, evaluation.value));
        }
    }

    /// Whether `budget` allows stopping: evaluations used up or target reached.
    pub fn target_reached(&self, budget: &czid_core::Budget) -> bool {
        budget.target.is_some_and(|t| self.best_value() <= t)
    }

    /// The run's result; `pareto` is filled by multi-objective methods.
    pub fn result(&self, dim: usize, pareto: Vec<(Vec<f64>, Evaluation)>) -> czid_core::OptimizationResult {
        let best = self.best.clone().unwrap_or_else(|| Evaluation::scalar(f64::INFINITY));
        let best_x = if self.best_x.is_empty() { vec![f64::NAN; dim] } else { self.best_x.clone() };
        let mut history = self.history.clone();
        if history.last().is_some_and(|&(n, _)| n != self.evaluations) {
            history.push((self.evaluations, best.value));
        }
        czid_core::OptimizationResult {
            best_x,
            best,
            evaluations: self.evaluations,
            failures: self.failures,
            repeats: self.repeats,
            history,
            pareto,
        }
    }
}

/// The penalised stand-in for a failed evaluation: every objective and the value set to
/// `failed_value`, so failures rank last but never stop the run.
pub fn failed_evaluation(failed_value: f64, objectives: usize) -> Evaluation {
    Evaluation { value: failed_value, objectives: vec![failed_value; objectives], residuals: Vec::new() }
}

/// Evaluates `xs` in parallel (the only parallel part of czid's optimizers), then records the
/// results in index order so the outcome does not depend on the number of threads.
///
/// Returns the evaluations, failures replaced by [`failed_evaluation`]. An evaluation is a
/// failure when the problem returns an error or a non-finite value, or when a multi-objective
/// problem returns the wrong number of objectives.
pub fn evaluate_batch(
    problem: &dyn Problem,
    xs: &[Vec<f64>],
    failed_value: f64,
    tracker: &mut Tracker,
) -> Vec<Evaluation> {
    let m = problem.objectives();
    let raw: Vec<Result<Evaluation>> = problem.evaluate_batch(xs);
    raw.into_iter()
        .zip(xs)
        .map(|(r, x)| {
            let (e, failed) = judged(r, m, failed_value);
            tracker.record(x, &e, failed);
            e
        })
        .collect()
}

/// Values of points a method may generate again, by the bits of their coordinates ([`key`]).
pub type Known = HashMap<Vec<u64>, f64>;

/// The key of `x` in [`Known`]: its coordinates' bit patterns (equal keys, equal points).
pub fn key(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

/// [`evaluate_batch`] for a single-objective method that generates the same point again (a
/// binary-coded genetic algorithm's child that no cut or mutation changed is a copy of a member):
/// a point whose value `known` holds, or that equals an earlier point of the batch, is recorded
/// with that value instead of being run again (the problem is deterministic, so running it again
/// would give the same). It still counts as an evaluation, and in [`Tracker::repeats`]; a known
/// value equal to `failed_value` counts as a failure, as it did when it was first evaluated. The
/// evaluation returned for a known point carries its value only.
pub fn evaluate_batch_reusing(
    problem: &dyn Problem,
    xs: &[Vec<f64>],
    failed_value: f64,
    tracker: &mut Tracker,
    known: &Known,
) -> Vec<Evaluation> {
    let m = problem.objectives();
    let keys: Vec<Vec<u64>> = xs.iter().map(|x| key(x)).collect();
    let mut first: HashMap<&[u64], usize> = HashMap::new();
    let fresh: Vec<usize> =
        (0..xs.len()).filter(|&k| !known.contains_key(&keys[k]) && *first.entry(&keys[k]).or_insert(k) == k).collect();
    let fresh_xs: Vec<Vec<f64>> = fresh.iter().map(|&k| xs[k].clone()).collect();
    let mut computed = problem.evaluate_batch(&fresh_xs).into_iter();
    let mut out: Vec<(Evaluation, bool)> = Vec::with_capacity(xs.len());
    for (k, x) in xs.iter().enumerate() {
        let (e, failed) = if let Some(&v) = known.get(&keys[k]) {
            tracker.repeats += 1;
            (Evaluation::scalar(v), v == failed_value)
        } else if first[keys[k].as_slice()] != k {
            tracker.repeats += 1;
            out[first[keys[k].as_slice()]].clone()
        } else {
            judged(computed.next().expect("one result per fresh point"), m, failed_value)
        };
        tracker.record(x, &e, failed);
        out.push((e, failed));
    }
    out.into_iter().map(|(e, _)| e).collect()
}

/// A problem's answer as recorded: the evaluation and `false`, or the penalised stand-in and
/// `true` for a failure.
fn judged(r: Result<Evaluation>, m: usize, failed_value: f64) -> (Evaluation, bool) {
    match r {
        Ok(e) if is_valid(&e, m) => (e, false),
        _ => (failed_evaluation(failed_value, m), true),
    }
}

fn is_valid(e: &Evaluation, m: usize) -> bool {
    e.value.is_finite()
        && e.objectives.iter().all(|v| v.is_finite())
        && (m <= 1 || e.objectives.len() == m)
        && e.residuals.iter().all(|v| v.is_finite())
}

/// Tells `observer` where the run stands (checkpoint first, so a stop request still leaves a
/// resumable state on disk). Returns `false` when the observer asks to stop.
pub fn report(
    observer: &mut dyn czid_core::Observer,
    iteration: usize,
    tracker: &Tracker,
    state: Option<&dyn czid_core::Snapshot>,
) -> Result<bool> {
    let progress = czid_core::Progress {
        iteration,
        evaluations: tracker.evaluations,
        failures: tracker.failures,
        best_value: tracker.best_value(),
        best_x: &tracker.best_x,
    };
    if let Some(state) = state {
        observer.checkpoint(&progress, state)?;
    }
    Ok(observer.observe(&progress))
}

/// Serialises a checkpoint state.
pub fn to_json<T: Serialize>(state: &T) -> Result<String> {
    serde_json::to_string(state).map_err(|e| czid_core::CzError::Optimizer(format!("cannot serialise state: {e}")))
}

/// Reads a checkpoint state written by optimizer `name`.
pub fn from_json<T: serde::de::DeserializeOwned>(name: &str, json: &str) -> Result<T> {
    serde_json::from_str(json)
        .map_err(|e| czid_core::CzError::config("checkpoint", format!("not a `{name}` state: {e}")))
}

/// Checks that a resumed state belongs to this optimizer and problem.
pub fn check_state(name: &str, state_name: &str, state_dim: usize, problem: &dyn Problem) -> Result<()> {
    if state_name != name {
        return Err(czid_core::CzError::config(
            "checkpoint",
            format!("state was written by `{state_name}`, cannot resume it with `{name}`"),
        ));
    }
    if state_dim != problem.dim() {
        return Err(czid_core::CzError::config(
            "checkpoint",
            format!("state has {state_dim} variables, the problem has {}", problem.dim()),
        ));
    }
    Ok(())
}

/// Validates a problem's bounds: finite with `lo ≤ hi`, one pair per variable.
pub fn checked_bounds(problem: &dyn Problem) -> Result<Vec<(f64, f64)>> {
    let bounds = problem.bounds();
    if bounds.len() != problem.dim() || bounds.is_empty() {
        return Err(czid_core::CzError::config(
            "problem bounds",
            format!(
                "{} bounds for {} variables (need one pair per variable, at least one)",
                bounds.len(),
                problem.dim()
            ),
        ));
    }
    for (i, &(lo, hi)) in bounds.iter().enumerate() {
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(czid_core::CzError::config(
                "problem bounds",
                format!("variable {i}: bounds ({lo}, {hi}) must be finite with lower ≤ upper"),
            ));
        }
    }
    Ok(bounds)
}

/// Settings validation helpers: each names the offending setting.
pub mod check {
    use czid_core::{CzError, Result};

    /// `value ∈ [0, 1]`.
    pub fn unit(owner: &str, name: &str, value: f64) -> Result<()> {
        if (0.0..=1.0).contains(&value) {
            Ok(())
        } else {
            Err(CzError::invalid(owner, name, value, "must be in [0, 1]"))
        }
    }

    /// `value ≥ min`.
    pub fn at_least(owner: &str, name: &str, value: usize, min: usize) -> Result<()> {
        if value >= min {
            Ok(())
        } else {
            Err(CzError::invalid(owner, name, value as f64, format!("must be at least {min}")))
        }
    }

    /// Finite and strictly positive.
    pub fn positive(owner: &str, name: &str, value: f64) -> Result<()> {
        czid_core::error::require_positive(owner, name, value)
    }

    /// Finite.
    pub fn finite(owner: &str, name: &str, value: f64) -> Result<()> {
        if value.is_finite() {
            Ok(())
        } else {
            Err(CzError::invalid(owner, name, value, "must be a finite number"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use czid_core::CzError;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// `x₀² + x₁`, failing for `x₀ > 1`; counts its runs.
    struct Counted(AtomicUsize);

    impl Problem for Counted {
        fn dim(&self) -> usize {
            2
        }
        fn bounds(&self) -> Vec<(f64, f64)> {
            vec![(-2.0, 2.0); 2]
        }
        fn evaluate(&self, x: &[f64]) -> Result<Evaluation> {
            self.0.fetch_add(1, Ordering::Relaxed);
            if x[0] > 1.0 {
                return Err(CzError::Simulation("diverged".into()));
            }
            Ok(Evaluation::scalar(x[0] * x[0] + x[1]))
        }
    }

    #[test]
    fn reused_evaluations_record_what_running_them_again_records() {
        let p = Counted(AtomicUsize::new(0));
        let first: Vec<Vec<f64>> = vec![vec![0.5, 0.1], vec![1.5, 0.0], vec![-0.2, 0.3]];
        // Repeats of the first batch (a failure among them), and a point twice within the batch.
        let second: Vec<Vec<f64>> =
            vec![vec![0.5, 0.1], vec![0.1, -0.4], vec![1.5, 0.0], vec![0.1, -0.4], vec![-0.2, 0.3], vec![0.0, 0.0]];
        let (mut plain, mut reusing) = (Tracker::default(), Tracker::default());
        let a1 = evaluate_batch(&p, &first, 1e30, &mut plain);
        let a2 = evaluate_batch(&p, &second, 1e30, &mut plain);
        let runs_plain = p.0.swap(0, Ordering::Relaxed);
        let b1 = evaluate_batch_reusing(&p, &first, 1e30, &mut reusing, &Known::new());
        // What a population holding the first batch's points knows.
        let known: Known = first.iter().zip(&b1).map(|(x, e)| (key(x), e.value)).collect();
        let b2 = evaluate_batch_reusing(&p, &second, 1e30, &mut reusing, &known);
        let runs_reusing = p.0.load(Ordering::Relaxed);
        let values = |v: &[Evaluation]| v.iter().map(|e| e.value.to_bits()).collect::<Vec<_>>();
        assert_eq!(values(&a1), values(&b1));
        assert_eq!(values(&a2), values(&b2));
        assert_eq!((runs_plain, runs_reusing), (9, 5));
        assert_eq!(reusing.repeats, 4);
        assert_eq!((reusing.evaluations, reusing.failures), (plain.evaluations, plain.failures));
        assert_eq!(reusing.failures, 2);
        assert_eq!((reusing.best_x.clone(), reusing.best.clone()), (plain.best_x.clone(), plain.best.clone()));
        assert_eq!(reusing.history, plain.history);
    }
}
