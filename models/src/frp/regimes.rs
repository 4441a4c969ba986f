//! Regimes of an FRP-strengthened RC beam test (forward model `frp_beam`), found from its
//! load–deflection curve and, when measured, its debonded length.
//!
//! * **debonding**: from the load peak, the intermediate-crack (IC) debonding load, to the end of
//!   the test (the debonded zone runs towards the plate end and the load falls), provided the
//!   load falls at least 5 % below the peak after it (else the test stopped before IC debonding:
//!   no debonding regime). When the debonded length is measured it must grow too, and may move
//!   the start later: the length's *onset* is the first reading from which every later one lies
//!   more than 5 noise standard deviations (estimated from the length curve itself) above the
//!   length at the start of the test. An onset before the peak is local debonding at the crack
//!   mouths, which barely changes the load path (in the paper's beam the stiffness goes from 14.1
//!   to 13.1 kN/mm) and stays in the regimes before; an onset after the peak starts the regime
//!   there; a length that never grows means no debonding regime.
//! * Before that, the readings from 5 % of the peak load on (below, a seating toe) are fitted by
//!   a **continuous three-segment piecewise-linear** load–deflection curve in the least-squares
//!   sense, its two breakpoints searched exhaustively over the readings (prefix sums make each
//!   candidate pair's fit O(1)); every segment holds at least 3 readings:
//!   * **uncracked**: from the start to the first breakpoint (concrete cracking);
//!   * **cracked**: to the second breakpoint (first yield of the bars);
//!   * **yielded**: to the start of debonding.
//!
//!   A breakpoint across which the fitted stiffness falls by less than 10 % marks no change of
//!   regime: the regime it would start is missing (merged into the one before).
//!
//! The model `frp_beam` takes its flexural cracks as formed (no concrete tension at a crack from
//! the first step), so its own curves have no uncracked stage: their first stiffness loss is the
//! bond leaving its elastic branch at the crack mouths, which this rule then reports as cracking.

use czid_core::noise;
use czid_core::regimes::{RegimeRule, Span};

/// Regime names, in test order.
pub const NAMES: [&str; 4] = ["uncracked", "cracked", "yielded", "debonding"];
/// Share of the peak load below which readings are left out of the piecewise-linear fit.
const FIRST_LOAD: f64 = 0.05;
/// Fewest readings per segment of the fit.
const MIN_SEGMENT: usize = 3;
/// Smallest relative stiffness loss across a breakpoint that marks a change of regime.
const STIFFNESS_LOSS: f64 = 0.1;
/// Noise standard deviations above its start value that the debonded length must exceed for good.
const LENGTH_ONSET: f64 = 5.0;
/// Load drop below the peak that shows IC debonding.
const PEAK_DROP: f64 = 0.05;

/// A continuous three-segment piecewise-linear fit: breakpoints (reading indices into the fitted
/// slice) and the slopes of the three segments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trilinear {
    /// Index of the first breakpoint.
    pub first: usize,
    /// Index of the second breakpoint.
    pub second: usize,
    /// Slopes of the three segments (N/mm).
    pub slopes: [f64; 3],
    /// Sum of squared residuals (N²).
    pub rss: f64,
}

/// Suffix sums of `1, x, x², y, xy` from each index to the end.
struct Suffix {
    n: Vec<f64>,
    x: Vec<f64>,
    xx: Vec<f64>,
    y: Vec<f64>,
    xy: Vec<f64>,
}

impl Suffix {
    fn new(x: &[f64], y: &[f64]) -> Self {
        let m = x.len();
        let mut s = Suffix {
            n: vec![0.0; m + 1],
            x: vec![0.0; m + 1],
            xx: vec![0.0; m + 1],
            y: vec![0.0; m + 1],
            xy: vec![0.0; m + 1],
        };
        for i in (0..m).rev() {
            s.n[i] = s.n[i + 1] + 1.0;
            s.x[i] = s.x[i + 1] + x[i];
            s.xx[i] = s.xx[i + 1] + x[i] * x[i];
            s.y[i] = s.y[i + 1] + y[i];
            s.xy[i] = s.xy[i + 1] + x[i] * y[i];
        }
        s
    }

    /// `Σ (x − a)(x − b)` over readings from `i` on.
    fn pp(&self, i: usize, a: f64, b: f64) -> f64 {
        self.xx[i] - (a + b) * self.x[i] + a * b * self.n[i]
    }

