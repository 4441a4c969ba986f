//! Work spread over MPI ranks (`--features mpi`).
//!
//! Every rank builds the same problem from the same input. Rank 0 runs the command unchanged and
//! hands tasks out one at a time to whichever rank is free (dynamic self-scheduling: tasks differ
//! in cost), doing tasks itself on a thread of its own; the other ranks [`serve`] (evaluations)
//! or [`serve_tasks`] (whole tasks, e.g. the cases of a benchmark) until rank 0 [`finish`]es.
//! Results are stored by task index, so the outcome on any number of ranks is the serial one,
//! bit for bit.
//!
//! * [`MpiEvaluator`]: the batches of evaluations of an optimizer (a [`BatchEvaluator`]).
//! * [`MpiEvaluator::farm`]: whole tasks named by an index, whose results are bytes (e.g. JSON).
//!
//! Only rank 0's main thread calls MPI (`MPI_THREAD_FUNNELED` is enough); numbers cross as their
//! bit patterns, so values arrive exactly.

use czid_core::{BatchEvaluator, CzError, Evaluation, Problem, Result};
use mpi::point_to_point::{Destination, Source};
use mpi::topology::{Communicator, SimpleCommunicator};
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

const JOB: i32 = 1;
const RESULT: i32 = 2;
const STOP: i32 = 3;

/// An evaluation as bit patterns, or why it failed.
type Outcome = std::result::Result<(u64, Vec<u64>, Vec<u64>), String>;

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn values(v: &[u64]) -> Vec<f64> {
    v.iter().map(|&b| f64::from_bits(b)).collect()
}

fn encode<T: Serialize>(t: &T) -> Vec<u8> {
    serde_json::to_vec(t).expect("plain data serialises")
}

fn outcome(r: &Result<Evaluation>) -> Outcome {
    r.as_ref().map(|e| (e.value.to_bits(), bits(&e.objectives), bits(&e.residuals))).map_err(|e| e.to_string())
}

fn evaluation(bytes: &[u8]) -> Result<Evaluation> {
    let o: Outcome =
        serde_json::from_slice(bytes).map_err(|e| CzError::Simulation(format!("unreadable result: {e}")))?;
    o.map(|(v, ob, r)| Evaluation { value: f64::from_bits(v), objectives: values(&ob), residuals: values(&r) })
        .map_err(CzError::Simulation)
}

/// A message: the task's index, then its payload.
fn message(index: usize, payload: &[u8]) -> Vec<u8> {
    let mut m = (index as u64).to_le_bytes().to_vec();
    m.extend_from_slice(payload);
    m
}

fn split(m: &[u8]) -> (usize, &[u8]) {
    let (head, payload) = m.split_at(8);
    (u64::from_le_bytes(head.try_into().expect("8 bytes")) as usize, payload)
}

/// Runs tasks `0..n` over every rank: rank 0 runs `local(k)` on a thread of its own, the other
/// ranks receive `job(k)` and answer. Returns each task's result bytes in task order and the
/// number of tasks each rank did.
fn schedule(
    n: usize,
    job: &(dyn Fn(usize) -> Vec<u8> + Sync),
    local: &(dyn Fn(usize) -> Vec<u8> + Sync),
) -> (Vec<Vec<u8>>, Vec<usize>) {
    let world = SimpleCommunicator::world();
    let ranks = world.size() as usize;
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Vec<u8>>> = Mutex::new(vec![Vec::new(); n]);
    let mut counts = vec![0usize; ranks];
    let done_here = AtomicUsize::new(0);
    std::thread::scope(|s| {
        s.spawn(|| loop {
            let k = next.fetch_add(1, Ordering::SeqCst);
            if k >= n {
                break;
            }
            let r = local(k);
            done_here.fetch_add(1, Ordering::Relaxed);
            if let Ok(mut all) = results.lock() {
                all[k] = r;
            }
        });
        let send = |rank: usize| -> bool {
            let k = next.fetch_add(1, Ordering::SeqCst);
            if k >= n {
                return false;
            }
            world.process_at_rank(rank as i32).send_with_tag(&message(k, &job(k))[..], JOB);
            true
        };
        let mut outstanding = (1..ranks).filter(|&r| send(r)).count();
        while outstanding > 0 {
            // Polled with short sleeps rather than a blocking receive, which would spin a core
            // that rank 0's own tasks need.
            if world.any_process().immediate_probe_with_tag(RESULT).is_none() {
                std::thread::sleep(std::time::Duration::from_micros(200));
                continue;
            }
            let (msg, status) = world.any_process().receive_vec_with_tag::<u8>(RESULT);
            let rank = status.source_rank() as usize;
            outstanding -= 1;
            counts[rank] += 1;
            let (k, payload) = split(&msg);
            if let Ok(mut all) = results.lock() {
                all[k] = payload.to_vec();
            }
            if send(rank) {
                outstanding += 1;
            }
        }
    });
    counts[0] += done_here.into_inner();
    (results.into_inner().unwrap_or_default(), counts)
}

