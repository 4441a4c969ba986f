//! Where the misfit lies: the test split into regimes, each experiment by the rule its forward
//! model declares ([`czid_core::ForwardModel::regimes`]; the generic rule of a test that loads,
//! peaks and softens unless the model has its own, e.g. an FRP-strengthened beam's uncracked,
//! cracked, yielded and debonding), and the misfit of each response summed per regime, with its
//! sign.

use crate::data::Experiment;
use crate::diagnose::gauge::{Gauge, Misfit};
use crate::identification::{Setup, Term};
use czid_core::regimes::{GenericRegimes, RegimeRule};
use serde::Serialize;

pub use czid_core::regimes::NAMES;

/// One regime of one experiment: displacements in `[from, to)` (mm).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Regime {
    /// Experiment name.
    pub experiment: String,
    /// One of its rule's names ([`RegimeRule::names`]).
    pub name: String,
    /// First displacement (mm).
    pub from: f64,
    /// End displacement (mm, exclusive; the last regime includes its end).
    pub to: f64,
}

/// Splits a load curve `(x, p)` (displacement in mm, load in N) into regimes by the generic rule.
pub fn split(experiment: &str, x: &[f64], p: &[f64]) -> Vec<Regime> {
    named(experiment, GenericRegimes.split((x, p), None))
}

fn named(experiment: &str, spans: Vec<czid_core::Span>) -> Vec<Regime> {
    spans
        .into_iter()
        .map(|s| Regime { experiment: experiment.into(), name: s.name.into(), from: s.from, to: s.to })
        .collect()
}

/// Whether displacement `x` lies in `regime` (the last regime of an experiment includes its end).
pub fn contains(regime: &Regime, x: f64, last: bool) -> bool {
    x >= regime.from && (x < regime.to || (last && x <= regime.to))
}

/// The regimes of every experiment of a gauge, from its load curves, by the generic rule.
pub fn split_all(gauge: &Gauge) -> Vec<Regime> {
    gauge.blocks.iter().filter(|b| b.term == Term::Load).flat_map(|b| split(&b.experiment, &b.x, &b.y)).collect()
}

/// The regime rule of `experiment` in `setup`: its model's (generic when it has no model there).
pub fn regime_set(setup: &Setup, experiment: &str) -> &'static dyn RegimeRule {
    setup.models.get(experiment).map_or(&GenericRegimes, |m| m.regimes())
}

/// The regimes of every experiment of a gauge, each by the rule of its model in `setup`; the
/// debonded length is taken from `experiments` when measured (fitted or not).
pub fn split_setup(gauge: &Gauge, setup: &Setup, experiments: &[Experiment]) -> Vec<Regime> {
    gauge
        .blocks
        .iter()
        .filter(|b| b.term == Term::Load)
        .flat_map(|b| {
            let length = experiments
                .iter()
                .find(|e| e.name == b.experiment)
                .and_then(|e| e.debonded_length.as_ref())
                .map(|c| (c.x(), c.y()));
            named(&b.experiment, regime_set(setup, &b.experiment).split((&b.x, &b.y), length))
        })
        .collect()
}

/// Misfit of one response in one regime.
#[derive(Clone, Debug, Serialize)]
pub struct RegimeMisfit {
    /// Experiment name.
    pub experiment: String,
    /// Regime name.
    pub regime: String,
    /// Load or debonded length (serialised as `F` or `L`).
    pub term: Term,
    /// Unit of the means (N or mm).
    pub unit: String,
    /// Readings in the regime.
    pub readings: usize,
    /// Mean of test − model (N or mm): negative when the model is above the test.
    pub mean: f64,
    /// Root mean square of test − model (N or mm).
    pub rms: f64,
    /// RMS in noise standard deviations (1: at the noise level).
    pub rms_over_noise: f64,
    /// Share of the whole misfit (sum of squares in noise units) that lies here.
    pub share: f64,
    /// "model above the test", "model below the test" or "at the noise level".
    pub sign: String,
}

/// Index of the regime holding displacement `x` of `experiment`, if any.
pub fn locate(regimes: &[Regime], experiment: &str, x: f64) -> Option<usize> {
    let mine: Vec<usize> = (0..regimes.len()).filter(|&k| regimes[k].experiment == experiment).collect();
    let last = mine.last().copied();
    mine.into_iter().find(|&k| contains(&regimes[k], x, Some(k) == last))
}

/// Splits `misfit` (on `gauge`) by regime and response.
pub fn misfit_by_regime(gauge: &Gauge, regimes: &[Regime], misfit: &Misfit) -> Vec<RegimeMisfit> {
    let total: f64 = misfit.rss().max(f64::MIN_POSITIVE);
    let mut out = Vec::new();
    for (b, range) in gauge.blocks.iter().zip(gauge.ranges()) {
        let r = &misfit.r[range];
        for (k, reg) in regimes.iter().enumerate().filter(|(_, g)| g.experiment == b.experiment) {
            let idx: Vec<usize> =
                (0..b.x.len()).filter(|&i| locate(regimes, &b.experiment, b.x[i]) == Some(k)).collect();
            if idx.is_empty() {
                continue;
            }
            let m = idx.len() as f64;
            let mean = idx.iter().map(|&i| r[i] * b.sigma).sum::<f64>() / m;
            let ss: f64 = idx.iter().map(|&i| r[i] * r[i]).sum();
            let rms_over_noise = (ss / m).sqrt();
            // A mean within 2 standard errors of zero carries no sign.
            let sign = if mean.abs() <= 2.0 * b.sigma / m.sqrt() && rms_over_noise < 2.0 {
                "at the noise level"
            } else if mean < 0.0 {
                "model above the test"
            } else {
                "model below the test"
            };
            out.push(RegimeMisfit {
                experiment: b.experiment.clone(),
                regime: reg.name.clone(),
                term: b.term,
                unit: b.term.unit().into(),
                readings: idx.len(),
                mean,
                rms: rms_over_noise * b.sigma,
                rms_over_noise,
                share: ss / total,
                sign: sign.into(),
            });
        }
    }
    out
}

/// Sum of squares (noise units) per regime index, for shrinkage per regime.
pub fn rss_by_regime(gauge: &Gauge, regimes: &[Regime], r: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; regimes.len()];
    for (b, range) in gauge.blocks.iter().zip(gauge.ranges()) {
        for (i, v) in r[range].iter().enumerate() {
            if let Some(k) = locate(regimes, &b.experiment, b.x[i]) {
                out[k] += v * v;
            }
        }
    }
    out
}
