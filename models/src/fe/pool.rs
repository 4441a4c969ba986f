//! Work arrays reused across runs on the same thread.
//!
//! An identification runs the same model thousands of times, each run needing a few megabytes
//! of work arrays (one entry per node or interface point). Allocated afresh, arrays of that size
//! come from the operating system as new pages, and the page faults that fill them cost about a
//! fifth of a windowed DCB run (system time). A run therefore takes its arrays from this per-thread
//! pool, and they go back to it when the run drops them: in the steady state nothing is allocated.
//!
//! The pool holds vectors of any element type, found by type; what a run takes is cleared and
//! refilled, so a reused vector holds exactly what a fresh one would.

use std::any::Any;
use std::cell::RefCell;

/// More vectors than any run holds at once: beyond it, returned vectors are dropped (a bound on
/// the memory a thread keeps).
const CAPACITY: usize = 64;

thread_local! {
    static POOL: RefCell<Vec<Box<dyn Any>>> = const { RefCell::new(Vec::new()) };
}

/// A vector from the pool, given back to it when dropped.
#[derive(Debug)]
pub(crate) struct Pooled<T: 'static>(Vec<T>);

impl<T> std::ops::Deref for Pooled<T> {
    type Target = Vec<T>;
    fn deref(&self) -> &Vec<T> {
        &self.0
    }
}

impl<T> std::ops::DerefMut for Pooled<T> {
    fn deref_mut(&mut self) -> &mut Vec<T> {
        &mut self.0
    }
}

impl<T> Default for Pooled<T> {
    fn default() -> Self {
        Pooled(Vec::new())
    }
}

impl<T> Drop for Pooled<T> {
    fn drop(&mut self) {
        let v = std::mem::take(&mut self.0);
        if v.capacity() == 0 {
            return;
        }
        // During a thread's teardown the pool may be gone: the vector is then simply freed.
        let _ = POOL.try_with(|pool| {
            let mut pool = pool.borrow_mut();
            if pool.len() < CAPACITY {
                pool.push(Box::new(v));
            }
        });
    }
}

/// A vector of `n` copies of `value`, reusing a pooled vector of the same element type if there
/// is one.
pub(crate) fn take<T: Copy + 'static>(n: usize, value: T) -> Pooled<T> {
    let reused = POOL
        .try_with(|pool| {
            let mut pool = pool.borrow_mut();
            let at = pool.iter().rposition(|b| b.is::<Vec<T>>())?;
            pool.swap_remove(at).downcast::<Vec<T>>().ok().map(|b| *b)
        })
        .ok()
        .flatten();
    let mut v = reused.unwrap_or_default();
    v.clear();
    v.resize(n, value);
    Pooled(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reused_vector_holds_what_a_fresh_one_would() {
        let mut v = take(5, 1.5f64);
        v[2] = 7.0;
        v.push(9.0);
        let ptr = v.as_ptr();
        drop(v);
        let w = take(3, 0.25f64);
        assert_eq!(*w, vec![0.25; 3]);
        assert_eq!(w.as_ptr(), ptr, "the pooled memory is reused");
        // Another element type does not take it.
        let u = take(2, [0u8; 3]);
        assert_eq!(*u, vec![[0u8; 3]; 2]);
        drop((w, u));
        let big = take(1000, 2.0f64);
        assert_eq!(big.len(), 1000);
        assert!(big.iter().all(|x| *x == 2.0));
    }
}
