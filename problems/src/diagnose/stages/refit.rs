//! How far: a candidate switched on and refitted with the fitted parameters, its realised
//! shrinkage of the misfit (overall and per regime) and its information criteria.

use super::base::{aic_bic, at_bound, Base, POLISH_STEP, RESTARTS};
use super::ranking::Ranked;
use crate::diagnose::candidate::CandidateEffect;
use crate::diagnose::gauge::{Gauge, Misfit};
use crate::diagnose::regimes::{self, Regime};
use crate::diagnose::run::{Refit, RegimeShrinkage, Value, NOISE_LEVEL};
use crate::diagnose::score::{Linearisation, Score, Sensitivity};
use czid_core::{Parameter, Result};
use czid_optimizers::least_squares::{self, JacobianUpdates, LmOptions, Parallel};
use nalgebra::DMatrix;

/// Refits start from the sensitivities of the scores and follow them with Broyden updates: one
/// run per step (a large-rotation run costs ~50 small-rotation ones), up to three fresh
/// finite-difference Jacobians if they stall.
pub fn refit_options(dim: usize) -> LmOptions {
    LmOptions {
        max_iterations: 80,
        updates: JacobianUpdates::Broyden { fresh: 3 },
        ..LmOptions::unit_cube(dim, POLISH_STEP)
    }
}
/// Unit-cube values from which the secondary parameters of a several-parameter effect are refitted
/// again.
const SECONDARY_STARTS: [f64; 3] = [0.1, 0.3, 0.6];
/// Unit-cube values of an effect's first parameter from which a refit that removed little is
/// started again, on either side of the null (a fitted parameter at a bound can pin the first
/// refit to its start: the steps it asks for leave the box).
const PRIMARY_STARTS: [f64; 2] = [0.25, 0.75];
/// A refit removing less than this share of the misfit is started again from [`PRIMARY_STARTS`].
const STALLED: f64 = 0.1;
/// A switched-on effect only moves the fitted parameters, whose Jacobian barely changes with it;
/// its runs can be far dearer (large rotations), so fewer steps, a looser stop and one fresh
/// Jacobian; the switch itself stays on.
fn switch_options(dim: usize, switches: std::ops::Range<usize>) -> LmOptions {
    LmOptions {
        max_iterations: 16,
        min_decrease: 1e-4,
        updates: JacobianUpdates::Broyden { fresh: 1 },
        fixed: switches.collect(),
        ..LmOptions::unit_cube(dim, POLISH_STEP)
    }
}

/// A candidate's extended model on `gauge`: fitted parameters then the effect's, unit-cube
/// coordinates.
pub fn extended<'a>(
    gauge: &'a Gauge,
    base: &'a Base,
    c: &'a dyn CandidateEffect,
    params: &'a [Parameter],
) -> impl Fn(&[f64]) -> Result<Misfit> + Sync + 'a {
    move |v: &[f64]| {
        let (space, p) = (&base.space, base.space.dim());
        let fitted = space.apply(&base.setup, &space.from_unit(&v[..p]))?;
        let values: Vec<f64> = params.iter().zip(&v[p..]).map(|(q, &u)| q.from_unit(u)).collect();
        Misfit::of(gauge, &c.apply(&fitted, &values)?)
    }
}

/// A refit: its point (fitted then effect coordinates), misfit, cost and last Jacobian.
pub struct RefitOutcome {
    /// Unit-cube point.
    pub v: Vec<f64>,
    /// Misfit there.
    pub misfit: Misfit,
    /// Residual evaluations spent.
    pub evaluations: usize,
    /// Last Jacobian.
    pub jacobian: Option<DMatrix<f64>>,
}

/// Refits a candidate on `gauge` from `start` (fitted and effect coordinates).
pub fn refit_on(
    gauge: &Gauge,
    base: &Base,
    c: &dyn CandidateEffect,
    params: &[Parameter],
    start: &[f64],
    jacobian: Option<DMatrix<f64>>,
) -> Result<RefitOutcome> {
    let model = extended(gauge, base, c, params);
    let f = |v: &[f64]| -> Result<Vec<f64>> { Ok(model(v)?.r) };
    let opts = if c.discrete() {
        switch_options(start.len(), base.space.dim()..start.len())
    } else {
        refit_options(start.len())
    };
    let res = least_squares::minimize(&Parallel(f), start, &opts, jacobian)?;
    let misfit = model(&res.z)?;
    Ok(RefitOutcome { v: res.z, misfit, evaluations: res.evaluations, jacobian: res.jacobian })
}

