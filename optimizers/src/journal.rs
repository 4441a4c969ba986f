//! An evaluation journal: every evaluation of a problem appended to a file as it finishes, and
//! served back from the file when the run is repeated, so a deterministic method that keeps no
//! resumable state (the local methods) resumes after any interruption, even `SIGKILL`, by running
//! again from its start: the evaluations already made cost nothing, the method passes through the
//! same states bit for bit and carries on where it stopped.
//!
//! One JSON object per line (`x` as the exact bits of each coordinate, the evaluation or the
//! error). A line cut short by a kill is dropped when the journal is read back.

use czid_core::{CzError, Evaluation, Problem, Result};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// One journal line. Every number is kept as its `f64::to_bits` pattern: exact, NaN and
/// infinities included (JSON has none), and `x` a hashable key.
#[derive(Serialize, Deserialize)]
struct Entry {
    x: Vec<u64>,
    /// The evaluation, or why it failed.
    outcome: std::result::Result<Bits, String>,
}

/// An [`Evaluation`] as bit patterns.
#[derive(Clone, Serialize, Deserialize)]
struct Bits {
    value: u64,
    objectives: Vec<u64>,
    residuals: Vec<u64>,
}

impl Bits {
    fn of(e: &Evaluation) -> Self {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect();
        Bits { value: e.value.to_bits(), objectives: bits(&e.objectives), residuals: bits(&e.residuals) }
    }

    fn evaluation(&self) -> Evaluation {
        let values = |v: &[u64]| v.iter().map(|&b| f64::from_bits(b)).collect();
        Evaluation {
            value: f64::from_bits(self.value),
            objectives: values(&self.objectives),
            residuals: values(&self.residuals),
        }
    }
}

/// A [`Problem`] that journals its evaluations and replays the ones it already holds.
pub struct Journal<'a> {
    inner: &'a dyn Problem,
    known: HashMap<Vec<u64>, std::result::Result<Bits, String>>,
    file: Mutex<std::fs::File>,
    path: PathBuf,
    replayed: std::sync::atomic::AtomicUsize,
}

impl<'a> Journal<'a> {
    /// Starts a new journal at `path` (truncating any old one).
    pub fn create(inner: &'a dyn Problem, path: &Path) -> Result<Self> {
        let file = std::fs::File::create(path).map_err(|e| io(path, e))?;
        Ok(Self::with(inner, HashMap::new(), file, path))
    }

    /// Opens the journal at `path` to replay what it holds and append to it. The lines after the
    /// first unreadable one (a line cut short by a kill) are dropped from the file.
    pub fn resume(inner: &'a dyn Problem, path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| io(path, e))?;
        let mut known = HashMap::new();
        let mut valid = 0;
        for line in text.split_inclusive('\n') {
            let Some(body) = line.strip_suffix('\n') else { break };
            let Ok(entry) = serde_json::from_str::<Entry>(body) else { break };
            known.insert(entry.x, entry.outcome);
            valid += line.len();
        }
        let file = std::fs::OpenOptions::new().write(true).open(path).map_err(|e| io(path, e))?;
        file.set_len(valid as u64).map_err(|e| io(path, e))?;
        let mut journal = Self::with(inner, known, file, path);
        let end = valid as u64;
        use std::io::Seek;
        journal
            .file
            .get_mut()
            .map_err(|_| poisoned(path))?
            .seek(std::io::SeekFrom::Start(end))
            .map_err(|e| io(path, e))?;
        Ok(journal)
    }

    fn with(
        inner: &'a dyn Problem,
        known: HashMap<Vec<u64>, std::result::Result<Bits, String>>,
        file: std::fs::File,
        path: &Path,
    ) -> Self {
        Journal {
            inner,
            known,
            file: Mutex::new(file),
            path: path.to_path_buf(),
            replayed: std::sync::atomic::AtomicUsize::new(0),
        }
    }

    /// Evaluations the journal held when it was opened.
    pub fn held(&self) -> usize {
        self.known.len()
    }

    /// Evaluations served from the journal so far.
    pub fn replayed(&self) -> usize {
        self.replayed.load(std::sync::atomic::Ordering::Relaxed)
    }

