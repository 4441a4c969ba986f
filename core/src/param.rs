//! Parameter spaces: what an optimizer varies, in physical units, and how it maps onto a
//! configured law or forward model.
//!
//! Each [`Parameter`] names a *path* into the serialised configuration (`law.strength_n`,
//! `model.a0`, ...), so any law or model that implements `serde` can be identified without code
//! of its own. Optimizers see the unit cube `[0, 1]^n`; [`ParameterSpace::from_unit`] maps it
//! to physical values, linearly or logarithmically per parameter.

use crate::error::{CzError, Result};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// How a parameter is spread over its bounds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scale {
    /// Uniform in the value.
    #[default]
    Linear,
    /// Uniform in the logarithm (for quantities spanning decades, e.g. penalty stiffness).
    Log,
}

/// Most decades a log-scaled parameter may span (physical parameters of a law or a test are known
/// far better than that).
const MAX_DECADES: f64 = 12.0;

/// One identified parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parameter {
    /// Dotted path into the configuration, e.g. `"law.strength_n"` or `"model.a0"`.
    pub path: String,
    /// Physical unit, e.g. `"MPa"`.
    pub unit: String,
    /// Lower bound (physical units).
    pub lower: f64,
    /// Upper bound (physical units).
    pub upper: f64,
    /// Spread over the bounds.
    #[serde(default)]
    pub scale: Scale,
}

impl Parameter {
    /// A linearly scaled parameter.
    pub fn new(path: &str, unit: &str, lower: f64, upper: f64) -> Self {
        Parameter { path: path.into(), unit: unit.into(), lower, upper, scale: Scale::Linear }
    }

    /// The same parameter spread logarithmically.
    pub fn log(mut self) -> Self {
        self.scale = Scale::Log;
        self
    }

