//! Parallel efficiency of population evaluation: MIGA's default generation (100 then 90
//! evaluations) on an objective costing a set CPU time, with 1 and 2 threads.

use crate::miga::{Miga, MigaSettings};
use czid_core::{Budget, CzError, Evaluation, NoObserver, Optimizer, Problem, Result};
use std::hint::black_box;
use std::time::Instant;

/// Timings with 1 and `threads` threads.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeedupReport {
    /// Measured cost of one evaluation, seconds (single thread).
    pub evaluation_seconds: f64,
    /// Evaluations per run.
    pub evaluations: usize,
    /// Threads of the parallel run.
    pub threads: usize,
    /// Wall seconds with one thread.
    pub serial_seconds: f64,
    /// Wall seconds with `threads` threads.
    pub parallel_seconds: f64,
    /// `serial / parallel`.
    pub speedup: f64,
    /// Whether both runs gave identical results (they must).
    pub identical: bool,
}

/// Rastrigin plus a fixed amount of arithmetic: CPU-bound, so the timings measure
/// computation rather than waiting.
struct Costly {
    work: u64,
}

fn burn(work: u64) -> f64 {
    let mut x = 0.5f64;
    for _ in 0..work {
        x = black_box(x.mul_add(1.000_000_1, 1e-9)).sin();
    }
    x
}

impl Problem for Costly {
    fn dim(&self) -> usize {
        10
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(-5.12, 5.12); 10]
    }
    fn evaluate(&self, x: &[f64]) -> Result<Evaluation> {
        let noise = burn(self.work);
        let f = crate::testfns::Function::Rastrigin.value(x);
        Ok(Evaluation::scalar(f + 0.0 * noise))
    }
}

/// Measures the speed-up of `evaluations` evaluations costing `cost_seconds` each.
pub fn measure_speedup(cost_seconds: f64, evaluations: usize, threads: usize) -> Result<SpeedupReport> {
    // Calibrate the work per evaluation on this machine; the fastest of several probes is
    // the uncontended cost (a slow probe would make every evaluation too cheap).
    let probe = 200_000u64;
    let per_iteration = (0..5)
        .map(|_| {
            let t = Instant::now();
            black_box(burn(probe));
            t.elapsed().as_secs_f64() / probe as f64
        })
        .fold(f64::INFINITY, f64::min);
    let work = (cost_seconds / per_iteration).ceil() as u64;
    let problem = Costly { work };
    let evaluation_seconds = (0..5)
        .map(|_| {
            let t = Instant::now();
            black_box(burn(work));
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min);

    let miga = Miga::new(MigaSettings::default())?;
    let budget = Budget::evaluations(evaluations);
    let timed = |n: usize| -> Result<(f64, czid_core::OptimizationResult)> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| CzError::Optimizer(format!("thread pool: {e}")))?;
        pool.install(|| {
            let t = Instant::now();
            let r = miga.minimize(&problem, &budget, 1, &mut NoObserver)?;
            Ok((t.elapsed().as_secs_f64(), r))
        })
    };
    // Alternate the two configurations and keep each one's fastest of three runs, which
    // filters out interference from other processes on a shared machine.
    let (mut serial_seconds, a) = timed(1)?;
    let (mut parallel_seconds, b) = timed(threads)?;
    for _ in 1..3 {
        serial_seconds = serial_seconds.min(timed(1)?.0);
        parallel_seconds = parallel_seconds.min(timed(threads)?.0);
    }
    Ok(SpeedupReport {
        evaluation_seconds,
        evaluations: a.evaluations,
        threads,
        serial_seconds,
        parallel_seconds,
        speedup: serial_seconds / parallel_seconds,
        identical: a == b,
    })
}
