//! Regimes of a test: its curves split into stretches where different physics governs, so a
//! diagnosis can say where a model misses (and hold the last stretch out to check transfer).
//!
//! A forward model declares the rule for its tests ([`crate::ForwardModel::regimes`]); the
//! default, [`GenericRegimes`], suits any test that loads, peaks and softens:
//! * **initial loading**: from the start until the load falls for good below 95 % of the initial
//!   line, the line through the readings at 10 % and 40 % of the peak load (so that a seating toe
//!   or a preload offset does not count as non-linearity);
//! * **onset / peak**: from there until the load has fallen 5 % below its peak (damage onset,
//!   crack initiation);
//! * **propagation**: from there over the first two thirds of the remaining displacement range;
//! * **late stage**: the last third (large displacements: where rotations, bridging lengths and
//!   machine effects grow most).
//!
//! A curve that never falls 5 % below its peak has no propagation or late stage.
//!
//! ```
//! use czid_core::regimes::{GenericRegimes, RegimeRule, NAMES};
//!
//! // Linear to 10 N at 1 mm, then softening.
//! let x: Vec<f64> = (0..=60).map(|i| i as f64 * 0.1).collect();
//! let p: Vec<f64> = x.iter().map(|&v| if v <= 1.0 { 10.0 * v } else { 10.0 / v }).collect();
//! let spans = GenericRegimes.split((&x, &p), None);
//! assert_eq!(spans.iter().map(|s| s.name).collect::<Vec<_>>(), NAMES);
//! assert_eq!(GenericRegimes.held_out(), "late stage");
//! ```

/// A regime of one test: displacements in `[from, to)` (mm; the last regime includes its end).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    /// One of the rule's [`RegimeRule::names`].
    pub name: &'static str,
    /// First displacement (mm).
    pub from: f64,
    /// End displacement (mm).
    pub to: f64,
}

/// How a test is split into regimes.
pub trait RegimeRule: Send + Sync + std::fmt::Debug {
    /// Regime names, in test order.
    fn names(&self) -> &'static [&'static str];

    /// The regime held out of a fit to check transfer, when it is the last of a test (default:
    /// the last name).
    fn held_out(&self) -> &'static str {
        self.names().last().copied().unwrap_or("")
    }

    /// How the held-out part is named in reports, e.g. "late stage of each curve".
    fn held_out_label(&self) -> &'static str;

    /// Splits a test: its load curve `(x, p)` (displacement in mm, load in N) and, when measured,
    /// its debonded length `(x, l)` (mm) on its own abscissae. Regimes that do not occur are
    /// left out.
    fn split(&self, load: (&[f64], &[f64]), length: Option<(&[f64], &[f64])>) -> Vec<Span>;
}

/// Regime names of the generic rule, in test order.
pub const NAMES: [&str; 4] = ["initial loading", "onset/peak", "propagation", "late stage"];

/// Secant stiffness drop that ends the initial loading.
const LINEAR_DROP: f64 = 0.05;
/// Share of the peak load where the initial line starts (below, toes and offsets).
const FIRST_LOAD: f64 = 0.1;
/// Share of the peak load where the initial line ends.
const LINE_LOAD: f64 = 0.4;
/// Load drop below the peak that ends the onset/peak regime.
const PEAK_DROP: f64 = 0.05;
/// Share of the post-peak displacement range counted as propagation; the rest is the late stage.
const PROPAGATION_SHARE: f64 = 2.0 / 3.0;

/// The rule for any test that loads, peaks and softens (module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GenericRegimes;

impl RegimeRule for GenericRegimes {
    fn names(&self) -> &'static [&'static str] {
        &NAMES
    }

    fn held_out_label(&self) -> &'static str {
        "late stage of each curve"
    }

    fn split(&self, load: (&[f64], &[f64]), _length: Option<(&[f64], &[f64])>) -> Vec<Span> {
        split_generic(load.0, load.1)
    }
}

/// The generic split of a load curve `(x, p)` (displacement in mm, load in N).
fn split_generic(x: &[f64], p: &[f64]) -> Vec<Span> {
    let n = x.len();
    if n == 0 {
        return Vec::new();
    }
    let end = x[n - 1];
    let peak = (0..n).max_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap_or(0);
    // The initial line: through the readings at 10 % and 40 % of the peak load (below 10 % a
    // seating toe or a preload offset dominates). Linear loading lasts until the load falls
    // below 95 % of that line for good (a single noisy reading does not end it).
    let at = |share: f64| (0..=peak).find(|&i| p[i] >= share * p[peak]);
    let linear_end = match (at(FIRST_LOAD), at(LINE_LOAD)) {
        (Some(a), Some(b)) if x[b] > x[a] => {
            let k0 = (p[b] - p[a]) / (x[b] - x[a]);
            let below = |i: usize| p[i] < (1.0 - LINEAR_DROP) * (p[a] + k0 * (x[i] - x[a]));
            (b..=peak).find(|&i| (i..=peak).all(below)).unwrap_or(peak)
        }
        _ => peak,
    };
    let peak_end = (peak..n).find(|&i| p[i] < (1.0 - PEAK_DROP) * p[peak]);
    let mut bounds = vec![(NAMES[0], x[0], x[linear_end])];
    match peak_end {
        Some(j) => {
            bounds.push((NAMES[1], x[linear_end], x[j]));
            let late = x[j] + PROPAGATION_SHARE * (end - x[j]);
            bounds.push((NAMES[2], x[j], late));
            bounds.push((NAMES[3], late, end));
        }
        None => bounds.push((NAMES[1], x[linear_end], end)),
    }
    bounds.into_iter().filter(|(_, a, b)| b > a).map(|(name, from, to)| Span { name, from, to }).collect()
}
