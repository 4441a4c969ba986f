//! What an identification keeps beside its results so that an interrupted run (Ctrl-C, `SIGTERM`
//! from a scheduler, or a `SIGKILL` that leaves no chance to clean up) continues to the result of
//! the uninterrupted run, bit for bit:
//!
//! * `run.json`: the run's [`Fingerprint`] (optimizer, settings, seed, budget, parameters and
//!   bounds, the setup and the data) and the wall time spent so far, rewritten as the run goes. A
//!   resume with anything different is refused with what differs.
//! * `checkpoint.json`: the state of a global method (MIGA, GA, NSGA-II, and the hybrid's global
//!   phase), saved after every iteration.
//! * `evaluations.jsonl`: the journal of a local method's evaluations ([`czid_optimizers::journal`]);
//!   a resumed local method runs again from its start and is served what the journal holds.

use crate::data::Experiment;
use crate::identification::Identification;
use crate::output::OutputDir;
use czid_core::{CzError, Observer, Progress, Result};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// What makes two runs the same run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fingerprint {
    /// Optimizer as named on the command line or in the file, and its registry name.
    pub optimizer: String,
    /// Its settings (TOML).
    pub settings: String,
    /// Seed.
    pub seed: u64,
    /// Evaluation budget.
    pub budget: usize,
    /// Identified parameters: path, unit, bounds and scale.
    pub parameters: Vec<String>,
    /// Hash of the law and models at their initial values.
    pub setup: String,
    /// Hash of the experiments' data.
    pub data: String,
    /// Objective weights.
    pub weights: Vec<String>,
}

impl Fingerprint {
    /// The fingerprint of a run of `optimizer` (`settings`) on `id` and `experiments`.
    pub fn of(
        id: &Identification,
        experiments: &[Experiment],
        optimizer: &str,
        settings: &toml::Value,
        seed: u64,
        budget: usize,
    ) -> Result<Self> {
        let setup = serde_json::to_string(id.setup()).map_err(|e| CzError::config("setup", e.to_string()))?;
        let mut data = Fnv::default();
        for e in experiments {
            data.write(e.name.as_bytes());
            for c in std::iter::once(&e.load).chain(&e.debonded_length) {
                c.x().iter().chain(c.y()).for_each(|v| data.write(&v.to_bits().to_le_bytes()));
            }
        }
        Ok(Fingerprint {
            optimizer: optimizer.to_string(),
            settings: settings.to_string(),
            seed,
            budget,
            parameters: id
                .space()
                .parameters()
                .iter()
                .map(|p| format!("{} in [{}, {}] {} ({:?})", p.path, p.lower, p.upper, p.unit, p.scale))
                .collect(),
            setup: Fnv::hash(setup.as_bytes()),
            data: data.hex(),
            weights: id.weights().iter().map(|(t, w)| format!("{t} = {w}")).collect(),
        })
    }

    /// What differs from `earlier`, in words (empty: the same run).
    pub fn differences(&self, earlier: &Fingerprint) -> Vec<String> {
        let mut out = Vec::new();
        let mut field = |name: &str, now: String, then: String| {
            if now != then {
                out.push(format!("{name}: {then} before, {now} now"));
            }
        };
        field("optimizer", self.optimizer.clone(), earlier.optimizer.clone());
        field("optimizer settings", self.settings.clone(), earlier.settings.clone());
        field("seed", self.seed.to_string(), earlier.seed.to_string());
        field("budget", self.budget.to_string(), earlier.budget.to_string());
        field("parameters", self.parameters.join("; "), earlier.parameters.join("; "));
        field("law and models", self.setup.clone(), earlier.setup.clone());
        field("test data", self.data.clone(), earlier.data.clone());
        field("objective weights", self.weights.join(", "), earlier.weights.join(", "));
        out
    }
}

/// `run.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunFile {
    /// The run.
    pub fingerprint: Fingerprint,
    /// Wall time spent on it so far, over every resumed part (s).
    pub elapsed_seconds: f64,
    /// How many times it was resumed.
    pub resumed: usize,
}

impl RunFile {
    /// The name of the file in the output folder.
    pub const NAME: &'static str = "run.json";

