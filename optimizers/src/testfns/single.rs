//! Classic single-objective test functions (minimum 0).

use super::TestProblem;
use czid_core::{CzError, Evaluation, Problem, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{E, PI};

/// Which function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Function {
    /// `10n + Σ (x² − 10 cos 2πx)` on `[−5.12, 5.12]ⁿ`, minimum at 0.
    Rastrigin,
    /// Ackley's function on `[−32.768, 32.768]ⁿ`, minimum at 0.
    Ackley,
    /// `418.9829 n − Σ x sin √|x|` on `[−500, 500]ⁿ`, minimum near `x = 420.9687`.
    Schwefel,
    /// `1 + Σ x²/4000 − Π cos(x_i/√i)` on `[−600, 600]ⁿ`, minimum at 0.
    Griewank,
    /// `Σ 100 (x_{i+1} − x_i²)² + (1 − x_i)²` on `[−5, 10]ⁿ`, minimum at 1; provides residuals.
    Rosenbrock,
}

impl Function {
    /// Default search box (same for every variable).
    pub fn bounds(self) -> (f64, f64) {
        match self {
            Function::Rastrigin => (-5.12, 5.12),
            Function::Ackley => (-32.768, 32.768),
            Function::Schwefel => (-500.0, 500.0),
            Function::Griewank => (-600.0, 600.0),
            Function::Rosenbrock => (-5.0, 10.0),
        }
    }

    /// Location of the minimum (same for every variable).
    pub fn argmin(self) -> f64 {
        match self {
            Function::Schwefel => 420.968_746_359_982,
            Function::Rosenbrock => 1.0,
            _ => 0.0,
        }
    }

    /// Value at `x`.
    pub fn value(self, x: &[f64]) -> f64 {
        let n = x.len() as f64;
        match self {
            Function::Rastrigin => 10.0 * n + x.iter().map(|&v| v * v - 10.0 * (2.0 * PI * v).cos()).sum::<f64>(),
            Function::Ackley => {
                let s2 = x.iter().map(|v| v * v).sum::<f64>() / n;
                let sc = x.iter().map(|&v| (2.0 * PI * v).cos()).sum::<f64>() / n;
                -20.0 * (-0.2 * s2.sqrt()).exp() - sc.exp() + 20.0 + E
            }
            Function::Schwefel => 418.982_887_272_433_9 * n - x.iter().map(|&v| v * v.abs().sqrt().sin()).sum::<f64>(),
            Function::Griewank => {
                let s = x.iter().map(|v| v * v).sum::<f64>() / 4000.0;
                let p = x.iter().enumerate().map(|(i, &v)| (v / ((i + 1) as f64).sqrt()).cos()).product::<f64>();
                1.0 + s - p
            }
            Function::Rosenbrock => {
                x.windows(2).map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (1.0 - w[0]).powi(2)).sum()
            }
        }
    }

    fn label(self) -> &'static str {
        match self {
            Function::Rastrigin => "rastrigin",
            Function::Ackley => "ackley",
            Function::Schwefel => "schwefel",
            Function::Griewank => "griewank",
            Function::Rosenbrock => "rosenbrock",
        }
    }
}

/// An orthogonal matrix drawn from a seed (Gram–Schmidt on Gaussian columns), row major.
#[derive(Clone, Debug, PartialEq)]
pub struct Rotation {
    n: usize,
    m: Vec<f64>,
    seed: u64,
}

impl Rotation {
    /// A random rotation of dimension `n` from `seed`.
    pub fn new(n: usize, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut m = vec![0.0; n * n];
        for row in 0..n {
            loop {
                for c in 0..n {
                    // Box–Muller: only the direction matters, so one normal per draw is enough.
                    let (u1, u2): (f64, f64) = (1.0 - rng.random::<f64>(), rng.random());
                    m[row * n + c] = (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos();
                }
                for prev in 0..row {
                    let d: f64 = (0..n).map(|c| m[row * n + c] * m[prev * n + c]).sum();
                    for c in 0..n {
                        m[row * n + c] -= d * m[prev * n + c];
                    }
                }
                let norm = (0..n).map(|c| m[row * n + c].powi(2)).sum::<f64>().sqrt();
                if norm > 1e-8 {
                    (0..n).for_each(|c| m[row * n + c] /= norm);
                    break;
                }
            }
        }
        Rotation { n, m, seed }
    }

    /// `out = R v`.
    pub fn apply(&self, v: &[f64], out: &mut [f64]) {
        for (r, o) in out.iter_mut().enumerate() {
            *o = self.m[r * self.n..(r + 1) * self.n].iter().zip(v).map(|(a, b)| a * b).sum();
        }
    }
}

/// A test function of a given dimension, optionally rotated about its minimiser:
/// `f(o + R (x − o))`, with `o` the minimiser, so the minimum stays where it was.
#[derive(Clone, Debug)]
pub struct TestFunction {
    function: Function,
    dim: usize,
    bounds: (f64, f64),
    rotation: Option<Rotation>,
}

impl TestFunction {
    /// `function` in `dim` variables on its default box.
    pub fn new(function: Function, dim: usize) -> Result<Self> {
        let min = if function == Function::Rosenbrock { 2 } else { 1 };
        if dim < min {
            return Err(CzError::invalid("test function", "dimension", dim as f64, format!("must be at least {min}")));
        }
        Ok(TestFunction { function, dim, bounds: function.bounds(), rotation: None })
    }

