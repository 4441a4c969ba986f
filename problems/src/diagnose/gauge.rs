//! The misfit measured in units of the measurement noise: every reading of every response becomes
//! `(test − model) / σ`, σ that response's noise, so that sums of squares are χ²-like and the
//! score statistics of the candidate effects can be compared with their χ² thresholds.

use crate::data::Experiment;
use crate::identification::{simulate_experiments, Runs, Setup, Term};
use czid_core::noise;
use czid_core::objective::scaled_residuals;
use czid_core::{CzError, Record, Response, Result};
use serde::Serialize;
use std::collections::BTreeMap;

/// One measured response of one experiment.
#[derive(Clone, Debug, Serialize)]
pub struct Block {
    /// Experiment name.
    pub experiment: String,
    /// Load (N) or debonded length (mm); serialised as `F` or `L`.
    pub term: Term,
    /// Displacements of the readings (mm).
    pub x: Vec<f64>,
    /// Measured values (N or mm).
    pub y: Vec<f64>,
    /// Noise standard deviation (N or mm).
    pub sigma: f64,
    /// Whether σ was estimated from the data (false: given by the user).
    pub sigma_estimated: bool,
    /// Per reading, the estimated error (N or mm, signed) of the model-form floor itself: the
    /// change its reference's coarsened twin makes ([`crate::diagnose::stages::model_form`]);
    /// empty: no estimate. [`Gauge::structure_p`] allows for an error of that shape and about
    /// that size.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub floor: Vec<f64>,
}

/// Noise levels given instead of estimated.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NoiseLevels {
    /// Load noise (N).
    pub load: Option<f64>,
    /// Debonded-length noise (mm).
    pub length: Option<f64>,
}

/// The responses a diagnosis compares, with their noise.
#[derive(Clone, Debug)]
pub struct Gauge {
    /// Blocks in residual order.
    pub blocks: Vec<Block>,
}

/// A setup's misfit.
#[derive(Debug)]
pub struct Misfit {
    /// `(test − model) / σ`, blocks concatenated.
    pub r: Vec<f64>,
    /// Records per experiment (partial when a run stopped early).
    pub records: BTreeMap<String, Record>,
    /// Messages of runs that stopped early.
    pub failures: Vec<String>,
}

impl Misfit {
    /// The misfit of `setup` on `gauge`: its experiments simulated through the path every
    /// identification uses ([`simulate_experiments`]), compared reading by reading.
    pub fn of(gauge: &Gauge, setup: &Setup) -> Result<Misfit> {
        let clock = std::time::Instant::now();
        let runs = simulate_experiments(setup, &gauge.experiments());
        tally::count(setup, clock.elapsed());
        let Runs { records, failures, .. } = runs?;
        Ok(Misfit { r: gauge.residuals(&records)?, records, failures })
    }

    /// Sum of squares (χ²-like).
    pub fn rss(&self) -> f64 {
        self.r.iter().map(|v| v * v).sum()
    }
}

impl Gauge {
    /// The load curve of every experiment and, with `use_length`, its debonded-length curve when
    /// measured; noise estimated from each curve unless given.
    pub fn new(experiments: &[Experiment], use_length: bool, noise_levels: NoiseLevels) -> Result<Self> {
        let mut blocks = Vec::new();
        for e in experiments {
            if e.ordinate != crate::data::Ordinate::Load {
                return Err(CzError::config(
                    format!("experiment `{}`", e.name),
                    "the diagnosis compares load curves; this one is a moment (`ordinate`)",
                ));
            }
            let (x, y) = (e.load.x().to_vec(), e.load.y().to_vec());
            let sigma = noise_levels.load.unwrap_or_else(|| noise::estimate(&x, &y, false));
            blocks.push(Block {
                experiment: e.name.clone(),
                term: Term::Load,
                x,
                y,
                sigma,
                sigma_estimated: noise_levels.load.is_none(),
                floor: Vec::new(),
            });
            if let (true, Some(l)) = (use_length, &e.debonded_length) {
                if l.norm() > 0.0 {
                    let (x, y) = (l.x().to_vec(), l.y().to_vec());
                    let sigma = noise_levels.length.unwrap_or_else(|| noise::estimate(&x, &y, true));
                    blocks.push(Block {
                        experiment: e.name.clone(),
                        term: Term::DebondedLength,
                        x,
                        y,
                        sigma,
                        sigma_estimated: noise_levels.length.is_none(),
                        floor: Vec::new(),
                    });
                }
            }
        }
        for b in &blocks {
            if !(b.sigma > 0.0 && b.sigma.is_finite()) {
                return Err(CzError::invalid(
                    format!("noise of {}:{}", b.term.symbol(), b.experiment),
                    "sigma",
                    b.sigma,
                    "must be positive and finite (give it with --noise-load / --noise-length)",
                ));
            }
        }
        Ok(Gauge { blocks })
    }

