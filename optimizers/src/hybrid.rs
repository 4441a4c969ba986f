//! Global search, then a local polish from its best point, within one budget.

use crate::local::LocalOptimizer;
use crate::registry::{local_from_table, optimizer_from_table};
use czid_core::{Budget, CzError, Observer, OptimizationResult, Optimizer, Problem, Progress, Result, Snapshot};
use serde::{Deserialize, Serialize};

/// Hybrid settings, e.g. in TOML:
/// `{ type = "hybrid", global = { type = "miga" }, local = { type = "nelder-mead" }, local_fraction = 0.2 }`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HybridSettings {
    /// The global method as a table with its `type` (default `{ type = "miga" }`).
    pub global: toml::Value,
    /// The local method as a table with its `type` (default `{ type = "nelder-mead" }`).
    pub local: toml::Value,
    /// Share of the evaluation budget kept for the local polish (default 0.2).
    pub local_fraction: f64,
}

impl Default for HybridSettings {
    fn default() -> Self {
        let table = |name: &str| {
            let mut t = toml::Table::new();
            t.insert("type".into(), toml::Value::String(name.into()));
            toml::Value::Table(t)
        };
        HybridSettings { global: table("miga"), local: table("nelder-mead"), local_fraction: 0.2 }
    }
}

/// The hybrid (registry name `hybrid`).
pub struct Hybrid {
    global: Box<dyn Optimizer + Send + Sync>,
    local: Box<dyn LocalOptimizer + Send + Sync>,
    local_fraction: f64,
}

impl Hybrid {
    /// From settings (builds both methods through the registry).
    pub fn new(settings: &HybridSettings) -> Result<Self> {
        if !(0.0..=1.0).contains(&settings.local_fraction) {
            return Err(CzError::invalid(
                "optimizer hybrid",
                "local_fraction",
                settings.local_fraction,
                "must be in [0, 1]",
            ));
        }
        Ok(Hybrid {
            global: optimizer_from_table(&settings.global)?,
            local: local_from_table(&settings.local)?,
            local_fraction: settings.local_fraction,
        })
    }

    /// From two methods.
    pub fn from_parts(
        global: Box<dyn Optimizer + Send + Sync>,
        local: Box<dyn LocalOptimizer + Send + Sync>,
        local_fraction: f64,
    ) -> Self {
        Hybrid { global, local, local_fraction: local_fraction.clamp(0.0, 1.0) }
    }
}

/// Shifts the local phase's counters by what the global phase spent.
struct Offset<'a> {
    inner: &'a mut dyn Observer,
    evaluations: usize,
    failures: usize,
    iterations: usize,
}

impl Offset<'_> {
    fn shift<'p>(&self, p: &Progress<'p>) -> Progress<'p> {
        Progress {
            iteration: p.iteration + self.iterations,
            evaluations: p.evaluations + self.evaluations,
            failures: p.failures + self.failures,
            ..p.clone()
        }
    }
}

impl Observer for Offset<'_> {
    fn observe(&mut self, p: &Progress<'_>) -> bool {
        let p = self.shift(p);
        self.inner.observe(&p)
    }

    fn checkpoint(&mut self, p: &Progress<'_>, state: &dyn Snapshot) -> Result<()> {
        let p = self.shift(p);
        self.inner.checkpoint(&p, state)
    }
}

impl Optimizer for Hybrid {
    fn name(&self) -> &str {
        "hybrid"
    }

    fn minimize(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        seed: u64,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        let local_budget = (self.local_fraction * budget.evaluations as f64).floor() as usize;
        let global_budget = Budget { evaluations: budget.evaluations - local_budget, target: budget.target };
        let mut g = self.global.minimize(problem, &global_budget, seed, observer)?;
        let remaining = budget.evaluations - g.evaluations;
        if remaining == 0 || budget.target.is_some_and(|t| g.best.value <= t) || g.best_x.iter().any(|v| !v.is_finite())
        {
            return Ok(g);
        }
        let mut offset =
            Offset { inner: observer, evaluations: g.evaluations, failures: g.failures, iterations: g.history.len() };
        let local = self.local.minimize_from(
            problem,
            &Budget { evaluations: remaining, target: budget.target },
            &g.best_x,
            &mut offset,
        )?;
        let total = g.evaluations + local.evaluations;
        // Drop the closing `(evaluations, best)` entry of the global phase if it only repeats
        // the last improvement: the merged history lists improvements.
        let h = &g.history;
        if h.len() > 1 && h[h.len() - 1].0 == g.evaluations && h[h.len() - 1].1 == h[h.len() - 2].1 {
            g.history.pop();
        }
        for &(n, v) in &local.history {
            if v < g.history.last().map_or(f64::INFINITY, |h| h.1) {
                g.history.push((n + g.evaluations, v));
            }
        }
        if local.best.value < g.best.value {
            g.best = local.best;
            g.best_x = local.best_x;
        }
        if g.history.last().is_some_and(|&(n, _)| n != total) {
            g.history.push((total, g.best.value));
        }
        g.evaluations = total;
        g.failures += local.failures;
        Ok(g)
    }
}