    fn check(&self) -> Result<()> {
        let owner = format!("parameter `{}`", self.path);
        if self.path.is_empty() {
            return Err(CzError::config("parameters", "a parameter has an empty path"));
        }
        for (name, v) in [("lower", self.lower), ("upper", self.upper)] {
            if !v.is_finite() {
                return Err(CzError::invalid(&owner, name, v, "bounds must be finite numbers"));
            }
        }
        if self.lower >= self.upper {
            return Err(CzError::invalid(
                &owner,
                "lower",
                self.lower,
                format!("lower bound must be below the upper bound {} (are they inverted?)", self.upper),
            ));
        }
        if self.scale == Scale::Log {
            if self.lower <= 0.0 {
                return Err(CzError::invalid(&owner, "lower", self.lower, "log scale needs a positive lower bound"));
            }
            // A subnormal bound, or bounds many decades apart, are typos (a missing exponent
            // digit), and the search would spend most of its effort on physically absurd values.
            if self.lower < f64::MIN_POSITIVE {
                return Err(CzError::invalid(
                    &owner,
                    "lower",
                    self.lower,
                    "is below the smallest normal number; give a physically meaningful positive bound",
                ));
            }
            let decades = (self.upper / self.lower).log10();
            if decades > MAX_DECADES {
                return Err(CzError::invalid(
                    &owner,
                    "lower",
                    self.lower,
                    format!(
                        "the bounds span {decades:.0} decades (more than {MAX_DECADES:.0}) up to {}: is an exponent mistyped?",
                        self.upper
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Physical value for a unit-interval coordinate `u` (clamped to [0, 1]).
    pub fn from_unit(&self, u: f64) -> f64 {
        let u = u.clamp(0.0, 1.0);
        match self.scale {
            Scale::Linear => self.lower + u * (self.upper - self.lower),
            Scale::Log => (self.lower.ln() + u * (self.upper.ln() - self.lower.ln())).exp(),
        }
    }

    /// Unit-interval coordinate of a physical value (not clamped).
    pub fn to_unit(&self, v: f64) -> f64 {
        match self.scale {
            Scale::Linear => (v - self.lower) / (self.upper - self.lower),
            Scale::Log => (v.ln() - self.lower.ln()) / (self.upper.ln() - self.lower.ln()),
        }
    }

    /// Whether `v` lies within the bounds.
    pub fn contains(&self, v: f64) -> bool {
        v >= self.lower && v <= self.upper
    }
}

/// An ordered set of [`Parameter`]s.
///
/// ```
/// # use czid_core::{Parameter, ParameterSpace};
/// # use serde::{Serialize, Deserialize};
/// #[derive(Serialize, Deserialize)]
/// struct Setup { law: Law }
/// #[derive(Serialize, Deserialize)]
/// struct Law { strength: f64, stiffness: f64 }
///
/// let space = ParameterSpace::new(vec![
///     Parameter::new("law.strength", "MPa", 10.0, 50.0),
///     Parameter::new("law.stiffness", "MPa/mm", 1e4, 1e6).log(),
/// ]).unwrap();
/// let base = Setup { law: Law { strength: 30.0, stiffness: 1e5 } };
/// let x = space.from_unit(&[0.5, 0.5]);
/// assert_eq!(x[0], 30.0);
/// assert!((x[1] - 1e5).abs() < 1e-6);
/// let s: Setup = space.apply(&base, &[20.0, 2e5]).unwrap();
/// assert_eq!((s.law.strength, s.law.stiffness), (20.0, 2e5));
/// assert_eq!(space.read(&s).unwrap(), vec![20.0, 2e5]);
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct ParameterSpace {
    params: Vec<Parameter>,
}

impl ParameterSpace {
    /// Checks bounds (finite, not inverted, positive for log scale) and that no path repeats.
    pub fn new(params: Vec<Parameter>) -> Result<Self> {
        for (i, p) in params.iter().enumerate() {
            p.check()?;
            if params[..i].iter().any(|q| q.path == p.path) {
                return Err(CzError::config("parameters", format!("`{}` is listed twice", p.path)));
            }
        }
        Ok(ParameterSpace { params })
    }

    /// The parameters.
    pub fn parameters(&self) -> &[Parameter] {
        &self.params
    }

    /// Number of parameters.
    pub fn dim(&self) -> usize {
        self.params.len()
    }

    /// Physical values of a unit-cube point.
    pub fn from_unit(&self, u: &[f64]) -> Vec<f64> {
        self.params.iter().zip(u).map(|(p, &v)| p.from_unit(v)).collect()
    }

    /// Unit-cube coordinates of physical values.
    pub fn to_unit(&self, x: &[f64]) -> Vec<f64> {
        self.params.iter().zip(x).map(|(p, &v)| p.to_unit(v)).collect()
    }

    /// Errors if a physical value lies outside its bounds (e.g. an initial guess).
    pub fn check_within(&self, x: &[f64]) -> Result<()> {
        for (p, &v) in self.params.iter().zip(x) {
            if !p.contains(v) {
                return Err(CzError::invalid(
                    format!("parameter `{}`", p.path),
                    "initial value",
                    v,
                    format!("must lie within its bounds [{}, {}] {}", p.lower, p.upper, p.unit),
                ));
            }
        }
        Ok(())
    }

    /// A copy of `base` with each parameter's path set to the physical value in `x`. A path that
    /// leads to a boolean (a switch) is set on for values of 0.5 and more, off below.
    pub fn apply<T: Serialize + DeserializeOwned>(&self, base: &T, x: &[f64]) -> Result<T> {
        if x.len() != self.params.len() {
            return Err(CzError::config(
                "parameters",
                format!("{} values for {} parameters", x.len(), self.params.len()),
            ));
        }
        let mut tree = serde_json::to_value(base).map_err(|e| CzError::config("parameters", e.to_string()))?;
        for (p, &v) in self.params.iter().zip(x) {
            let number = serde_json::Number::from_f64(v)
                .map(Value::Number)
                .ok_or_else(|| CzError::invalid(format!("parameter `{}`", p.path), "value", v, "must be finite"))?;
            for slot in lookup(&mut tree, &p.path)? {
                *slot = if slot.is_boolean() { Value::Bool(v >= 0.5) } else { number.clone() };
            }
        }
        serde_json::from_value(tree).map_err(|e| CzError::config("parameters", e.to_string()))
    }

    /// The current physical values of the parameters in `config` (a switch reads 1 when on, 0 when
    /// off).
    pub fn read<T: Serialize>(&self, config: &T) -> Result<Vec<f64>> {
        let mut tree = serde_json::to_value(config).map_err(|e| CzError::config("parameters", e.to_string()))?;
        self.params
            .iter()
            .map(|p| {
                let owner = || format!("parameter `{}`", p.path);
                let values = lookup(&mut tree, &p.path)?
                    .into_iter()
                    .map(|v| {
                        v.as_f64()
                            .or_else(|| v.as_bool().map(f64::from))
                            .ok_or_else(|| CzError::config(owner(), "path does not lead to a number"))
                    })
                    .collect::<Result<Vec<f64>>>()?;
                // A wildcard ties several values to one parameter: they must start equal.
                if values.iter().any(|v| *v != values[0]) {
                    return Err(CzError::config(
                        owner(),
                        format!("the values it ties together differ ({values:?}); make them equal in the file"),
                    ));
                }
                Ok(values[0])
            })
            .collect()
    }
}

/// A deep copy of a configuration through its serde tree: the one way czid copies laws and models,
/// which are trait objects (`Box<dyn CohesiveLaw>`, `Box<dyn ForwardModel>`) with no `Clone`.
/// `owner` names what was copied in an error.
///
/// ```
/// # use czid_core::param::duplicate;
/// let v: Vec<f64> = duplicate(&vec![1.0, 2.0], "values").unwrap();
/// assert_eq!(v, [1.0, 2.0]);
/// ```
pub fn duplicate<T: Serialize + DeserializeOwned>(value: &T, owner: &str) -> Result<T> {
    let tree = serde_json::to_value(value).map_err(|e| CzError::config(owner, e.to_string()))?;
    serde_json::from_value(tree).map_err(|e| CzError::config(owner, e.to_string()))
}

/// The values at a dotted path; a `*` segment matches every key of a table (e.g.
/// `models.*.material.e11` ties one parameter to every experiment's modulus). Errors list the keys
/// available where the path breaks.
fn lookup<'a>(tree: &'a mut Value, path: &str) -> Result<Vec<&'a mut Value>> {
    let mut nodes = vec![tree];
    let mut walked = String::new();
    for key in path.split('.') {
        let here = if walked.is_empty() { "the configuration".to_string() } else { format!("`{walked}`") };
        let mut next = Vec::new();
        for node in nodes {
            let Value::Object(map) = node else {
                return Err(CzError::config(format!("parameter `{path}`"), format!("{here} is not a table")));
            };
            if key == "*" {
                next.extend(map.values_mut());
            } else {
                let keys: Vec<String> = map.keys().cloned().collect();
                next.push(map.get_mut(key).ok_or_else(|| {
                    CzError::config(
                        format!("parameter `{path}`"),
                        format!("{here} has no key `{key}`; it has: {}", keys.join(", ")),
                    )
                })?);
            }
        }
        if next.is_empty() {
            return Err(CzError::config(format!("parameter `{path}`"), format!("`*` matches nothing in {here}")));
        }
        nodes = next;
        if !walked.is_empty() {
            walked.push('.');
        }
        walked.push_str(key);
    }
    Ok(nodes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_switch_is_a_parameter_that_is_one_when_on() {
        #[derive(Serialize, Deserialize)]
        struct Model {
            large: bool,
        }
        let space = ParameterSpace::new(vec![Parameter::new("large", "on/off", 0.0, 1.0)]).unwrap();
        let on: Model = space.apply(&Model { large: false }, &[1.0]).unwrap();
        assert!(on.large);
        assert_eq!(space.read(&on).unwrap(), vec![1.0]);
        let off: Model = space.apply(&on, &[0.2]).unwrap();
        assert_eq!(space.read(&off).unwrap(), vec![0.0]);
    }

    #[test]
    fn absurd_bounds_are_refused_with_the_bound_named() {
        let err = |p: Parameter| ParameterSpace::new(vec![p]).unwrap_err().to_string();
        let e = err(Parameter::new("law.u", "mm", 0.0, f64::INFINITY));
        assert!(e.contains("upper") && e.contains("inf"), "{e}");
        let e = err(Parameter::new("law.u", "mm", 5e-324, 0.01).log());
        assert!(e.contains("smallest normal"), "{e}");
        let e = err(Parameter::new("law.u", "mm", 1e-20, 0.01).log());
        assert!(e.contains("18 decades"), "{e}");
        // Realistic log ranges pass (a penalty stiffness over four decades).
        assert!(ParameterSpace::new(vec![Parameter::new("law.k", "MPa/mm", 1e3, 1e7).log()]).is_ok());
    }

    #[test]
    fn inverted_bounds_are_reported() {
        let e = ParameterSpace::new(vec![Parameter::new("law.a", "mm", 2.0, 1.0)]).unwrap_err();
        assert!(e.to_string().contains("inverted"), "{e}");
    }

    #[test]
    fn log_scale_round_trips() {
        let p = Parameter::new("k", "MPa/mm", 1e3, 1e7).log();
        assert!((p.from_unit(0.5) - 1e5).abs() < 1e-6);
        assert!((p.to_unit(1e5) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn wildcard_ties_one_parameter_to_several_values() {
        #[derive(Debug, Serialize, Deserialize, PartialEq)]
        struct M {
            e: f64,
        }
        #[derive(Debug, Serialize, Deserialize, PartialEq)]
        struct S {
            models: std::collections::BTreeMap<String, M>,
        }
        let base = S { models: [("a".into(), M { e: 1.0 }), ("b".into(), M { e: 1.0 })].into() };
        let space = ParameterSpace::new(vec![Parameter::new("models.*.e", "MPa", 0.0, 10.0)]).unwrap();
        assert_eq!(space.read(&base).unwrap(), vec![1.0]);
        let s = space.apply(&base, &[3.0]).unwrap();
        assert!(s.models.values().all(|m| m.e == 3.0));
        let uneven = S { models: [("a".into(), M { e: 1.0 }), ("b".into(), M { e: 2.0 })].into() };
        assert!(space.read(&uneven).unwrap_err().to_string().contains("differ"));
    }

    #[test]
    fn unknown_path_lists_available_keys() {
        #[derive(Debug, Serialize, Deserialize)]
        struct S {
            alpha: f64,
        }
        let space = ParameterSpace::new(vec![Parameter::new("beta", "-", 0.0, 1.0)]).unwrap();
        let e = space.apply(&S { alpha: 1.0 }, &[0.5]).unwrap_err().to_string();
        assert!(e.contains("no key `beta`") && e.contains("alpha"), "{e}");
    }
}
