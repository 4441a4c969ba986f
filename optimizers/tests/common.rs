//! Helpers shared by the integration tests.
#![allow(dead_code)]

use czid_core::{CzError, Evaluation, Observer, Problem, Progress, Result};
use czid_optimizers::testfns::{Function, TestFunction};

/// Runs `f` on a rayon pool of `threads` threads.
pub fn with_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool").install(f)
}

/// Rastrigin whose evaluations fail on a slab of the box: failures must be counted and
/// penalised, never fatal.
pub struct Flaky(pub TestFunction);

impl Flaky {
    pub fn rastrigin(n: usize) -> Self {
        Flaky(TestFunction::new(Function::Rastrigin, n).unwrap())
    }
}

impl Problem for Flaky {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        self.0.bounds()
    }
    fn evaluate(&self, x: &[f64]) -> Result<Evaluation> {
        if x[0] > 4.0 {
            return Err(CzError::Simulation("diverged".into()));
        }
        if x[0] < -4.5 {
            return Ok(Evaluation::scalar(f64::NAN));
        }
        self.0.evaluate(x)
    }
}

/// Asks the optimizer to stop after iteration `at`.
pub struct StopAt(pub usize);

impl Observer for StopAt {
    fn observe(&mut self, p: &Progress<'_>) -> bool {
        p.iteration < self.0
    }
}
