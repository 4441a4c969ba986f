//! What a message between two MPI ranks costs czid (`--features mpi`, two ranks):
//!
//! 1. round trips as the batch evaluator makes them: rank 0 sends a candidate (its index and the
//!    bit patterns of its 6 values as JSON), rank 1 answers with an evaluation (value, 2 objectives
//!    and 200 residuals as bit patterns); the median of many, in microseconds;
//! 2. the batch evaluator itself (`MpiEvaluator`, rank 0 evaluating too) on batches of runs of a
//!    fixed length (5 ms by default, a DCB run): the share of the time the ranks spend in runs,
//!    and how long rank 1 waits per run for rank 0 to take its result and send the next candidate
//!    (the scheduling cost of a run). The runs sleep by default, which leaves rank 0's scheduling
//!    thread a core of its own, as on a cluster node; `busy` makes them spin instead (on a 2-core
//!    machine rank 0's scheduling thread then has no core to run on).
//!
//! ```text
//! cargo build --release --features mpi --example mpi_round_trip
//! mpiexec -n 2 target/release/examples/mpi_round_trip [round trips: 20000] [run ms: 5] [batch: 200] [sleep|busy]
//! ```

use czid_core::{BatchEvaluator, Evaluation, Problem, Result};
use czid_optimizers::mpi::{finish, serve, MpiEvaluator};
use mpi::collective::CommunicatorCollectives;
use mpi::point_to_point::{Destination, Source};
use mpi::topology::Communicator;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

const DIM: usize = 6;
const RESIDUALS: usize = 200;

/// An evaluation that takes `run` (asleep or spinning), adding the time it took to `spent`.
struct Timed {
    run: Duration,
    busy: bool,
    spent: AtomicU64,
}

impl Problem for Timed {
    fn dim(&self) -> usize {
        DIM
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(0.0, 1.0); DIM]
    }
    fn evaluate(&self, x: &[f64]) -> Result<Evaluation> {
        let start = Instant::now();
        if self.busy {
            while start.elapsed() < self.run {
                std::hint::spin_loop();
            }
        } else {
            std::thread::sleep(self.run);
        }
        self.spent.fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
        Ok(evaluation(x))
    }
}

fn evaluation(x: &[f64]) -> Evaluation {
    let residuals: Vec<f64> = (0..RESIDUALS).map(|i| x[i % DIM] * (i as f64 + 0.1).sqrt()).collect();
    Evaluation { value: residuals.iter().map(|r| r * r).sum(), objectives: vec![0.3, 0.7], residuals }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A message as the evaluator frames it: the index, then the JSON payload.
fn message(index: u64, payload: &[u8]) -> Vec<u8> {
    let mut m = index.to_le_bytes().to_vec();
    m.extend_from_slice(payload);
    m
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: f64| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(d);
    let (trips, run_ms, batch) = (arg(1, 20_000.0) as usize, arg(2, 5.0), arg(3, 200.0) as usize);
    let busy = args.get(4).is_some_and(|a| a == "busy");
    let universe = mpi::initialize_with_threading(mpi::Threading::Funneled).expect("MPI").0;
    let world = universe.world();
    assert_eq!(world.size(), 2, "run on two ranks: mpiexec -n 2 ...");
    let rank = world.rank();
    let other = world.process_at_rank(1 - rank);
    let x: Vec<f64> = (0..DIM).map(|i| 0.1 + 0.13 * i as f64).collect();

    // 1. Round trips, encoding and decoding included; the first 1000 warm up.
    let mut times = Vec::with_capacity(trips);
    for k in 0..trips + 1000 {
        if rank == 0 {
            let start = Instant::now();
            other.send(&message(k as u64, &serde_json::to_vec(&bits(&x)).unwrap())[..]);
            let (answer, _) = other.receive_vec::<u8>();
            let _: std::result::Result<(u64, Vec<u64>, Vec<u64>), String> =
                serde_json::from_slice(&answer[8..]).unwrap();
            if k >= 1000 {
                times.push(start.elapsed().as_secs_f64() * 1e6);
            }
        } else {
            // As a serving rank waits: polling.
            while other.immediate_probe().is_none() {
                std::hint::spin_loop();
            }
            let (job, _) = other.receive_vec::<u8>();
            let v: Vec<u64> = serde_json::from_slice(&job[8..]).unwrap();
            let e = evaluation(&v.iter().map(|&b| f64::from_bits(b)).collect::<Vec<f64>>());
            let out: std::result::Result<(u64, Vec<u64>, Vec<u64>), String> =
                Ok((e.value.to_bits(), bits(&e.objectives), bits(&e.residuals)));
            other.send(&message(k as u64, &serde_json::to_vec(&out).unwrap())[..]);
        }
    }
    if rank == 0 {
        let mut sorted = times.clone();
        sorted.sort_by(f64::total_cmp);
        let q = |p: f64| sorted[((sorted.len() - 1) as f64 * p) as usize];
        println!(
            "round trip of a candidate ({DIM} values) and its evaluation ({RESIDUALS} residuals), {trips} times: \
             median {:.1} µs (10 %: {:.1}, 90 %: {:.1})",
            median(times),
            q(0.1),
            q(0.9)
        );
    }

    // 2. The batch evaluator on runs of a fixed length.
    let problem = Timed { run: Duration::from_secs_f64(run_ms / 1e3), busy, spent: AtomicU64::new(0) };
    world.barrier();
    if rank == 1 {
        let runs = serve(&problem) as u64;
        other.send(&[runs, problem.spent.load(Ordering::Relaxed)][..]);
        return;
    }
    let xs: Vec<Vec<f64>> = (0..batch).map(|k| x.iter().map(|v| v + k as f64 * 1e-3).collect()).collect();
    let evaluator = MpiEvaluator::new();
    let mut wall = 0.0;
    for _ in 0..3 {
        let start = Instant::now();
        let r = evaluator.evaluate(&problem, &xs);
        wall += start.elapsed().as_secs_f64();
        assert!(r.iter().zip(&xs).all(|(e, x)| e.as_ref().is_ok_and(|e| e.value == evaluation(x).value)));
    }
    finish();
    let (theirs, _) = other.receive_vec::<u64>();
    let (runs_1, spent_1) = (theirs[0] as f64, theirs[1] as f64 / 1e9);
    let spent_0 = problem.spent.load(Ordering::Relaxed) as f64 / 1e9;
    println!(
        "3 batches of {batch} runs of {run_ms} ms ({}) on 2 ranks: {wall:.3} s, {:.1} % of it in runs; \
         rank 1 waits {:.0} µs per run for its next candidate; runs per rank {:?}",
        if busy { "spinning" } else { "asleep" },
        100.0 * (spent_0 + spent_1) / (2.0 * wall),
        (wall - spent_1) / runs_1 * 1e6,
        evaluator.counts()
    );
}