    /// `Σ (x − a)` over readings from `i` on.
    fn p(&self, i: usize, a: f64) -> f64 {
        self.x[i] - a * self.n[i]
    }

    /// `Σ y (x − a)` over readings from `i` on.
    fn py(&self, i: usize, a: f64) -> f64 {
        self.xy[i] - a * self.y[i]
    }
}

/// Solves the symmetric 4×4 system `a z = b` by Gaussian elimination with partial pivoting;
/// `None` when it is singular.
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> Option<[f64; 4]> {
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    for c in 0..4 {
        let piv = (c..4).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[piv][c].abs() <= 1e-12 * scale {
            return None;
        }
        a.swap(c, piv);
        b.swap(c, piv);
        let pivot = a[c];
        for r in c + 1..4 {
            let f = a[r][c] / pivot[c];
            for (v, w) in a[r][c..].iter_mut().zip(&pivot[c..]) {
                *v -= f * w;
            }
            b[r] -= f * b[c];
        }
    }
    let mut z = [0.0; 4];
    for c in (0..4).rev() {
        let s: f64 = (c + 1..4).map(|k| a[c][k] * z[k]).sum();
        z[c] = (b[c] - s) / a[c][c];
    }
    Some(z)
}

/// The least-squares continuous three-segment piecewise-linear fit of `y(x)` (x increasing), its
/// breakpoints at readings, each segment with at least `MIN_SEGMENT` readings (counting the
/// breakpoints); `None` when there are too few readings.
///
/// For breakpoints `t₁ < t₂` the fit is `y = c₀ + c₁ x + c₂ (x − t₁)₊ + c₃ (x − t₂)₊`; the normal
/// equations need only suffix sums of `1, x, x², y, xy`, so each of the O(n²) pairs costs O(1).
pub fn trilinear(x: &[f64], y: &[f64]) -> Option<Trilinear> {
    let m = x.len().min(y.len());
    if m < 3 * MIN_SEGMENT {
        return None;
    }
    let s = Suffix::new(&x[..m], &y[..m]);
    let yy: f64 = y[..m].iter().map(|v| v * v).sum();
    let mut best: Option<Trilinear> = None;
    for i in MIN_SEGMENT - 1..m {
        for j in i + MIN_SEGMENT - 1..m.saturating_sub(MIN_SEGMENT - 1) {
            let (t1, t2) = (x[i], x[j]);
            if !(t2 > t1 && t1 > x[0] && x[m - 1] > t2) {
                continue;
            }
            // Readings strictly beyond a breakpoint carry its hinge (at the breakpoint it is 0).
            let (a, b) = (i + 1, j + 1);
            let g = [
                [s.n[0], s.x[0], s.p(a, t1), s.p(b, t2)],
                [s.x[0], s.xx[0], s.pp(a, t1, 0.0), s.pp(b, t2, 0.0)],
                [s.p(a, t1), s.pp(a, t1, 0.0), s.pp(a, t1, t1), s.pp(b, t1, t2)],
                [s.p(b, t2), s.pp(b, t2, 0.0), s.pp(b, t1, t2), s.pp(b, t2, t2)],
            ];
            let r = [s.y[0], s.xy[0], s.py(a, t1), s.py(b, t2)];
            let Some(c) = solve4(g, r) else { continue };
            // At the least-squares solution, RSS = Σy² − cᵀ(Gᵀy).
            let rss = (yy - (0..4).map(|k| c[k] * r[k]).sum::<f64>()).max(0.0);
            if best.is_none_or(|t| rss < t.rss) {
                best = Some(Trilinear { first: i, second: j, slopes: [c[1], c[1] + c[2], c[1] + c[2] + c[3]], rss });
            }
        }
    }
    best
}

/// Index of the first reading from which the debonded length `l` stays clearly above its start
/// value for good, if any.
pub fn length_onset(x: &[f64], l: &[f64]) -> Option<usize> {
    let n = x.len().min(l.len());
    if n < 2 {
        return None;
    }
    let mut start: Vec<f64> = l[..(n / 10).max(1)].to_vec();
    start.sort_by(f64::total_cmp);
    let base = start[start.len() / 2];
    let sigma = noise::estimate(&x[..n], &l[..n], true);
    let level = base + LENGTH_ONSET * sigma;
    // The last reading at or below the level; the onset follows it.
    match (0..n).rev().find(|&i| l[i].is_nan() || l[i] <= level) {
        Some(k) if k + 1 < n => Some(k + 1),
        Some(_) => None,
        None => Some(0),
    }
}

