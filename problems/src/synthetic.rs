//! Synthetic "experiments": a forward model's curves sampled at chosen displacements, with
//! documented Gaussian measurement noise, for studies where the truth must be known.
//!
//! Noise model: load readings get independent N(0, σ_F²) errors; debonded-length readings get
//! N(0, σ_L²) errors once the crack has grown (a length of zero is read exactly, and no reading is
//! negative). The random stream is `ChaCha8Rng` seeded explicitly, so a data set is reproducible.

use czid_core::{columns, CzError, Record, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Measurement noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// Standard deviation of load readings (N).
    pub load_sd: f64,
    /// Standard deviation of debonded-length readings (mm).
    pub length_sd: f64,
    /// Seed of the random stream.
    pub seed: u64,
}

/// A synthetic test: displacement (mm), load (N), debonded length (mm).
#[derive(Clone, Debug, PartialEq)]
pub struct Synthetic {
    /// Displacements.
    pub displacement: Vec<f64>,
    /// Noisy loads.
    pub load: Vec<f64>,
    /// Noisy debonded lengths.
    pub debonded_length: Vec<f64>,
}

impl Synthetic {
    /// As CSV text with columns `displacement_mm,load_N,debonded_length_mm`.
    pub fn to_csv(&self) -> String {
        let mut s = String::from("displacement_mm,load_N,debonded_length_mm\n");
        for i in 0..self.displacement.len() {
            s.push_str(&format!("{},{},{}\n", self.displacement[i], self.load[i], self.debonded_length[i]));
        }
        s
    }

    /// The synthetic test as an experiment named `name`: its load and debonded-length curves,
    /// nothing dropped, no events, no stated noise (set [`crate::data::Experiment::noise`] to give
    /// the one it was made with).
    pub fn experiment(&self, name: &str) -> Result<crate::data::Experiment> {
        Ok(crate::data::Experiment {
            name: name.into(),
            load: czid_core::Curve::new(self.displacement.clone(), self.load.clone())?,
            debonded_length: Some(czid_core::Curve::new(self.displacement.clone(), self.debonded_length.clone())?),
            initial_crack: None,
            dropped: Default::default(),
            events: Vec::new(),
            ordinate: Default::default(),
            noise: Default::default(),
        })
    }
}

/// Samples `record` at `points` equally spaced displacements over (0, max] and adds noise.
pub fn synthesize(record: &Record, points: usize, max_displacement: Option<f64>, noise: &Noise) -> Result<Synthetic> {
    if points < 2 {
        return Err(CzError::config("synthesize", "at least 2 points are needed"));
    }
    if !(noise.load_sd >= 0.0 && noise.length_sd >= 0.0) {
        return Err(CzError::config("synthesize", "noise standard deviations must be ≥ 0"));
    }
    let load = record.curve(columns::DISPLACEMENT, columns::LOAD)?;
    let length = record.curve(columns::DISPLACEMENT, columns::DEBONDED_LENGTH)?;
    let end = max_displacement.unwrap_or(load.x_max()).min(load.x_max());
    let mut rng = ChaCha8Rng::seed_from_u64(noise.seed);
    let mut out = Synthetic { displacement: Vec::new(), load: Vec::new(), debonded_length: Vec::new() };
    for i in 1..=points {
        let d = end * i as f64 / points as f64;
        // Both draws happen for every point so the load noise does not depend on the crack.
        let (e_f, e_l) = (gaussian(&mut rng), gaussian(&mut rng));
        let l = length.at(d);
        out.displacement.push(d);
        out.load.push(load.at(d) + noise.load_sd * e_f);
        out.debonded_length.push(if l > 0.0 { (l + noise.length_sd * e_l).max(0.0) } else { 0.0 });
    }
    Ok(out)
}

