//! L-BFGS (argmin's `LBFGS` with a Moré–Thuente line search) on finite-difference gradients.

use super::{local_optimizer, Ctx, Differences, LocalSettings};
use argmin::core::{CostFunction, Error, Executor, Gradient};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use std::cell::RefCell;

/// L-BFGS (registry name `lbfgs`).
#[derive(Clone, Debug)]
pub struct Lbfgs {
    settings: LocalSettings,
}

local_optimizer!(Lbfgs, "lbfgs");

struct Fd<'c, 'a> {
    ctx: &'c Ctx<'a>,
    /// Last `(z, f(z))`: forward differences reuse the value the line search just computed.
    last: RefCell<Option<(Vec<f64>, f64)>>,
}

impl CostFunction for Fd<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, z: &Vec<f64>) -> std::result::Result<f64, Error> {
        let f = self.ctx.eval(std::slice::from_ref(z))?[0].value;
        *self.last.borrow_mut() = Some((z.clone(), f));
        Ok(f)
    }
}

impl Gradient for Fd<'_, '_> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;

    fn gradient(&self, z: &Vec<f64>) -> std::result::Result<Vec<f64>, Error> {
        let (pts, h) = self.ctx.fd_points(z);
        let f = self.ctx.eval(&pts)?;
        Ok(match self.ctx.settings.differences {
            Differences::Central => {
                (0..z.len()).map(|i| (f[2 * i].value - f[2 * i + 1].value) / (2.0 * h[i])).collect()
            }
            Differences::Forward => {
                let cached = self.last.borrow().as_ref().filter(|(lz, _)| lz == z).map(|&(_, v)| v);
                let f0 = match cached {
                    Some(v) => v,
                    None => self.cost(z)?,
                };
                (0..z.len()).map(|i| (f[i].value - f0) / h[i]).collect()
            }
        })
    }
}

impl Lbfgs {
    fn polish(&self, ctx: &Ctx<'_>, z0: Vec<f64>) {
        let s = &self.settings;
        let solver = argmin::solver::quasinewton::LBFGS::new(MoreThuenteLineSearch::new(), s.memory)
            .with_tolerance_grad(s.tolerance)
            .and_then(|l| l.with_tolerance_cost(0.0));
        let Ok(solver) = solver else { return };
        let fd = Fd { ctx, last: RefCell::new(None) };
        // Errors mean a stop (budget, target, observer) or a failed line search: either
        // way the best point is in the tracker.
        let _ = Executor::new(fd, solver).configure(|st| st.param(z0).max_iters(s.max_iterations)).run();
    }
}
