//! Where the misfit lies: the test split into regimes found from its load curve alone, and the
//! misfit of each response summed per regime, with its sign.
//!
//! Regimes of a load–displacement curve (any test that loads, peaks and softens):
//! * **initial loading**: from the start until the load falls for good below 95 % of the initial
//!   line, the line through the readings at 10 % and 40 % of the peak load (so that a seating toe
//!   or a preload offset does not count as non-linearity);
//! * **onset / peak**: from there until the load has fallen 5 % below its peak (damage onset,
//!   crack initiation);
//! * **propagation**: from there over the first two thirds of the remaining displacement range;
//! * **late stage**: the last third (large displacements: where rotations, bridging lengths and
//!   machine effects grow most).
//!
//! A curve that never falls 5 % below its peak has no propagation or late stage.
//!
//! Some models have regimes of their own, chosen per experiment from the name of its forward model
//! ([`RegimeSet::of_model`]): an FRP-strengthened beam (`frp_beam`) is split into uncracked, cracked,
//! yielded and debonding ([`beam`]); every other model gets the generic regimes above.

pub mod beam;

use crate::data::Experiment;
use crate::diagnose::gauge::{Gauge, Misfit};
use crate::identification::Setup;
use serde::Serialize;

/// Secant stiffness drop that ends the initial loading.
const LINEAR_DROP: f64 = 0.05;
/// Share of the peak load where the initial line starts (below, toes and offsets).
const FIRST_LOAD: f64 = 0.1;
/// Share of the peak load where the initial line ends.
const LINE_LOAD: f64 = 0.4;
/// Load drop below the peak that ends the onset/peak regime.
const PEAK_DROP: f64 = 0.05;
/// Share of the post-peak displacement range counted as propagation; the rest is the late stage.
const PROPAGATION_SHARE: f64 = 2.0 / 3.0;

/// Regime names, in test order.
pub const NAMES: [&str; 4] = ["initial loading", "onset/peak", "propagation", "late stage"];

/// A set of regimes and the rule that finds them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RegimeSet {
    /// Any test that loads, peaks and softens: [`NAMES`], found by [`split`].
    Generic,
    /// An FRP-strengthened RC beam: [`beam::NAMES`], found by [`beam::split`].
    Beam,
}

impl RegimeSet {
    /// The regime set for a forward model type (`ForwardModel::name`).
    pub fn of_model(model: &str) -> Self {
        match model {
            "frp_beam" => RegimeSet::Beam,
            _ => RegimeSet::Generic,
        }
    }

    /// Regime names, in test order.
    pub fn names(self) -> [&'static str; 4] {
        match self {
            RegimeSet::Generic => NAMES,
            RegimeSet::Beam => beam::NAMES,
        }
    }

    /// The regime held out of a fit to check transfer, when it is the last of a test: the late
    /// stage of a generic curve, the debonding of a beam.
    pub fn held_out(self) -> &'static str {
        self.names()[3]
    }

    /// How the held-out part is named in reports.
    pub fn held_out_label(self) -> &'static str {
        match self {
            RegimeSet::Generic => "late stage of each curve",
            RegimeSet::Beam => "debonding regime of each curve",
        }
    }
}

/// One regime of one experiment: displacements in `[from, to)` (mm).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Regime {
    /// Experiment name.
    pub experiment: String,
    /// One of [`NAMES`] (or of its family's names, [`RegimeSet::names`]).
    pub name: String,
    /// First displacement (mm).
    pub from: f64,
    /// End displacement (mm, exclusive; the last regime includes its end).
    pub to: f64,
}

/// Splits a load curve `(x, p)` (displacement in mm, load in N) into regimes.
pub fn split(experiment: &str, x: &[f64], p: &[f64]) -> Vec<Regime> {
    let n = x.len();
    if n == 0 {
        return Vec::new();
    }
    let end = x[n - 1];
    let peak = (0..n).max_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap_or(0);
    // The initial line: through the readings at 10 % and 40 % of the peak load (below 10 % a
    // seating toe or a preload offset dominates). Linear loading lasts until the load falls
    // below 95 % of that line for good (a single noisy reading does not end it).
    let at = |share: f64| (0..=peak).find(|&i| p[i] >= share * p[peak]);
    let linear_end = match (at(FIRST_LOAD), at(LINE_LOAD)) {
        (Some(a), Some(b)) if x[b] > x[a] => {
            let k0 = (p[b] - p[a]) / (x[b] - x[a]);
            let below = |i: usize| p[i] < (1.0 - LINEAR_DROP) * (p[a] + k0 * (x[i] - x[a]));
            (b..=peak).find(|&i| (i..=peak).all(below)).unwrap_or(peak)
        }
        _ => peak,
    };
    let peak_end = (peak..n).find(|&i| p[i] < (1.0 - PEAK_DROP) * p[peak]);
    let mut bounds = vec![(NAMES[0], x[0], x[linear_end])];
    match peak_end {
        Some(j) => {
            bounds.push((NAMES[1], x[linear_end], x[j]));
            let late = x[j] + PROPAGATION_SHARE * (end - x[j]);
            bounds.push((NAMES[2], x[j], late));
            bounds.push((NAMES[3], late, end));
        }
        None => bounds.push((NAMES[1], x[linear_end], end)),
    }
    bounds
        .into_iter()
        .filter(|(_, a, b)| b > a)
        .map(|(name, from, to)| Regime { experiment: experiment.into(), name: name.into(), from, to })
        .collect()
}

/// Whether displacement `x` lies in `regime` (the last regime of an experiment includes its end).
pub fn contains(regime: &Regime, x: f64, last: bool) -> bool {
    x >= regime.from && (x < regime.to || (last && x <= regime.to))
}

/// The regimes of every experiment of a gauge, from its load curves, by the generic rule.
pub fn split_all(gauge: &Gauge) -> Vec<Regime> {
    gauge.blocks.iter().filter(|b| b.term == "F").flat_map(|b| split(&b.experiment, &b.x, &b.y)).collect()
}

/// The regime set of `experiment` in `setup` (generic when it has no model there).
pub fn regime_set(setup: &Setup, experiment: &str) -> RegimeSet {
    setup.models.get(experiment).map_or(RegimeSet::Generic, |m| RegimeSet::of_model(m.name()))
}

/// The regimes of every experiment of a gauge, each by the rule of its model's family in `setup`;
/// a beam's debonded length is taken from `experiments` when measured (fitted or not).
pub fn split_setup(gauge: &Gauge, setup: &Setup, experiments: &[Experiment]) -> Vec<Regime> {
    gauge
        .blocks
        .iter()
        .filter(|b| b.term == "F")
        .flat_map(|b| match regime_set(setup, &b.experiment) {
            RegimeSet::Generic => split(&b.experiment, &b.x, &b.y),
            RegimeSet::Beam => {
                let length = experiments
                    .iter()
                    .find(|e| e.name == b.experiment)
                    .and_then(|e| e.debonded_length.as_ref())
                    .map(|c| (c.x(), c.y()));
                beam::split(&b.experiment, &b.x, &b.y, length)
            }
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
    /// `F` (load) or `L` (debonded length).
    pub term: String,
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
                term: b.term.clone(),
                unit: if b.term == "F" { "N".into() } else { "mm".into() },
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