/// A standard normal draw (Box–Muller).
fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>(); // in (0, 1]
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record() -> Record {
        let mut r =
            Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N"), (columns::DEBONDED_LENGTH, "mm")]);
        for i in 0..=100 {
            let d = i as f64 / 10.0;
            r.push(&[d, 10.0 * d, (d - 5.0).max(0.0)]);
        }
        r
    }

    #[test]
    fn noise_has_the_stated_spread_and_is_reproducible() {
        let noise = Noise { load_sd: 0.5, length_sd: 0.2, seed: 3 };
        let s = synthesize(&record(), 4000, None, &noise).unwrap();
        let errs: Vec<f64> = s.displacement.iter().zip(&s.load).map(|(d, f)| f - 10.0 * d).collect();
        let mean = errs.iter().sum::<f64>() / errs.len() as f64;
        let sd = (errs.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (errs.len() - 1) as f64).sqrt();
        // 4000 draws: the sample sd is within ~3.4% of 0.5 with 99.9% probability.
        assert!((sd - 0.5).abs() < 0.02, "sd {sd}");
        assert!(mean.abs() < 0.03, "mean {mean}");
        // No crack yet: read exactly; never negative.
        assert!(s.displacement.iter().zip(&s.debonded_length).all(|(d, l)| *d > 5.0 || *l == 0.0));
        assert!(s.debonded_length.iter().all(|l| *l >= 0.0));
        assert_eq!(s, synthesize(&record(), 4000, None, &noise).unwrap());
    }
}

/// A truth file: the law and forward model a synthetic test is made with, and its noise.
///
/// ```toml
/// [law]
/// type = "st_czm"
/// # ...
/// [model]
/// type = "dcb"
/// # ...
/// [noise]
/// load_sd = 0.1        # N
/// length_sd = 0.2      # mm
/// seed = 7
/// points = 100
/// ```
#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TruthFile {
    /// The law.
    pub law: Box<dyn czid_core::CohesiveLaw>,
    /// The forward model.
    pub model: Box<dyn czid_core::ForwardModel>,
    /// Noise and sampling (default: no noise, 200 readings).
    #[serde(default)]
    pub noise: NoiseSpec,
    /// Events read off the synthetic test (`[[event]]`), e.g. debonded lengths read to 10 mm.
    #[serde(default)]
    pub event: Vec<TruthEvent>,
}

/// An event of a synthetic test (`[[event]]` of a truth file): the model's value of a
/// [`crate::event::EventKind`] response, perturbed by Gaussian noise and rounded as a reading.
///
/// ```toml
/// [[event]]
/// kind = "debonded_length_at_onset"
/// fraction = 0.98        # onset only (default 0.98)
/// sd = 10.0              # mm (N for the peak load): standard deviation of the reading
/// resolution = 5.0       # the reading is rounded to a multiple of this (0: not rounded)
/// ```
///
/// The end of the test is the last displacement read (`[noise] max_displacement`, or the end of
/// the run). The noise is drawn after the curve's, from the same seed, in the order of the events.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TruthEvent {
    /// What is read.
    pub kind: crate::event::EventKind,
    /// Onset: fraction of the peak load.
    #[serde(default)]
    pub fraction: Option<f64>,
    /// Displacement at load: the load (N).
    #[serde(default)]
    pub load: Option<f64>,
    /// Standard deviation of the reading (mm or N).
    #[serde(default)]
    pub sd: f64,
    /// Rounding of the reading (mm or N; 0: none).
    #[serde(default)]
    pub resolution: f64,
}

/// An event's true and read values.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadEvent {
    /// What was read.
    pub kind: crate::event::EventKind,
    /// The model's value (mm or N).
    pub truth: f64,
    /// The reading: the value plus noise, rounded.
    pub read: f64,
    /// The spec the value was computed with (for the problem file).
    pub spec: crate::event::EventSpec,
}

/// The `[noise]` table of a truth file; every field has a default (no noise, seed 1, 200
/// readings to the end of the simulation).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseSpec {
    /// Standard deviation of load readings (N).
    pub load_sd: f64,
    /// Standard deviation of debonded-length readings (mm).
    pub length_sd: f64,
    /// Seed.
    pub seed: u64,
    /// Number of equally spaced readings.
    pub points: usize,
    /// Last displacement read (mm); default: the end of the simulation.
    pub max_displacement: Option<f64>,
}

