//! Independent tasks run side by side: on this process's threads by default ([`Threads`]), or
//! spread by a [`TaskFarm`] of another kind (the `czid` command's MPI ranks, each holding the same
//! inputs). A task is named by an index and gives its result as bytes, so a farm can move it
//! between processes; results come back in the order of the tasks asked for, so the outcome does
//! not depend on where or in which order the tasks ran.
//!
//! Floating values cross as their bit patterns ([`bits`], [`values`]) and arrive exactly.

use czid_core::Result;

/// Where independent tasks run.
pub trait TaskFarm: Send + Sync {
    /// Runs the tasks `tasks` (`run(k)` gives task `k`'s result) and returns their results in the
    /// order of `tasks`. `Ok(None)` on a process that only ran tasks for another one, which keeps
    /// the results (its caller has nothing left to do); an error when a task could not be run
    /// (e.g. it panicked, here or on another process).
    fn run(&self, tasks: &[usize], run: &(dyn Fn(usize) -> Vec<u8> + Sync)) -> Result<Option<Vec<Vec<u8>>>>;
}

/// This process's threads (rayon).
#[derive(Clone, Copy, Debug, Default)]
pub struct Threads;

impl TaskFarm for Threads {
    fn run(&self, tasks: &[usize], run: &(dyn Fn(usize) -> Vec<u8> + Sync)) -> Result<Option<Vec<Vec<u8>>>> {
        use rayon::prelude::*;
        Ok(Some(tasks.par_iter().map(|&k| run(k)).collect()))
    }
}

/// The bit patterns of `v`.
pub fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// The values of the bit patterns `b`.
pub fn values(b: &[u64]) -> Vec<f64> {
    b.iter().map(|&x| f64::from_bits(x)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threads_keep_the_order_of_the_tasks() {
        let r = Threads.run(&[3, 1, 2], &|k| vec![k as u8; k]).unwrap().unwrap();
        assert_eq!(r, vec![vec![3, 3, 3], vec![1], vec![2, 2]]);
    }

    #[test]
    fn bit_patterns_give_every_value_back() {
        let v = [0.1 + 0.2, -0.0, f64::MIN_POSITIVE / 3.0, f64::INFINITY, f64::NAN, 1e308];
        let back = values(&bits(&v));
        assert!(v.iter().zip(&back).all(|(a, b)| a.to_bits() == b.to_bits()));
        let json = serde_json::to_vec(&bits(&v)).unwrap();
        assert_eq!(values(&serde_json::from_slice::<Vec<u64>>(&json).unwrap())[0].to_bits(), v[0].to_bits());
    }
}
