//! Optimizers by name and TOML settings, for problem files:
//! `optimizer = { type = "miga", islands = 8 }`.
//!
//! [`REGISTRY`] is the one list of methods: a name, its aliases and a constructor that says
//! what kind of method it builds. A [`Method::Local`] starts from a given point (an
//! identification starts it from the problem's initial values); a [`Method::Global`] samples
//! the bounds from its seed. A local method can only be registered as local if it implements
//! [`LocalOptimizer`], so none can silently start from the box centre instead of the initial
//! values.

use crate::ga::{ga, GaSettings};
use crate::hybrid::{Hybrid, HybridSettings};
use crate::local::{GaussNewton, Lbfgs, LevenbergMarquardt, LocalOptimizer, LocalSettings, NelderMead};
use crate::miga::{Miga, MigaSettings};
use crate::nsga2::{Nsga2, Nsga2Settings};
use czid_core::{CzError, Optimizer, Result};
use serde::de::DeserializeOwned;

/// A registered method, built from its settings.
pub enum Method {
    /// Searches the bounds from its seed (population methods, hybrids).
    Global(Box<dyn Optimizer + Send + Sync>),
    /// Polishes from a given starting point (an identification gives it the initial values).
    Local(Box<dyn LocalOptimizer + Send + Sync>),
}

impl Method {
    /// The method as a plain optimizer (a local one then starts from its `start` setting, or the
    /// box centre).
    pub fn into_optimizer(self) -> Box<dyn Optimizer + Send + Sync> {
        match self {
            Method::Global(g) => g,
            Method::Local(l) => l,
        }
    }

    /// Whether it starts from the problem's initial values rather than sampling the bounds.
    pub fn starts_from_initial(&self) -> bool {
        matches!(self, Method::Local(_))
    }
}

/// One entry of the registry.
pub struct Entry {
    /// Registered name (what `type = "..."` says and [`Optimizer::name`] returns).
    pub name: &'static str,
    /// Other names accepted for it.
    pub aliases: &'static [&'static str],
    /// Builds it from its settings table.
    pub build: fn(&toml::Value) -> Result<Method>,
}

fn parse<T: DeserializeOwned>(name: &str, settings: &toml::Value) -> Result<T> {
    settings
        .clone()
        .try_into()
        .map_err(|e: toml::de::Error| CzError::config(format!("optimizer `{name}` settings"), e.message().to_string()))
}

fn local<T: LocalOptimizer + Send + Sync + 'static>(
    name: &str,
    settings: &toml::Value,
    new: fn(LocalSettings) -> Result<T>,
) -> Result<Method> {
    Ok(Method::Local(Box::new(new(parse::<LocalSettings>(name, settings)?)?)))
}

/// Every registered method.
pub const REGISTRY: &[Entry] = &[
    Entry {
        name: "miga",
        aliases: &[],
        build: |s| Ok(Method::Global(Box::new(Miga::new(parse::<MigaSettings>("miga", s)?)?))),
    },
    Entry { name: "ga", aliases: &[], build: |s| Ok(Method::Global(Box::new(ga(&parse::<GaSettings>("ga", s)?)?))) },
    Entry {
        name: "nsga2",
        aliases: &[],
        build: |s| Ok(Method::Global(Box::new(Nsga2::new(parse::<Nsga2Settings>("nsga2", s)?)?))),
    },
    Entry { name: "nelder-mead", aliases: &[], build: |s| local("nelder-mead", s, NelderMead::new) },
    Entry { name: "lbfgs", aliases: &[], build: |s| local("lbfgs", s, Lbfgs::new) },
    Entry { name: "gauss-newton", aliases: &[], build: |s| local("gauss-newton", s, GaussNewton::new) },
    Entry {
        name: "levenberg-marquardt",
        aliases: &["lm"],
        build: |s| local("levenberg-marquardt", s, LevenbergMarquardt::new),
    },
    Entry {
        name: "hybrid",
        aliases: &[],
        build: |s| Ok(Method::Global(Box::new(Hybrid::new(&parse::<HybridSettings>("hybrid", s)?)?))),
    },
];

