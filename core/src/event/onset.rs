//! The debonded length at the onset of local debonding.

use super::{first_reaching, largest};
use crate::error::{CzError, Result};
use crate::record::{columns, Record};
use crate::response::Response;
use serde::{Deserialize, Serialize};

/// The debonded length (mm) at the onset of local debonding: where the load first reaches
/// `fraction` of its largest value, on the rising branch, linearly interpolated between the two
/// states around it.
///
/// **Why this state.** In a plated beam (the `frp_beam` model) the bond fails first at the
/// flexural crack mouths of the high-moment region, long before the peak (the paper's beam with
/// its Table 8 law: first failed points at 184 kN, 68 % of the 269 kN peak), and the debonded
/// stretches grow stably with the load. At the peak the debonding becomes unstable: the debonded
/// zone runs towards the plate end and the load falls. That instability, the first load drop, is
/// what a test reports as the onset of local debonding (the debonding is then heard and seen); the
/// first failure is not (the debonded length is zero there, a length that starts continuously from
/// zero). The peak itself is a limit point where the run jumps, and which recorded state is
/// largest depends on the path steps; so the event is read just before it, on the rising branch,
/// where the load first reaches `fraction` of the peak (0.98 by default: 534 mm debonded for the
/// paper's beam, against 572 mm at the state of the peak load). There the debonded length moves
/// with the parameters as smoothly as the run's states do. `fraction = 1` reads it at the first
/// state of the peak load.
///
/// ```
/// # use czid_core::{event::OnsetOfDebonding, Record, Response, columns};
/// let mut r = Record::new(&[(columns::LOAD, "N"), (columns::DEBONDED_LENGTH, "mm")]);
/// for (p, l) in [(0.0, 0.0), (90.0, 100.0), (99.0, 300.0), (100.0, 400.0), (60.0, 900.0)] {
///     r.push(&[p, l]);
/// }
/// // 98 % of the 100 N peak is first reached 8/9 of the way from 90 N to 99 N.
/// let onset = OnsetOfDebonding::default();
/// let l = onset.predict(&r, &[f64::NAN]).unwrap()[0];
/// assert!((l - (100.0 + 8.0 / 9.0 * 200.0)).abs() < 1e-12);
/// assert_eq!(OnsetOfDebonding::new(1.0).unwrap().predict(&r, &[0.0]).unwrap(), vec![400.0]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OnsetOfDebonding {
    /// Fraction of the peak load at which the debonded length is read, in (0, 1].
    pub fraction: f64,
}

impl Default for OnsetOfDebonding {
    fn default() -> Self {
        OnsetOfDebonding { fraction: 0.98 }
    }
}

impl OnsetOfDebonding {
    /// The debonded length where the load first reaches `fraction` of its peak.
    pub fn new(fraction: f64) -> Result<Self> {
        if !(fraction > 0.0 && fraction <= 1.0) {
            return Err(CzError::invalid("debonded_length_at_onset", "fraction", fraction, "must lie in (0, 1]"));
        }
        Ok(OnsetOfDebonding { fraction })
    }
}

impl Response for OnsetOfDebonding {
    fn name(&self) -> &str {
        "debonded_length_at_onset"
    }

    fn predict(&self, record: &Record, at: &[f64]) -> Result<Vec<f64>> {
        let (_, peak) = largest(record, columns::LOAD, self.name())?;
        let (p, l) = (record.column(columns::LOAD)?, record.column(columns::DEBONDED_LENGTH)?);
        // A load that is negative at its largest never rises to a fraction of it.
        let value = first_reaching(p, self.fraction * peak, l).ok_or_else(|| {
            CzError::data(
                format!("response `{}`", self.name()),
                format!(
                    "the load never reaches {} of its largest value {peak} (a positive load is expected)",
                    self.fraction
                ),
            )
        })?;
        Ok(vec![value; at.len()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_load_that_never_rises_to_the_fraction_is_an_error_not_a_panic() {
        let mut r = Record::new(&[(columns::LOAD, "N"), (columns::DEBONDED_LENGTH, "mm")]);
        r.push(&[-10.0, 0.0]);
        r.push(&[-20.0, 1.0]);
        let e = OnsetOfDebonding::default().predict(&r, &[0.0]).unwrap_err().to_string();
        assert!(e.contains("never reaches"), "{e}");
    }

    #[test]
    fn the_fraction_must_lie_in_zero_one() {
        for bad in [0.0, -0.5, 1.5, f64::NAN] {
            let e = OnsetOfDebonding::new(bad).unwrap_err().to_string();
            assert!(e.contains("fraction"), "{e}");
        }
    }
}
