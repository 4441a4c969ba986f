//! Measured events of a test: single values (the peak load, the debonded length at the onset of
//! local debonding or at the end of the test, the displacement at a load) compared with the
//! matching [`czid_core::event`] response of the run.
//!
//! In a problem file, one `[[experiment.event]]` table per event:
//!
//! ```toml
//! [[experiment.event]]
//! kind = "debonded_length_at_onset"   # or debonded_length_at_end, peak_load, displacement_at_load
//! value = 436.0                       # the measured value, in `unit`
//! unit = "mm"                         # mm, m, in (lengths); N, kN, lbf (the peak load)
//! fraction = 0.98                     # onset only: of the peak load (default 0.98)
//! weight = 1.0                        # optional factor on the term's α (default 1)
//! uncertainty = 10.0                  # optional: the reading's standard uncertainty, in `unit`
//!
//! [[experiment.event]]
//! kind = "debonded_length_at_end"
//! value = 1048.0
//! unit = "mm"
//! at = 26.0                           # end only: the test's last displacement, in `unit`
//!                                     # (default: the last displacement of the data)
//!
//! [[experiment.event]]
//! kind = "displacement_at_load"
//! value = 12.6
//! unit = "mm"
//! load = 200.0                        # the load, in `load_unit` (default N)
//! load_unit = "kN"
//! ```
//!
//! Each event is one term of the objective, `φ = (y − ŷ)/|y|` (its relative error), weighted like
//! a curve: `weights = "balanced"` gives it the same share at the initial guess as every other
//! term, explicit weights give it `events = α_E` (default 1); `weight` multiplies either.
//!
//! **Uncertainty.** A measured event is one reading, so the data cannot say how well it is known;
//! `uncertainty` says it (e.g. 10 mm for a debonded length read off a plate with a ruler). It does
//! not change the objective. After an identification, an event that the fit misses by more than
//! [`MISSED_EVENT_FACTOR`] times its uncertainty is named in a warning and makes every verdict
//! provisional: the fit is not at the level of the data (a local minimum, or a model-form
//! difference), and standard errors computed there describe that misfit, not the parameters.

use crate::data::{ForceUnit, LengthUnit};
use czid_core::event::{DisplacementAtLoad, EndOfTest, OnsetOfDebonding, PeakLoad};
use czid_core::{CzError, Response, Result};
use serde::{Deserialize, Serialize};

/// What an event is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// [`OnsetOfDebonding`].
    DebondedLengthAtOnset,
    /// [`EndOfTest`].
    DebondedLengthAtEnd,
    /// [`PeakLoad`].
    PeakLoad,
    /// [`DisplacementAtLoad`].
    DisplacementAtLoad,
}

impl EventKind {
    /// The name used in term names and reports.
    pub fn key(self) -> &'static str {
        match self {
            EventKind::DebondedLengthAtOnset => "debonded_length_at_onset",
            EventKind::DebondedLengthAtEnd => "debonded_length_at_end",
            EventKind::PeakLoad => "peak_load",
            EventKind::DisplacementAtLoad => "displacement_at_load",
        }
    }

    /// Whether its value is a force (else a length).
    fn is_force(self) -> bool {
        self == EventKind::PeakLoad
    }
}

/// One `[[experiment.event]]` table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EventSpec {
    /// What is measured.
    pub kind: EventKind,
    /// Name in reports (default: the kind).
    #[serde(default)]
    pub name: Option<String>,
    /// The measured value, in `unit`.
    pub value: f64,
    /// Unit of `value` (and of `at`): `mm`, `m`, `in`, or for the peak load `N`, `kN`, `lbf`.
    pub unit: String,
    /// Factor on the term's weight α (default 1).
    #[serde(default)]
    pub weight: Option<f64>,
    /// `debonded_length_at_onset`: fraction of the peak load at which the length is read.
    #[serde(default)]
    pub fraction: Option<f64>,
    /// `debonded_length_at_end`: the test's last displacement, in `unit`.
    #[serde(default)]
    pub at: Option<f64>,
    /// `displacement_at_load`: the load, in `load_unit`.
    #[serde(default)]
    pub load: Option<f64>,
    /// Unit of `load` (default N).
    #[serde(default)]
    pub load_unit: ForceUnit,
    /// Standard uncertainty of the reading, in `unit` (optional; see the module documentation).
    #[serde(default)]
    pub uncertainty: Option<f64>,
}

/// How many uncertainties an identified fit may miss a measured event by before it is reported
/// (a normally distributed reading lies within 3 standard uncertainties 99.7 % of the time).
pub const MISSED_EVENT_FACTOR: f64 = 3.0;

