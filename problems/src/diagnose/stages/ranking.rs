//! Which effects: every candidate that applies to the fitted setup, its score statistic at the
//! base fit (best first), and the pairs of candidates whose sensitivities the data cannot tell
//! apart.

use super::base::Base;
use crate::diagnose::candidate::CandidateEffect;
use crate::diagnose::run::{CandidateResult, Confusable, CONFUSABLE};
use crate::diagnose::score::{self, Linearisation, Sensitivity};
use std::sync::Arc;

/// How much smaller the step of a second try at a failed candidate's sensitivity is.
const RETRY_STEP: f64 = 4.0;

/// A candidate with its result so far and, when it could be evaluated, its sensitivity.
pub struct Ranked {
    /// The effect.
    pub effect: Arc<dyn CandidateEffect>,
    /// Its score, and later its refit and transfer.
    pub result: CandidateResult,
    /// Its sensitivity at the base fit (`None` when its runs failed).
    pub sensitivity: Option<Sensitivity>,
}

/// The candidates ranked at the base fit.
pub struct Ranking {
    /// Best score first.
    pub ranked: Vec<Ranked>,
    /// Candidates that do not apply, with the reason.
    pub skipped: Vec<(String, String)>,
    /// Every pair's cosine beyond the fitted parameters' span.
    pub pairs: Vec<Confusable>,
    /// The pairs above [`CONFUSABLE`].
    pub confusable: Vec<Confusable>,
}

/// Scores the `chosen` candidates that apply to the base fit and ranks them.
pub fn rank(base: &Base, lin: &Linearisation, chosen: Vec<Arc<dyn CandidateEffect>>) -> Ranking {
    let mut skipped = Vec::new();
    let applicable: Vec<Arc<dyn CandidateEffect>> = chosen
        .into_iter()
        .filter(|c| {
            let ok = c.applies(&base.fitted);
            if !ok {
                skipped.push((
                    c.name().to_string(),
                    "does not apply to this setup (other model type or law, or already switched on)".to_string(),
                ));
            }
            ok
        })
        .collect();
    let effects: Vec<&dyn CandidateEffect> = applicable.iter().map(|c| c.as_ref()).collect();
    let mut sens = score::sensitivities(&base.gauge, &base.fitted, &base.misfit.r, &effects, score::EFFECT_STEP);
    // A candidate whose runs failed is tried again closer to its null value (a run at a smaller
    // effect is more often one the model can follow); if it fails again, it is reported as not
    // evaluated and the verdict is provisional.
    let failed: Vec<usize> = (0..sens.len()).filter(|&i| sens[i].is_err()).collect();
    if !failed.is_empty() {
        let again: Vec<&dyn CandidateEffect> = failed.iter().map(|&i| effects[i]).collect();
        let retried =
            score::sensitivities(&base.gauge, &base.fitted, &base.misfit.r, &again, score::EFFECT_STEP / RETRY_STEP);
        for (&i, r) in failed.iter().zip(retried) {
            sens[i] = r.map_err(|e| format!("{e} (also with a {RETRY_STEP}× smaller step)"));
        }
    }
    let tests = applicable.len();
    let mut ranked: Vec<Ranked> = applicable
        .iter()
        .zip(sens)
        .map(|(c, s)| {
            let (score, error, sensitivity) = match s {
                Ok(s) => (Some(score::score(lin, &s, &base.space, &base.u, tests)), None, Some(s)),
                Err(e) => (None, Some(e), None),
            };
            let result = CandidateResult {
                name: c.name().into(),
                description: c.describe(),
                score,
                error,
                refit: None,
                transfer: Vec::new(),
                on_request: false,
            };
            Ranked { effect: c.clone(), result, sensitivity }
        })
        .collect();
    ranked.sort_by(|a, b| {
        let s = |r: &CandidateResult| r.score.as_ref().map_or(-1.0, |s| s.statistic);
        s(&b.result).total_cmp(&s(&a.result))
    });
    let mut pairs = Vec::new();
    for i in 0..ranked.len() {
        for j in i + 1..ranked.len() {
            if let (Some(a), Some(b)) = (&ranked[i].sensitivity, &ranked[j].sensitivity) {
                let cos = score::confusability(lin, a, b);
                pairs.push(Confusable { a: a.name.clone(), b: b.name.clone(), cos });
            }
        }
    }
    let confusable = pairs.iter().filter(|c| c.cos > CONFUSABLE).cloned().collect();
    Ranking { ranked, skipped, pairs, confusable }
}

impl Ranking {
    /// Indices of the candidates to refit: every significant one, best score first, up to
    /// `refit`; when the base fit is `above_noise`, the two best scored at least (an effect the
    /// first-order score underrates may still remove the misfit); plus any named in `always`
    /// (e.g. a benchmark's planted effect), which are marked
    /// [`CandidateResult::on_request`](crate::diagnose::run::CandidateResult::on_request) when
    /// the diagnosis would not have refitted them itself.
    pub fn to_refit(&mut self, refit: usize, above_noise: bool, always: &[String]) -> Vec<usize> {
        let scored: Vec<usize> = (0..self.ranked.len())
            .filter(|&i| self.ranked[i].result.score.as_ref().is_some_and(|s| s.dof > 0))
            .collect();
        let significant = |i: &usize| self.ranked[*i].result.score.as_ref().is_some_and(|s| s.significant);
        let mut top: Vec<usize> = scored.iter().copied().filter(significant).take(refit).collect();
        if above_noise {
            for &i in scored.iter().take(2) {
                if !top.contains(&i) {
                    top.push(i);
                }
            }
        }
        let extra: Vec<usize> = scored
            .iter()
            .copied()
            .filter(|&i| !top.contains(&i) && always.contains(&self.ranked[i].result.name))
            .collect();
        for &i in &extra {
            self.ranked[i].result.on_request = true;
        }
        top.extend(extra);
        top
    }
}
