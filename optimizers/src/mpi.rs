//! Batches of evaluations spread over MPI ranks (`--features mpi`).
//!
//! Every rank builds the same problem from the same input. Rank 0 runs the optimizer unchanged;
//! its batches go through an [`MpiEvaluator`], which hands the candidates out one at a time to
//! whichever rank is free (dynamic self-scheduling: runs differ in cost) and evaluates them on
//! rank 0 as well, on a thread of its own. The other ranks [`serve`] until rank 0 [`finish`]es.
//! Results are keyed by the candidate's index in its batch, so a run on any number of ranks is
//! the serial run, bit for bit.
//!
//! Only rank 0's main thread calls MPI (`MPI_THREAD_FUNNELED` is enough); the messages are
//! JSON with every number as its bit pattern, so values cross exactly.

use czid_core::{BatchEvaluator, CzError, Evaluation, Problem, Result};
use mpi::point_to_point::{Destination, Source};
use mpi::topology::{Communicator, SimpleCommunicator};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

const JOB: i32 = 1;
const RESULT: i32 = 2;
const STOP: i32 = 3;

#[derive(Serialize, Deserialize)]
struct Job {
    index: usize,
    x: Vec<u64>,
}

#[derive(Serialize, Deserialize)]
struct Done {
    index: usize,
    outcome: std::result::Result<(u64, Vec<u64>, Vec<u64>), String>,
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn values(v: &[u64]) -> Vec<f64> {
    v.iter().map(|&b| f64::from_bits(b)).collect()
}

fn encode<T: Serialize>(t: &T) -> Vec<u8> {
    serde_json::to_vec(t).expect("plain data serialises")
}

fn done(index: usize, r: &Result<Evaluation>) -> Done {
    Done {
        index,
        outcome: r
            .as_ref()
            .map(|e| (e.value.to_bits(), bits(&e.objectives), bits(&e.residuals)))
            .map_err(|e| e.to_string()),
    }
}

fn evaluation(d: Done) -> Result<Evaluation> {
    d.outcome
        .map(|(v, o, r)| Evaluation { value: f64::from_bits(v), objectives: values(&o), residuals: values(&r) })
        .map_err(CzError::Simulation)
}

/// The batch evaluator of rank 0.
#[derive(Debug, Default)]
pub struct MpiEvaluator {
    /// Evaluations done by each rank.
    counts: Mutex<Vec<usize>>,
}

impl MpiEvaluator {
    /// An evaluator over the ranks of the world communicator (MPI must be initialised).
    pub fn new() -> Self {
        let size = SimpleCommunicator::world().size() as usize;
        MpiEvaluator { counts: Mutex::new(vec![0; size]) }
    }

    /// Evaluations done so far by each rank (rank 0 first).
    pub fn counts(&self) -> Vec<usize> {
        self.counts.lock().map(|c| c.clone()).unwrap_or_default()
    }
}

impl BatchEvaluator for MpiEvaluator {
    fn evaluate(&self, problem: &dyn Problem, xs: &[Vec<f64>]) -> Vec<Result<Evaluation>> {
        let world = SimpleCommunicator::world();
        let ranks = world.size() as usize;
        let n = xs.len();
        let next = AtomicUsize::new(0);
        let results: Mutex<Vec<Option<Result<Evaluation>>>> = Mutex::new((0..n).map(|_| None).collect());
        let mut counts = vec![0usize; ranks];
        let local = AtomicUsize::new(0);
        std::thread::scope(|s| {
            // Rank 0 evaluates too, on a thread that never calls MPI.
            s.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                if k >= n {
                    break;
                }
                let r = problem.evaluate(&xs[k]);
                local.fetch_add(1, Ordering::Relaxed);
                if let Ok(mut all) = results.lock() {
                    all[k] = Some(r);
                }
            });
            let send = |rank: usize| -> bool {
                let k = next.fetch_add(1, Ordering::SeqCst);
                if k >= n {
                    return false;
                }
                let job = encode(&Job { index: k, x: bits(&xs[k]) });
                world.process_at_rank(rank as i32).send_with_tag(&job[..], JOB);
                true
            };
            let mut outstanding = (1..ranks).filter(|&r| send(r)).count();
            while outstanding > 0 {
                // Polled with short sleeps rather than a blocking receive, which spins a core
                // that rank 0's own evaluations need.
                if world.any_process().immediate_probe_with_tag(RESULT).is_none() {
                    std::thread::sleep(std::time::Duration::from_micros(200));
                    continue;
                }
                let (msg, status) = world.any_process().receive_vec_with_tag::<u8>(RESULT);
                let rank = status.source_rank() as usize;
                outstanding -= 1;
                counts[rank] += 1;
                let d: Done = match serde_json::from_slice(&msg) {
                    Ok(d) => d,
                    Err(e) => panic!("rank {rank} sent an unreadable result: {e}"),
                };
                let index = d.index;
                if let Ok(mut all) = results.lock() {
                    all[index] = Some(evaluation(d));
                }
                if send(rank) {
                    outstanding += 1;
                }
            }
        });
        counts[0] += local.into_inner();
        if let Ok(mut c) = self.counts.lock() {
            c.iter_mut().zip(&counts).for_each(|(a, b)| *a += b);
        }
        results
            .into_inner()
            .unwrap_or_default()
            .into_iter()
            .map(|r| r.unwrap_or_else(|| Err(CzError::Simulation("a candidate was not evaluated".into()))))
            .collect()
    }
}

/// Runs on ranks other than 0: evaluates the candidates rank 0 sends with this rank's copy of
/// the problem until rank 0 says stop. Returns the number of evaluations done.
pub fn serve(problem: &dyn Problem) -> usize {
    let world = SimpleCommunicator::world();
    let root = world.process_at_rank(0);
    let mut done_here = 0;
    loop {
        let (msg, status) = root.receive_vec::<u8>();
        if status.tag() == STOP {
            return done_here;
        }
        let job: Job = match serde_json::from_slice(&msg) {
            Ok(j) => j,
            Err(e) => panic!("rank 0 sent an unreadable job: {e}"),
        };
        let r = problem.evaluate(&values(&job.x));
        done_here += 1;
        root.send_with_tag(&encode(&done(job.index, &r))[..], RESULT);
    }
}

/// Tells every other rank to stop serving (rank 0, once its runs are over).
pub fn finish() {
    let world = SimpleCommunicator::world();
    for r in 1..world.size() {
        world.process_at_rank(r).send_with_tag(&[0u8][..], STOP);
    }
}
