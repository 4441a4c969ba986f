//! Two-node Timoshenko beam element (axial, bending, shear), small rotations.
//!
//! The bending part is the *interdependent interpolation element* (Reddy 1997): the deflection is
//! cubic and the section rotation quadratic, both exact solutions of the homogeneous Timoshenko
//! equations, so the element is free of shear locking, its stiffness is the exact Timoshenko
//! stiffness, and with loads applied consistently with its shape functions the nodal values are
//! exact whatever the element length. With `φ = 12 EI / (κGA l²)`:
//!
//! * `w(ξ) = N_w1 w1 + N_θ1 θ1 + N_w2 w2 + N_θ2 θ2` ([`deflection_shape`]);
//! * relative to the chord, `w = w_lin + N_θ1 θ̄1 + N_θ2 θ̄2` with `θ̄_i = θ_i − (w2 − w1)/l`
//!   ([`rotation_shape`] gives these two functions), which is how interface points between the
//!   nodes see the deflection;
//! * the stiffness on the rotations relative to the chord is
//!   `EI / ((1 + φ) l) [[4 + φ, 2 − φ], [2 − φ, 4 + φ]]` (also used by the co-rotational element).
//!
//! The axial displacement is linear. Sign conventions: `θ` is counter-clockwise, so a fibre at
//! height `z` above the centroid moves axially by `u − z θ`; with negligible shear `θ = w'`.

use super::mesh::Section;

/// `φ = 12 EI / (κGA l²)` of a section and element length.
#[inline]
pub fn shear_ratio(s: &Section, l: f64) -> f64 {
    12.0 * s.ei() / (s.ga() * l * l)
}

/// The deflection's departure from linear interpolation per unit relative rotation,
/// `[N_θ1(ξ), N_θ2(ξ)]` (mm per rad), for an element of length `l` and shear ratio `phi`.
#[inline]
pub fn rotation_shape(l: f64, phi: f64, xi: f64) -> [f64; 2] {
    let c = 0.5 * l * xi * (1.0 - xi) / (1.0 + phi);
    [c * (phi + 2.0 - 2.0 * xi), -c * (phi + 2.0 * xi)]
}

/// Local stiffness on `[ū, θ̄1, θ̄2]` (stretch and rotations relative to the chord).
#[inline]
pub fn local_stiffness(s: &Section, l: f64) -> [[f64; 3]; 3] {
    let phi = shear_ratio(s, l);
    let c = s.ei() / ((1.0 + phi) * l);
    let (d, o) = (c * (4.0 + phi), c * (2.0 - phi));
    [[s.ea() / l, 0.0, 0.0], [0.0, d, o], [0.0, o, d]]
}

/// Element stiffness matrix (6×6, row-major in `[u1, w1, θ1, u2, w2, θ2]`).
pub fn stiffness(s: &Section, l: f64) -> [[f64; 6]; 6] {
    // K = Bᵀ K_local B with ū = u2 − u1 and θ̄_i = θ_i − (w2 − w1)/l.
    let kl = local_stiffness(s, l);
    let b: [[f64; 6]; 3] = [
        [-1.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        [0.0, 1.0 / l, 1.0, 0.0, -1.0 / l, 0.0],
        [0.0, 1.0 / l, 0.0, 0.0, -1.0 / l, 1.0],
    ];
    let mut k = [[0.0; 6]; 6];
    for r in 0..3 {
        for c in 0..3 {
            if kl[r][c] == 0.0 {
                continue;
            }
            for i in 0..6 {
                for j in 0..6 {
                    k[i][j] += b[r][i] * kl[r][c] * b[c][j];
                }
            }
        }
    }
    k
}

/// Strain energy (N·mm) of an element with nodal values `q`.
pub fn energy(s: &Section, l: f64, q: &[f64; 6]) -> f64 {
    let kl = local_stiffness(s, l);
    let chord = (q[4] - q[1]) / l;
    let d = [q[3] - q[0], q[2] - chord, q[5] - chord];
    let mut e = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            e += d[i] * kl[i][j] * d[j];
        }
    }
    0.5 * e
}
