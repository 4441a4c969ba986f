//! Prediction of tests at identified parameters: the law (and moduli) calibrated on some
//! specimens, run on others, and how far each test lies from its prediction.
//!
//! `czid identify file.toml --leave-out enf03` calibrates on the other specimens; `czid predict
//! file.toml --from out/result.json` then runs every specimen of the file at the identified
//! values and reports each one's root-mean-square error, marked calibrated or held out (held out:
//! absent from the calibration's result). A law that describes the material predicts a held-out
//! specimen about as well as it fits the calibration specimens.

use czid_core::{CzError, Result};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

use crate::identification::RmsError;
use crate::identify::write_fits;
use crate::output::OutputDir;
use crate::problem_file::LoadedProblem;

/// One experiment's term, predicted.
#[derive(Clone, Debug, Serialize)]
pub struct PredictedTerm {
    /// Term name, e.g. `F:enf03`.
    pub term: String,
    /// Whether the calibration fitted this experiment (else it was held out).
    pub calibrated: bool,
    /// Its error at the identified values.
    pub error: RmsError,
}

/// `prediction.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Prediction {
    /// The problem file.
    pub problem: String,
    /// The calibration's `result.json`.
    pub from: String,
    /// The values used, by parameter path.
    pub parameters: BTreeMap<String, f64>,
    /// Every experiment's terms.
    pub terms: Vec<PredictedTerm>,
    /// Runs that failed part way (their last state is held).
    pub failures: Vec<String>,
}

/// The values a calibration identified, read from its `result.json` for the parameters of a
/// problem file.
#[derive(Clone, Debug)]
pub struct Calibration {
    /// The result file.
    pub from: String,
    /// Physical values in the order of the problem's parameters.
    pub x: Vec<f64>,
    /// The same by parameter path.
    pub parameters: BTreeMap<String, f64>,
    /// Terms the calibration fitted (e.g. `F:enf04`).
    pub fitted: Vec<String>,
}

impl Calibration {
    /// Reads `from` (a `result.json` of `czid identify`); every parameter of `problem` must be
    /// in it.
    pub fn read(problem: &LoadedProblem, from: &Path) -> Result<Self> {
        let shown = from.display().to_string();
        let text =
            std::fs::read_to_string(from).map_err(|e| CzError::Io { path: shown.clone(), message: e.to_string() })?;
        let result: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| CzError::config(&shown, format!("not a result.json: {e}")))?;
        let mut x = Vec::new();
        let mut parameters = BTreeMap::new();
        for p in &problem.file.parameter {
            let v = result["parameters"][&p.path]["value"].as_f64().ok_or_else(|| {
                CzError::config(
                    &shown,
                    format!("holds no value for the parameter `{}` of {}", p.path, problem.path.display()),
                )
            })?;
            x.push(v);
            parameters.insert(p.path.clone(), v);
        }
        let fitted = result["rms_error"]
            .as_object()
            .or_else(|| result["misfit"].as_object())
            .map(|m| m.keys().cloned().collect())
            .unwrap_or_default();
        Ok(Calibration { from: shown, x, parameters, fitted })
    }
}

/// Runs every experiment of `problem` at the values of `calibration`, writes `prediction.json`
/// and the fits (`predict-*.csv`, plots) to `out`.
pub fn predict(problem: &LoadedProblem, calibration: &Calibration, out: &OutputDir) -> Result<Prediction> {
    let id = problem.identification()?;
    let outcome = id.simulate(&calibration.x)?;
    let terms = id
        .term_errors(&outcome)?
        .into_iter()
        .map(|(term, error)| PredictedTerm { calibrated: calibration.fitted.contains(&term), term, error })
        .collect();
    let prediction = Prediction {
        problem: problem.path.display().to_string(),
        from: calibration.from.clone(),
        parameters: calibration.parameters.clone(),
        terms,
        failures: outcome.failures.clone(),
    };
    let json = serde_json::to_string_pretty(&prediction).map_err(|e| CzError::config("prediction", e.to_string()))?;
    out.write("prediction.json", &json)?;
    write_fits(problem, &outcome, out, "predict")?;
    Ok(prediction)
}
