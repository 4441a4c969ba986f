//! Transfer: does a refitted effect predict data withheld from the fit?
//!
//! * [`Holdout`]: the last regime of every curve (its rule's held-out regime, e.g. the late stage
//!   or a beam's debonding, else the last quarter of its displacements), held out of both the
//!   base fit and the refit, then predicted.
//! * [`Withheld`]: other tests (other specimens), predicted with the parameters calibrated here
//!   and the effect when it carries over.

use super::base::Base;
use super::refit::{extended, refit_on, refit_options, RefitOutcome};
use crate::diagnose::candidate::CandidateEffect;
use crate::diagnose::gauge::{Gauge, Misfit};
use crate::diagnose::regimes::{self, Regime};
use crate::diagnose::run::Transfer;
use crate::diagnose::score::Linearisation;
use crate::identification::{Setup, Term};
use crate::problem_file::LoadedProblem;
use czid_core::{Parameter, ParameterSpace, Result};
use czid_optimizers::least_squares::{self, Parallel};
use nalgebra::DMatrix;
use std::collections::BTreeMap;

/// Realised shrinkage below which the held-out part is not refitted for a candidate: an effect
/// that barely changes the fit has nothing to transfer, and its refit may be dear.
const TRANSFER_FROM: f64 = 0.05;

/// The rows `rows` of `m`.
pub fn select_rows(m: &DMatrix<f64>, rows: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), m.ncols(), |i, j| m[(rows[i], j)])
}

/// The held-out part of every curve, and the base model's prediction of it.
pub struct Holdout {
    /// How the held-out part is named in reports.
    pub label: &'static str,
    /// The readings fitted, and their rows in the whole data's residual vector.
    early: Gauge,
    early_rows: Vec<usize>,
    /// The readings held out.
    late: Gauge,
    /// χ² of the late readings predicted by the base model fitted to the early ones.
    base_chi2: f64,
}

