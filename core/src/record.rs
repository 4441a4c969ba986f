//! What a simulation records per converged step: named columns with units.

use crate::curve::Curve;
use crate::error::{CzError, Result};
use serde::{Deserialize, Serialize};

/// Standard column names every DCB/ENF/beam forward model records.
pub mod columns {
    /// Applied (control) displacement, mm. For a DCB: the load-line opening.
    pub const DISPLACEMENT: &str = "displacement";
    /// Reaction load at the control point, N.
    pub const LOAD: &str = "load";
    /// Total interface length with damage D ≥ threshold (fully debonded), mm.
    pub const DEBONDED_LENGTH: &str = "debonded_length";
    /// Interface length with 0 < D < threshold (the process zone), mm.
    pub const PROCESS_ZONE_LENGTH: &str = "process_zone_length";
    /// Crack-tip position (farthest fully debonded point from the load line), mm.
    pub const CRACK_TIP: &str = "crack_tip";
    /// Work done by the applied load, N·mm.
    pub const EXTERNAL_WORK: &str = "external_work";
    /// Recoverable strain energy (adherends and interface), N·mm.
    pub const ELASTIC_ENERGY: &str = "elastic_energy";
    /// Energy dissipated by the interface, N·mm.
    pub const DISSIPATED_ENERGY: &str = "dissipated_energy";
}

/// One named quantity over the converged steps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Column {
    /// Name (see [`columns`]).
    pub name: String,
    /// Unit, e.g. `"N"`.
    pub unit: String,
    /// One value per converged step.
    pub values: Vec<f64>,
}

/// A table of named columns, one row per converged step.
///
/// ```
/// # use czid_core::{Record, columns};
/// let mut r = Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N")]);
/// r.push(&[0.0, 0.0]);
/// r.push(&[1.0, 12.5]);
/// assert_eq!(r.column(columns::LOAD).unwrap(), &[0.0, 12.5]);
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Record {
    columns: Vec<Column>,
}

impl Record {
    /// An empty record with the given `(name, unit)` columns.
    pub fn new(spec: &[(&str, &str)]) -> Self {
        Record {
            columns: spec
                .iter()
                .map(|(n, u)| Column { name: n.to_string(), unit: u.to_string(), values: Vec::new() })
                .collect(),
        }
    }

    /// Appends one row; `row` follows the column order given to [`Record::new`].
    pub fn push(&mut self, row: &[f64]) {
        debug_assert_eq!(row.len(), self.columns.len(), "row length must match the number of columns");
        for (c, v) in self.columns.iter_mut().zip(row) {
            c.values.push(*v);
        }
    }

    /// Keeps the first `rows` rows.
    pub fn truncate(&mut self, rows: usize) {
        for c in &mut self.columns {
            c.values.truncate(rows);
        }
    }

    /// Number of rows (converged steps).
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |c| c.values.len())
    }

    /// All columns.
    pub fn columns(&self) -> &[Column] {
        &self.columns
    }

    /// Values of a column, or an error listing the columns that exist.
    pub fn column(&self, name: &str) -> Result<&[f64]> {
        self.columns.iter().find(|c| c.name == name).map(|c| c.values.as_slice()).ok_or_else(|| {
            let names: Vec<&str> = self.columns.iter().map(|c| c.name.as_str()).collect();
            CzError::data("simulation record", format!("no column `{name}`; it has {}", names.join(", ")))
        })
    }

    /// Unit of a column.
    pub fn unit(&self, name: &str) -> Option<&str> {
        self.columns.iter().find(|c| c.name == name).map(|c| c.unit.as_str())
    }

    /// `y` against `x` as a [`Curve`] (snap-back parts dropped, see [`Curve::from_path`]).
    pub fn curve(&self, x: &str, y: &str) -> Result<Curve> {
        Curve::from_path(self.column(x)?, self.column(y)?)
    }
}