/// Every registered name, in registry order (aliases not included).
pub fn names() -> Vec<&'static str> {
    REGISTRY.iter().map(|e| e.name).collect()
}

/// The entry registered as `name` or with `name` as an alias.
pub fn entry(name: &str) -> Result<&'static Entry> {
    REGISTRY.iter().find(|e| e.name == name || e.aliases.contains(&name)).ok_or_else(|| {
        CzError::config("optimizer type", format!("unknown optimizer `{name}`; known: {}", names().join(", ")))
    })
}

/// Builds method `name` from its settings (a table; unknown keys are errors, missing keys take
/// their documented defaults).
pub fn method_from_config(name: &str, settings: &toml::Value) -> Result<Method> {
    (entry(name)?.build)(settings)
}

/// Builds optimizer `name` from its settings, as a plain optimizer.
pub fn optimizer_from_config(name: &str, settings: &toml::Value) -> Result<Box<dyn Optimizer + Send + Sync>> {
    method_from_config(name, settings).map(Method::into_optimizer)
}

/// Builds a local method (one that can start from a given point); a global one is an error.
pub fn local_from_config(name: &str, settings: &toml::Value) -> Result<Box<dyn LocalOptimizer + Send + Sync>> {
    match method_from_config(name, settings)? {
        Method::Local(l) => Ok(l),
        Method::Global(_) => {
            let locals: Vec<&str> = REGISTRY
                .iter()
                .filter(|e| (e.build)(&toml::Value::Table(Default::default())).is_ok_and(|m| m.starts_from_initial()))
                .map(|e| e.name)
                .collect();
            Err(CzError::config(
                "optimizer type",
                format!("`{name}` does not start from a given point; local methods: {}", locals.join(", ")),
            ))
        }
    }
}

fn split(table: &toml::Value) -> Result<(String, toml::Value)> {
    let mut t = table
        .as_table()
        .cloned()
        .ok_or_else(|| CzError::config("optimizer", "expected a table such as `{ type = \"miga\" }`"))?;
    match t.remove("type") {
        Some(toml::Value::String(name)) => Ok((name, toml::Value::Table(t))),
        _ => Err(CzError::config("optimizer", "missing `type = \"<name>\"`")),
    }
}

/// Builds an optimizer from a table with a `type` key and its settings.
pub fn optimizer_from_table(table: &toml::Value) -> Result<Box<dyn Optimizer + Send + Sync>> {
    let (name, settings) = split(table)?;
    optimizer_from_config(&name, &settings)
}

/// Builds a local method from a table with a `type` key.
pub fn local_from_table(table: &toml::Value) -> Result<Box<dyn LocalOptimizer + Send + Sync>> {
    let (name, settings) = split(table)?;
    local_from_config(&name, &settings)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn empty() -> toml::Value {
        toml::Value::Table(Default::default())
    }

    #[test]
    fn each_name_and_alias_builds_the_method_it_names() {
        for e in REGISTRY {
            for n in std::iter::once(&e.name).chain(e.aliases) {
                assert_eq!(optimizer_from_config(n, &empty()).unwrap().name(), e.name, "`{n}`");
            }
        }
    }

    #[test]
    fn the_local_methods_are_the_ones_that_start_from_a_point() {
        let locals: Vec<&str> =
            REGISTRY.iter().filter(|e| (e.build)(&empty()).unwrap().starts_from_initial()).map(|e| e.name).collect();
        assert_eq!(locals, ["nelder-mead", "lbfgs", "gauss-newton", "levenberg-marquardt"]);
        let e = local_from_config("miga", &empty()).err().unwrap().to_string();
        assert!(e.contains("does not start from a given point") && e.contains("nelder-mead"), "{e}");
    }
}
