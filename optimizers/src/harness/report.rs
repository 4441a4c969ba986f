//! Summary statistics (COCO-style success rates, evaluations to target, ERT) and Moré–Wild
//! data profiles.

use super::records::{ConvergencePoint, RunRecord};
use std::collections::BTreeMap;

/// Statistics of one optimizer on one problem over its seeds.
#[derive(Clone, Debug, PartialEq)]
pub struct SummaryRow {
    /// Problem name.
    pub problem: String,
    /// Optimizer label.
    pub optimizer: String,
    /// Number of runs (seeds).
    pub runs: usize,
    /// Runs that reached the target.
    pub successes: usize,
    /// The target.
    pub target: f64,
    /// Median evaluations to target over successful runs.
    pub median_evaluations_to_target: Option<f64>,
    /// Expected running time (COCO): evaluations of all runs until success or budget,
    /// divided by the number of successes.
    pub ert: Option<f64>,
    /// Quartiles (25 %, 50 %, 75 %) of the best value.
    pub best_quartiles: [f64; 3],
    /// Median wall-clock seconds per run.
    pub median_wall_seconds: f64,
}

/// Quantile `q` of sorted data (linear interpolation).
pub(crate) fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let pos = q * (sorted.len() - 1) as f64;
    let (i, f) = (pos.floor() as usize, pos - pos.floor());
    if i + 1 < sorted.len() {
        sorted[i] * (1.0 - f) + sorted[i + 1] * f
    } else {
        sorted[i]
    }
}

fn sorted(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v
}

/// One row per (problem, optimizer), in order of first appearance.
pub fn summary_table(runs: &[RunRecord]) -> Vec<SummaryRow> {
    let mut order: Vec<(String, String)> = Vec::new();
    for r in runs {
        let key = (r.problem.clone(), r.optimizer.clone());
        if !order.contains(&key) {
            order.push(key);
        }
    }
    order
        .into_iter()
        .map(|(problem, optimizer)| {
            let rs: Vec<&RunRecord> =
                runs.iter().filter(|r| r.problem == problem && r.optimizer == optimizer).collect();
            let hits = sorted(rs.iter().filter_map(|r| r.evaluations_to_target.map(|n| n as f64)).collect());
            let spent: f64 = rs.iter().map(|r| r.evaluations_to_target.unwrap_or(r.evaluations) as f64).sum();
            let best = sorted(rs.iter().map(|r| r.best_value).collect());
            let wall = sorted(rs.iter().map(|r| r.wall_seconds).collect());
            SummaryRow {
                runs: rs.len(),
                successes: hits.len(),
                target: rs[0].target,
                median_evaluations_to_target: (!hits.is_empty()).then(|| quantile(&hits, 0.5)),
                ert: (!hits.is_empty()).then(|| spent / hits.len() as f64),
                best_quartiles: [quantile(&best, 0.25), quantile(&best, 0.5), quantile(&best, 0.75)],
                median_wall_seconds: quantile(&wall, 0.5),
                problem,
                optimizer,
            }
        })
        .collect()
}

/// A Moré–Wild data profile: the fraction of problem instances solved within `κ (n + 1)`
/// evaluations, as the sorted `κ` at which each solved instance was solved.
#[derive(Clone, Debug, PartialEq)]
pub struct DataProfile {
    /// Optimizer label.
    pub optimizer: String,
    /// Sorted budgets (in simplex gradients, `evaluations / (n + 1)`) of the solved instances.
    pub solved_at: Vec<f64>,
    /// Number of instances (problem × seed).
    pub instances: usize,
}

impl DataProfile {
    /// `d(κ)`: fraction of instances solved within `κ (n + 1)` evaluations.
    pub fn fraction(&self, kappa: f64) -> f64 {
        self.solved_at.partition_point(|&k| k <= kappa) as f64 / self.instances.max(1) as f64
    }
}

/// `(optimizer, problem, seed)`.
type RunKey<'a> = (&'a str, &'a str, u64);

