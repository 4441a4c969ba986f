//! Responses: what of a simulation is compared with a test, reading by reading.

use crate::error::Result;
use crate::record::Record;
use serde::{Deserialize, Serialize};

/// An observable of a simulated test, predicted at the readings of a measurement.
///
/// A *curve* response (load against displacement, see [`ColumnResponse`]) interpolates its
/// simulated curve at each reading's abscissa. An *event* response is one value of the run, such
/// as the debonded length when the load peaks ([`AtPeak`]): its measurement is a single reading and
/// the abscissa is not used. Both feed the same residuals (see
/// [`crate::objective::scaled_residuals`]), so a new observable is a new implementation of this
/// trait and nothing else.
pub trait Response: Send + Sync + std::fmt::Debug {
    /// Short name used in reports, e.g. `"load"`.
    fn name(&self) -> &str;

    /// The simulated value for each reading abscissa in `at` (one value per reading).
    fn predict(&self, record: &Record, at: &[f64]) -> Result<Vec<f64>>;
}

/// A response that is one recorded column against another; where the run stops short of a
/// reading, its last value is held.
///
/// ```
/// # use czid_core::{ColumnResponse, Record, Response, columns};
/// let mut r = Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N")]);
/// r.push(&[0.0, 0.0]);
/// r.push(&[2.0, 8.0]);
/// let load = ColumnResponse::new(columns::DISPLACEMENT, columns::LOAD);
/// assert_eq!(load.predict(&r, &[1.0, 3.0]).unwrap(), vec![4.0, 8.0]);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ColumnResponse {
    /// Abscissa column.
    pub x: String,
    /// Ordinate column.
    pub y: String,
}

impl ColumnResponse {
    /// `y` against `x`.
    pub fn new(x: &str, y: &str) -> Self {
        ColumnResponse { x: x.to_string(), y: y.to_string() }
    }
}

impl Response for ColumnResponse {
    fn name(&self) -> &str {
        &self.y
    }

    fn predict(&self, record: &Record, at: &[f64]) -> Result<Vec<f64>> {
        Ok(record.curve(&self.x, &self.y)?.sample(at))
    }
}

/// An event response: the value of column `value` at the step where column `peak` is largest
/// (e.g. the debonded length at the peak load), the same for every reading.
///
/// ```
/// # use czid_core::{AtPeak, Record, Response, columns};
/// let mut r = Record::new(&[(columns::LOAD, "N"), (columns::DEBONDED_LENGTH, "mm")]);
/// r.push(&[10.0, 0.0]);
/// r.push(&[25.0, 4.0]);
/// r.push(&[20.0, 9.0]);
/// let length_at_peak = AtPeak::new(columns::DEBONDED_LENGTH, columns::LOAD);
/// assert_eq!(length_at_peak.predict(&r, &[f64::NAN]).unwrap(), vec![4.0]);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AtPeak {
    /// Column read.
    pub value: String,
    /// Column whose largest value marks the event.
    pub peak: String,
}

impl AtPeak {
    /// `value` where `peak` is largest.
    pub fn new(value: &str, peak: &str) -> Self {
        AtPeak { value: value.to_string(), peak: peak.to_string() }
    }
}

impl Response for AtPeak {
    fn name(&self) -> &str {
        &self.value
    }

    fn predict(&self, record: &Record, at: &[f64]) -> Result<Vec<f64>> {
        let (i, _) = crate::event::largest(record, &self.peak, &self.value)?;
        Ok(vec![record.column(&self.value)?[i]; at.len()])
    }
}