/// A checked event with its value in N or mm.
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuredEvent {
    /// Name in reports.
    pub name: String,
    /// What is measured.
    pub kind: EventKind,
    /// The measured value (N or mm).
    pub value: f64,
    /// Factor on the term's weight.
    pub weight: f64,
    /// Standard uncertainty of the reading (N or mm), if given.
    pub uncertainty: Option<f64>,
    /// The response it is compared with.
    pub response: EventResponse,
}

/// The simulated counterpart of an event (a closed set, so that events can be cloned and compared).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EventResponse {
    /// Debonded length at the onset of local debonding.
    Onset(OnsetOfDebonding),
    /// Debonded length at the end of the test.
    End(EndOfTest),
    /// Peak load.
    Peak(PeakLoad),
    /// Displacement at a load.
    AtLoad(DisplacementAtLoad),
}

impl EventResponse {
    /// As a boxed [`Response`].
    pub fn boxed(&self) -> Box<dyn Response> {
        match *self {
            EventResponse::Onset(r) => Box::new(r),
            EventResponse::End(r) => Box::new(r),
            EventResponse::Peak(r) => Box::new(r),
            EventResponse::AtLoad(r) => Box::new(r),
        }
    }
}

impl MeasuredEvent {
    /// Its unit after conversion: `N` or `mm`.
    pub fn unit(&self) -> &'static str {
        if self.kind.is_force() {
            "N"
        } else {
            "mm"
        }
    }
}

fn length_unit(unit: &str) -> Option<LengthUnit> {
    match unit {
        "mm" => Some(LengthUnit::Millimetre),
        "m" => Some(LengthUnit::Metre),
        "in" => Some(LengthUnit::Inch),
        _ => None,
    }
}

fn force_unit(unit: &str) -> Option<ForceUnit> {
    match unit {
        "N" => Some(ForceUnit::N),
        "kN" => Some(ForceUnit::KiloNewton),
        "lbf" => Some(ForceUnit::PoundForce),
        _ => None,
    }
}

