//! Regimes of an ENF test (forward models `enf` and `enf_2d`), found from its load curve.
//!
//! An ENF specimen with `a0/L` below about 0.7 loads linearly, bends over as the process zone
//! forms, drops when the crack jumps towards the loading nose, and then loads again: with the crack
//! under the nose the arms carry the load as two beams sliding on each other, and that later rise
//! can exceed the first peak. So the peak that matters is the first one, not the largest:
//!
//! * **initial loading** and **onset/peak** as the generic rule ([`czid_core::regimes`]) finds
//!   them on the curve up to the onset (the largest load before the load first falls 5 % below
//!   its running maximum, [`crate::enf_reduction::onset_index`]); onset/peak lasts until that
//!   drop;
//! * **unstable propagation**: from the drop to the lowest load after it (the crack's jump, and
//!   its arrest);
//! * **crack at the loading nose**: from that lowest load to the end (the rise of the cracked
//!   specimen; no toughness acts there, contact and friction between the arms do).
//!
//! A curve that never drops 5 % has only the first two.
//!
//! ```
//! use czid_core::regimes::RegimeRule;
//! use czid_models::enf_regimes::{EnfRegimes, NAMES};
//!
//! // Linear to 1000 N at 4 mm, a drop to 760 N by 4.4 mm, then a rise to 1100 N at 6 mm.
//! let x: Vec<f64> = (0..=60).map(|i| i as f64 * 0.1).collect();
//! let p: Vec<f64> = x
//!     .iter()
//!     .map(|&v| if v <= 4.0 { 250.0 * v } else if v <= 4.4 { 1000.0 - 600.0 * (v - 4.0) } else { 760.0 + 212.5 * (v - 4.4) })
//!     .collect();
//! let spans = EnfRegimes.split((&x, &p), None);
//! assert_eq!(spans.iter().map(|s| s.name).collect::<Vec<_>>(), NAMES);
//! assert!((spans[3].from - 4.4).abs() < 1e-9, "the rise starts at the lowest load");
//! ```

use czid_core::regimes::{GenericRegimes, RegimeRule, Span};

use crate::enf_reduction::{onset_index, ONSET_DROP};

/// Regime names, in test order.
pub const NAMES: [&str; 4] = ["initial loading", "onset/peak", "unstable propagation", "crack at the loading nose"];

/// The ENF rule (module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EnfRegimes;

impl RegimeRule for EnfRegimes {
    fn names(&self) -> &'static [&'static str] {
        &NAMES
    }

    fn held_out_label(&self) -> &'static str {
        "rise of each curve once the crack reaches the loading nose"
    }

    fn split(&self, (x, p): (&[f64], &[f64]), _length: Option<(&[f64], &[f64])>) -> Vec<Span> {
        let n = x.len().min(p.len());
        if n == 0 {
            return Vec::new();
        }
        let onset = onset_index(&p[..n]);
        // The generic rule on the rise up to the onset: its initial loading and onset/peak.
        let mut spans: Vec<Span> = GenericRegimes
            .split((&x[..=onset], &p[..=onset]), None)
            .into_iter()
            .map(|s| Span { name: if s.name == "initial loading" { NAMES[0] } else { NAMES[1] }, ..s })
            .collect();
        let drop = (onset..n).find(|&i| p[i] < (1.0 - ONSET_DROP) * p[onset]);
        let peak_end = drop.map_or(x[n - 1], |j| x[j]);
        match spans.last_mut() {
            Some(last) if last.name == NAMES[1] => last.to = peak_end,
            _ => spans.push(Span { name: NAMES[1], from: x[onset], to: peak_end }),
        }
        if let Some(j) = drop {
            let trough = (j..n).min_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap_or(j);
            spans.push(Span { name: NAMES[2], from: x[j], to: x[trough] });
            spans.push(Span { name: NAMES[3], from: x[trough], to: x[n - 1] });
        }
        spans.retain(|s| s.to > s.from);
        spans
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_later_rise_above_the_first_peak_does_not_move_the_onset() {
        // ENF-05's shape: the rise after the jump ends above the first peak (1100 > 1000 N).
        let x: Vec<f64> = (0..=60).map(|i| i as f64 * 0.1).collect();
        let p: Vec<f64> = x
            .iter()
            .map(|&v| {
                if v <= 4.0 {
                    250.0 * v
                } else if v <= 4.4 {
                    1000.0 - 600.0 * (v - 4.0)
                } else {
                    760.0 + 212.5 * (v - 4.4)
                }
            })
            .collect();
        let spans = EnfRegimes.split((&x, &p), None);
        let names: Vec<&str> = spans.iter().map(|s| s.name).collect();
        assert_eq!(names, NAMES);
        // The load is below 950 N first at 4.1 mm (940 N); the lowest load is at 4.4 mm.
        assert!((spans[1].to - 4.1).abs() < 1e-9, "{spans:?}");
        assert!((spans[2].from - 4.1).abs() < 1e-9 && (spans[2].to - 4.4).abs() < 1e-9, "{spans:?}");
        assert!((spans[3].to - 6.0).abs() < 1e-9);
        // The generic rule, which takes the largest load as the peak, would see no drop at all.
        assert_eq!(GenericRegimes.split((&x, &p), None).len(), 2);
    }

    #[test]
    fn both_enf_models_declare_this_rule() {
        use czid_core::ForwardModel;
        let beam = crate::enf::Enf::hartlen_enf03();
        assert_eq!(beam.regimes().names(), NAMES);
        assert_eq!(beam.regimes().held_out(), NAMES[3]);
        let continuum = crate::enf_2d::Enf2d::from_beam(&beam).unwrap();
        assert_eq!(continuum.regimes().names(), NAMES);
    }

    #[test]
    fn a_curve_that_never_drops_has_only_loading_and_onset() {
        let x: Vec<f64> = (0..=40).map(|i| i as f64 * 0.1).collect();
        let p: Vec<f64> = x.iter().map(|&v| 250.0 * v - 10.0 * v * v).collect();
        let spans = EnfRegimes.split((&x, &p), None);
        assert!(spans.iter().all(|s| s.name == NAMES[0] || s.name == NAMES[1]), "{spans:?}");
        assert_eq!(spans.last().unwrap().to, 4.0);
        assert!(EnfRegimes.split((&[], &[]), None).is_empty());
    }
}