    fn append(&self, entry: &Entry) -> Result<()> {
        let mut line = serde_json::to_string(entry).map_err(|e| CzError::config("journal", e.to_string()))?;
        line.push('\n');
        // One write per line: a kill can cut the last line short but never interleave two.
        let mut f = self.file.lock().map_err(|_| poisoned(&self.path))?;
        f.write_all(line.as_bytes()).map_err(|e| io(&self.path, e))
    }
}

impl Problem for Journal<'_> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        self.inner.bounds()
    }

    fn objectives(&self) -> usize {
        self.inner.objectives()
    }

    fn evaluate(&self, x: &[f64]) -> Result<Evaluation> {
        self.evaluate_batch(std::slice::from_ref(&x.to_vec())).remove(0)
    }

    /// The candidates the journal holds are served from it; the others go to the wrapped problem
    /// as one batch and are journaled.
    fn evaluate_batch(&self, xs: &[Vec<f64>]) -> Vec<Result<Evaluation>> {
        let keys: Vec<Vec<u64>> = xs.iter().map(|x| crate::eval::key(x)).collect();
        let fresh: Vec<usize> = (0..xs.len()).filter(|&k| !self.known.contains_key(&keys[k])).collect();
        let fresh_xs: Vec<Vec<f64>> = fresh.iter().map(|&k| xs[k].clone()).collect();
        let mut computed = self.inner.evaluate_batch(&fresh_xs).into_iter();
        let mut out = Vec::with_capacity(xs.len());
        for (k, key) in keys.into_iter().enumerate() {
            if let Some(known) = self.known.get(&key) {
                self.replayed.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                out.push(known.as_ref().map(Bits::evaluation).map_err(|e| CzError::Simulation(e.clone())));
                continue;
            }
            debug_assert!(fresh.contains(&k));
            let outcome = computed.next().expect("one result per fresh candidate");
            let entry = Entry { x: key, outcome: outcome.as_ref().map(Bits::of).map_err(|e| e.to_string()) };
            out.push(self.append(&entry).and(outcome));
        }
        out
    }
}

fn io(path: &Path, e: std::io::Error) -> CzError {
    CzError::Io { path: path.display().to_string(), message: e.to_string() }
}

fn poisoned(path: &Path) -> CzError {
    CzError::Io { path: path.display().to_string(), message: "a thread writing the journal panicked".into() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::local::{LevenbergMarquardt, LocalOptimizer, LocalSettings};
    use crate::testfns::{Function, TestFunction};
    use czid_core::{Budget, NoObserver, Observer, Progress};

    /// Stops the run after `n` observed iterations, as an interruption would.
    struct StopAfter(usize);

    impl Observer for StopAfter {
        fn observe(&mut self, _: &Progress<'_>) -> bool {
            self.0 = self.0.saturating_sub(1);
            self.0 > 0
        }
    }

    #[test]
    fn a_replayed_run_equals_the_uninterrupted_one_and_a_cut_line_is_dropped() {
        let dir = std::env::temp_dir().join(format!("czid-journal-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("evaluations.jsonl");
        let f = TestFunction::new(Function::Rosenbrock, 3).unwrap();
        let lm = LevenbergMarquardt::new(LocalSettings::default()).unwrap();
        let budget = Budget::evaluations(300);
        let start = [0.2, 0.7, 0.4];
        let whole = lm.minimize_from(&f, &budget, &start, &mut NoObserver).unwrap();

        // Interrupted after a few iterations, with its last journal line cut in half.
        {
            let j = Journal::create(&f, &path).unwrap();
            let _ = lm.minimize_from(&j, &budget, &start, &mut StopAfter(5)).unwrap();
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let cut = text.len() - 40;
        std::fs::write(&path, &text[..cut]).unwrap();

        let j = Journal::resume(&f, &path).unwrap();
        assert!(j.held() > 0);
        let resumed = lm.minimize_from(&j, &budget, &start, &mut NoObserver).unwrap();
        assert!(j.replayed() > 0);
        assert_eq!(resumed.best_x, whole.best_x);
        assert_eq!(resumed.best.value.to_bits(), whole.best.value.to_bits());
        assert_eq!(resumed.evaluations, whole.evaluations);
        assert_eq!(resumed.history, whole.history);
        // Every line of the journal is whole again.
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.lines().all(|l| serde_json::from_str::<Entry>(l).is_ok()));
        std::fs::remove_dir_all(&dir).ok();
    }
}