/// Where a refit starts: the joint first-order prediction (the effect at the size the data ask
/// for, the fitted parameters moved by what they no longer have to absorb). When the response is
/// strongly non-linear in the effect, a fraction of that step is the better start; failing all,
/// the null (a switch: on, with the fitted values).
fn start(base: &Base, c: &dyn CandidateEffect, sens: &Sensitivity, s: &Score, params: &[Parameter]) -> Vec<f64> {
    let u = &base.u;
    let model = extended(&base.gauge, base, c, params);
    let along = |t: f64| -> Vec<f64> {
        let fitted = u.iter().zip(&s.fitted_shift).map(|(a, b)| (a + t * b).clamp(0.0, 1.0));
        if c.discrete() {
            fitted.chain(std::iter::repeat_n(1.0, params.len())).collect()
        } else {
            let effect = sens.null_u.iter().zip(params.iter().zip(&s.predicted)).map(|(&u0, (q, v))| {
                let full = q.to_unit(v.1);
                (u0 + t * (full - u0)).clamp(0.0, 1.0)
            });
            fitted.chain(effect).collect()
        }
    };
    [1.0, 0.5, 0.25, 0.125]
        .into_iter()
        .map(along)
        .find(|v| model(v).is_ok_and(|m| m.rss() <= base.chi2))
        .unwrap_or_else(|| {
            if c.discrete() {
                u.iter().copied().chain(std::iter::repeat_n(1.0, params.len())).collect()
            } else {
                u.iter().copied().chain(sens.null_u.iter().copied()).collect()
            }
        })
}

/// The refit of one ranked candidate from the start the scores predict, repeated from other
/// values of the secondary parameters of a several-parameter effect.
pub fn refit(
    base: &Base,
    lin: &Linearisation,
    c: &dyn CandidateEffect,
    sens: &Sensitivity,
    s: &Score,
) -> Result<RefitOutcome> {
    let (n, p) = (base.readings(), base.space.dim());
    let params: Vec<Parameter> = sens.parameters.iter().map(|q| q.parameter.clone()).collect();
    let jac0 = if c.discrete() {
        lin.jac.clone()
    } else {
        let mut m = DMatrix::zeros(n, p + params.len());
        m.columns_mut(0, p).copy_from(&lin.jac);
        m.columns_mut(p, params.len()).copy_from(&sens.columns);
        m
    };
    let first = start(base, c, sens, s, &params);
    let mut out = refit_on(&base.gauge, base, c, &params, &first, Some(jac0.clone()))?;
    // A base fit stopped at a bound has distorted the fitted parameters to absorb what the
    // effect explains, and a refit from there has to travel back across the range (a beam's
    // bond strength at its lower bound when the deflection is offset). When the refit leaves
    // structure behind, those parameters are started again at a quarter, the middle and three
    // quarters of their range, as the base fit's are, and the best refit kept.
    let stuck = at_bound(&base.u);
    if !c.discrete() && !stuck.is_empty() && base.gauge.structure_p(&out.misfit.r) <= NOISE_LEVEL {
        let starts: Vec<Vec<f64>> = RESTARTS
            .into_iter()
            .map(|w| {
                let mut v = first.clone();
                for &j in &stuck {
                    v[j] = w;
                }
                v
            })
            .collect();
        keep_best(&mut out, refits_from(base, c, &params, &starts, None));
    }
    if !c.discrete() && out.misfit.rss() > (1.0 - STALLED) * base.chi2 {
        let starts: Vec<Vec<f64>> = PRIMARY_STARTS
            .into_iter()
            .filter(|w| (out.v[p] - w).abs() >= 0.1)
            .map(|w| base.u.iter().copied().chain(std::iter::once(w)).chain(out.v[p + 1..].iter().copied()).collect())
            .collect();
        keep_best(&mut out, refits_from(base, c, &params, &starts, Some(&jac0)));
    }
    // An effect of several parameters can trade one against another along a valley (a bridging
    // tail's strength against its length): the refit is repeated from other values of every
    // parameter but the first, and the best kept.
    if !c.discrete() && params.len() > 1 {
        let starts: Vec<Vec<f64>> = (1..params.len())
            .flat_map(|j| SECONDARY_STARTS.into_iter().map(move |w| (j, w)))
            .filter(|&(j, w)| (out.v[p + j] - w).abs() >= 0.1)
            .map(|(j, w)| {
                let mut v = out.v.clone();
                v[p + j] = w;
                v
            })
            .collect();
        let jacobian = out.jacobian.clone();
        keep_best(&mut out, refits_from(base, c, &params, &starts, jacobian.as_ref()));
    }
    Ok(out)
}

