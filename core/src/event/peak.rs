//! The peak load of a run.

use super::largest;
use crate::error::Result;
use crate::record::{columns, Record};
use crate::response::Response;
use serde::{Deserialize, Serialize};

/// The largest load of the run (N), the same for every reading.
///
/// The maximum over the recorded states: each state's load moves continuously with the
/// parameters, and so does their maximum (it has a kink where two states tie).
///
/// ```
/// # use czid_core::{event::PeakLoad, Record, Response, columns};
/// let mut r = Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N")]);
/// for (d, p) in [(0.0, 0.0), (1.0, 150.0), (2.0, 240.0), (3.0, 180.0)] {
///     r.push(&[d, p]);
/// }
/// assert_eq!(PeakLoad.predict(&r, &[f64::NAN]).unwrap(), vec![240.0]);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PeakLoad;

impl Response for PeakLoad {
    fn name(&self) -> &str {
        "peak_load"
    }

    fn predict(&self, record: &Record, at: &[f64]) -> Result<Vec<f64>> {
        let (_, peak) = largest(record, columns::LOAD, self.name())?;
        Ok(vec![peak; at.len()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_loads_are_skipped_and_a_run_without_any_is_an_error() {
        let mut r = Record::new(&[(columns::LOAD, "N")]);
        r.push(&[f64::NAN]);
        assert!(PeakLoad.predict(&r, &[0.0]).unwrap_err().to_string().contains("no finite `load`"));
        r.push(&[3.0]);
        assert_eq!(PeakLoad.predict(&r, &[0.0, 1.0]).unwrap(), vec![3.0, 3.0]);
    }
}
