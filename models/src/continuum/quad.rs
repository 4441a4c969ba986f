//! The four-node quadrilateral with incompatible modes (QM6: Wilson's bubble modes with Taylor's
//! correction), in small strain or total Lagrangian large displacement.
//!
//! Why this element: the arms are thin (1.5–3 mm) and bend. A plain bilinear quadrilateral locks
//! in bending (its shear strain cannot vanish under a linear bending stress), and 8/9-node
//! elements that do not lock cost several times the unknowns and the bandwidth. Adding the two
//! bubble modes `1 − ξ²` and `1 − η²` per direction lets each element bend with a linear stress
//! through its depth (exact pure bending of rectangles), and the modes are condensed out element
//! by element, so the global system keeps two unknowns per node and a narrow band. Taylor's
//! correction (the bubble gradients taken with the centre Jacobian, scaled by `det J₀ / det J`)
//! makes the element pass the patch test on distorted meshes.
//!
//! Large displacements: the enhanced displacement gradient `H = ∇u + Σ αₖ ⊗ ∇Pₖ` enters the
//! Green–Lagrange strain `E = ½(H + Hᵀ + HᵀH)` with the Saint Venant–Kirchhoff law `S = D E`
//! (strains stay small, rotations do not). The bubble amplitudes are solved element by element for
//! each trial displacement (a local Newton), so the condensed element is stateless.
//!
//! Integration: 2 × 2 Gauss points.

use nalgebra::{Matrix2, Matrix3, Matrix4, SMatrix, SVector, Vector3, Vector4};

/// Nodal forces of an element (N), `[fx₀, fy₀, fx₁, …]`.
pub type ElementForce = SVector<f64, 8>;
/// Element tangent (N/mm).
pub type ElementTangent = SMatrix<f64, 8, 8>;

/// What an element returns for a trial displacement.
#[derive(Clone, Debug)]
pub struct QuadResponse {
    /// Internal nodal forces (N).
    pub force: ElementForce,
    /// Condensed tangent (N/mm).
    pub tangent: ElementTangent,
    /// Strain energy (N·mm).
    pub energy: f64,
    /// Bubble amplitudes at equilibrium (mm), the next call's starting guess.
    pub bubbles: Vector4<f64>,
}

/// A quadrilateral in reference coordinates (mm), nodes counter-clockwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad {
    /// Corner coordinates `[x, y]`.
    pub nodes: [[f64; 2]; 4],
    /// Out-of-plane thickness (the specimen's width, mm).
    pub thickness: f64,
}

const CORNERS: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// Gradients (w.r.t. reference coordinates) of the four shape functions and the two bubble modes
/// at one Gauss point, and the point's weight × det J × thickness.
struct Point {
    grads: [[f64; 2]; 6],
    weight: f64,
}

impl Quad {
    fn jacobian(&self, xi: f64, eta: f64) -> (Matrix2<f64>, [[f64; 2]; 4]) {
        let mut dn = [[0.0; 2]; 4];
        let mut j = Matrix2::zeros();
        for (a, c) in CORNERS.iter().enumerate() {
            dn[a] = [0.25 * c[0] * (1.0 + c[1] * eta), 0.25 * c[1] * (1.0 + c[0] * xi)];
            for i in 0..2 {
                for k in 0..2 {
                    j[(i, k)] += self.nodes[a][i] * dn[a][k];
                }
            }
        }
        (j, dn)
    }

    fn points(&self) -> [Point; 4] {
        let g = 1.0 / 3f64.sqrt();
        let (j0, _) = self.jacobian(0.0, 0.0);
        let det0 = j0.determinant();
        let inv0t = j0.try_inverse().unwrap_or_else(Matrix2::zeros).transpose();
        let mut out: [Point; 4] = std::array::from_fn(|_| Point { grads: [[0.0; 2]; 6], weight: 0.0 });
        for (p, c) in CORNERS.iter().enumerate() {
            let (xi, eta) = (g * c[0], g * c[1]);
            let (j, dn) = self.jacobian(xi, eta);
            let det = j.determinant();
            let invt = j.try_inverse().unwrap_or_else(Matrix2::zeros).transpose();
            for a in 0..4 {
                let v = invt * nalgebra::Vector2::new(dn[a][0], dn[a][1]);
                out[p].grads[a] = [v[0], v[1]];
            }
            let scale = det0 / det;
            for (k, d) in [[-2.0 * xi, 0.0], [0.0, -2.0 * eta]].iter().enumerate() {
                let v = inv0t * nalgebra::Vector2::new(d[0], d[1]) * scale;
                out[p].grads[4 + k] = [v[0], v[1]];
            }
            out[p].weight = det * self.thickness;
        }
        out
    }

