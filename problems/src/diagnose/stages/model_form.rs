//! The model-form floor: how much of the misfit the base model's own form leaves on any test.
//!
//! A beam model is not the specimen: even a test with no unmodelled effect differs from it by the
//! root rotation and the local shear at the crack front that beam theory leaves out, a misfit
//! that is smooth, systematic and, at the noise of a good test, significant. Judged against the
//! noise alone, that misfit is taken for an effect (a shear or root compliance, a crack-length
//! offset). Where a model names an independent model of the same test
//! ([`czid_core::ForwardModel::reference`], e.g. the continuum DCB for the beam DCB), the base fit's
//! law is run through it and the difference between the two models' predictions, smoothed along
//! each curve, is the model-form misfit: the data are shifted by it (`y + (beam − reference)`),
//! the base fit polished again, and every later stage (scores, refits, transfer) judges the
//! candidates against the noise on data whose model-form part is accounted for. The base model
//! then stands for the reference model at the cost of one reference run. Where the reference
//! has a coarsened twin ([`czid_core::ForwardModel::coarsened`]), the twin's shift minus the
//! reference's is the floor's own error, which the structure test allows for
//! ([`crate::diagnose::stats::structure_p_with_floor`]).

use super::base::Base;
use crate::diagnose::gauge::{Gauge, Misfit};
use crate::identification::Setup;
use czid_core::{ForwardModel, Result};
use serde::Serialize;
use std::collections::BTreeMap;

/// Readings on either side of each reading in the local straight-line fit that smooths the
/// model-form shift: wide enough to average a crack front's element-by-element ripple (about one
/// reading of a DCB test), narrow enough to keep the shift's shape at the peak.
const HALF_WINDOW: usize = 5;

/// What the model-form floor found.
#[derive(Clone, Debug, Serialize)]
pub struct ModelForm {
    /// The reference model of each experiment (`None`: the floor was not estimated).
    pub reference: BTreeMap<String, String>,
    /// χ² of the base fit on the data as measured.
    pub chi2_as_measured: f64,
    /// χ² of the base fit once the model-form shift is accounted for.
    pub chi2_accounted: f64,
    /// RMS of the model-form shift (noise units): how far the base model's form alone sits from
    /// the reference's.
    pub shift_rms: f64,
    /// Largest shift (noise units).
    pub shift_max: f64,
    /// RMS of the floor's own uncertainty (noise units): the shift computed again with each
    /// reference model's coarsened twin ([`czid_core::ForwardModel::coarsened`]), minus the shift,
    /// smoothed. 0 when a reference has no coarsened twin (the floor is then taken as exact).
    pub floor_rms: f64,
    /// Why the floor was not estimated, when it was not.
    pub note: Option<String>,
}

impl ModelForm {
    /// A floor that was not estimated, and why.
    pub fn not_estimated(chi2: f64, note: String) -> Self {
        ModelForm {
            reference: BTreeMap::new(),
            chi2_as_measured: chi2,
            chi2_accounted: chi2,
            shift_rms: 0.0,
            shift_max: 0.0,
            floor_rms: 0.0,
            note: Some(note),
        }
    }

    /// Whether the shift was applied.
    pub fn applied(&self) -> bool {
        self.note.is_none()
    }
}

/// The fitted setup with every model replaced by its reference, or why it has none.
fn reference_setup(fitted: &Setup) -> std::result::Result<(Setup, BTreeMap<String, String>), String> {
    let mut models: BTreeMap<String, Box<dyn ForwardModel>> = BTreeMap::new();
    let mut names = BTreeMap::new();
    for (name, m) in &fitted.models {
        let r = m.reference().ok_or_else(|| format!("the `{}` model of {name} names no reference model", m.name()))?;
        names.insert(name.clone(), r.name().to_string());
        models.insert(name.clone(), r);
    }
    let law = fitted.duplicate().map_err(|e| e.to_string())?.law;
    Ok((Setup { law, models }, names))
}

/// `reference` with every model replaced by its coarsened twin; `None` when one has none.
fn coarsened_setup(reference: &Setup) -> Option<Setup> {
    let models = reference.models.iter().map(|(n, m)| Some((n.clone(), m.coarsened()?))).collect::<Option<_>>()?;
    let law = reference.duplicate().ok()?.law;
    Some(Setup { law, models })
}

/// Per block and reading, the estimated error of the model-form shift `raw` (noise units,
/// unsmoothed `(base − reference)/σ`): `smooth(raw_coarse − raw)`, signed, the change the
/// reference's coarsened twin makes; `None` when there is no twin or its run stopped early (the
/// floor is then taken as exact).
fn floor_error(gauge: &Gauge, reference: &Setup, raw: &[f64], r: &[f64]) -> Result<Option<Vec<f64>>> {
    let Some(coarse) = coarsened_setup(reference) else { return Ok(None) };
    let misfit = Misfit::of(gauge, &coarse)?;
    if !misfit.failures.is_empty() {
        return Ok(None);
    }
    let mut out = Vec::with_capacity(gauge.len());
    for (b, range) in gauge.blocks.iter().zip(gauge.ranges()) {
        let d: Vec<f64> = range.map(|i| (misfit.r[i] - r[i]) - raw[i]).collect();
        out.extend(smooth(&b.x, &d));
    }
    Ok(Some(out))
}

