//! Several MPI ranks running one identification (`--features mpi`, `mpiexec -n N czid identify
//! ...`): rank 0 runs the command as usual and spreads its batches of evaluations over every
//! rank; the other ranks read the same problem file, build the same problem and evaluate what
//! rank 0 sends until it is done. Without the feature, or on one rank, nothing changes.

use czid_core::{CzError, Problem};
use czid_problems::identify::Spread;

/// This process's place among the ranks.
pub struct Cluster {
    #[cfg(feature = "mpi")]
    _universe: Option<mpi::environment::Universe>,
    #[cfg(feature = "mpi")]
    evaluator: Option<std::sync::Arc<czid_optimizers::mpi::MpiEvaluator>>,
    rank: usize,
    #[cfg(feature = "mpi")]
    size: usize,
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
            let evaluator =
                (rank == 0 && size > 1).then(|| std::sync::Arc::new(czid_optimizers::mpi::MpiEvaluator::new()));
            Cluster { _universe: universe, evaluator, rank, size }
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

    /// Where rank 0 runs a benchmark's cases (`None` on one rank).
    pub fn case_farm(&self) -> Option<Box<dyn czid_problems::diagnose::bench::CaseFarm + '_>> {
        #[cfg(feature = "mpi")]
        if let Some(e) = &self.evaluator {
            return Some(Box::new(MpiFarm(e)));
        }
        None
    }

    /// On a rank other than 0: runs the tasks rank 0 farms out with `run(id)`.
    pub fn serve_tasks(&self, run: &dyn Fn(usize) -> String) -> Result<(), CzError> {
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

/// A benchmark's cases spread over the ranks.
#[cfg(feature = "mpi")]
struct MpiFarm<'a>(&'a czid_optimizers::mpi::MpiEvaluator);

#[cfg(feature = "mpi")]
impl czid_problems::diagnose::bench::CaseFarm for MpiFarm<'_> {
    fn run(&self, indices: &[usize], run: &(dyn Fn(usize) -> String + Sync)) -> Vec<String> {
        self.0.farm(indices, run)
    }
}
