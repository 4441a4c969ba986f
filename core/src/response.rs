//! Responses: the curves of a simulation that are compared with a test.

use crate::curve::Curve;
use crate::error::Result;
use crate::record::Record;
use serde::{Deserialize, Serialize};

/// An observable of a simulated test as a curve over the control variable.
///
/// Implement it for derived quantities (e.g. compliance, or crack length measured from a
/// different origin); most responses are plain columns, see [`ColumnResponse`].
pub trait Response: Send + Sync + std::fmt::Debug {
    /// Short name used in reports, e.g. `"load"`.
    fn name(&self) -> &str;
    /// The simulated curve.
    fn curve(&self, record: &Record) -> Result<Curve>;
}

/// A response that is one recorded column against another.
///
/// ```
/// # use czid_core::{ColumnResponse, Record, Response, columns};
/// let mut r = Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N")]);
/// r.push(&[0.0, 0.0]);
/// r.push(&[2.0, 8.0]);
/// let load = ColumnResponse::new(columns::DISPLACEMENT, columns::LOAD);
/// assert_eq!(load.curve(&r).unwrap().at(1.0), 4.0);
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

    fn curve(&self, record: &Record) -> Result<Curve> {
        record.curve(&self.x, &self.y)
    }
}
