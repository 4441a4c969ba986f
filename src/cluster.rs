//! Several MPI ranks running one command (`--features mpi`, `mpiexec -n N czid identify ...`):
//! rank 0 runs the command as usual and spreads its batches of evaluations (identify, compare) or
//! its tasks (gap-bench's cases, a diagnosis's refits) over every rank; the other ranks read the
//! same input, build the same problem, plan or diagnosis and do what rank 0 sends until it is
//! done. Without the feature, or on one rank, nothing changes.
//!
//! A rank that fails ends every rank: it prints its error (or panic) with its number and exits
//! without finalising MPI ([`Cluster::abort`]), and `mpiexec` then ends the other ranks. A rank
//! that finalised and returned would leave the others waiting for it; `MPI_Abort` can lose the
//! message.

use czid_core::{CzError, Problem};
use czid_problems::farm::TaskFarm;
use czid_problems::identify::Spread;
use std::sync::Arc;

/// This process's place among the ranks.
pub struct Cluster {
    #[cfg(feature = "mpi")]
    _universe: Option<mpi::environment::Universe>,
    #[cfg(feature = "mpi")]
    evaluator: Option<std::sync::Arc<czid_optimizers::mpi::MpiEvaluator>>,
    rank: usize,
    #[cfg(feature = "mpi")]
    size: usize,
    /// Set once this rank has run tasks for rank 0 ([`Cluster::task_farm`]).
    #[cfg(feature = "mpi")]
    served: Arc<std::sync::atomic::AtomicBool>,
}

impl Cluster {
    /// Joins the ranks started by `mpiexec` (one rank when started alone or built without MPI).
    pub fn join() -> Cluster {
        #[cfg(feature = "mpi")]
        {
            use mpi::topology::Communicator;
            let universe = mpi::initialize_with_threading(mpi::Threading::Funneled).map(|(u, _)| u);
            let (rank, size) =
                universe.as_ref().map_or((0, 1), |u| (u.world().rank() as usize, u.world().size() as usize));
            let evaluator = (rank == 0 && size > 1).then(|| Arc::new(czid_optimizers::mpi::MpiEvaluator::new()));
            if size > 1 {
                // Unwinding would finalise MPI while the other ranks wait for this one; a process
                // that exits without finalising ends them all.
                let report = std::panic::take_hook();
                std::panic::set_hook(Box::new(move |info| {
                    eprintln!("rank {rank} of {size} panicked; ending every rank");
                    report(info);
                    std::process::exit(101);
                }));
            }
            Cluster { _universe: universe, evaluator, rank, size, served: Arc::default() }
        }
        #[cfg(not(feature = "mpi"))]
        Cluster { rank: 0 }
    }

    /// Whether this process serves rank 0 rather than running the command.
    pub fn is_worker(&self) -> bool {
        self.rank > 0
    }

    /// Where rank 0's batches go (`None` on one rank).
    pub fn spread(&self) -> Option<Spread> {
        #[cfg(feature = "mpi")]
        if let Some(e) = &self.evaluator {
            return Some(Spread(e.clone()));
        }
        None
    }

    /// On a rank other than 0: evaluates what rank 0 sends with this rank's copy of `problem`.
    pub fn serve(&self, problem: &dyn Problem) -> Result<(), CzError> {
        #[cfg(feature = "mpi")]
        {
            czid_optimizers::mpi::serve(problem);
            Ok(())
        }
        #[cfg(not(feature = "mpi"))]
        {
            let _ = problem;
            Err(CzError::config("mpi", "this czid was built without the `mpi` feature"))
        }
    }

    /// Where tasks run (`None` on one rank): on rank 0, spread over every rank (rank 0 keeps the
    /// results); on the others, the tasks rank 0 hands out are run until it is done, and the farm
    /// gives no results ([`Cluster::served`] then tells so).
    pub fn task_farm(&self) -> Option<Arc<dyn TaskFarm>> {
        #[cfg(feature = "mpi")]
        if self.size > 1 {
            return Some(match &self.evaluator {
                Some(e) => Arc::new(MpiFarm(e.clone())),
                None => Arc::new(Served(self.served.clone())),
            });
        }
        None
    }

    /// Whether this rank has run tasks for rank 0 through its [`Cluster::task_farm`].
    pub fn served(&self) -> bool {
        #[cfg(feature = "mpi")]
        {
            self.served.load(std::sync::atomic::Ordering::SeqCst)
        }
        #[cfg(not(feature = "mpi"))]
        {
            false
        }
    }

    /// Whether several ranks run the command.
    pub fn is_spread(&self) -> bool {
        #[cfg(feature = "mpi")]
        {
            self.size > 1
        }
        #[cfg(not(feature = "mpi"))]
        {
            false
        }
    }

    /// Ends the run on every rank after `e`, printed with this rank's number: the process exits
    /// without finalising MPI, and `mpiexec` ends the other ranks (a rank that returned would
    /// leave them waiting for it).
    pub fn abort(&self, e: &CzError) -> ! {
        #[cfg(feature = "mpi")]
        eprintln!("error on rank {} of {}: {e}", self.rank, self.size);
        #[cfg(not(feature = "mpi"))]
        eprintln!("error: {e}");
        std::process::exit(1)
    }

    /// On a rank other than 0: runs the tasks rank 0 farms out with `run(id)`.
    pub fn serve_tasks(&self, run: &dyn Fn(usize) -> Vec<u8>) -> Result<(), CzError> {
        #[cfg(feature = "mpi")]
        {
            czid_optimizers::mpi::serve_tasks(run);
            Ok(())
        }
        #[cfg(not(feature = "mpi"))]
        {
            let _ = run;
            Err(CzError::config("mpi", "this czid was built without the `mpi` feature"))
        }
    }

    /// On rank 0, once the command is over (whether it succeeded or not): releases the other
    /// ranks and says how many `units` (evaluations, cases) each did.
    pub fn finish(&self, units: &str) {
        #[cfg(not(feature = "mpi"))]
        let _ = units;
        #[cfg(feature = "mpi")]
        if let Some(e) = &self.evaluator {
            czid_optimizers::mpi::finish();
            let counts = e.counts();
            let shown: Vec<String> = counts.iter().enumerate().map(|(r, n)| format!("rank {r}: {n}")).collect();
            println!("{units} on {} ranks: {}", self.size, shown.join(", "));
        }
    }
}

/// Rank 0's tasks (a benchmark's cases, a diagnosis's refits) spread over the ranks.
#[cfg(feature = "mpi")]
struct MpiFarm(Arc<czid_optimizers::mpi::MpiEvaluator>);

#[cfg(feature = "mpi")]
impl TaskFarm for MpiFarm {
    fn run(&self, tasks: &[usize], run: &(dyn Fn(usize) -> Vec<u8> + Sync)) -> czid_core::Result<Option<Vec<Vec<u8>>>> {
        Ok(Some(self.0.farm(tasks, run)))
    }
}

/// Another rank's side of [`MpiFarm`]: runs what rank 0 hands out until it is done.
#[cfg(feature = "mpi")]
struct Served(Arc<std::sync::atomic::AtomicBool>);

#[cfg(feature = "mpi")]
impl TaskFarm for Served {
    fn run(&self, _: &[usize], run: &(dyn Fn(usize) -> Vec<u8> + Sync)) -> czid_core::Result<Option<Vec<Vec<u8>>>> {
        czid_optimizers::mpi::serve_tasks(run);
        self.0.store(true, std::sync::atomic::Ordering::SeqCst);
        Ok(None)
    }
}