    /// Internal force, condensed tangent and energy at nodal displacements `u` (`[ux₀, uy₀, …]`,
    /// mm), with stiffness `d` (MPa) and `large` displacements or small strain; `bubbles` is the
    /// starting guess of the bubble amplitudes (zero, or the last converged ones).
    pub fn respond(&self, u: &ElementForce, d: &Matrix3<f64>, large: bool, bubbles: &Vector4<f64>) -> QuadResponse {
        let points = self.points();
        let mut alpha = *bubbles;
        // Small strain: the bubble equations are linear and one Newton step solves them exactly.
        let rounds = if large { 12 } else { 1 };
        // The local Newton needs only the bubbles' residual and block, a ninth of the tangent;
        // the whole element is evaluated once, where it ends.
        let (mut ra, mut kaa) = self.bubble_block(&points, u, &alpha, d, large);
        for round in 0..rounds {
            let Some(inv) = kaa.try_inverse() else { break };
            let step = -(inv * ra);
            alpha += step;
            if !large || step.amax() <= 1e-13 * (1.0 + alpha.amax()) || round + 1 == rounds {
                break;
            }
            (ra, kaa) = self.bubble_block(&points, u, &alpha, d, large);
        }
        let full = self.full(&points, u, &alpha, d, large);
        let kuu = full.k.fixed_view::<8, 8>(0, 0).into_owned();
        let kua = full.k.fixed_view::<8, 4>(0, 8).into_owned();
        let kau = full.k.fixed_view::<4, 8>(8, 0).into_owned();
        let kaa: Matrix4<f64> = full.k.fixed_view::<4, 4>(8, 8).into_owned();
        let inv = kaa.try_inverse().unwrap_or_else(Matrix4::zeros);
        let ra: Vector4<f64> = full.r.fixed_rows::<4>(8).into_owned();
        let ru: ElementForce = full.r.fixed_rows::<8>(0).into_owned();
        QuadResponse {
            // The remaining bubble residual (round-off, or an unconverged local Newton) is condensed
            // consistently with the tangent.
            force: ru - kua * (inv * ra),
            tangent: kuu - kua * inv * kau,
            energy: full.energy,
            bubbles: alpha,
        }
    }

    /// The bubbles' rows of [`Quad::full`]: their residual and their block of the tangent, computed
    /// by the same operations in the same order (so the local Newton takes the same steps).
    fn bubble_block(
        &self,
        points: &[Point; 4],
        u: &ElementForce,
        alpha: &Vector4<f64>,
        d: &Matrix3<f64>,
        large: bool,
    ) -> (Vector4<f64>, Matrix4<f64>) {
        let mut r = Vector4::zeros();
        let mut k = Matrix4::zeros();
        for p in points {
            let (f, strain) = strains(p, u, alpha, large);
            let s: Vector3<f64> = d * strain;
            let mut b = SMatrix::<f64, 3, 4>::zeros();
            for m in 4..6 {
                let g = p.grads[m];
                for i in 0..2 {
                    let col = 2 * (m - 4) + i;
                    b[(0, col)] = f[(i, 0)] * g[0];
                    b[(1, col)] = f[(i, 1)] * g[1];
                    b[(2, col)] = f[(i, 0)] * g[1] + f[(i, 1)] * g[0];
                }
            }
            r += b.transpose() * s * p.weight;
            k += b.transpose() * d * b * p.weight;
            if large {
                let smat = Matrix2::new(s[0], s[2], s[2], s[1]);
                for m in 4..6 {
                    let gm = nalgebra::Vector2::new(p.grads[m][0], p.grads[m][1]);
                    for n in 4..6 {
                        let gn = nalgebra::Vector2::new(p.grads[n][0], p.grads[n][1]);
                        let v = gm.dot(&(smat * gn)) * p.weight;
                        k[(2 * (m - 4), 2 * (n - 4))] += v;
                        k[(2 * (m - 4) + 1, 2 * (n - 4) + 1)] += v;
                    }
                }
            }
        }
        (r, k)
    }

    /// Residual and tangent over nodal and bubble unknowns (12 of them).
    fn full(&self, points: &[Point; 4], u: &ElementForce, alpha: &Vector4<f64>, d: &Matrix3<f64>, large: bool) -> Full {
        let mut r = SVector::<f64, 12>::zeros();
        let mut k = SMatrix::<f64, 12, 12>::zeros();
        let mut energy = 0.0;
        for p in points {
            let (f, strain) = strains(p, u, alpha, large);
            let s: Vector3<f64> = d * strain;
            energy += 0.5 * strain.dot(&s) * p.weight;
            // B columns: δE of a unit value of each of the 12 unknowns.
            let mut b = SMatrix::<f64, 3, 12>::zeros();
            for m in 0..6 {
                let g = p.grads[m];
                for i in 0..2 {
                    let col = 2 * m + i;
                    b[(0, col)] = f[(i, 0)] * g[0];
                    b[(1, col)] = f[(i, 1)] * g[1];
                    b[(2, col)] = f[(i, 0)] * g[1] + f[(i, 1)] * g[0];
                }
            }
            r += b.transpose() * s * p.weight;
            k += b.transpose() * d * b * p.weight;
            if large {
                // Geometric stiffness: δ_ij ∇N_a · S ∇N_c.
                let smat = Matrix2::new(s[0], s[2], s[2], s[1]);
                for m in 0..6 {
                    let gm = nalgebra::Vector2::new(p.grads[m][0], p.grads[m][1]);
                    for n in 0..6 {
                        let gn = nalgebra::Vector2::new(p.grads[n][0], p.grads[n][1]);
                        let v = gm.dot(&(smat * gn)) * p.weight;
                        k[(2 * m, 2 * n)] += v;
                        k[(2 * m + 1, 2 * n + 1)] += v;
                    }
                }
            }
        }
        Full { r, k, energy }
    }
}

