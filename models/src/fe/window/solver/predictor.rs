//! The step's predictor: the last state translated with the crack front.

use super::Solver;
use crate::fe::window::blocks::{blk_vec, Vct};

/// Weights of the cubic through the abscissae `x` evaluated at `t`. The translated field is
/// smooth across the process zone (the arms' deflection is that of a beam on its cohesive
/// foundation), so a cubic places it closer than a line: on the paper's DCB the residual after two
/// Newton corrections falls from about 10⁻⁶ to 10⁻⁸ of the interface forces, and one step in five
/// converges a correction earlier.
pub(super) fn cubic_weights(x: &[f64; 4], t: f64) -> [f64; 4] {
    let d = [t - x[0], t - x[1], t - x[2], t - x[3]];
    let den = |m: usize| (0..4).filter(|&l| l != m).fold(1.0, |p, l| p * (x[m] - x[l]));
    [d[1] * d[2] * d[3] / den(0), d[0] * d[2] * d[3] / den(1), d[0] * d[1] * d[3] / den(2), d[0] * d[1] * d[2] / den(3)]
}

impl<'a, const D: usize> Solver<'a, D> {
    /// Translates the window's unknowns within `zone` of the front at `x` by `da` (see
    /// [`crate::fe::path`]'s shift predictor; here interpolated by cubics, [`cubic_weights`]), from
    /// the committed values `from` at control `c_from` (behind the window they are recovered from
    /// the left region).
    pub(super) fn shift(&mut self, from: &[Vct<D>], c_from: f64, x: f64, da: f64, zone: f64) {
        let xs = &self.p.mesh.x;
        let (i0, i1) = (self.i0, self.i1);
        // Sources behind the window: recovered down to the farthest one needed.
        let lowest = xs[i0..=i1].partition_point(|v| *v < x - zone) + i0;
        let need = xs.partition_point(|v| *v < xs[lowest] - da.abs()).saturating_sub(1).max(self.lay.first);
        let mut behind = vec![[0.0; D]; i0 - need.min(i0)];
        let mut next = from[i0];
        for j in (need..i0).rev() {
            let mut v = blk_vec(&self.tl[j], &next);
            for a in 0..D {
                v[a] += self.tlc[j][a] * c_from;
            }
            behind[j - need] = v;
            next = v;
        }
        let value = |j: usize| if j >= i0 { from[j] } else { behind[j - need] };
        // The targets move right with `i`, so the interval holding each is found by walking on.
        let mut j = need;
        for i in i0..=i1 {
            if (xs[i] - x).abs() > zone {
                continue;
            }
            let xt = xs[i] - da;
            if xt < xs[need] || xt > xs[i1] {
                continue;
            }
            while j + 1 < i1 && xs[j + 1] <= xt {
                j += 1;
            }
            // A cubic through the four nearest nodes where there are four, else a line.
            if j > need && j + 2 <= i1 {
                let w = cubic_weights(&[xs[j - 1], xs[j], xs[j + 1], xs[j + 2]], xt);
                let v = [value(j - 1), value(j), value(j + 1), value(j + 2)];
                for a in 0..D {
                    self.q[i][a] = w[0] * v[0][a] + w[1] * v[1][a] + w[2] * v[2][a] + w[3] * v[3][a];
                }
            } else {
                let t = ((xt - xs[j]) / (xs[j + 1] - xs[j])).clamp(0.0, 1.0);
                let (va, vb) = (value(j), value(j + 1));
                for a in 0..D {
                    self.q[i][a] = (1.0 - t) * va[a] + t * vb[a];
                }
            }
        }
    }
}