    /// Number of readings.
    pub fn len(&self) -> usize {
        self.blocks.iter().map(|b| b.x.len()).sum()
    }

    /// Whether there are no readings.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The same responses restricted to readings whose displacement satisfies `keep(experiment,
    /// x)` (e.g. a held-out part of the curve). Blocks left with no reading are dropped.
    pub fn restricted(&self, keep: impl Fn(&str, f64) -> bool) -> Gauge {
        let blocks = self
            .blocks
            .iter()
            .filter_map(|b| {
                let idx: Vec<usize> = (0..b.x.len()).filter(|&i| keep(&b.experiment, b.x[i])).collect();
                (!idx.is_empty()).then(|| Block {
                    x: idx.iter().map(|&i| b.x[i]).collect(),
                    y: idx.iter().map(|&i| b.y[i]).collect(),
                    floor: if b.floor.is_empty() { Vec::new() } else { idx.iter().map(|&i| b.floor[i]).collect() },
                    ..b.clone()
                })
            })
            .collect();
        Gauge { blocks }
    }

    /// Positions in the residual vector of the readings [`Gauge::restricted`] keeps with `keep`.
    pub fn rows(&self, keep: impl Fn(&str, f64) -> bool) -> Vec<usize> {
        let mut out = Vec::new();
        for (b, range) in self.blocks.iter().zip(self.ranges()) {
            out.extend(range.zip(&b.x).filter(|(_, &x)| keep(&b.experiment, x)).map(|(i, _)| i));
        }
        out
    }

    /// The curve a block compares (blocks are curves: loads and debonded lengths).
    fn curve(block: &Block) -> Result<czid_core::ColumnResponse> {
        block.term.response().ok_or_else(|| {
            CzError::config(format!("experiment `{}`", block.experiment), "the diagnosis compares curves, not events")
        })
    }

    /// Model value of a block's response at its readings.
    pub fn model_values(block: &Block, record: &Record) -> Result<Vec<f64>> {
        Self::curve(block)?.predict(record, &block.x)
    }

    /// The experiments the gauge measures, in block order (each once).
    pub fn experiments(&self) -> Vec<&str> {
        let mut names: Vec<&str> = self.blocks.iter().map(|b| b.experiment.as_str()).collect();
        names.dedup();
        names
    }

    /// `(test − model) / σ` for every reading, blocks concatenated, from a record per experiment.
    pub fn residuals(&self, records: &BTreeMap<String, Record>) -> Result<Vec<f64>> {
        let mut r = Vec::with_capacity(self.len());
        for b in &self.blocks {
            let record = records
                .get(&b.experiment)
                .ok_or_else(|| CzError::config(format!("experiment `{}`", b.experiment), "has no simulation record"))?;
            r.extend(scaled_residuals(&Self::curve(b)?, record, &b.x, &b.y, b.sigma)?);
        }
        Ok(r)
    }

    /// Probability that residuals `r` (noise units) show at least the structure they show, with
    /// the floor's uncertainty of every block allowed for
    /// ([`crate::diagnose::stats::structure_p_with_floor`]).
    pub fn structure_p(&self, r: &[f64]) -> f64 {
        let floor: Vec<f64> = if self.blocks.iter().all(|b| b.floor.is_empty()) {
            Vec::new()
        } else {
            self.blocks
                .iter()
                .flat_map(|b| {
                    let f = |i: usize| b.floor.get(i).map_or(0.0, |f| f / b.sigma);
                    (0..b.x.len()).map(f)
                })
                .collect()
        };
        crate::diagnose::stats::structure_p_with_floor(r, &self.ranges(), &floor)
    }

    /// Index ranges of the blocks in the residual vector.
    pub fn ranges(&self) -> Vec<std::ops::Range<usize>> {
        let mut start = 0;
        self.blocks
            .iter()
            .map(|b| {
                let r = start..start + b.x.len();
                start = r.end;
                r
            })
            .collect()
    }
}

/// A count of the misfits evaluated in this process, by the models run (what a diagnosis's
/// stages cost, in forward runs and their summed time).
pub mod tally {
    use crate::identification::Setup;
    use std::collections::BTreeMap;
    use std::sync::Mutex;
    use std::time::Duration;

    static RUNS: Mutex<BTreeMap<String, (usize, Duration)>> = Mutex::new(BTreeMap::new());

    pub(super) fn count(setup: &Setup, spent: Duration) {
        let key: Vec<&str> = setup.models.values().map(|m| m.name()).collect();
        if let Ok(mut runs) = RUNS.lock() {
            let e = runs.entry(key.join("+")).or_default();
            e.0 += 1;
            e.1 += spent;
        }
    }

    /// Misfits evaluated so far, and the time spent in them (summed over threads), by the models
    /// run.
    pub fn snapshot() -> BTreeMap<String, (usize, Duration)> {
        RUNS.lock().map(|r| r.clone()).unwrap_or_default()
    }
}
