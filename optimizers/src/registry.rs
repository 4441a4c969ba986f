//! Optimizers by name and TOML settings, for problem files:
//! `optimizer = { type = "miga", islands = 8 }`.

use crate::ga::{ga, GaSettings};
use crate::hybrid::{Hybrid, HybridSettings};
use crate::local::{GaussNewton, Lbfgs, LevenbergMarquardt, LocalOptimizer, LocalSettings, NelderMead};
use crate::miga::{Miga, MigaSettings};
use crate::nsga2::{Nsga2, Nsga2Settings};
use czid_core::{CzError, Optimizer, Result};
use serde::de::DeserializeOwned;

/// Every registered name (`lm` is accepted as an alias of `levenberg-marquardt`).
pub const OPTIMIZER_NAMES: &[&str] =
    &["miga", "ga", "nsga2", "nelder-mead", "lbfgs", "gauss-newton", "levenberg-marquardt", "hybrid"];

fn parse<T: DeserializeOwned>(name: &str, settings: &toml::Value) -> Result<T> {
    settings
        .clone()
        .try_into()
        .map_err(|e: toml::de::Error| CzError::config(format!("optimizer `{name}` settings"), e.message().to_string()))
}

/// Builds optimizer `name` from its settings (a table; unknown keys are errors, missing keys
/// take their documented defaults).
pub fn optimizer_from_config(name: &str, settings: &toml::Value) -> Result<Box<dyn Optimizer + Send + Sync>> {
    Ok(match name {
        "miga" => Box::new(Miga::new(parse::<MigaSettings>(name, settings)?)?),
        "ga" => Box::new(ga(&parse::<GaSettings>(name, settings)?)?),
        "nsga2" => Box::new(Nsga2::new(parse::<Nsga2Settings>(name, settings)?)?),
        "hybrid" => Box::new(Hybrid::new(&parse::<HybridSettings>(name, settings)?)?),
        _ => return local_from_config(name, settings).map(|l| l as Box<dyn Optimizer + Send + Sync>),
    })
}

/// Builds a local method (one that can start from a given point).
pub fn local_from_config(name: &str, settings: &toml::Value) -> Result<Box<dyn LocalOptimizer + Send + Sync>> {
    Ok(match name {
        "nelder-mead" => Box::new(NelderMead::new(parse::<LocalSettings>(name, settings)?)?),
        "lbfgs" => Box::new(Lbfgs::new(parse::<LocalSettings>(name, settings)?)?),
        "gauss-newton" => Box::new(GaussNewton::new(parse::<LocalSettings>(name, settings)?)?),
        "levenberg-marquardt" | "lm" => Box::new(LevenbergMarquardt::new(parse::<LocalSettings>(name, settings)?)?),
        _ => {
            return Err(CzError::config(
                "optimizer type",
                format!("unknown optimizer `{name}`; known: {}", OPTIMIZER_NAMES.join(", ")),
            ))
        }
    })
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
