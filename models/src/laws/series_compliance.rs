//! A cohesive law in series with a through-thickness compliance: the opening between the
//! adherends' sections is the interface's own opening plus the elastic give of the material
//! between the section and the interface, `w_n = u_n + c T_n(u_n, u_t)`, the slip unchanged.
//!
//! **Why a law, not springs.** The adherends' through-thickness compliance (Kanninen's elastic
//! foundation; the DCB's `effects.root_compliance`) acts point by point along the interface. Nodal
//! springs between each section and its own surface unknown lump it: every point then carries the
//! whole tributary length, and when the law softens steeply the series pair drops point by point
//! as the crack passes. Steep softening in series makes that worse, since the springs give back
//! the share `c |dT_n/du_n|` of every unit of opening. The global response then snaps back at each
//! node, which displacement control cannot follow. Put into the law, the compliance acts at every
//! point of the interface integration, and the segments integrate it exactly. For a law that is
//! piecewise linear along its loading path, so is the law in series (a bilinear law in series
//! with `c` is the bilinear law with the penalty `k/(1 + c k)`).
//!
//! **How.** For a gap `[w_n, w_t]` the interface's opening `u_n` solves the scalar equation
//! `u_n + c T_n(u_n, w_t) = w_n`, which is increasing in `u_n` as long as `c |dT_n/du_n| < 1`
//! (the share that [`crate::effects::Effects::check_root_compliance`] bounds). Safeguarded
//! Newton on the bracket between 0 and `w_n` solves it to round-off. The state is the wrapped
//! law's: damage, history and inner kinks mean what they mean there.

use czid_core::{CohesiveLaw, CzError, Gap, LawEval, LawState, ParameterInfo, Result, Tangent};
use serde::{Deserialize, Serialize};

use super::root::solve_monotone;

/// `law` in series with the normal compliance `normal_compliance` (mm/MPa): the opening added per
/// unit of normal traction by whatever lies between the sections and the interface (`2 c_r` for
/// two adherends with through-thickness compliance `c_r` each).
///
/// ```
/// use czid_core::CohesiveLaw;
/// use czid_models::laws::{Bilinear, SeriesCompliance};
/// let law = Bilinear::bk(1e5, 30.0, 40.0, 0.6, 1.2, 2.0).unwrap();
/// let series = SeriesCompliance::new(Box::new(law), 1e-4).unwrap();
/// // The same strength and toughness; the penalty in series with the compliance.
/// assert_eq!(series.strength(), [30.0, 40.0]);
/// assert_eq!(series.fracture_energy(), [0.6, 1.2]);
/// assert!((series.initial_stiffness()[0] - 1.0 / (1.0 / 1e5 + 1e-4)).abs() < 1e-9);
/// ```
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeriesCompliance {
    /// The interface's own law.
    pub law: Box<dyn CohesiveLaw>,
    /// Opening per unit normal traction in series with it (mm/MPa).
    pub normal_compliance: f64,
}

impl SeriesCompliance {
    /// A validated law in series.
    pub fn new(law: Box<dyn CohesiveLaw>, normal_compliance: f64) -> Result<Self> {
        let series = SeriesCompliance { law, normal_compliance };
        series.validate()?;
        Ok(series)
    }

    /// `law` (copied) in series with `normal_compliance`.
    pub fn around(law: &dyn CohesiveLaw, normal_compliance: f64) -> Result<Self> {
        Self::new(copy_of(law)?, normal_compliance)
    }

    /// The interface's own opening `u_n` at the gap `gap`, and the wrapped law's response there.
    fn solve(&self, gap: &Gap, previous: &LawState) -> (f64, LawEval) {
        let c = self.normal_compliance;
        let (w, slip) = (gap[0], gap[1]);
        let inner = |u: f64| self.law.evaluate(&Gap::new(u, slip), previous);
        let k = self.law.initial_stiffness()[0];
        // The elastic answer first: exact (one evaluation) wherever the wrapped law is linear.
        let start = w * (1.0 / (1.0 + c * k));
        // A traction of the opening's sign puts the root between 0 and `w`. The bracket reaches a
        // hair beyond `w` so that Newton may land on `w` itself: the root of failed material.
        let reach = 1e-12 * w.abs();
        let (lo, hi) = if w >= 0.0 { (0.0, w + reach) } else { (w - reach, 0.0) };
        let mut last: Option<(f64, LawEval)> = None;
        let u = solve_monotone(
            |u| {
                let e = inner(u);
                last = Some((u, e));
                (u + c * e.traction[0] - w, 1.0 + c * e.tangent[(0, 0)])
            },
            lo,
            hi,
            start,
            true,
        );
        match last {
            Some((x, e)) if x == u => (u, e),
            _ => (u, inner(u)),
        }
    }
}

