//! Nelder–Mead simplex search (argmin's `NelderMead`), restarted from its best point.

use super::{local_optimizer, with_restarts, Ctx, LocalOptimizer, LocalSettings};
use argmin::core::{CostFunction, Error, Executor};
use czid_core::{Budget, Observer, OptimizationResult, Problem, Result};

/// Nelder–Mead (registry name `nelder-mead`).
#[derive(Clone, Debug)]
pub struct NelderMead {
    settings: LocalSettings,
}

local_optimizer!(NelderMead, "nelder-mead");

struct Cost<'c, 'a>(&'c Ctx<'a>);

impl CostFunction for Cost<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, z: &Vec<f64>) -> std::result::Result<f64, Error> {
        Ok(self.0.eval(std::slice::from_ref(z))?[0].value)
    }
}

impl LocalOptimizer for NelderMead {
    fn minimize_from(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        start: &[f64],
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        let ctx = Ctx::new(problem, &self.settings, budget, observer)?;
        let s = &self.settings;
        with_restarts(&ctx, start, |z0| {
            let mut simplex = vec![z0.clone()];
            for i in 0..ctx.dim() {
                let mut v = z0.clone();
                v[i] += s.initial_step;
                simplex.push(v);
            }
            let Ok(solver) = argmin::solver::neldermead::NelderMead::new(simplex).with_sd_tolerance(s.tolerance) else {
                return;
            };
            // An error here only means that the run was stopped (budget, target, observer).
            let _ = Executor::new(Cost(&ctx), solver).configure(|st| st.max_iters(s.max_iterations)).run();
        });
        ctx.finish()
    }
}