/// Moré & Wild (2009) data profiles. An instance is a (problem, seed) pair; optimizer `s`
/// solves it after `t` evaluations when its best value first satisfies
/// `f ≤ f_L + τ (f_0 − f_L)`, with `f_L` the best value any optimizer found on the instance
/// and `f_0` the largest first-evaluation value among the optimizers (they do not share a
/// starting point, so the least favourable start sets the scale).
pub fn data_profiles(runs: &[RunRecord], curves: &[ConvergencePoint], tau: f64) -> Vec<DataProfile> {
    let mut by_run: BTreeMap<RunKey<'_>, Vec<(usize, f64)>> = BTreeMap::new();
    for c in curves {
        by_run.entry((&c.optimizer, &c.problem, c.seed)).or_default().push((c.evaluations, c.best_value));
    }
    by_run.values_mut().for_each(|v| v.sort_by_key(|p| p.0));
    let mut optimizers: Vec<&str> = Vec::new();
    let mut instances: BTreeMap<(&str, u64), (usize, f64, f64)> = BTreeMap::new(); // dim, f0, fL
    for r in runs {
        if !optimizers.contains(&r.optimizer.as_str()) {
            optimizers.push(&r.optimizer);
        }
        let first =
            by_run.get(&(r.optimizer.as_str(), r.problem.as_str(), r.seed)).and_then(|c| c.first()).map(|p| p.1);
        let e = instances.entry((&r.problem, r.seed)).or_insert((r.dim, f64::NEG_INFINITY, f64::INFINITY));
        e.1 = e.1.max(first.unwrap_or(f64::NEG_INFINITY));
        e.2 = e.2.min(r.best_value);
    }
    optimizers
        .iter()
        .map(|&opt| {
            let mut solved_at: Vec<f64> = instances
                .iter()
                .filter_map(|(&(problem, seed), &(dim, f0, fl))| {
                    let threshold = fl + tau * (f0 - fl).max(0.0);
                    let curve = by_run.get(&(opt, problem, seed))?;
                    let &(n, _) = curve.iter().find(|&&(_, v)| v <= threshold)?;
                    Some(n as f64 / (dim + 1) as f64)
                })
                .collect();
            solved_at.sort_by(f64::total_cmp);
            DataProfile { optimizer: opt.to_string(), solved_at, instances: instances.len() }
        })
        .collect()
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("—".to_string(), |v| format!("{v:.0}"))
}

/// The summary as markdown tables.
pub fn markdown(rows: &[SummaryRow], profiles: &[DataProfile], tau: f64) -> String {
    let mut s = String::from(
        "| problem | optimizer | target | success | median evals to target | ERT | best value: median [q1, q3] | median wall s |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {:.0e} | {}/{} ({:.0} %) | {} | {} | {:.3e} [{:.3e}, {:.3e}] | {:.3} |\n",
            r.problem,
            r.optimizer,
            r.target,
            r.successes,
            r.runs,
            100.0 * r.successes as f64 / r.runs.max(1) as f64,
            fmt_opt(r.median_evaluations_to_target),
            fmt_opt(r.ert),
            r.best_quartiles[1],
            r.best_quartiles[0],
            r.best_quartiles[2],
            r.median_wall_seconds,
        ));
    }
    if !profiles.is_empty() {
        let kappas = [10.0, 100.0, 1000.0, 10_000.0];
        s.push_str(&format!("\nData profiles (τ = {tau:e}): fraction of (problem, seed) instances solved within κ (n + 1) evaluations\n\n| optimizer |"));
        kappas.iter().for_each(|k| s.push_str(&format!(" κ = {k} |")));
        s.push_str("\n|---|");
        kappas.iter().for_each(|_| s.push_str("---|"));
        s.push('\n');
        for p in profiles {
            s.push_str(&format!("| {} |", p.optimizer));
            kappas.iter().for_each(|&k| s.push_str(&format!(" {:.2} |", p.fraction(k))));
            s.push('\n');
        }
    }
    s
}
