//! Two-node Timoshenko beam element (axial, bending, shear), small rotations.
//!
//! Linear interpolation of `u`, `w` and `θ` with the shear strain `γ = w' − θ` sampled at the
//! element midpoint (one-point reduced integration). Linear interpolation integrated exactly would
//! lock in shear for slender elements; sampling `γ` at the midpoint, where the constant part of
//! `w'` and the mean of `θ` are consistent, removes the locking. The element reproduces constant
//! bending exactly and a linearly varying moment with a nodal error `O(l_e²)` that is negligible
//! at the element sizes cohesive zones need.
//!
//! Sign conventions: `θ` is counter-clockwise, so a fibre at height `z` above the centroid moves
//! axially by `u − z θ`; the curvature is `θ'`.

use super::mesh::Section;

/// Generalised strains `[ε, κ, γ]` of an element of length `l` with nodal values
/// `[u1, w1, θ1, u2, w2, θ2]`.
#[inline]
pub fn strains(l: f64, q: &[f64; 6]) -> [f64; 3] {
    [(q[3] - q[0]) / l, (q[5] - q[2]) / l, (q[4] - q[1]) / l - 0.5 * (q[2] + q[5])]
}

/// Element stiffness matrix (6×6, row-major in `[u1, w1, θ1, u2, w2, θ2]`).
pub fn stiffness(s: &Section, l: f64) -> [[f64; 6]; 6] {
    // Strain–displacement rows (times l for ε, κ; γ as is) assembled as Bᵀ D B l.
    let b: [[f64; 6]; 3] = [
        [-1.0 / l, 0.0, 0.0, 1.0 / l, 0.0, 0.0],
        [0.0, 0.0, -1.0 / l, 0.0, 0.0, 1.0 / l],
        [0.0, -1.0 / l, -0.5, 0.0, 1.0 / l, -0.5],
    ];
    let d = [s.ea(), s.ei(), s.ga()];
    let mut k = [[0.0; 6]; 6];
    for (r, br) in b.iter().enumerate() {
        for i in 0..6 {
            if br[i] == 0.0 {
                continue;
            }
            for j in 0..6 {
                k[i][j] += br[i] * d[r] * br[j] * l;
            }
        }
    }
    k
}

/// Strain energy (N·mm) of an element with nodal values `q`.
pub fn energy(s: &Section, l: f64, q: &[f64; 6]) -> f64 {
    let e = strains(l, q);
    0.5 * l * (s.ea() * e[0] * e[0] + s.ei() * e[1] * e[1] + s.ga() * e[2] * e[2])
}
