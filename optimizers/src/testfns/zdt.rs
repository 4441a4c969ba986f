//! The ZDT bi-objective test problems (Zitzler, Deb & Thiele 2000) and their analytic
//! Pareto fronts.

use super::TestProblem;
use czid_core::{CzError, Evaluation, Problem, Result};
use std::f64::consts::PI;

/// Which ZDT problem.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ZdtKind {
    /// Convex front `f2 = 1 − √f1`.
    Zdt1,
    /// Concave front `f2 = 1 − f1²`.
    Zdt2,
    /// Disconnected front: the non-dominated parts of `f2 = 1 − √f1 − f1 sin 10πf1`.
    Zdt3,
}

impl ZdtKind {
    fn h(self, f1: f64, g: f64) -> f64 {
        let r = f1 / g;
        match self {
            ZdtKind::Zdt1 => 1.0 - r.sqrt(),
            ZdtKind::Zdt2 => 1.0 - r * r,
            ZdtKind::Zdt3 => 1.0 - r.sqrt() - r * (10.0 * PI * f1).sin(),
        }
    }
}

/// A ZDT problem on `[0, 1]ⁿ`. Its `value` is `f1 + f2` (the equally weighted composite).
#[derive(Clone, Debug)]
pub struct Zdt {
    kind: ZdtKind,
    n: usize,
}

impl Zdt {
    /// `kind` with `n ≥ 2` variables (30 in the reference studies).
    pub fn new(kind: ZdtKind, n: usize) -> Result<Self> {
        if n < 2 {
            return Err(CzError::invalid("test function zdt", "dimension", n as f64, "must be at least 2"));
        }
        Ok(Zdt { kind, n })
    }

    /// `(f1, f2)` at `x`.
    pub fn objectives(&self, x: &[f64]) -> [f64; 2] {
        let f1 = x[0];
        let g = 1.0 + 9.0 * x[1..].iter().sum::<f64>() / (self.n - 1) as f64;
        [f1, g * self.kind.h(f1, g)]
    }
}

impl Problem for Zdt {
    fn dim(&self) -> usize {
        self.n
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(0.0, 1.0); self.n]
    }

    fn evaluate(&self, x: &[f64]) -> Result<Evaluation> {
        if x.len() != self.n {
            return Err(CzError::Optimizer(format!("expected {} variables, got {}", self.n, x.len())));
        }
        let f = self.objectives(x);
        Ok(Evaluation { value: f[0] + f[1], objectives: f.to_vec(), residuals: Vec::new() })
    }

    fn objectives(&self) -> usize {
        2
    }
}

impl TestProblem for Zdt {
    fn name(&self) -> String {
        let k = match self.kind {
            ZdtKind::Zdt1 => 1,
            ZdtKind::Zdt2 => 2,
            ZdtKind::Zdt3 => 3,
        };
        if self.n == 30 {
            format!("zdt{k}")
        } else {
            format!("zdt{k}-{}", self.n)
        }
    }

    fn optimum_value(&self) -> f64 {
        // Minimum of f1 + h(f1) along the front.
        let front = zdt_front(self.kind, 10_001);
        front.iter().map(|p| p[0] + p[1]).fold(f64::INFINITY, f64::min)
    }

    fn default_target(&self) -> f64 {
        self.optimum_value() + 1e-2
    }
}

/// `points` points of the analytic Pareto front, uniform in `f1` (as pymoo's reference fronts).
///
/// ZDT3's front is disconnected: its regions are found as the runs of non-dominated points of
/// the curve `f2 = h(f1)` sampled every 1e-6, and the points are shared equally between the
/// regions (uniform in `f1` within each).
pub fn zdt_front(kind: ZdtKind, points: usize) -> Vec<[f64; 2]> {
    let line = |a: f64, b: f64, k: usize| -> Vec<[f64; 2]> {
        (0..k)
            .map(|i| {
                let f1 = if k == 1 { a } else { a + (b - a) * i as f64 / (k - 1) as f64 };
                [f1, kind.h(f1, 1.0)]
            })
            .collect()
    };
    match kind {
        ZdtKind::Zdt1 | ZdtKind::Zdt2 => line(0.0, 1.0, points),
        ZdtKind::Zdt3 => {
            let regions = zdt3_regions();
            let per = points / regions.len();
            let extra = points % regions.len();
            regions.iter().enumerate().flat_map(|(i, &(a, b))| line(a, b, per + usize::from(i < extra))).collect()
        }
    }
}

/// The `f1` intervals of ZDT3's Pareto front.
pub fn zdt3_regions() -> Vec<(f64, f64)> {
    const SAMPLES: usize = 1_000_000;
    let mut regions = Vec::new();
    let mut min_f2 = f64::INFINITY;
    let mut start: Option<f64> = None;
    let mut last = 0.0;
    for i in 0..=SAMPLES {
        let f1 = i as f64 / SAMPLES as f64;
        let f2 = ZdtKind::Zdt3.h(f1, 1.0);
        // Sweeping f1 upwards, a point is non-dominated iff its f2 is below every earlier f2.
        if f2 < min_f2 {
            min_f2 = f2;
            start.get_or_insert(f1);
            last = f1;
        } else if let Some(a) = start.take() {
            regions.push((a, last));
        }
    }
    if let Some(a) = start {
        regions.push((a, last));
    }
    regions
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zdt3_regions_match_known_endpoints() {
        let r = zdt3_regions();
        let known = [
            (0.0, 0.083_001_534_9),
            (0.182_228_780, 0.257_762_363_4),
            (0.409_313_674_8, 0.453_882_104_1),
            (0.618_396_794_4, 0.652_511_703_8),
            (0.823_331_798_3, 0.851_832_865_4),
        ];
        assert_eq!(r.len(), 5, "{r:?}");
        for ((a, b), (ka, kb)) in r.iter().zip(known) {
            assert!((a - ka).abs() < 2e-6 && (b - kb).abs() < 2e-6, "{a} {b} vs {ka} {kb}");
        }
        assert_eq!(zdt_front(ZdtKind::Zdt3, 100).len(), 100);
    }
}