/// At one Gauss point: the deformation gradient `F` (the identity in small strain) and the strain
/// `[E₁₁, E₂₂, 2E₁₂]` from the displacement gradient `H[i][j] = ∂u_i/∂X_j`, enhanced by the bubbles.
fn strains(p: &Point, u: &ElementForce, alpha: &Vector4<f64>, large: bool) -> (Matrix2<f64>, Vector3<f64>) {
    let mut h: Matrix2<f64> = Matrix2::zeros();
    for m in 0..6 {
        let (ux, uy) = if m < 4 { (u[2 * m], u[2 * m + 1]) } else { (alpha[2 * (m - 4)], alpha[2 * (m - 4) + 1]) };
        for j in 0..2 {
            h[(0, j)] += ux * p.grads[m][j];
            h[(1, j)] += uy * p.grads[m][j];
        }
    }
    let f = if large { Matrix2::identity() + h } else { Matrix2::identity() };
    let strain = if large {
        let e = 0.5 * (h + h.transpose() + h.transpose() * h);
        Vector3::new(e[(0, 0)], e[(1, 1)], 2.0 * e[(0, 1)])
    } else {
        Vector3::new(h[(0, 0)], h[(1, 1)], h[(0, 1)] + h[(1, 0)])
    };
    (f, strain)
}

struct Full {
    r: SVector<f64, 12>,
    k: SMatrix<f64, 12, 12>,
    energy: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn iso(e: f64, nu: f64) -> Matrix3<f64> {
        let c = e / (1.0 - nu * nu);
        Matrix3::new(c, c * nu, 0.0, c * nu, c, 0.0, 0.0, 0.0, 0.5 * c * (1.0 - nu))
    }

    fn rect(w: f64, h: f64) -> Quad {
        Quad { nodes: [[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]], thickness: 2.0 }
    }

    /// Pure bending: u = −κ x y, v = κ x²/2 (ν = 0) is an exact elasticity solution with
    /// σ_xx = −E κ y and no shear; the element must carry it with no shear energy.
    #[test]
    fn bends_without_locking() {
        let q = rect(4.0, 1.0);
        let d = iso(1000.0, 0.0);
        let kappa = 0.01;
        let mut u = ElementForce::zeros();
        for (a, n) in q.nodes.iter().enumerate() {
            let y = n[1] - 0.5;
            u[2 * a] = -kappa * n[0] * y;
            u[2 * a + 1] = 0.5 * kappa * n[0] * n[0];
        }
        let r = q.respond(&u, &d, false, &Vector4::zeros());
        // Exact bending energy: ½ E I κ² L with I = t h³/12.
        let exact = 0.5 * 1000.0 * (2.0 / 12.0) * kappa * kappa * 4.0;
        assert!((r.energy - exact).abs() < 1e-10 * exact, "{} vs {exact}", r.energy);
    }

    #[test]
    fn tangent_is_the_derivative_of_the_force() {
        let q = Quad { nodes: [[0.0, 0.0], [1.3, 0.1], [1.2, 0.9], [-0.1, 1.0]], thickness: 1.5 };
        let d = iso(2000.0, 0.3);
        let u = ElementForce::from_fn(|i, _| 0.05 * ((i as f64) * 1.7).sin());
        for large in [false, true] {
            let r0 = q.respond(&u, &d, large, &Vector4::zeros());
            let h = 1e-6;
            for j in 0..8 {
                let mut up = u;
                up[j] += h;
                let mut um = u;
                um[j] -= h;
                let fd = (q.respond(&up, &d, large, &Vector4::zeros()).force
                    - q.respond(&um, &d, large, &Vector4::zeros()).force)
                    / (2.0 * h);
                let err = (fd - r0.tangent.column(j)).amax();
                assert!(err < 1e-5 * r0.tangent.amax(), "large {large}, column {j}: {err}");
            }
        }
    }

    #[test]
    fn rigid_rotation_is_stress_free_in_large_displacement() {
        let q = rect(3.0, 1.0);
        let d = iso(1000.0, 0.2);
        let th: f64 = 0.7;
        let mut u = ElementForce::zeros();
        for (a, n) in q.nodes.iter().enumerate() {
            u[2 * a] = th.cos() * n[0] - th.sin() * n[1] - n[0];
            u[2 * a + 1] = th.sin() * n[0] + th.cos() * n[1] - n[1];
        }
        let r = q.respond(&u, &d, true, &Vector4::zeros());
        assert!(r.force.amax() < 1e-10 && r.energy.abs() < 1e-12, "{}", r.force);
    }
}