    /// The same function on another box (same for every variable).
    pub fn with_bounds(mut self, lo: f64, hi: f64) -> Result<Self> {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(CzError::config("test function", format!("bounds ({lo}, {hi}) must be finite with lo < hi")));
        }
        self.bounds = (lo, hi);
        Ok(self)
    }

    /// The rotated variant (seeded rotation).
    pub fn rotated(mut self, seed: u64) -> Result<Self> {
        self.rotation = Some(Rotation::new(self.dim, seed));
        Ok(self)
    }

    /// The function.
    pub fn function(&self) -> Function {
        self.function
    }

    fn value(&self, x: &[f64]) -> f64 {
        match &self.rotation {
            None => self.function.value(x),
            Some(r) => {
                let o = self.function.argmin();
                let shifted: Vec<f64> = x.iter().map(|v| v - o).collect();
                let mut y = vec![0.0; x.len()];
                r.apply(&shifted, &mut y);
                y.iter_mut().for_each(|v| *v += o);
                self.function.value(&y)
            }
        }
    }
}

impl Problem for TestFunction {
    fn dim(&self) -> usize {
        self.dim
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![self.bounds; self.dim]
    }

    fn evaluate(&self, x: &[f64]) -> Result<Evaluation> {
        if x.len() != self.dim {
            return Err(CzError::Optimizer(format!("expected {} variables, got {}", self.dim, x.len())));
        }
        if self.function == Function::Rosenbrock && self.rotation.is_none() {
            // Residuals r = (10 (x_{i+1} − x_i²), 1 − x_i) so that value = ||r||².
            let mut residuals = Vec::with_capacity(2 * (self.dim - 1));
            for w in x.windows(2) {
                residuals.push(10.0 * (w[1] - w[0] * w[0]));
                residuals.push(1.0 - w[0]);
            }
            let value = residuals.iter().map(|r| r * r).sum();
            return Ok(Evaluation { value, objectives: Vec::new(), residuals });
        }
        Ok(Evaluation::scalar(self.value(x)))
    }
}

impl TestProblem for TestFunction {
    fn name(&self) -> String {
        let r = if self.rotation.is_some() { "rotated-" } else { "" };
        format!("{r}{}{}", self.function.label(), self.dim)
    }

    fn optimum_value(&self) -> f64 {
        0.0
    }

    fn default_target(&self) -> f64 {
        // Below the value of the nearest non-global local minima (≈ 1 for Rastrigin, ≈ 118 for
        // Schwefel, ≈ 0.0074 for Griewank), so a success means the global basin was found.
        match self.function {
            Function::Griewank => 1e-3,
            _ => 1e-2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minima_are_zero_and_rotation_is_orthogonal() {
        for f in [Function::Rastrigin, Function::Ackley, Function::Schwefel, Function::Griewank, Function::Rosenbrock] {
            let x = vec![f.argmin(); 10];
            assert!(f.value(&x).abs() < 1e-9, "{f:?} {}", f.value(&x));
        }
        let r = Rotation::new(6, 3);
        for i in 0..6 {
            for j in 0..6 {
                let d: f64 = (0..6).map(|c| r.m[i * 6 + c] * r.m[j * 6 + c]).sum();
                assert!((d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
        let rot = TestFunction::new(Function::Rastrigin, 6).unwrap().rotated(1).unwrap();
        assert_eq!(rot.value(&[0.0; 6]), 0.0);
        assert_eq!(r.seed, 3);
    }
}
