//! Event responses: one value of a run (the peak load, the debonded length at the onset of
//! local debonding or at the end of the test, the displacement at a given load), compared with
//! one measured value.
//!
//! Each is a [`Response`](crate::Response) whose prediction is the same value for every reading
//! (an event's measurement is a single reading; its abscissa is not used), so it enters the
//! [composite objective](crate::objective) as a term like a curve: `φ = (y − ŷ)/|y|`, weighted by
//! its α. Each event is located between two recorded states by linear interpolation, so it moves
//! continuously with the run's states (and, where they do, with the parameters) rather than
//! jumping from one recorded state to the next.

mod at_load;
mod end_of_test;
mod onset;
mod peak;

pub use at_load::DisplacementAtLoad;
pub use end_of_test::EndOfTest;
pub use onset::OnsetOfDebonding;
pub use peak::PeakLoad;

use crate::error::{CzError, Result};
use crate::record::Record;

/// `value` at the first state where `level_of` reaches `level`, linearly interpolated between
/// that state and the one before it; `None` if it never does. At the first state, its value.
pub(crate) fn first_reaching(level_of: &[f64], level: f64, value: &[f64]) -> Option<f64> {
    let i = level_of.iter().position(|&c| c >= level)?;
    if i == 0 {
        return Some(value[0]);
    }
    let (c0, c1) = (level_of[i - 1], level_of[i]);
    let t = if c1 > c0 { (level - c0) / (c1 - c0) } else { 1.0 };
    Some(value[i - 1] + t * (value[i] - value[i - 1]))
}

/// The largest finite value of a column and its row.
pub(crate) fn largest(record: &Record, column: &str, owner: &str) -> Result<(usize, f64)> {
    let c = record.column(column)?;
    (0..c.len())
        .filter(|&i| c[i].is_finite())
        .max_by(|&a, &b| c[a].total_cmp(&c[b]))
        .map(|i| (i, c[i]))
        .ok_or_else(|| CzError::data(format!("response `{owner}`"), format!("no finite `{column}` in the run")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_reaching_interpolates_between_the_states_around_the_level() {
        let c = [0.0, 10.0, 30.0, 20.0, 40.0];
        let v = [0.0, 1.0, 2.0, 3.0, 4.0];
        // 20 is first reached between the second and third states, halfway.
        assert_eq!(first_reaching(&c, 20.0, &v), Some(1.5));
        assert_eq!(first_reaching(&c, 0.0, &v), Some(0.0));
        assert_eq!(first_reaching(&c, 41.0, &v), None);
    }
}
