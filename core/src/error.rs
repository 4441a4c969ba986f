//! Typed errors. czid never panics on user input: every failure is one of these, and its message
//! says what is wrong, where, and (when it can) how to fix it.

use thiserror::Error;

/// A value as a reader wants it: plain for ordinary magnitudes, in scientific notation for very
/// small or large ones (a subnormal would otherwise print as hundreds of zeros).
fn readable(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && a.is_finite() && !(1e-4..1e9).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Result with a [`CzError`].
pub type Result<T, E = CzError> = std::result::Result<T, E>;

/// Everything that can go wrong in czid, as values.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CzError {
    /// A parameter of a law, model or optimizer is out of its valid range.
    #[error("invalid parameter `{name}` = {} in {owner}: {reason}", readable(*.value))]
    InvalidParameter {
        /// What the parameter belongs to (e.g. `law st_czm`).
        owner: String,
        /// The parameter's name as written in configuration files.
        name: String,
        /// The offending value.
        value: f64,
        /// What is expected instead.
        reason: String,
    },
    /// A configuration file or value could not be understood.
    #[error("configuration error in {location}: {message}")]
    Config {
        /// File, key or line/column.
        location: String,
        /// What is wrong and what is expected.
        message: String,
    },
    /// Experimental or tabulated data is unusable.
    #[error("data error in {location}: {message}")]
    Data {
        /// File and row/column.
        location: String,
        /// What is wrong and what is expected.
        message: String,
    },
    /// A simulation could not be completed.
    #[error("simulation failed: {0}")]
    Simulation(String),
    /// An optimizer could not run.
    #[error("optimizer error: {0}")]
    Optimizer(String),
    /// Reading or writing a file failed.
    #[error("i/o error on {path}: {message}")]
    Io {
        /// The file concerned.
        path: String,
        /// The operating system's message.
        message: String,
    },
}

impl CzError {
    /// Shorthand for [`CzError::InvalidParameter`].
    pub fn invalid(owner: impl Into<String>, name: impl Into<String>, value: f64, reason: impl Into<String>) -> Self {
        CzError::InvalidParameter { owner: owner.into(), name: name.into(), value, reason: reason.into() }
    }

    /// Shorthand for [`CzError::Config`].
    pub fn config(location: impl Into<String>, message: impl Into<String>) -> Self {
        CzError::Config { location: location.into(), message: message.into() }
    }

    /// Shorthand for [`CzError::Data`].
    pub fn data(location: impl Into<String>, message: impl Into<String>) -> Self {
        CzError::Data { location: location.into(), message: message.into() }
    }
}

/// Checks shared by every constructor: a value must be finite and strictly positive.
pub fn require_positive(owner: &str, name: &str, value: f64) -> Result<()> {
    if !value.is_finite() {
        return Err(CzError::invalid(owner, name, value, "must be a finite number"));
    }
    if value <= 0.0 {
        return Err(CzError::invalid(owner, name, value, "must be strictly positive"));
    }
    Ok(())
}

/// A value must be finite and not negative.
pub fn require_non_negative(owner: &str, name: &str, value: f64) -> Result<()> {
    if !value.is_finite() {
        return Err(CzError::invalid(owner, name, value, "must be a finite number"));
    }
    if value < 0.0 {
        return Err(CzError::invalid(owner, name, value, "must not be negative"));
    }
    Ok(())
}