/// How long a waiting rank polls for its next message before it starts sleeping between polls:
/// within a batch the next job follows a result at once, and a blocking receive would keep the
/// core busy for as long as rank 0 works alone (e.g. the end of a diagnosis).
const SPIN: std::time::Duration = std::time::Duration::from_millis(2);
/// The sleep between polls after that.
const NAP: std::time::Duration = std::time::Duration::from_micros(500);

/// Serves rank 0 on another rank: answers each job with `handle(index, payload)` until told to
/// stop. Returns the number of jobs done.
fn serve_with(handle: &dyn Fn(usize, &[u8]) -> Vec<u8>) -> usize {
    let world = SimpleCommunicator::world();
    let root = world.process_at_rank(0);
    let mut done_here = 0;
    loop {
        let since = std::time::Instant::now();
        while root.immediate_probe().is_none() {
            if since.elapsed() < SPIN {
                std::hint::spin_loop();
            } else {
                std::thread::sleep(NAP);
            }
        }
        let (msg, status) = root.receive_vec::<u8>();
        if status.tag() == STOP {
            return done_here;
        }
        let (k, payload) = split(&msg);
        let answer = handle(k, payload);
        done_here += 1;
        root.send_with_tag(&message(k, &answer)[..], RESULT);
    }
}

/// The batch evaluator of rank 0.
#[derive(Debug, Default)]
pub struct MpiEvaluator {
    /// Evaluations (or tasks) done by each rank.
    counts: Mutex<Vec<usize>>,
}

impl MpiEvaluator {
    /// An evaluator over the ranks of the world communicator (MPI must be initialised).
    pub fn new() -> Self {
        let size = SimpleCommunicator::world().size() as usize;
        MpiEvaluator { counts: Mutex::new(vec![0; size]) }
    }

    /// Evaluations (and tasks) done so far by each rank (rank 0 first).
    pub fn counts(&self) -> Vec<usize> {
        self.counts.lock().map(|c| c.clone()).unwrap_or_default()
    }

    fn add(&self, counts: &[usize]) {
        if let Ok(mut c) = self.counts.lock() {
            c.iter_mut().zip(counts).for_each(|(a, b)| *a += b);
        }
    }

    /// Runs the tasks `tasks` (any task ids) over the ranks (`run(id)` on rank 0, [`serve_tasks`]
    /// on the others) and returns their results in the order of `tasks`.
    pub fn farm(&self, tasks: &[usize], run: &(dyn Fn(usize) -> Vec<u8> + Sync)) -> Vec<Vec<u8>> {
        let job = |k: usize| (tasks[k] as u64).to_le_bytes().to_vec();
        let (results, counts) = schedule(tasks.len(), &job, &|k| run(tasks[k]));
        self.add(&counts);
        results
    }
}

impl BatchEvaluator for MpiEvaluator {
    fn evaluate(&self, problem: &dyn Problem, xs: &[Vec<f64>]) -> Vec<Result<Evaluation>> {
        let job = |k: usize| encode(&bits(&xs[k]));
        let local = |k: usize| encode(&outcome(&problem.evaluate(&xs[k])));
        let (results, counts) = schedule(xs.len(), &job, &local);
        self.add(&counts);
        results.iter().map(|b| evaluation(b)).collect()
    }
}

/// Runs on ranks other than 0: evaluates the candidates rank 0 sends with this rank's copy of
/// the problem until rank 0 says stop. Returns the number of evaluations done.
pub fn serve(problem: &dyn Problem) -> usize {
    serve_with(&|_, payload| {
        let r = match serde_json::from_slice::<Vec<u64>>(payload) {
            Ok(x) => problem.evaluate(&values(&x)),
            Err(e) => Err(CzError::Simulation(format!("unreadable candidate: {e}"))),
        };
        encode(&outcome(&r))
    })
}

/// Runs on ranks other than 0: does the tasks rank 0's [`MpiEvaluator::farm`] sends, with
/// `run(id)`, until rank 0 says stop. Returns the number of tasks done.
pub fn serve_tasks(run: &dyn Fn(usize) -> Vec<u8>) -> usize {
    serve_with(&|_, payload| {
        let id = payload.try_into().map(u64::from_le_bytes).unwrap_or(u64::MAX) as usize;
        run(id)
    })
}

/// Tells every other rank to stop serving (rank 0, once its work is over).
pub fn finish() {
    let world = SimpleCommunicator::world();
    for r in 1..world.size() {
        world.process_at_rank(r).send_with_tag(&[0u8][..], STOP);
    }
}