impl EventSpec {
    /// Checks the event and converts it to N and mm; `owner` names it in errors (e.g.
    /// `problem.toml, experiment 1, event 2`), `last_displacement` is the data's last displacement
    /// (mm), the default end of the test.
    pub fn check(&self, owner: &str, last_displacement: f64) -> Result<MeasuredEvent> {
        let kind = self.kind;
        let field = |f: &str| format!("{owner} ({}): `{f}`", kind.key());
        let factor = if kind.is_force() {
            force_unit(&self.unit).map(ForceUnit::to_newton).ok_or_else(|| {
                CzError::config(field("unit"), format!("`{}` is not a force unit; use N, kN or lbf", self.unit))
            })?
        } else {
            length_unit(&self.unit).map(LengthUnit::to_mm).ok_or_else(|| {
                CzError::config(field("unit"), format!("`{}` is not a length unit; use mm, m or in", self.unit))
            })?
        };
        let value = self.value * factor;
        if !(value.is_finite() && value > 0.0) {
            return Err(CzError::config(field("value"), format!("{} must be a positive, finite value", self.value)));
        }
        let weight = self.weight.unwrap_or(1.0);
        if !(weight.is_finite() && weight >= 0.0) {
            return Err(CzError::config(field("weight"), format!("{weight} must be finite and ≥ 0")));
        }
        let only = |name: &str, given: bool, for_kind: EventKind| -> Result<()> {
            if given && kind != for_kind {
                return Err(CzError::config(field(name), format!("only applies to `{}` events", for_kind.key())));
            }
            Ok(())
        };
        only("fraction", self.fraction.is_some(), EventKind::DebondedLengthAtOnset)?;
        only("at", self.at.is_some(), EventKind::DebondedLengthAtEnd)?;
        only("load", self.load.is_some(), EventKind::DisplacementAtLoad)?;
        let rename = |e: CzError, name: &str| CzError::config(field(name), e.to_string());
        let response = match kind {
            EventKind::DebondedLengthAtOnset => EventResponse::Onset(match self.fraction {
                Some(f) => OnsetOfDebonding::new(f).map_err(|e| rename(e, "fraction"))?,
                None => OnsetOfDebonding::default(),
            }),
            EventKind::DebondedLengthAtEnd => {
                let at = self.at.map_or(last_displacement, |a| a * factor);
                EventResponse::End(EndOfTest::at(at).map_err(|e| rename(e, "at"))?)
            }
            EventKind::PeakLoad => EventResponse::Peak(PeakLoad),
            EventKind::DisplacementAtLoad => {
                let load = self.load.ok_or_else(|| {
                    CzError::config(field("load"), "is missing: the load at which the displacement is read")
                })?;
                EventResponse::AtLoad(
                    DisplacementAtLoad::new(load * self.load_unit.to_newton()).map_err(|e| rename(e, "load"))?,
                )
            }
        };
        let uncertainty = match self.uncertainty {
            Some(u) if u.is_finite() && u > 0.0 => Some(u * factor),
            Some(u) => {
                return Err(CzError::config(
                    field("uncertainty"),
                    format!("{u} must be a positive, finite value in `{}`", self.unit),
                ))
            }
            None => None,
        };
        let name = self.name.clone().unwrap_or_else(|| kind.key().to_string());
        Ok(MeasuredEvent { name, kind, value, weight, uncertainty, response })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(text: &str) -> EventSpec {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn values_are_converted_and_defaults_applied() {
        let e = spec("kind = \"debonded_length_at_end\"\nvalue = 1.048\nunit = \"m\"").check("p", 26.0).unwrap();
        assert_eq!((e.value, e.weight, e.unit()), (1048.0, 1.0, "mm"));
        assert_eq!(e.response, EventResponse::End(EndOfTest { at: Some(26.0) }));
        let e = spec("kind = \"peak_load\"\nvalue = 269.2\nunit = \"kN\"\nweight = 0.5").check("p", 1.0).unwrap();
        assert_eq!((e.value, e.weight, e.unit(), e.name.as_str()), (269_200.0, 0.5, "N", "peak_load"));
        let e = spec("kind = \"displacement_at_load\"\nvalue = 12.6\nunit = \"mm\"\nload = 200\nload_unit = \"kN\"")
            .check("p", 1.0)
            .unwrap();
        assert_eq!(e.response, EventResponse::AtLoad(DisplacementAtLoad { load: 200_000.0 }));
        let e = spec("kind = \"debonded_length_at_onset\"\nvalue = 436\nunit = \"mm\"").check("p", 1.0).unwrap();
        assert_eq!(e.response, EventResponse::Onset(OnsetOfDebonding { fraction: 0.98 }));
        assert_eq!(e.uncertainty, None);
        let e = spec("kind = \"debonded_length_at_onset\"\nvalue = 0.436\nunit = \"m\"\nuncertainty = 0.01")
            .check("p", 1.0)
            .unwrap();
        assert_eq!(e.uncertainty, Some(10.0));
    }

    #[test]
    fn errors_name_the_field() {
        let cases = [
            ("kind = \"peak_load\"\nvalue = 1\nunit = \"mm\"", "`unit`"),
            ("kind = \"debonded_length_at_end\"\nvalue = 1\nunit = \"kN\"", "`unit`"),
            ("kind = \"peak_load\"\nvalue = -1\nunit = \"N\"", "`value`"),
            ("kind = \"peak_load\"\nvalue = 1\nunit = \"N\"\nweight = -2", "`weight`"),
            ("kind = \"peak_load\"\nvalue = 1\nunit = \"N\"\nfraction = 0.9", "`fraction`"),
            ("kind = \"debonded_length_at_onset\"\nvalue = 1\nunit = \"mm\"\nfraction = 1.5", "`fraction`"),
            ("kind = \"displacement_at_load\"\nvalue = 1\nunit = \"mm\"", "`load`"),
            ("kind = \"displacement_at_load\"\nvalue = 1\nunit = \"mm\"\nload = 0", "`load`"),
            ("kind = \"debonded_length_at_onset\"\nvalue = 1\nunit = \"mm\"\nat = 3", "`at`"),
            ("kind = \"peak_load\"\nvalue = 1\nunit = \"N\"\nuncertainty = 0", "`uncertainty`"),
            ("kind = \"peak_load\"\nvalue = 1\nunit = \"N\"\nuncertainty = -3", "`uncertainty`"),
        ];
        for (text, name) in cases {
            let e = spec(text).check("problem.toml, experiment 1, event 1", 10.0).unwrap_err().to_string();
            assert!(e.contains(name) && e.contains("experiment 1, event 1"), "{text}: {e}");
        }
        let unknown = toml::from_str::<EventSpec>("kind = \"peak_load\"\nvalue = 1\nunit = \"N\"\nsigma = 2");
        assert!(unknown.unwrap_err().to_string().contains("sigma"));
        let kind = toml::from_str::<EventSpec>("kind = \"onset\"\nvalue = 1\nunit = \"N\"");
        assert!(kind.unwrap_err().to_string().contains("debonded_length_at_onset"));
    }
}
