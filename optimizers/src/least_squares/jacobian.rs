//! The finite-difference Jacobian `∂r/∂z` of a [`ResidualSource`], all its points evaluated as
//! one batch.

use super::ResidualSource;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Finite-difference scheme for gradients and Jacobians.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Differences {
    /// `(f(z + h) − f(z − h)) / 2h`: `2n` evaluations, error `O(h²)`.
    #[default]
    Central,
    /// `(f(z + h) − f(z)) / h`: `n` evaluations, error `O(h)`.
    Forward,
}

/// How a Jacobian is differenced: the step `h = step · max(1, |z_i|)` and the scheme.
///
/// A forward model's response carries a small ripple from its discretisation (a crack front
/// crossing an element): in the coordinates of a problem's box a step of ~1e-3 of the range
/// differences the trend rather than the ripple; in unbounded, well-scaled coordinates 1e-7 is
/// the usual choice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FiniteDifferences {
    /// Relative step.
    pub step: f64,
    /// Central or forward.
    pub scheme: Differences,
}

impl FiniteDifferences {
    /// Points evaluated for a Jacobian of `columns` columns (plus one for forward differences
    /// without the residuals at the point).
    pub fn points(&self, columns: usize, have_residuals: bool) -> usize {
        match self.scheme {
            Differences::Central => 2 * columns,
            Differences::Forward => columns + usize::from(!have_residuals),
        }
    }
}

/// The Jacobian `∂r/∂z_j` at `z` for the coordinates `columns` (one matrix column each, in that
/// order; rows: residuals).
///
/// Central differences evaluate `z ± h e_j` (plus first), forward ones `z + h e_j` and reuse
/// `r0`, the residuals at `z`, when given. With `bounds`, a point that would leave the box is put
/// on its bound (the difference becomes one-sided), so a coordinate on a bound is differenced
/// inside the box. Any failed point fails the Jacobian with that point's error.
pub fn jacobian<S: ResidualSource>(
    src: &S,
    z: &[f64],
    r0: Option<&[f64]>,
    fd: &FiniteDifferences,
    bounds: Option<&[(f64, f64)]>,
    columns: &[usize],
) -> Result<DMatrix<f64>, S::Error> {
    let h: Vec<f64> = columns.iter().map(|&j| fd.step * z[j].abs().max(1.0)).collect();
    let clip = |j: usize, v: f64| bounds.map_or(v, |b| v.clamp(b[j].0, b[j].1));
    let mut points = Vec::with_capacity(2 * columns.len());
    // Per column, the distance between the two points differenced: in a box the distance between
    // the points actually evaluated (clipped at a bound); unbounded, the nominal 2h or h.
    let mut widths = Vec::with_capacity(columns.len());
    for (c, &j) in columns.iter().enumerate() {
        let at = |v: f64| {
            let mut p = z.to_vec();
            p[j] = v;
            p
        };
        let (up, down) = (z[j] + h[c], z[j] - h[c]);
        match fd.scheme {
            Differences::Central => {
                let (hi, lo) = (clip(j, up), clip(j, down));
                points.push(at(hi));
                points.push(at(lo));
                widths.push(if bounds.is_some() { hi - lo } else { 2.0 * h[c] });
            }
            Differences::Forward => {
                // At the upper bound the difference looks backwards (a negative width).
                let v = if clip(j, up) == up { up } else { clip(j, down) };
                points.push(at(v));
                widths.push(if bounds.is_some() { v - z[j] } else { h[c] });
            }
        }
    }
    let mut rs = src.residuals(&points)?;
    if fd.scheme == Differences::Central {
        // A central point whose run failed is replaced by the point itself (a one-sided
        // difference) when its residuals are known; otherwise the Jacobian fails.
        if let Some(r0) = r0 {
            for c in 0..columns.len() {
                let (plus, minus) = (rs[2 * c].is_err(), rs[2 * c + 1].is_err());
                if plus != minus {
                    let j = columns[c];
                    let failed = if plus { 2 * c } else { 2 * c + 1 };
                    rs[failed] = Ok(r0.to_vec());
                    let other = if plus { points[2 * c + 1][j] } else { points[2 * c][j] };
                    widths[c] = if plus { z[j] - other } else { other - z[j] };
                }
            }
        }
    }
    let rs: Vec<Vec<f64>> = rs.into_iter().collect::<Result<_, _>>()?;
    let base = match (fd.scheme, r0) {
        (Differences::Central, _) => None,
        (Differences::Forward, Some(r)) => Some(r.to_vec()),
        (Differences::Forward, None) => Some(src.residuals_at(z)?),
    };
    let m = rs.first().map_or(0, Vec::len);
    let mut jac = DMatrix::zeros(m, columns.len());
    for (c, &width) in widths.iter().enumerate() {
        for k in 0..m {
            jac[(k, c)] = match &base {
                None => (rs[2 * c][k] - rs[2 * c + 1][k]) / width,
                Some(r) => (rs[c][k] - r[k]) / width,
            };
        }
    }
    Ok(jac)
}

#[cfg(test)]
mod tests {
    use super::super::Parallel;
    use super::*;

    fn quadratic(z: &[f64]) -> Result<Vec<f64>, ()> {
        Ok(vec![z[0] * z[0], 3.0 * z[1], z[0] * z[1]])
    }

    #[test]
    fn central_and_forward_match_the_derivatives() {
        let z = [0.5, 0.25];
        for scheme in [Differences::Central, Differences::Forward] {
            let fd = FiniteDifferences { step: 1e-6, scheme };
            let j = jacobian(&Parallel(quadratic), &z, None, &fd, None, &[0, 1]).unwrap();
            let exact = [[1.0, 0.0], [0.0, 3.0], [0.25, 0.5]];
            for (k, row) in exact.iter().enumerate() {
                for (c, v) in row.iter().enumerate() {
                    assert!((j[(k, c)] - v).abs() < 1e-5, "{scheme:?} ({k},{c}): {} vs {v}", j[(k, c)]);
                }
            }
        }
    }

    #[test]
    fn a_coordinate_on_a_bound_is_differenced_inside_the_box() {
        // r = z² is steep on one side only if the point left the box: z = 0 on the lower bound.
        let src = Parallel(|z: &[f64]| -> Result<Vec<f64>, ()> {
            assert!(z[0] >= 0.0, "evaluated outside the box");
            Ok(vec![z[0] * z[0] + z[0]])
        });
        let fd = FiniteDifferences { step: 1e-3, scheme: Differences::Central };
        let j = jacobian(&src, &[0.0], None, &fd, Some(&[(0.0, 1.0)]), &[0]).unwrap();
        // One-sided: (h² + h) / h = 1 + h.
        assert!((j[(0, 0)] - 1.001).abs() < 1e-12, "{}", j[(0, 0)]);
    }

    #[test]
    fn a_failed_point_gives_a_one_sided_difference_or_fails_the_jacobian() {
        let src = Parallel(|z: &[f64]| if z[0] > 0.5 { Err("diverged") } else { Ok(vec![2.0 * z[0]]) });
        let fd = FiniteDifferences { step: 1e-3, scheme: Differences::Central };
        // Without the residuals at the point there is nothing to difference against.
        assert_eq!(jacobian(&src, &[0.5], None, &fd, None, &[0]).unwrap_err(), "diverged");
        // With them, the backward difference.
        let j = jacobian(&src, &[0.5], Some(&[1.0]), &fd, None, &[0]).unwrap();
        assert!((j[(0, 0)] - 2.0).abs() < 1e-9, "{}", j[(0, 0)]);
    }
}