    /// Reads `run.json` of the run to resume and checks that it is the run `fingerprint`
    /// describes; the error says what differs.
    pub fn for_resume(out: &OutputDir, fingerprint: &Fingerprint) -> Result<RunFile> {
        let path = out.file(Self::NAME);
        let text = std::fs::read_to_string(&path).map_err(|e| CzError::Io {
            path: path.display().to_string(),
            message: format!("{e}: nothing to resume here (run without --resume to start)"),
        })?;
        let earlier: RunFile = serde_json::from_str(&text)
            .map_err(|e| CzError::data(path.display().to_string(), format!("not a czid run file: {e}")))?;
        let differences = fingerprint.differences(&earlier.fingerprint);
        if !differences.is_empty() {
            return Err(CzError::config(
                "--resume",
                format!(
                    "the interrupted run in {} is not this run: {}. Give the same problem, optimizer, \
                     seed and budget to continue it, or start afresh with --force",
                    out.path().display(),
                    differences.join("; ")
                ),
            ));
        }
        Ok(earlier)
    }

    fn write(&self, out: &OutputDir) -> Result<()> {
        let json = serde_json::to_string_pretty(self).map_err(|e| CzError::config("run.json", e.to_string()))?;
        out.write(Self::NAME, &json).map(|_| ())
    }
}

/// Keeps `run.json` up to date while the run goes (at most once a second, and at the end).
pub struct RunClock<'a> {
    out: &'a OutputDir,
    file: RunFile,
    start: Instant,
    last: Instant,
}

impl<'a> RunClock<'a> {
    /// Starts the clock of `fingerprint`'s run, continuing `earlier` when it resumes one, and
    /// writes `run.json`.
    pub fn start(out: &'a OutputDir, fingerprint: Fingerprint, earlier: Option<RunFile>) -> Result<Self> {
        let file = match earlier {
            Some(e) => RunFile { fingerprint, elapsed_seconds: e.elapsed_seconds, resumed: e.resumed + 1 },
            None => RunFile { fingerprint, elapsed_seconds: 0.0, resumed: 0 },
        };
        file.write(out)?;
        let now = Instant::now();
        Ok(RunClock { out, file, start: now, last: now })
    }

    /// Wall time over every part of the run (s).
    pub fn elapsed(&self) -> f64 {
        self.file.elapsed_seconds + self.start.elapsed().as_secs_f64()
    }

    /// Times the run was resumed.
    pub fn resumed(&self) -> usize {
        self.file.resumed
    }

    /// Writes the final wall time.
    pub fn finish(&mut self) -> Result<f64> {
        let total = self.elapsed();
        RunFile { elapsed_seconds: total, ..self.file.clone() }.write(self.out)?;
        Ok(total)
    }
}

impl Observer for RunClock<'_> {
    fn observe(&mut self, _: &Progress<'_>) -> bool {
        if self.last.elapsed().as_secs_f64() >= 1.0 {
            self.last = Instant::now();
            // Losing one update only costs that second in the reported wall time.
            let _ = RunFile { elapsed_seconds: self.elapsed(), ..self.file.clone() }.write(self.out);
        }
        true
    }
}

/// The rows of an interrupted run's `history.csv` (header first) that precede `first_new`, the
/// first iteration the resumed run writes; a line cut short by a kill, and rows of iterations
/// after the checkpoint, are dropped.
pub fn earlier_rows(text: &str, first_new: Option<usize>) -> Vec<String> {
    let mut lines = text.lines();
    let Some(header) = lines.next() else { return Vec::new() };
    let cells = header.split(',').count();
    let mut out = vec![header.to_string()];
    for line in lines {
        let row: Vec<&str> = line.split(',').collect();
        let whole = row.len() == cells && row.iter().all(|c| !c.is_empty());
        let iteration = row.first().and_then(|c| c.parse::<usize>().ok());
        match (whole, iteration) {
            (true, Some(i)) if first_new.is_none_or(|n| i < n) => out.push(line.to_string()),
            _ => break,
        }
    }
    out
}

/// FNV-1a, 64 bits: a hash that stays the same across builds and platforms.
struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 ^= u64::from(*b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }

    fn hash(bytes: &[u8]) -> String {
        let mut h = Fnv::default();
        h.write(bytes);
        h.hex()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn earlier_rows_stop_at_a_cut_line_and_at_the_resumed_iteration() {
        let text = "iteration,evaluations,x\n0,10,0.5\n1,20,0.25\n2,30,0.1\n3,4";
        assert_eq!(earlier_rows(text, Some(2)), vec!["iteration,evaluations,x", "0,10,0.5", "1,20,0.25"]);
        assert_eq!(earlier_rows(text, None).len(), 4, "the cut line `3,4` is dropped");
    }
}
