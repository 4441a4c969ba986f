//! Test problems with known optima: the classic single-objective functions (optionally
//! rotated by a seeded orthogonal matrix) and the ZDT bi-objective suite.
//!
//! Names accepted by [`by_name`]: `rastrigin10`, `ackley5`, `schwefel10`, `griewank10`,
//! `rosenbrock2` (any dimension suffix), a `rotated-` prefix (`rotated-rastrigin10`), and
//! `zdt1`, `zdt2`, `zdt3` (30 variables; `zdt1-10` for another count).

mod single;
mod zdt;

pub use single::{Function, Rotation, TestFunction};
pub use zdt::{zdt_front, Zdt, ZdtKind};

use czid_core::{CzError, Problem, Result};

/// A boxed test problem with the metadata the harness needs.
pub trait TestProblem: Problem + Send {
    /// The registry name.
    fn name(&self) -> String;
    /// Known optimal `value`.
    fn optimum_value(&self) -> f64;
    /// A success threshold on `value` for success rates and evaluations-to-target.
    fn default_target(&self) -> f64;
}

/// Builds a test problem from its name (see the module documentation).
pub fn by_name(name: &str) -> Result<Box<dyn TestProblem>> {
    let lower = name.to_ascii_lowercase();
    if let Some(rest) = lower.strip_prefix("zdt") {
        let (k, n) = match rest.split_once('-') {
            Some((k, n)) => (k, n.parse::<usize>().ok()),
            None => (rest, Some(30)),
        };
        let kind = match k {
            "1" => ZdtKind::Zdt1,
            "2" => ZdtKind::Zdt2,
            "3" => ZdtKind::Zdt3,
            _ => return Err(unknown(name)),
        };
        let n = n.ok_or_else(|| unknown(name))?;
        return Ok(Box::new(Zdt::new(kind, n)?));
    }
    let (rotated, base) = match lower.strip_prefix("rotated-") {
        Some(b) => (true, b),
        None => (false, lower.as_str()),
    };
    let split = base.find(|c: char| c.is_ascii_digit()).ok_or_else(|| unknown(name))?;
    let dim: usize = base[split..].parse().map_err(|_| unknown(name))?;
    let function = match &base[..split] {
        "rastrigin" => Function::Rastrigin,
        "ackley" => Function::Ackley,
        "schwefel" => Function::Schwefel,
        "griewank" => Function::Griewank,
        "rosenbrock" => Function::Rosenbrock,
        _ => return Err(unknown(name)),
    };
    let f = TestFunction::new(function, dim)?;
    Ok(Box::new(if rotated { f.rotated(ROTATION_SEED)? } else { f }))
}

/// Seed of the rotation used by `rotated-*` names, fixed so every run sees the same problem.
pub const ROTATION_SEED: u64 = 20_02;

fn unknown(name: &str) -> CzError {
    CzError::config(
        "test problem",
        format!(
            "unknown test problem `{name}`: expected rastrigin|ackley|schwefel|griewank|rosenbrock followed by \
             the dimension (e.g. rastrigin10), optionally prefixed by `rotated-`, or zdt1|zdt2|zdt3[-n]"
        ),
    )
}
