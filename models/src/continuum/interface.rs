//! Integration points of the cohesive line between two faces of a mesh.
//!
//! Two rules, chosen per model with `mesh.interface_points`:
//! * **Gauss–Legendre** (`n ≥ 1` points per element, the default 4): the gap is interpolated
//!   linearly between the element's node pairs and the traction sampled inside it. A crack front
//!   then crosses an element point by point, and the load falls smoothly as it runs.
//! * **Nodal** (`0`, Newton–Cotes / trapezoidal): one point per node pair with its tributary
//!   length. Each point's tangent is a 2 × 2 block, which avoids the traction oscillations Gauss
//!   points can show under very stiff penalties (Schellekens & de Borst, 1993), but each node's
//!   release is a small snap-back: the load–displacement curve saw-tooths unless the cohesive
//!   zone spans many elements.
//!
//! The book's "Beam or continuum?" chapter gives the measured effect of each on the DCB peak.

use super::problem::InterfacePoint;

/// A node pair across the interface at one column: the upper face's node and the lower face's
/// (`None` on a symmetry plane).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pair {
    /// Position (mm).
    pub x: f64,
    /// Node of the upper face.
    pub upper: usize,
    /// Node of the lower face, or `None`.
    pub lower: Option<usize>,
}

/// Gauss–Legendre abscissae on `[0, 1]` and weights (summing to 1) for 1–4 points.
fn gauss(n: usize) -> Vec<(f64, f64)> {
    let rule: &[(f64, f64)] = match n {
        1 => &[(0.0, 2.0)],
        2 => &[(-0.577_350_269_189_625_8, 1.0), (0.577_350_269_189_625_8, 1.0)],
        3 => &[(-0.774_596_669_241_483_4, 5.0 / 9.0), (0.0, 8.0 / 9.0), (0.774_596_669_241_483_4, 5.0 / 9.0)],
        _ => &[
            (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
            (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        ],
    };
    rule.iter().map(|&(x, w)| (0.5 * (x + 1.0), 0.5 * w)).collect()
}

/// Integration points along the pairs `pairs` (increasing `x`) of a specimen `width` mm wide,
/// with `n` Gauss points per element or nodal integration (`n = 0`).
pub fn line(pairs: &[Pair], width: f64, n: usize) -> Vec<InterfacePoint> {
    let both = |a: &Pair, b: &Pair| match (a.lower, b.lower) {
        (Some(x), Some(y)) => Some([x, y]),
        _ => None,
    };
    if n == 0 {
        let m = pairs.len();
        return (0..m)
            .map(|i| {
                let left = if i > 0 { 0.5 * (pairs[i].x - pairs[i - 1].x) } else { 0.0 };
                let right = if i + 1 < m { 0.5 * (pairs[i + 1].x - pairs[i].x) } else { 0.0 };
                let p = &pairs[i];
                InterfacePoint {
                    x: p.x,
                    upper: [p.upper, p.upper],
                    lower: p.lower.map(|l| [l, l]),
                    shape: [1.0, 0.0],
                    area: width * (left + right),
                }
            })
            .collect();
    }
    let rule = gauss(n.min(4));
    let mut out = Vec::with_capacity(rule.len() * pairs.len());
    for w in pairs.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let len = b.x - a.x;
        for &(s, weight) in &rule {
            out.push(InterfacePoint {
                x: a.x + s * len,
                upper: [a.upper, b.upper],
                lower: both(a, b),
                shape: [1.0 - s, s],
                area: width * len * weight,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_rules_integrate_the_length() {
        let pairs: Vec<Pair> =
            [0.0, 0.5, 1.5, 2.0].iter().enumerate().map(|(i, &x)| Pair { x, upper: i, lower: None }).collect();
        for n in 0..=4 {
            let pts = line(&pairs, 3.0, n);
            let area: f64 = pts.iter().map(|p| p.area).sum();
            assert!((area - 6.0).abs() < 1e-12, "n = {n}: {area}");
            // Linear interpolation reproduces x itself.
            for p in &pts {
                let x = p.shape[0] * pairs[p.upper[0]].x + p.shape[1] * pairs[p.upper[1]].x;
                assert!((x - p.x).abs() < 1e-12);
            }
        }
    }
}