/// Local straight-line fit of `v` over `x`, `HALF_WINDOW` readings on either side.
pub fn smooth(x: &[f64], v: &[f64]) -> Vec<f64> {
    let n = v.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(HALF_WINDOW), (i + HALF_WINDOW + 1).min(n));
            let m = (b - a) as f64;
            let (mx, mv) = (x[a..b].iter().sum::<f64>() / m, v[a..b].iter().sum::<f64>() / m);
            let sxx: f64 = x[a..b].iter().map(|xi| (xi - mx) * (xi - mx)).sum();
            let sxv: f64 = x[a..b].iter().zip(&v[a..b]).map(|(xi, vi)| (xi - mx) * (vi - mv)).sum();
            let slope = if sxx > 0.0 { sxv / sxx } else { 0.0 };
            mv + slope * (x[i] - mx)
        })
        .collect()
}

/// The gauge with the model-form shift of the base fit added to its data, and what was found;
/// the gauge is `None` when the floor could not be estimated (no reference model, a reference
/// run that stopped early).
pub fn account(base: &Base) -> Result<(Option<Gauge>, ModelForm)> {
    let (setup, reference) = match reference_setup(&base.fitted) {
        Ok(s) => s,
        Err(note) => return Ok((None, ModelForm::not_estimated(base.chi2, note))),
    };
    let shifted = match shift(&base.gauge, &base.misfit.r, &setup)? {
        Ok(s) => s,
        Err(note) => return Ok((None, ModelForm::not_estimated(base.chi2, note))),
    };
    let (mut gauge, shift, raw) = shifted;
    let n = shift.len().max(1) as f64;
    let mut floor_rms = 0.0;
    if let Some(floor) = floor_error(&base.gauge, &setup, &raw, &base.misfit.r)? {
        floor_rms = (floor.iter().map(|f| f * f).sum::<f64>() / n).sqrt();
        for (b, range) in gauge.blocks.iter_mut().zip(base.gauge.ranges()) {
            b.floor = floor[range].iter().map(|f| f * b.sigma).collect();
        }
    }
    let form = ModelForm {
        reference,
        chi2_as_measured: base.chi2,
        chi2_accounted: f64::NAN,
        shift_rms: (shift.iter().map(|s| s * s).sum::<f64>() / n).sqrt(),
        shift_max: shift.iter().fold(0.0, |m, s| m.max(s.abs())),
        floor_rms,
        note: None,
    };
    Ok((Some(gauge), form))
}

/// The measured gauge shifted by the model-form misfit of `fitted` (the base model with other
/// values of the fitted parameters, e.g. a refit's), for a second look at a refit once the
/// parameters have moved; `None` when it cannot be estimated.
pub fn account_at(measured: &Gauge, fitted: &Setup) -> Result<Option<Gauge>> {
    let Ok((setup, _)) = reference_setup(fitted) else { return Ok(None) };
    let beam = Misfit::of(measured, fitted)?;
    if !beam.failures.is_empty() {
        return Ok(None);
    }
    Ok(shift(measured, &beam.r, &setup)?.ok().map(|s| s.0))
}

/// `gauge` with the floor uncertainty of `from` (the same blocks, e.g. the base fit's gauge).
pub fn with_floor_of(mut gauge: Gauge, from: &Gauge) -> Gauge {
    for (b, f) in gauge.blocks.iter_mut().zip(&from.blocks) {
        if b.x.len() == f.floor.len() {
            b.floor.clone_from(&f.floor);
        }
    }
    gauge
}

/// A shifted gauge, the smoothed shift and the raw one (noise units).
type Shifted = (Gauge, Vec<f64>, Vec<f64>);

/// `gauge` with its data shifted by the smoothed difference between the residuals `r` of the
/// base model and those of the `reference` setup, and that shift (noise units, smoothed and raw);
/// or why not.
fn shift(gauge: &Gauge, r: &[f64], reference: &Setup) -> Result<std::result::Result<Shifted, String>> {
    let misfit = Misfit::of(gauge, reference)?;
    if !misfit.failures.is_empty() {
        return Ok(Err(format!("the reference model stopped early: {}", misfit.failures.join("; "))));
    }
    let mut shifted = gauge.clone();
    let (mut all, mut all_raw) = (Vec::with_capacity(gauge.len()), Vec::with_capacity(gauge.len()));
    for (b, range) in shifted.blocks.iter_mut().zip(gauge.ranges()) {
        // (test − reference)/σ − (test − base)/σ = (base − reference)/σ.
        let raw: Vec<f64> = range.map(|i| misfit.r[i] - r[i]).collect();
        let s = smooth(&b.x, &raw);
        for (y, v) in b.y.iter_mut().zip(&s) {
            *y += b.sigma * v;
        }
        all.extend(s);
        all_raw.extend(raw);
    }
    Ok(Ok((shifted, all, all_raw)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothing_keeps_a_straight_line_and_averages_a_ripple() {
        let x: Vec<f64> = (0..60).map(|i| 0.1 * i as f64).collect();
        let line: Vec<f64> = x.iter().map(|v| 2.0 - 0.5 * v).collect();
        for (a, b) in smooth(&x, &line).iter().zip(&line) {
            assert!((a - b).abs() < 1e-12);
        }
        let ripple: Vec<f64> = (0..60).map(|i| if i % 2 == 0 { 1.0 } else { -1.0 }).collect();
        let s = smooth(&x, &ripple);
        assert!(s[10..50].iter().all(|v| v.abs() < 0.1), "{s:?}");
    }
}
