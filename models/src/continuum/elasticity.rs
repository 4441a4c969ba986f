//! Orthotropic linear elasticity of the arms in the plane they bend in.
//!
//! The arms lie in the 1–3 plane: axis 1 (`x`) along the fibres and the specimen, axis 3 (`y`)
//! through the thickness. The continuum models are **plane stress** in that plane (the stress
//! across the width vanishes): coupon DCB and ENF specimens are 20–25 mm wide against arms of
//! 1.5–3 mm, their width faces are free, and corrected beam theory, the beam models and the
//! published reference values all use `E11` unreduced. (Plane strain would stiffen the arms by
//! `1/(1 − ν12 ν21)`, a few per cent for laminates, and needs `ν12, ν23` that test reports rarely
//! give.)

use czid_core::{CzError, Result};
use nalgebra::Matrix3;

use crate::beamtest::{Material, Plane};

/// The plane-stress stiffness `[σ11, σ33, τ13] = D [ε11, ε33, γ13]` (MPa) of `m` in the 1–3 plane:
/// `E11`, `E33 = e22` (through the thickness), `G13`, and `ν13` (the contraction through the
/// thickness under axial stress; `ν31 = ν13 E33 / E11`).
pub fn plane_stress(m: &Material, owner: &str) -> Result<Matrix3<f64>> {
    if m.plane == Plane::Strain {
        return Err(CzError::invalid(
            owner,
            "material.plane",
            f64::NAN,
            "the continuum models are plane stress in the plane the arms bend in (narrow coupons with free width faces); remove `plane = \"strain\"`",
        ));
    }
    let (e1, e3, g, nu13) = (m.e11, m.e22, m.g13, m.nu13);
    let nu31 = nu13 * e3 / e1;
    let det = 1.0 - nu13 * nu31;
    if det <= 0.0 {
        return Err(CzError::invalid(
            owner,
            "material.nu13",
            nu13,
            "makes the stiffness indefinite (ν13² E33/E11 ≥ 1)",
        ));
    }
    Ok(Matrix3::new(e1 / det, nu31 * e1 / det, 0.0, nu31 * e1 / det, e3 / det, 0.0, 0.0, 0.0, g))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverts_the_engineering_compliance() {
        let m = Material { e11: 130_000.0, e22: 6_500.0, g13: 2_700.0, nu13: 0.26, plane: Plane::Stress };
        let d = plane_stress(&m, "t").unwrap();
        // The compliance written from the engineering constants, independently of `plane_stress`.
        let s =
            Matrix3::new(1.0 / m.e11, -m.nu13 / m.e11, 0.0, -m.nu13 / m.e11, 1.0 / m.e22, 0.0, 0.0, 0.0, 1.0 / m.g13);
        let id = d * s;
        assert!((id - Matrix3::identity()).abs().max() < 1e-12, "{id}");
    }

    #[test]
    fn refuses_plane_strain() {
        let m = Material { e11: 1.0, e22: 1.0, g13: 1.0, nu13: 0.0, plane: Plane::Strain };
        assert!(plane_stress(&m, "t").unwrap_err().to_string().contains("plane stress"));
    }
}
