//! Traction and tangent pieces shared by the damage laws.
//!
//! Every bundled law is a secant-damage law: the traction is `(1 − D) K u` on the part of the gap
//! that damage acts on (opening and slip), while a closing gap (`u_n < 0`) meets the undamaged
//! normal penalty so that faces never interpenetrate and compression never causes damage.

use czid_core::{Gap, Tangent, Traction};

/// Normal opening that damage acts on, `⟨u_n⟩ = max(u_n, 0)`.
pub(crate) fn opening(gap: &Gap) -> f64 {
    gap.x.max(0.0)
}

/// Traction and secant tangent at fixed damage, given as `intact = 1 − D` (laws compute it
/// directly: near separation `1 − D` computed from D would lose digits to cancellation). Unloading
/// and reloading follow this secant to the origin, which is why `½ T·u` is the stored energy of
/// every bundled law.
pub(crate) fn secant(stiffness: [f64; 2], intact: f64, gap: &Gap) -> (Traction, Tangent) {
    let k_normal = if gap.x > 0.0 { intact * stiffness[0] } else { stiffness[0] };
    let k_slip = intact * stiffness[1];
    (Traction::new(k_normal * gap.x, k_slip * gap.y), Tangent::new(k_normal, 0.0, 0.0, k_slip))
}

/// Adds the damage-growth term `−K ⟨u⟩ ⊗ ∂D/∂u` to a secant tangent (the consistent tangent of
/// `T = (1 − D(u)) K ⟨u⟩` while damage grows). Unsymmetric.
pub(crate) fn add_damage_growth(tangent: &mut Tangent, stiffness: [f64; 2], gap: &Gap, damage_gradient: [f64; 2]) {
    let t_n = stiffness[0] * opening(gap);
    let t_t = stiffness[1] * gap.y;
    tangent[(0, 0)] -= t_n * damage_gradient[0];
    tangent[(0, 1)] -= t_n * damage_gradient[1];
    tangent[(1, 0)] -= t_t * damage_gradient[0];
    tangent[(1, 1)] -= t_t * damage_gradient[1];
}
