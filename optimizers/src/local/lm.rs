//! Levenberg–Marquardt on [`czid_core::Evaluation::residuals`] (ours: argmin 0.11 has none): the
//! shared [`crate::least_squares::levenberg_marquardt`] in the unbounded coordinates of the box's
//! transform, with a fresh Jacobian after every accepted step.

use super::gauss_newton::Residuals;
use super::{local_optimizer, Ctx, LocalSettings};
use crate::least_squares::{self, FiniteDifferences, JacobianUpdates, LmOptions};
use std::cell::RefCell;

/// Levenberg–Marquardt (registry name `levenberg-marquardt`, alias `lm`); needs residuals.
#[derive(Clone, Debug)]
pub struct LevenbergMarquardt {
    settings: LocalSettings,
}

local_optimizer!(LevenbergMarquardt, "levenberg-marquardt");

impl LevenbergMarquardt {
    fn polish(&self, ctx: &Ctx<'_>, z0: Vec<f64>) {
        let s = &self.settings;
        let op = Residuals { ctx, last: RefCell::new(None) };
        let opts = LmOptions {
            max_iterations: s.max_iterations,
            tolerance: s.tolerance,
            min_decrease: 0.0,
            updates: JacobianUpdates::Fresh,
            differences: FiniteDifferences { step: s.fd_step, scheme: s.differences },
            bounds: None,
            fixed: Vec::new(),
        };
        // An error is a stop (budget, target, observer) or a failed Jacobian: the best point is
        // in the tracker either way.
        let _ = least_squares::minimize(&op, &z0, &opts, None);
    }
}
