//! The composite objective of Shi & Zhang (Eq. 14–18), over any set of responses.
//!
//! For each term i with experimental points `(x_k, y_k)` and simulated curve `ŷ_i(x)`:
//!
//! ```text
//! φ_i = (y − ŷ_i(x)) / ||y||          (normalised residual vector, simulation interpolated at x)
//! f   = Σ_i α_i ||φ_i||²
//! ```
//!
//! With the load and the debonded length as the two terms this is the paper's
//! `f = α_F ||φ_F||² + α_L ||φ_L||²`. Where the simulation stops short of an experimental
//! abscissa its last value is held, so a run that ends early is penalised smoothly rather than
//! rejected.

use crate::curve::Curve;
use crate::error::{CzError, Result};
use crate::record::Record;
use crate::response::Response;

/// One response compared with one experimental curve.
#[derive(Debug)]
pub struct ObjectiveTerm {
    /// Name in reports (e.g. `"F"` for load, `"L"` for debonded length).
    pub name: String,
    /// The simulated response.
    pub response: Box<dyn Response>,
    /// The experimental curve.
    pub data: Curve,
    /// Weight α (non-negative).
    pub weight: f64,
}

/// Value of the composite objective and its parts.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectiveValue {
    /// `f = Σ α_i ||φ_i||²`.
    pub value: f64,
    /// Unweighted `||φ_i||²` per term, in term order.
    pub terms: Vec<f64>,
}

/// `f(x) = Σ α_i ||φ_i||²` over a set of [`ObjectiveTerm`]s.
#[derive(Debug)]
pub struct CompositeObjective {
    terms: Vec<ObjectiveTerm>,
}

impl CompositeObjective {
    /// Checks that weights are finite and non-negative and that no experimental curve is all zero
    /// (its norm normalises the residual).
    pub fn new(terms: Vec<ObjectiveTerm>) -> Result<Self> {
        if terms.is_empty() {
            return Err(CzError::config("objective", "at least one response must be compared"));
        }
        for t in &terms {
            if !t.weight.is_finite() || t.weight < 0.0 {
                return Err(CzError::invalid(
                    "objective",
                    format!("weight of `{}`", t.name),
                    t.weight,
                    "must be finite and ≥ 0",
                ));
            }
            if t.data.norm() == 0.0 {
                return Err(CzError::data(format!("objective term `{}`", t.name), "experimental values are all zero"));
            }
        }
        Ok(CompositeObjective { terms })
    }

    /// The terms.
    pub fn terms(&self) -> &[ObjectiveTerm] {
        &self.terms
    }

    /// The weights α, in term order.
    pub fn weights(&self) -> Vec<f64> {
        self.terms.iter().map(|t| t.weight).collect()
    }

    /// Sets the weights α (same order as the terms).
    pub fn set_weights(&mut self, weights: &[f64]) -> Result<()> {
        if weights.len() != self.terms.len() {
            return Err(CzError::config(
                "objective",
                format!("{} weights for {} terms", weights.len(), self.terms.len()),
            ));
        }
        for (t, &w) in self.terms.iter_mut().zip(weights) {
            if !w.is_finite() || w < 0.0 {
                return Err(CzError::invalid(
                    "objective",
                    format!("weight of `{}`", t.name),
                    w,
                    "must be finite and ≥ 0",
                ));
            }
            t.weight = w;
        }
        Ok(())
    }

    /// Normalised residual vectors φ_i, one per term.
    pub fn term_residuals(&self, record: &Record) -> Result<Vec<Vec<f64>>> {
        self.terms
            .iter()
            .map(|t| scaled_residuals(t.response.as_ref(), record, t.data.x(), t.data.y(), t.data.norm()))
            .collect()
    }

    /// The weighted residual vector `r = [√α_1 φ_1, √α_2 φ_2, ...]`, so that `f = ||r||²`
    /// (what least-squares methods and sensitivity analyses work on).
    pub fn residuals(&self, record: &Record) -> Result<Vec<f64>> {
        let phis = self.term_residuals(record)?;
        Ok(self.terms.iter().zip(phis).flat_map(|(t, phi)| phi.into_iter().map(move |p| t.weight.sqrt() * p)).collect())
    }

    /// `f` and its unweighted parts for a simulation record.
    pub fn evaluate(&self, record: &Record) -> Result<ObjectiveValue> {
        let phis = self.term_residuals(record)?;
        let terms: Vec<f64> = phis.iter().map(|p| p.iter().map(|v| v * v).sum()).collect();
        let value = self.terms.iter().zip(&terms).map(|(t, s)| t.weight * s).sum();
        Ok(ObjectiveValue { value, terms })
    }

