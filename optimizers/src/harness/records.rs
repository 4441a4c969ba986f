//! The harness's CSV records.

use czid_core::{CzError, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One run of one optimizer on one problem with one seed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// Optimizer label.
    pub optimizer: String,
    /// Problem name.
    pub problem: String,
    /// Number of variables.
    pub dim: usize,
    /// Seed.
    pub seed: u64,
    /// Best value found.
    pub best_value: f64,
    /// The problem's known optimal value.
    pub optimum: f64,
    /// Evaluations spent.
    pub evaluations: usize,
    /// Failed evaluations.
    pub failures: usize,
    /// Success threshold on the value.
    pub target: f64,
    /// Evaluations until the best value first reached the target (empty if never).
    pub evaluations_to_target: Option<usize>,
    /// Wall-clock seconds of the run.
    pub wall_seconds: f64,
}

/// One improvement of a run's best value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConvergencePoint {
    /// Optimizer label.
    pub optimizer: String,
    /// Problem name.
    pub problem: String,
    /// Seed.
    pub seed: u64,
    /// Evaluations so far, including the improving one.
    pub evaluations: usize,
    /// The new best value.
    pub best_value: f64,
}

fn to_csv<T: Serialize>(rows: &[T]) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r).map_err(|e| CzError::Optimizer(format!("csv: {e}")))?;
    }
    let bytes = w.into_inner().map_err(|e| CzError::Optimizer(format!("csv: {e}")))?;
    String::from_utf8(bytes).map_err(|e| CzError::Optimizer(format!("csv: {e}")))
}

fn from_csv<T: serde::de::DeserializeOwned>(path: &Path) -> Result<Vec<T>> {
    let mut r = csv::Reader::from_path(path)
        .map_err(|e| CzError::Io { path: path.display().to_string(), message: e.to_string() })?;
    r.deserialize()
        .enumerate()
        .map(|(i, row)| row.map_err(|e| CzError::data(format!("{} row {}", path.display(), i + 2), e.to_string())))
        .collect()
}

/// `runs.csv` content.
pub fn runs_csv(runs: &[RunRecord]) -> Result<String> {
    to_csv(runs)
}

/// `convergence.csv` content.
pub fn convergence_csv(points: &[ConvergencePoint]) -> Result<String> {
    to_csv(points)
}

/// Reads a `runs.csv`.
pub fn read_runs(path: &Path) -> Result<Vec<RunRecord>> {
    from_csv(path)
}

/// Reads a `convergence.csv`.
pub fn read_convergence(path: &Path) -> Result<Vec<ConvergencePoint>> {
    from_csv(path)
}