/// Refits from each of `starts`, side by side (a refit runs one simulation per step), each from
/// `jacobian` when given (else differenced afresh).
fn refits_from(
    base: &Base,
    c: &dyn CandidateEffect,
    params: &[Parameter],
    starts: &[Vec<f64>],
    jacobian: Option<&DMatrix<f64>>,
) -> Vec<Result<RefitOutcome>> {
    use rayon::prelude::*;
    starts.par_iter().map(|v| refit_on(&base.gauge, base, c, params, v, jacobian.cloned())).collect()
}

/// Keeps in `out` the best of it and the refits `again` (the first of equals), counting every
/// evaluation spent.
fn keep_best(out: &mut RefitOutcome, again: Vec<Result<RefitOutcome>>) {
    for o in again.into_iter().flatten() {
        let spent = out.evaluations + o.evaluations;
        if o.misfit.rss() < out.misfit.rss() {
            *out = RefitOutcome { evaluations: spent, ..o };
        } else {
            out.evaluations = spent;
        }
    }
}

/// The report of a refit: fitted and effect values, χ², shrinkage overall and per regime, and
/// information criteria against the base.
pub fn report(base: &Base, regs: &[Regime], entry: &Ranked, out: &RefitOutcome) -> Refit {
    let (n, p, space) = (base.readings(), base.space.dim(), &base.space);
    let c = entry.effect.as_ref();
    let sens = entry.sensitivity.as_ref().expect("refitted candidates have a sensitivity");
    let params: Vec<Parameter> = sens.parameters.iter().map(|q| q.parameter.clone()).collect();
    let k = p + if c.discrete() { 1 } else { sens.columns.ncols() };
    let chi = out.misfit.rss();
    let (aic, bic) = aic_bic(chi, n, k);
    let (base_aic, base_bic) = aic_bic(base.chi2, n, p);
    let before = regimes::rss_by_regime(&base.gauge, regs, &base.misfit.r);
    let after = regimes::rss_by_regime(&base.gauge, regs, &out.misfit.r);
    let by_regime = regs
        .iter()
        .zip(before.iter().zip(&after))
        .map(|(g, (b, a))| RegimeShrinkage {
            experiment: g.experiment.clone(),
            regime: g.name.clone(),
            before: *b,
            after: *a,
            shrinkage: if *b > 0.0 { 1.0 - a / b } else { 0.0 },
        })
        .collect();
    let value = |q: &Parameter, v: f64| Value { name: q.path.clone(), value: v, unit: q.unit.clone() };
    let xv = space.from_unit(&out.v[..p]);
    Refit {
        parameters: space.parameters().iter().zip(&xv).map(|(q, &v)| value(q, v)).collect(),
        effect: params.iter().zip(&out.v[p..]).map(|(q, &w)| value(q, q.from_unit(w))).collect(),
        switch: c.discrete(),
        chi2: chi,
        shrinkage: 1.0 - chi / base.chi2.max(f64::MIN_POSITIVE),
        by_regime,
        aic,
        bic,
        delta_aic: aic - base_aic,
        delta_bic: bic - base_bic,
        evaluations: out.evaluations,
        chi2_reestimated: None,
        structure_p: base.gauge.structure_p(&out.misfit.r),
    }
}
