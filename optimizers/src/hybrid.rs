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

/// The checkpoint of a hybrid run: the global method's own state while it runs, then the global
/// phase's result once the local polish has started (the polish keeps no state: a run resumed
/// in that phase polishes again from the same point, which gives the same result).
#[derive(Serialize, Deserialize)]
#[serde(tag = "phase", rename_all = "snake_case")]
enum Phase {
    Global { state: serde_json::Value },
    Local { global: OptimizationResult },
}

impl Snapshot for Phase {
    fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| CzError::Optimizer(format!("hybrid checkpoint: {e}")))
    }
}

/// Wraps the global method's checkpoints as [`Phase::Global`], and notes whether an observer
/// stopped the run (then there is no polish: the run resumes in the global phase).
struct GlobalPhase<'a> {
    inner: &'a mut dyn Observer,
    stopped: bool,
}

impl Observer for GlobalPhase<'_> {
    fn observe(&mut self, p: &Progress<'_>) -> bool {
        let go_on = self.inner.observe(p);
        self.stopped |= !go_on;
        go_on
    }

    fn checkpoint(&mut self, p: &Progress<'_>, state: &dyn Snapshot) -> Result<()> {
        let state = serde_json::from_str(&state.to_json()?)
            .map_err(|e| CzError::Optimizer(format!("hybrid checkpoint of the global phase: {e}")))?;
        self.inner.checkpoint(p, &Phase::Global { state })
    }
}

impl Hybrid {
    /// The budgets of the two phases.
    fn split(&self, budget: &Budget) -> Budget {
        let local_budget = (self.local_fraction * budget.evaluations as f64).floor() as usize;
        Budget { evaluations: budget.evaluations - local_budget, target: budget.target }
    }

    /// The local polish from the global phase's result `g`, and the two merged.
    fn polish(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        mut g: OptimizationResult,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        let remaining = budget.evaluations - g.evaluations;
        if remaining == 0 || budget.target.is_some_and(|t| g.best.value <= t) || g.best_x.iter().any(|v| !v.is_finite())
        {
            return Ok(g);
        }
        let mut offset =
            Offset { inner: observer, evaluations: g.evaluations, failures: g.failures, iterations: g.history.len() };
        let start = Progress {
            iteration: g.history.len(),
            evaluations: g.evaluations,
            failures: g.failures,
            best_value: g.best.value,
            best_x: &g.best_x,
        };
        offset.inner.checkpoint(&start, &Phase::Local { global: g.clone() })?;
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
        g.repeats += local.repeats;
        Ok(g)
    }
}

impl Optimizer for Hybrid {
    fn name(&self) -> &str {
        "hybrid"
    }

    /// The polish ends on the local method's criterion.
    fn stops_when_converged(&self) -> bool {
        true
    }

    fn check_budget(&self, budget: &Budget) -> Result<()> {
        let global = self.split(budget);
        self.global.check_budget(&global).map_err(|e| {
            CzError::config(
                "optimizer hybrid",
                format!(
                    "its global phase ({}) gets {} of the budget's {} evaluations (the rest, local_fraction = {}, is \
                     the polish's) and cannot run with them: {e}. Raise the budget or lower local_fraction",
                    self.global.name(),
                    global.evaluations,
                    budget.evaluations,
                    self.local_fraction
                ),
            )
        })
    }

    fn minimize(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        seed: u64,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        self.check_budget(budget)?;
        let mut phase = GlobalPhase { inner: observer, stopped: false };
        let g = self.global.minimize(problem, &self.split(budget), seed, &mut phase)?;
        if phase.stopped {
            return Ok(g);
        }
        self.polish(problem, budget, g, observer)
    }

    fn resume(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        state: &str,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        let phase: Phase = serde_json::from_str(state)
            .map_err(|e| CzError::Optimizer(format!("the checkpoint is not a hybrid run's: {e}")))?;
        let g = match phase {
            Phase::Global { state } => {
                let mut phase = GlobalPhase { inner: observer, stopped: false };
                let g = self.global.resume(problem, &self.split(budget), &state.to_string(), &mut phase)?;
                if phase.stopped {
                    return Ok(g);
                }
                g
            }
            Phase::Local { global } => global,
        };
        self.polish(problem, budget, g, observer)
    }
}