impl Holdout {
    /// Splits each curve where its held-out part starts and fits the base model without it;
    /// `None` when not asked for or when either part would be empty.
    pub fn prepare(
        base: &Base,
        regs: &[Regime],
        lin: &Linearisation,
        asked: bool,
        say: &dyn Fn(&str),
    ) -> Result<Option<Holdout>> {
        let gauge = &base.gauge;
        let mut starts: BTreeMap<String, (f64, Option<&'static str>)> = BTreeMap::new();
        for b in gauge.blocks.iter().filter(|b| b.term == Term::Load) {
            let rule = regimes::regime_set(&base.setup, &b.experiment);
            let held = rule.held_out();
            let from = regs.iter().rfind(|r| r.experiment == b.experiment).filter(|r| r.name == held).map(|r| r.from);
            let quarter = b.x[0] + 0.75 * (b.x[b.x.len() - 1] - b.x[0]);
            starts.insert(b.experiment.clone(), (from.unwrap_or(quarter), from.map(|_| rule.held_out_label())));
        }
        let split = |exp: &str| starts.get(exp).map_or(f64::INFINITY, |s| s.0);
        let labels: Vec<Option<&str>> = starts.values().map(|s| s.1).collect();
        let label = match labels.first() {
            Some(Some(l)) if labels.iter().all(|g| *g == Some(*l)) => l,
            Some(None) if labels.iter().all(Option::is_none) => "last quarter of each curve",
            _ => "last regime or quarter of each curve",
        };
        let early = gauge.restricted(|e, x| x < split(e));
        let early_rows = gauge.rows(|e, x| x < split(e));
        let late = gauge.restricted(|e, x| x >= split(e));
        if !(asked && !late.is_empty() && !early.is_empty()) {
            return Ok(None);
        }
        say(&format!("base fit without the {label} (held out)"));
        let fit = least_squares::minimize(
            &Parallel(base.residuals(&early)),
            &base.u,
            &refit_options(base.u.len()),
            Some(select_rows(&lin.jac, &early_rows)),
        )?;
        let base_chi2 = Misfit::of(&late, &base.space.apply(&base.setup, &base.space.from_unit(&fit.z))?)?.rss();
        Ok(Some(Holdout { label, early, early_rows, late, base_chi2 }))
    }

    /// The held-out part predicted with effect `c` refitted without it (from the whole refit
    /// `out`), or why it was not checked.
    pub fn check(
        &self,
        base: &Base,
        c: &dyn CandidateEffect,
        params: &[Parameter],
        out: &RefitOutcome,
        realised: f64,
        say: &dyn Fn(&str),
    ) -> Transfer {
        let mut t = Transfer {
            withheld: self.label.into(),
            readings: self.late.len(),
            base_chi2: self.base_chi2,
            effect_chi2: None,
            shrinkage: None,
            note: None,
        };
        if realised < TRANSFER_FROM {
            t.note = Some(format!("not checked: the effect removes under {:.0}% of the misfit", 100.0 * TRANSFER_FROM));
            return t;
        }
        say(&format!("{}: fit without the {}, predict it", c.name(), self.label));
        let jac_early = out.jacobian.as_ref().map(|j| select_rows(j, &self.early_rows));
        let predicted = refit_on(&self.early, base, c, params, &out.v, jac_early)
            .and_then(|o| Ok(extended(&self.late, base, c, params)(&o.v)?.rss()));
        match predicted {
            Ok(e) => {
                t.effect_chi2 = Some(e);
                t.shrinkage = Some(1.0 - e / self.base_chi2.max(f64::MIN_POSITIVE));
            }
            Err(e) => t.note = Some(format!("the refit without the late stage failed: {e}")),
        }
        t
    }
}

/// Another test, predicted with the parameters calibrated here.
pub struct Withheld {
    /// Its problem file.
    name: String,
    /// Its responses and noise.
    gauge: Gauge,
    /// Its setup at its own initial values.
    setup: Setup,
    /// The calibrated parameters that exist in its setup (a law, a shared modulus; not another
    /// specimen's own), and their indices among the calibrated ones.
    space: ParameterSpace,
    indices: Vec<usize>,
    /// χ² of its prediction by the base fit.
    base_chi2: f64,
}

impl Withheld {
    /// Each withheld problem predicted by the base fit.
    pub fn prepare(base: &Base, problems: &[LoadedProblem], noise: crate::diagnose::NoiseLevels) -> Result<Vec<Self>> {
        problems
            .iter()
            .map(|w| {
                let gauge = Gauge::new(&w.experiments, w.file.objective.debonded_length, noise)?;
                let setup = w.setup()?;
                let all = base.space.parameters();
                let indices: Vec<usize> = (0..all.len())
                    .filter(|&j| ParameterSpace::new(vec![all[j].clone()]).and_then(|s| s.read(&setup)).is_ok())
                    .collect();
                let space = ParameterSpace::new(indices.iter().map(|&j| all[j].clone()).collect())?;
                let xs: Vec<f64> = indices.iter().map(|&j| base.x[j]).collect();
                let base_chi2 = Misfit::of(&gauge, &space.apply(&setup, &xs)?)?.rss();
                Ok(Withheld { name: w.path.display().to_string(), gauge, setup, space, indices, base_chi2 })
            })
            .collect()
    }

    /// This test predicted with the refitted parameters `x` and the effect `c` at `values`.
    pub fn predict(&self, c: &dyn CandidateEffect, x: &[f64], values: &[f64]) -> Transfer {
        let note = if !c.transferable() {
            Some("specimen-specific effect: its value does not carry over to another test".to_string())
        } else if !c.applies(&self.setup) {
            Some("does not apply to the withheld test's model".to_string())
        } else {
            None
        };
        let mut t = Transfer {
            withheld: self.name.clone(),
            readings: self.gauge.len(),
            base_chi2: self.base_chi2,
            effect_chi2: None,
            shrinkage: None,
            note: note.clone(),
        };
        if note.is_none() {
            let xs: Vec<f64> = self.indices.iter().map(|&j| x[j]).collect();
            let predicted = self
                .space
                .apply(&self.setup, &xs)
                .and_then(|s| c.apply(&s, values))
                .and_then(|s| Misfit::of(&self.gauge, &s));
            match predicted {
                Ok(m) => {
                    t.effect_chi2 = Some(m.rss());
                    t.shrinkage = Some(1.0 - m.rss() / self.base_chi2.max(f64::MIN_POSITIVE));
                }
                Err(e) => t.note = Some(format!("prediction failed: {e}")),
            }
        }
        t
    }
}
