//! The displacement at which the load first reaches a given value.

use super::{first_reaching, largest};
use crate::error::{CzError, Result};
use crate::record::{columns, Record};
use crate::response::Response;
use serde::{Deserialize, Serialize};

/// The displacement (mm) at which the load first reaches `load` (N): on the rising branch, the
/// first crossing, linearly interpolated between the two states around it. A run whose load
/// never reaches `load` gives the displacement at its peak load (the nearest it comes), so an
/// objective stays finite and grows as the run falls short.
///
/// For the FRP beam this is the mid-span deflection at a load, e.g. at the service load or at
/// the yield of the bars read off a test curve.
///
/// ```
/// # use czid_core::{event::DisplacementAtLoad, Record, Response, columns};
/// let mut r = Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N")]);
/// for (d, p) in [(0.0, 0.0), (2.0, 100.0), (4.0, 300.0), (5.0, 200.0)] {
///     r.push(&[d, p]);
/// }
/// // 200 N is first reached halfway between 100 N (2 mm) and 300 N (4 mm).
/// let at_200 = DisplacementAtLoad::new(200.0).unwrap();
/// assert_eq!(at_200.predict(&r, &[f64::NAN]).unwrap(), vec![3.0]);
/// // 400 N is never reached: the displacement at the peak.
/// assert_eq!(DisplacementAtLoad::new(400.0).unwrap().predict(&r, &[0.0]).unwrap(), vec![4.0]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DisplacementAtLoad {
    /// The load (N).
    pub load: f64,
}

impl DisplacementAtLoad {
    /// The displacement at `load` (N, finite and positive).
    pub fn new(load: f64) -> Result<Self> {
        if !(load.is_finite() && load > 0.0) {
            return Err(CzError::invalid("displacement_at_load", "load", load, "must be a positive load (N)"));
        }
        Ok(DisplacementAtLoad { load })
    }
}

impl Response for DisplacementAtLoad {
    fn name(&self) -> &str {
        "displacement_at_load"
    }

    fn predict(&self, record: &Record, at: &[f64]) -> Result<Vec<f64>> {
        let (p, d) = (record.column(columns::LOAD)?, record.column(columns::DISPLACEMENT)?);
        let value = match first_reaching(p, self.load, d) {
            Some(v) => v,
            None => d[largest(record, columns::LOAD, self.name())?.0],
        };
        Ok(vec![value; at.len()])
    }
}