    /// Chooses α so that every term contributes equally at `record` (the initial guess) and
    /// `f = 1` there: α_i = 1 / (m ||φ_i||²), m the number of terms with a misfit. Terms that
    /// already fit exactly keep α_i = 1.
    pub fn balance_at(&mut self, record: &Record) -> Result<()> {
        let weights = balanced_weights(&self.evaluate(record)?.terms);
        self.set_weights(&weights)
    }
}

/// The residuals of a measurement: `(y_k − ŷ(x_k)) / scale` for each reading `(x_k, y_k)`, `ŷ` the
/// simulated response. The one residual builder: identification scales by the data's norm
/// (`||y||`, Eq. 17), the diagnosis by the noise σ of the measurement.
pub fn scaled_residuals(
    response: &dyn Response,
    record: &Record,
    x: &[f64],
    y: &[f64],
    scale: f64,
) -> Result<Vec<f64>> {
    let model = response.predict(record, x)?;
    Ok(y.iter().zip(&model).map(|(y, m)| (y - m) / scale).collect())
}

/// The weights that make every term contribute equally and the objective 1, from the terms'
/// unweighted values `||φ_i||²` (of one objective or of several side by side): α_i = 1 / (m
/// ||φ_i||²), m the number of terms with a misfit. Terms that already fit exactly keep α_i = 1
/// and do not count.
pub fn balanced_weights(parts: &[f64]) -> Vec<f64> {
    let m = parts.iter().filter(|&&s| s > 0.0).count().max(1) as f64;
    parts.iter().map(|&s| if s > 0.0 { 1.0 / (m * s) } else { 1.0 }).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::columns::*;
    use crate::response::ColumnResponse;

    fn record() -> Record {
        let mut r = Record::new(&[(DISPLACEMENT, "mm"), (LOAD, "N"), (DEBONDED_LENGTH, "mm")]);
        for i in 0..=10 {
            let d = i as f64;
            r.push(&[d, 2.0 * d, (d - 5.0).max(0.0)]);
        }
        r
    }

    fn term(name: &str, y: &str, data: Curve, weight: f64) -> ObjectiveTerm {
        ObjectiveTerm { name: name.into(), response: Box::new(ColumnResponse::new(DISPLACEMENT, y)), data, weight }
    }

    #[test]
    fn matches_hand_computed_value() {
        // Experiment: F = 2d + 1 at d = 1, 2; L = 1 at d = 6, 0 at d = 7 (model 1 and 2).
        let f_exp = Curve::new(vec![1.0, 2.0], vec![3.0, 5.0]).unwrap();
        let l_exp = Curve::new(vec![6.0, 7.0], vec![1.0, 0.0]).unwrap();
        let obj =
            CompositeObjective::new(vec![term("F", LOAD, f_exp, 2.0), term("L", DEBONDED_LENGTH, l_exp, 0.5)]).unwrap();
        let v = obj.evaluate(&record()).unwrap();
        // φ_F = [1, 1]/√34 → ||φ_F||² = 2/34; φ_L = [0, -2]/1 → 4.
        assert!((v.terms[0] - 2.0 / 34.0).abs() < 1e-15);
        assert!((v.terms[1] - 4.0).abs() < 1e-15);
        assert!((v.value - (2.0 * 2.0 / 34.0 + 0.5 * 4.0)).abs() < 1e-15);
        let r = obj.residuals(&record()).unwrap();
        let sq: f64 = r.iter().map(|x| x * x).sum();
        assert!((sq - v.value).abs() < 1e-14);
    }

    #[test]
    fn balancing_makes_terms_equal_and_value_one() {
        let f_exp = Curve::new(vec![1.0, 2.0], vec![3.0, 5.0]).unwrap();
        let l_exp = Curve::new(vec![6.0, 7.0], vec![1.0, 0.0]).unwrap();
        let mut obj =
            CompositeObjective::new(vec![term("F", LOAD, f_exp, 1.0), term("L", DEBONDED_LENGTH, l_exp, 1.0)]).unwrap();
        obj.balance_at(&record()).unwrap();
        let v = obj.evaluate(&record()).unwrap();
        assert!((v.value - 1.0).abs() < 1e-14);
        let w = obj.weights();
        assert!((w[0] * v.terms[0] - w[1] * v.terms[1]).abs() < 1e-14);
    }

    #[test]
    fn negative_weight_is_named() {
        let f_exp = Curve::new(vec![1.0], vec![3.0]).unwrap();
        let e = CompositeObjective::new(vec![term("F", LOAD, f_exp, -1.0)]).unwrap_err();
        assert!(e.to_string().contains("weight of `F`"), "{e}");
    }
}
