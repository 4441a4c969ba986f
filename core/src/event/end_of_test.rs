//! The debonded length at the end of the test.

use super::first_reaching;
use crate::error::{CzError, Result};
use crate::record::{columns, Record};
use crate::response::Response;
use serde::{Deserialize, Serialize};

/// The debonded length (mm) at the end of the test: where the displacement first reaches the
/// test's last reading `at` (mm), linearly interpolated between the two states around it; without
/// `at`, or if the run ends before reaching it, at the run's last state.
///
/// **Why at the test's last displacement.** A test stops at some displacement, often before the
/// plate has come off entirely (the paper's beam: 1048 mm of the 1900 mm half plate), while a run
/// goes on to complete debonding; the run's state comparable with the test's end is the one at the
/// same displacement (for the FRP beam, the mid-span deflection). Where the debonded zone grows
/// with the displacement (a plateau of the load) this moves continuously with the parameters;
/// inside a burst of unstable debonding, where the displacement hardly changes while the length
/// runs, it is sensitive to the displacement read.
///
/// ```
/// # use czid_core::{event::EndOfTest, Record, Response, columns};
/// let mut r = Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::DEBONDED_LENGTH, "mm")]);
/// for (d, l) in [(0.0, 0.0), (20.0, 400.0), (24.0, 1000.0), (25.0, 1800.0)] {
///     r.push(&[d, l]);
/// }
/// let end = EndOfTest::at(22.0).unwrap();
/// assert_eq!(end.predict(&r, &[f64::NAN]).unwrap(), vec![700.0]);
/// assert_eq!(EndOfTest::default().predict(&r, &[0.0]).unwrap(), vec![1800.0]);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EndOfTest {
    /// The test's last displacement reading (mm); `None`: the run's last state.
    pub at: Option<f64>,
}

impl EndOfTest {
    /// The debonded length where the displacement first reaches `at` (mm, finite).
    pub fn at(at: f64) -> Result<Self> {
        if !at.is_finite() {
            return Err(CzError::invalid("debonded_length_at_end", "at", at, "must be a finite displacement (mm)"));
        }
        Ok(EndOfTest { at: Some(at) })
    }
}

impl Response for EndOfTest {
    fn name(&self) -> &str {
        "debonded_length_at_end"
    }

    fn predict(&self, record: &Record, at: &[f64]) -> Result<Vec<f64>> {
        let l = record.column(columns::DEBONDED_LENGTH)?;
        let last = *l.last().ok_or_else(|| CzError::data("response `debonded_length_at_end`", "the run is empty"))?;
        let value = match self.at {
            Some(x) => first_reaching(record.column(columns::DISPLACEMENT)?, x, l).unwrap_or(last),
            None => last,
        };
        Ok(vec![value; at.len()])
    }
}
