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
    // With r = ∂l_n/∂q = (−c, −s, 0, c, s, 0), z = (s, −c, 0, −s, c, 0) and v = −z/l_n, the
    // strain–displacement rows are b = (r, v + e₂, v + e₅); `bᵀ K_l b` plus the geometric terms
    // collapses to closed forms: the translational block is ±X with
    // X = (EA/l₀) r′r′ᵀ + (N/l_n + 2 k_v/l_n²) z′z′ᵀ + g_m (r′z′ᵀ + z′r′ᵀ) on the first node's
    // (u, w), `k_v = k₁₁ + k₁₂`; the rotations couple to the translations through `k_v v` and to
    // each other through the local bending and shear stiffness.
    let (r1, z1) = ([-c, -sn], [sn, -c]);
    let v = [-z1[0] / ln, -z1[1] / ln];
    let force = [
        r1[0] * fl[0] + v[0] * (fl[1] + fl[2]),
        r1[1] * fl[0] + v[1] * (fl[1] + fl[2]),
        fl[1],
        -(r1[0] * fl[0] + v[0] * (fl[1] + fl[2])),
        -(r1[1] * fl[0] + v[1] * (fl[1] + fl[2])),
        fl[2],
    ];
    let (k11, k12) = (kl[1][1], kl[1][2]);
    let kv = k11 + k12;
    let gn = fl[0] / ln;
    let gm = (fl[1] + fl[2]) / (ln * ln);
    let a = gn + 2.0 * kv / (ln * ln);
    let ka = kl[0][0];
    let mut x = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            x[i][j] = ka * r1[i] * r1[j] + a * z1[i] * z1[j] + gm * (r1[i] * z1[j] + z1[i] * r1[j]);
        }
    }
    let mut tangent = [[0.0; 6]; 6];
    for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
        tangent[i][j] = x[i][j];
        tangent[i + 3][j + 3] = x[i][j];
        tangent[i][j + 3] = -x[i][j];
        tangent[i + 3][j] = -x[i][j];
    }
    for i in 0..2 {
        let t = kv * v[i];
        for rot in [2, 5] {
            tangent[i][rot] = t;
            tangent[rot][i] = t;
            tangent[i + 3][rot] = -t;
            tangent[rot][i + 3] = -t;
        }
    }
    tangent[2][2] = k11;
    tangent[5][5] = kl[2][2];
    tangent[2][5] = k12;
    tangent[5][2] = kl[2][1];
    CrElement { force, tangent, energy }
}
