//! Co-rotational kinematics for the two-node Timoshenko element (large rotations, small strains).
//!
//! Crisfield's formulation (Non-linear Finite Element Analysis of Solids and Structures, vol. 1,
//! ch. 7): the element's rigid-body motion is taken out by following its chord; what is left, the
//! chord stretch `ū = l_n − l_0` and the nodal rotations relative to the chord `θ̄_i = θ_i − (β − β_0)`,
//! is small and is resisted by the same linear Timoshenko stiffness as in [`super::beam`]. The
//! tangent adds the geometric terms `z zᵀ N / l_n + (r zᵀ + z rᵀ)(M_1 + M_2)/l_n²`.

use super::mesh::Section;

/// Internal force, tangent and strain energy of one element.
pub struct CrElement {
    /// Internal forces on `[u1, w1, θ1, u2, w2, θ2]`.
    pub force: [f64; 6],
    /// Tangent stiffness (row-major).
    pub tangent: [[f64; 6]; 6],
    /// Strain energy (N·mm).
    pub energy: f64,
}

/// Evaluates the element from `x1, x2` (undeformed nodal coordinates along the axis; the layer is
/// straight and horizontal) and nodal values `q = [u1, w1, θ1, u2, w2, θ2]`.
pub fn element(s: &Section, x1: f64, x2: f64, q: &[f64; 6]) -> CrElement {
    let l0 = x2 - x1;
    let dx = l0 + q[3] - q[0];
    let dy = q[4] - q[1];
    let ln = (dx * dx + dy * dy).sqrt();
    let (c, sn) = (dx / ln, dy / ln);
    let beta = dy.atan2(dx);
    let ub = ln - l0;
    let t1 = q[2] - beta;
    let t2 = q[5] - beta;
    // Local stiffness on [ū, θ̄1, θ̄2]: stretch, bending, and midpoint shear γ = −(θ̄1 + θ̄2)/2.
    let (ea, ei, ga) = (s.ea(), s.ei(), s.ga());
    let kb = ei / l0;
    let ks = 0.25 * ga * l0;
    let kl = [[ea / l0, 0.0, 0.0], [0.0, kb + ks, -kb + ks], [0.0, -kb + ks, kb + ks]];
    let dl = [ub, t1, t2];
    let mut fl = [0.0; 3];
    for i in 0..3 {
        for j in 0..3 {
            fl[i] += kl[i][j] * dl[j];
        }
    }
    let energy = 0.5 * (fl[0] * dl[0] + fl[1] * dl[1] + fl[2] * dl[2]);
    let r = [-c, -sn, 0.0, c, sn, 0.0];
    let z = [sn, -c, 0.0, -sn, c, 0.0];
    let mut b = [[0.0; 6]; 3];
    b[0] = r;
    for j in 0..6 {
        b[1][j] = -z[j] / ln;
        b[2][j] = -z[j] / ln;
    }
    b[1][2] += 1.0;
    b[2][5] += 1.0;
    let mut force = [0.0; 6];
    for j in 0..6 {
        force[j] = b[0][j] * fl[0] + b[1][j] * fl[1] + b[2][j] * fl[2];
    }
    let mut tangent = [[0.0; 6]; 6];
    let mut kb_ = [[0.0; 6]; 3];
    for a in 0..3 {
        for j in 0..6 {
            kb_[a][j] = kl[a][0] * b[0][j] + kl[a][1] * b[1][j] + kl[a][2] * b[2][j];
        }
    }
    let gn = fl[0] / ln;
    let gm = (fl[1] + fl[2]) / (ln * ln);
    for i in 0..6 {
        for j in 0..6 {
            tangent[i][j] = b[0][i] * kb_[0][j]
                + b[1][i] * kb_[1][j]
                + b[2][i] * kb_[2][j]
                + z[i] * z[j] * gn
                + (r[i] * z[j] + z[i] * r[j]) * gm;
        }
    }
    CrElement { force, tangent, energy }
}
