//! Nelder–Mead simplex search (argmin's `NelderMead`), restarted from its best point.

use super::{local_optimizer, Ctx, LocalSettings};
use argmin::core::{CostFunction, Error, Executor};
use std::cell::Cell;

/// Nelder–Mead (registry name `nelder-mead`).
#[derive(Clone, Debug)]
pub struct NelderMead {
    settings: LocalSettings,
}

local_optimizer!(NelderMead, "nelder-mead");

/// The cost seen by argmin. argmin evaluates the initial simplex with `unwrap`, so a refusal (budget
/// spent, target reached, run stopped) during those first `n + 1` calls is reported as an infinitely
/// bad vertex instead of an error; the refusal after them ends the run as usual.
struct Cost<'c, 'a> {
    ctx: &'c Ctx<'a>,
    initial_vertices_left: Cell<usize>,
}

impl CostFunction for Cost<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, z: &Vec<f64>) -> std::result::Result<f64, Error> {
        let in_simplex = self.initial_vertices_left.get() > 0;
        self.initial_vertices_left.set(self.initial_vertices_left.get().saturating_sub(1));
        match self.ctx.eval(std::slice::from_ref(z)) {
            Ok(evaluations) => Ok(evaluations[0].value),
            Err(_) if in_simplex => Ok(f64::INFINITY),
            Err(e) => Err(e),
        }
    }
}

impl NelderMead {
    fn polish(&self, ctx: &Ctx<'_>, z0: Vec<f64>) {
        let s = &self.settings;
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
        let cost = Cost { ctx, initial_vertices_left: Cell::new(ctx.dim() + 1) };
        let _ = Executor::new(cost, solver).configure(|st| st.max_iters(s.max_iterations)).run();
    }
}