/// The rule of an FRP-strengthened beam test (module documentation), declared by
/// [`crate::frp::beam::FrpBeam`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BeamRegimes;

impl RegimeRule for BeamRegimes {
    fn names(&self) -> &'static [&'static str] {
        &NAMES
    }

    fn held_out_label(&self) -> &'static str {
        "debonding regime of each curve"
    }

    fn split(&self, load: (&[f64], &[f64]), length: Option<(&[f64], &[f64])>) -> Vec<Span> {
        split(load.0, load.1, length)
    }
}

/// Splits a beam test into its regimes: load curve `(x, p)` (mid-span deflection in mm, load in
/// N) and, when measured, the debonded length `(x, l)` (mm) on its own abscissae.
pub fn split(x: &[f64], p: &[f64], length: Option<(&[f64], &[f64])>) -> Vec<Span> {
    let n = x.len().min(p.len());
    if n == 0 {
        return Vec::new();
    }
    let (x, p) = (&x[..n], &p[..n]);
    let end = x[n - 1];
    let peak = (0..n).max_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap_or(0);
    // Where debonding governs: the peak, if the load falls clearly after it, unless the measured
    // length says otherwise.
    let falls = (peak..n).any(|i| p[i] < (1.0 - PEAK_DROP) * p[peak]);
    let debonding = match length {
        Some((lx, l)) => length_onset(lx, l).map(|k| lx[k]).filter(|&o| falls || o > x[peak]).map(|o| o.max(x[peak])),
        None => falls.then_some(x[peak]),
    };
    let fit_end = debonding.unwrap_or(end);
    // Readings of the rising curve, from FIRST_LOAD of the peak load (below: a seating toe).
    let from = (0..n).find(|&i| p[i] >= FIRST_LOAD * p[peak]).unwrap_or(0);
    let upto = (from..n).take_while(|&i| x[i] <= fit_end).count();
    let knees = trilinear(&x[from..from + upto], &p[from..from + upto]);
    let mut bounds: Vec<(&'static str, f64)> = vec![(NAMES[0], x[0])];
    if let Some(t) = knees {
        let loses = |a: f64, b: f64| a > 0.0 && b <= (1.0 - STIFFNESS_LOSS) * a;
        if loses(t.slopes[0], t.slopes[1]) {
            bounds.push((NAMES[1], x[from + t.first]));
        }
        // The second knee is judged against the stiffness just before it.
        if loses(t.slopes[1], t.slopes[2]) {
            bounds.push((NAMES[2], x[from + t.second]));
        }
    }
    if let Some(d) = debonding {
        bounds.retain(|b| b.1 < d);
        bounds.push((NAMES[3], d));
    }
    let mut out = Vec::new();
    for (k, (name, a)) in bounds.iter().enumerate() {
        let b = bounds.get(k + 1).map_or(end, |q| q.1);
        if b > *a {
            out.push(Span { name, from: *a, to: b });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fit_finds_the_knees_of_an_exact_trilinear_curve() {
        let x: Vec<f64> = (0..=300).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|&v| {
                if v <= 5.0 {
                    30.0 * v
                } else if v <= 20.0 {
                    150.0 + 10.0 * (v - 5.0)
                } else {
                    300.0 + 2.0 * (v - 20.0)
                }
            })
            .collect();
        let t = trilinear(&x, &y).unwrap();
        assert_eq!((x[t.first], x[t.second]), (5.0, 20.0));
        for (s, e) in t.slopes.iter().zip([30.0, 10.0, 2.0]) {
            assert!((s - e).abs() < 1e-6, "{:?}", t.slopes);
        }
        assert!(t.rss < 1e-6);
    }

    #[test]
    fn too_few_readings_give_no_fit_and_no_panic() {
        assert!(trilinear(&[0.0, 1.0, 2.0], &[0.0, 1.0, 2.0]).is_none());
        assert!(split(&[], &[], None).is_empty());
        let r = split(&[0.0, 1.0], &[0.0, 1.0], None);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].name, NAMES[0]);
    }

    #[test]
    fn the_length_onset_ignores_noise_before_growth() {
        let x: Vec<f64> = (0..200).map(|i| i as f64).collect();
        let l: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, &v)| if v < 120.0 { [0.3, -0.2, 0.1, -0.3][i % 4] } else { 5.0 * (v - 119.0) })
            .collect();
        assert_eq!(length_onset(&x, &l), Some(120));
        assert_eq!(length_onset(&x, &vec![0.0; 200]), None);
    }
}