/// A copy of any registered law, through its serialised form.
fn copy_of(law: &dyn CohesiveLaw) -> Result<Box<dyn CohesiveLaw>> {
    let value = serde_json::to_value(law).map_err(|e| CzError::config("law", format!("could not be copied: {e}")))?;
    serde_json::from_value(value).map_err(|e| CzError::config("law", format!("could not be read back: {e}")))
}

#[typetag::serde(name = "series_compliance")]
impl CohesiveLaw for SeriesCompliance {
    fn validate(&self) -> Result<()> {
        let c = self.normal_compliance;
        czid_core::error::require_non_negative("law series_compliance", "normal_compliance", c)?;
        // Name the wrapped law's field by its path in the configuration (`law.strength_n`).
        self.law.validate().map_err(|e| match e {
            CzError::InvalidParameter { name, value, reason, .. } => {
                CzError::invalid("law series_compliance", format!("law.{name}"), value, reason)
            }
            other => other,
        })
    }

    fn evaluate(&self, gap: &Gap, previous: &LawState) -> LawEval {
        let (_, e) = self.solve(gap, previous);
        // du_n/dw_n = a, du_n/dw_t = −c J_nt a, du_t/dw_t = 1, with a = 1/(1 + c J_nn).
        let j = e.tangent;
        let c = self.normal_compliance;
        let a = 1.0 / (1.0 + c * j[(0, 0)]);
        let tangent =
            Tangent::new(j[(0, 0)] * a, j[(0, 1)] * a, j[(1, 0)] * a, j[(1, 1)] - j[(1, 0)] * a * c * j[(0, 1)]);
        LawEval { traction: e.traction, tangent, state: e.state }
    }

    /// The compliance gives back all it stores: the toughness is the wrapped law's.
    fn fracture_energy(&self) -> [f64; 2] {
        self.law.fracture_energy()
    }

    /// The normal penalty in series with the compliance (the same expression as the elastic
    /// tangent, to the bit); the shear penalty unchanged.
    fn initial_stiffness(&self) -> [f64; 2] {
        let [k_n, k_t] = self.law.initial_stiffness();
        [k_n * (1.0 / (1.0 + self.normal_compliance * k_n)), k_t]
    }

    fn strength(&self) -> [f64; 2] {
        self.law.strength()
    }

    fn parameters(&self) -> Vec<ParameterInfo> {
        let mut list = self.law.parameters();
        list.push(ParameterInfo {
            name: "normal_compliance",
            value: self.normal_compliance,
            unit: "mm/MPa",
            meaning: "opening per unit normal traction in series with the law",
        });
        list
    }

    fn initial_state(&self) -> LawState {
        self.law.initial_state()
    }

    /// The wrapped law's stored energy at its own opening plus the compliance's `c T_n² / 2`.
    fn stored_energy(&self, gap: &Gap, state: &LawState) -> f64 {
        let (u, e) = self.solve(gap, state);
        let t = e.traction[0];
        self.law.stored_energy(&Gap::new(u, gap[1]), state) + 0.5 * self.normal_compliance * t * t
    }

    fn visible_front_kink(&self) -> Option<usize> {
        self.law.visible_front_kink()
    }

    fn inner_kinks(&self) -> usize {
        self.law.inner_kinks()
    }

    fn beyond_inner_kink(&self, state: &LawState, k: usize) -> bool {
        self.law.beyond_inner_kink(state, k)
    }

    fn with_bridging_tail(&self, strength: f64, opening: f64) -> Option<Result<Box<dyn CohesiveLaw>>> {
        let c = self.normal_compliance;
        self.law.with_bridging_tail(strength, opening).map(|tailed| {
            tailed.and_then(|law| SeriesCompliance::new(law, c).map(|s| Box::new(s) as Box<dyn CohesiveLaw>))
        })
    }
}