impl Default for NoiseSpec {
    fn default() -> Self {
        NoiseSpec { load_sd: 0.0, length_sd: 0.0, seed: 1, points: 200, max_displacement: None }
    }
}

impl TruthFile {
    /// Reads and validates a truth file.
    pub fn read(path: &std::path::Path) -> Result<Self> {
        Self::read_with(path, &[])
    }

    /// [`TruthFile::read`] with some values replaced, e.g. `("model.a0", "45")` or
    /// `("law.strength_n", "20")` (`czid simulate --set`; paths as in
    /// [`crate::problem_file::LoadedProblem::read_with`], the model's as `model.*`).
    pub fn read_with(path: &std::path::Path, overrides: &[(String, String)]) -> Result<Self> {
        czid_models::registry::ensure_linked();
        let shown = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| CzError::Io { path: shown.clone(), message: e.to_string() })?;
        let t: TruthFile = if overrides.is_empty() {
            toml::from_str(&text).map_err(|e| CzError::config(&shown, e.to_string().trim_end()))?
        } else {
            // The rebuilt file's line numbers would mean nothing to the user: the message names the
            // overrides instead.
            let edited = crate::problem_file::with_overrides(&text, &shown, overrides)?;
            let sets: Vec<String> = overrides.iter().map(|(k, v)| format!("--set {k}={v}")).collect();
            toml::from_str(&edited)
                .map_err(|e| CzError::config(format!("{shown} with {}", sets.join(" ")), e.message().trim_end()))?
        };
        t.law.validate()?;
        t.model.validate()?;
        Ok(t)
    }

    /// Simulates and samples with noise.
    pub fn generate(&self) -> Result<Synthetic> {
        Ok(self.generate_with_events()?.0)
    }

    /// Simulates, samples with noise and reads the `[[event]]`s.
    pub fn generate_with_events(&self) -> Result<(Synthetic, Vec<ReadEvent>)> {
        use crate::event::{EventKind, EventSpec};
        let record = self.model.simulate(self.law.as_ref()).map_err(|f| CzError::Simulation(f.to_string()))?;
        let n = &self.noise;
        let data = synthesize(
            &record,
            n.points,
            n.max_displacement,
            &Noise { load_sd: n.load_sd, length_sd: n.length_sd, seed: n.seed },
        )?;
        // The events' noise: a stream of its own, from the same seed, after the curve's draws.
        let mut rng = ChaCha8Rng::seed_from_u64(n.seed);
        for _ in 0..2 * n.points {
            gaussian(&mut rng);
        }
        let last = *data.displacement.last().expect("at least 2 readings");
        let mut events = Vec::new();
        for (j, e) in self.event.iter().enumerate() {
            let unit = if e.kind == EventKind::PeakLoad { "N" } else { "mm" };
            let spec = EventSpec {
                kind: e.kind,
                name: None,
                value: 1.0,
                unit: unit.into(),
                weight: None,
                fraction: e.fraction,
                at: (e.kind == EventKind::DebondedLengthAtEnd).then_some(last),
                load: e.load,
                load_unit: Default::default(),
                // The reading's error and its rounding (uniform over one resolution step).
                uncertainty: Some((e.sd * e.sd + e.resolution * e.resolution / 12.0).sqrt()).filter(|u| *u > 0.0),
            };
            let owner = format!("truth file, event {}", j + 1);
            let measured = spec.check(&owner, last)?;
            let truth = measured.response.boxed().predict(&record, &[0.0])?[0];
            let noisy = truth + e.sd * gaussian(&mut rng);
            let read = if e.resolution > 0.0 { (noisy / e.resolution).round() * e.resolution } else { noisy };
            events.push(ReadEvent { kind: e.kind, truth, read, spec: EventSpec { value: read, ..spec } });
        }
        Ok((data, events))
    }
}
