//! Checkpoint files: a run's [`Snapshot`] written atomically every few iterations, and read
//! back for [`Optimizer::resume`].

use czid_core::{Budget, CzError, Observer, OptimizationResult, Optimizer, Problem, Progress, Result, Snapshot};
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, flushed, then
/// renamed over `path`, so a crash leaves either the old or the new file, never half of one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let io = |e: std::io::Error| CzError::Io { path: path.display().to_string(), message: e.to_string() };
    let name = path
        .file_name()
        .ok_or_else(|| CzError::Io { path: path.display().to_string(), message: "not a file path".into() })?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp{}", std::process::id()));
    let tmp = path.with_file_name(tmp_name);
    let mut f = std::fs::File::create(&tmp).map_err(io)?;
    f.write_all(bytes).and_then(|_| f.sync_all()).map_err(io)?;
    drop(f);
    std::fs::rename(&tmp, path).map_err(io)
}

/// Reads a checkpoint file.
pub fn read_checkpoint(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| CzError::Io { path: path.display().to_string(), message: e.to_string() })
}

/// Resumes the run saved in `path` with `optimizer` (built with the same settings).
pub fn resume_from_file(
    optimizer: &dyn Optimizer,
    problem: &dyn Problem,
    budget: &Budget,
    path: &Path,
    observer: &mut dyn Observer,
) -> Result<OptimizationResult> {
    optimizer.resume(problem, budget, &read_checkpoint(path)?, observer)
}

/// An observer that saves the run's state every `every` iterations (and never stops it).
#[derive(Clone, Debug)]
pub struct CheckpointWriter {
    path: PathBuf,
    every: usize,
    written: usize,
}

impl CheckpointWriter {
    /// Saves to `path` after every `every`-th iteration (`every ≥ 1`).
    pub fn new(path: impl Into<PathBuf>, every: usize) -> Result<Self> {
        if every == 0 {
            return Err(CzError::invalid("checkpoint", "every", 0.0, "must be at least 1"));
        }
        Ok(CheckpointWriter { path: path.into(), every, written: 0 })
    }

    /// Number of checkpoints written so far.
    pub fn written(&self) -> usize {
        self.written
    }
}

impl Observer for CheckpointWriter {
    fn observe(&mut self, _: &Progress<'_>) -> bool {
        true
    }

    fn checkpoint(&mut self, progress: &Progress<'_>, state: &dyn Snapshot) -> Result<()> {
        if progress.iteration % self.every == 0 {
            write_atomic(&self.path, state.to_json()?.as_bytes())?;
            self.written += 1;
        }
        Ok(())
    }
}
