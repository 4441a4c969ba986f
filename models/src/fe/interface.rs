//! Zero-thickness interface points between layer surfaces.
//!
//! The gap is measured between the bottom surface of the `upper` layer and the top surface of
//! the `lower` layer (or its mirror image about a symmetry plane), from each layer's section
//! kinematics: a surface fibre at height `z` above the centroid of a layer with unknowns
//! `(u, w, θ)` sits at `(X + u − z sin θ, Y + w + z cos θ)`: the layers are rigid through their
//! thickness (a through-thickness compliance belongs to the law: [`crate::laws::SeriesCompliance`]).
//!
//! **Integration.** Points sit at the mesh nodes and carry the nodal (trapezoidal, i.e.
//! two-point Newton–Cotes/Lobatto) weights of their neighbouring elements. Nodal integration
//! decouples the interface points, so the stiff elastic branch of a cohesive law cannot produce the
//! spurious traction oscillations Gauss integration shows ahead of a crack tip (Schellekens &
//! de Borst 1993), and the law is evaluated once per node rather than twice per element.
//!
//! **Small rotations**: `g_n = w_U − w_L`, `g_t = (u_U − z_U θ_U) − (u_L − z_L θ_L)`,
//! linear in the unknowns. **Large rotations**: the surface points' separation `d` is resolved on
//! the frame of the mean rotation `θ̄ = (θ_L + θ_U)/2`, `g_n = d·n(θ̄)`, `g_t = d·t(θ̄)`; the Hessians of
//! `g` give the geometric part of the tangent. On a symmetry plane `g_n` is twice the upper
//! surface's normal displacement and `g_t = 0`.

use czid_core::{Gap, LawEval, LawState, Tangent, Traction};

use super::mesh::{Mesh, NONE};

/// What a point resists.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointKind {
    /// The cohesive law of the run.
    Cohesive,
    /// Contact only (a pre-crack): normal penalty in compression, free otherwise; with Coulomb
    /// friction when the problem's `contact_friction` is positive ([`frictional_contact`]).
    Contact,
}

/// One nodal interface integration point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InterfacePoint {
    /// Node index.
    pub node: usize,
    /// Layer above the interface.
    pub upper: usize,
    /// Layer below, or `None` for a symmetry plane (the lower surface is the mirror image of the
    /// upper one, so `g_n = 2 × (upper surface displacement)` and `g_t = 0`).
    pub lower: Option<usize>,
    /// Interface area the point represents: width × tributary length (mm²).
    pub area: f64,
    /// Share of the point's energy that belongs to the simulated part (½ on a symmetry plane).
    pub factor: f64,
    /// Cohesive or contact-only.
    pub kind: PointKind,
}

/// Unknowns of one side of a point: its layer's `[u, w, θ]` at the point's node.
pub const SIDE: usize = 3;
/// Unknowns of a point: the lower side's, then the upper side's.
pub const POINT_DOFS: usize = 2 * SIDE;

/// Gap of a point and its derivatives with respect to the point's unknowns
/// `[u_L, w_L, θ_L, u_U, w_U, θ_U]`.
#[derive(Clone, Copy, Debug, Default)]
pub struct GapKinematics {
    /// Global indices of the point's unknowns ([`NONE`] where absent).
    pub dofs: [usize; POINT_DOFS],
    /// `[g_n, g_t]` (mm).
    pub gap: [f64; 2],
    /// `∂g/∂q`.
    pub grad: [[f64; POINT_DOFS]; 2],
    /// Whether the gap is nonlinear in the unknowns (large rotations: see [`Hessian`]).
    pub nonlinear: bool,
}

/// `∂²g/∂q²` of a point (large rotations only), kept out of [`GapKinematics`] so the
/// small-rotation path never touches it.
pub type Hessian = [[[f64; POINT_DOFS]; POINT_DOFS]; 2];

#[inline]
fn val(q: &[f64], d: usize) -> f64 {
    if d == NONE {
        0.0
    } else {
        q[d]
    }
}

/// Displacement of a surface point of one side (relative to its undeformed position) and its
/// first and second derivatives with respect to `[u, w, θ]`.
struct Surface {
    p: [f64; 2],
    dp: [[f64; SIDE]; 2],
    d2p: [[[f64; SIDE]; SIDE]; 2],
}

fn surface(q: &[f64], dofs: &[usize; SIDE], z: f64, large: bool) -> Surface {
    let (u, w, t) = (val(q, dofs[0]), val(q, dofs[1]), val(q, dofs[2]));
    let mut r = Surface { p: [0.0; 2], dp: [[0.0; SIDE]; 2], d2p: [[[0.0; SIDE]; SIDE]; 2] };
    if large {
        // (d2p stays zero with small rotations)
        let (sn, cs) = t.sin_cos();
        r.p = [u - z * sn, w + z * cs - z];
        r.dp[0] = [1.0, 0.0, -z * cs];
        r.dp[1] = [0.0, 1.0, -z * sn];
        r.d2p[0][2][2] = z * sn;
        r.d2p[1][2][2] = -z * cs;
    } else {
        r.p = surface_position(q, dofs, z);
        r.dp[0] = [1.0, 0.0, -z];
        r.dp[1] = [0.0, 1.0, 0.0];
    }
    r
}

/// The gap `[g_n, g_t]` of point `p` at `q` under small rotations, the same numbers as
/// [`kinematics`] gives without its gradient (which is then constant: a solver keeps it once).
pub fn small_gap(mesh: &Mesh, p: &InterfacePoint, q: &[f64]) -> [f64; 2] {
    let du = mesh.dofs(p.upper, p.node);
    let su = surface_position(q, &du, -0.5 * mesh.layers[p.upper].section.h);
    let Some(lo) = p.lower else {
        return [2.0 * su[1], 0.0];
    };
    let sl = surface_position(q, &mesh.dofs(lo, p.node), 0.5 * mesh.layers[lo].section.h);
    [su[1] - sl[1], su[0] - sl[0]]
}

/// [`surface`]'s displacement alone, small rotations.
#[inline]
fn surface_position(q: &[f64], dofs: &[usize; SIDE], z: f64) -> [f64; 2] {
    let (u, w, t) = (val(q, dofs[0]), val(q, dofs[1]), val(q, dofs[2]));
    [u - z * t, w]
}

/// Gap kinematics of point `p` at unknowns `q`; with `large`, also the Hessians into `hess`
/// (on a symmetry plane only the upper side's block, the only one with unknowns).
pub fn kinematics(mesh: &Mesh, p: &InterfacePoint, q: &[f64], large: bool, hess: &mut Hessian) -> GapKinematics {
    let mut k = GapKinematics { dofs: [NONE; POINT_DOFS], ..Default::default() };
    let du = mesh.dofs(p.upper, p.node);
    k.dofs[SIDE..].copy_from_slice(&du);
    let su = surface(q, &du, -0.5 * mesh.layers[p.upper].section.h, large);
    let Some(lo) = p.lower else {
        // Only the upper side's block is written (and read: the lower side has no unknowns).
        if large {
            for side in hess.iter_mut() {
                for row in &mut side[SIDE..] {
                    row[SIDE..].fill(0.0);
                }
            }
        }
        // Mirror image below: d = (0, 2 p_y), frame fixed by symmetry.
        k.gap[0] = 2.0 * su.p[1];
        for j in 0..SIDE {
            k.grad[0][SIDE + j] = 2.0 * su.dp[1][j];
            if large {
                for m in 0..SIDE {
                    hess[0][SIDE + j][SIDE + m] = 2.0 * su.d2p[1][j][m];
                }
            }
        }
        k.nonlinear = large;
        return k;
    };
    let dl = mesh.dofs(lo, p.node);
    k.dofs[..SIDE].copy_from_slice(&dl);
    let sl = surface(q, &dl, 0.5 * mesh.layers[lo].section.h, large);
    let d = [su.p[0] - sl.p[0], su.p[1] - sl.p[1]];
    let mut dd = [[0.0; POINT_DOFS]; 2];
    for c in 0..2 {
        for j in 0..SIDE {
            dd[c][j] = -sl.dp[c][j];
            dd[c][SIDE + j] = su.dp[c][j];
        }
    }
    if !large {
        k.gap = [d[1], d[0]];
        k.grad = [dd[1], dd[0]];
        return k;
    }
    *hess = [[[0.0; POINT_DOFS]; POINT_DOFS]; 2];
    let tb = 0.5 * (val(q, dl[2]) + val(q, du[2]));
    let (sb, cb) = tb.sin_cos();
    let n = [-sb, cb];
    let t = [cb, sb];
    let gn = n[0] * d[0] + n[1] * d[1];
    let gt = t[0] * d[0] + t[1] * d[1];
    k.gap = [gn, gt];
    let mut dtb = [0.0; POINT_DOFS];
    dtb[2] = 0.5;
    dtb[SIDE + 2] = 0.5;
    let mut nd = [0.0; POINT_DOFS];
    let mut td = [0.0; POINT_DOFS];
    for j in 0..POINT_DOFS {
        nd[j] = n[0] * dd[0][j] + n[1] * dd[1][j];
        td[j] = t[0] * dd[0][j] + t[1] * dd[1][j];
        // ∂n/∂θ̄ = −t, ∂t/∂θ̄ = n
        k.grad[0][j] = nd[j] - gt * dtb[j];
        k.grad[1][j] = td[j] + gn * dtb[j];
    }
    for a in 0..SIDE {
        for b in 0..SIDE {
            for (off, side, sign) in [(0usize, &sl, -1.0), (SIDE, &su, 1.0)] {
                let (vx, vy) = (sign * side.d2p[0][a][b], sign * side.d2p[1][a][b]);
                hess[0][off + a][off + b] += n[0] * vx + n[1] * vy;
                hess[1][off + a][off + b] += t[0] * vx + t[1] * vy;
            }
        }
    }
    // ∂²n/∂θ̄² = −n, ∂²t/∂θ̄² = −t
    for i in 0..POINT_DOFS {
        for j in 0..POINT_DOFS {
            hess[0][i][j] += -td[i] * dtb[j] - dtb[i] * td[j] - gn * dtb[i] * dtb[j];
            hess[1][i][j] += nd[i] * dtb[j] + dtb[i] * nd[j] - gt * dtb[i] * dtb[j];
        }
    }
    k.nonlinear = true;
    k
}

/// Frictionless contact: penalty `k` on closure, nothing in opening or slip.
pub fn contact(gap: &Gap, k: f64) -> LawEval {
    let (t, kt) = if gap[0] < 0.0 { (k * gap[0], k) } else { (0.0, 0.0) };
    LawEval { traction: Traction::new(t, 0.0), tangent: Tangent::new(kt, 0.0, 0.0, 0.0), state: LawState::default() }
}

/// Recoverable energy per unit area of a contact point (N/mm) at `gap` with the evaluation `ev`:
/// `½ T·(g − (0, s))`, `s` the slip in `ev`'s state (0 without friction, where this is `½ T·g`).
/// The normal penalty stores `½ k g_n²` in closure; the stick spring `T_t² / (2k)`.
pub fn contact_stored(ev: &LawEval, gap: &Gap) -> f64 {
    let slip = ev.state.history[SLIP];
    if slip == 0.0 {
        0.5 * ev.traction.dot(gap)
    } else {
        0.5 * ev.traction.dot(&(gap - Gap::new(0.0, slip)))
    }
}

/// Index of the slip `s` (mm) in a contact point's [`LawState::history`]: the tangential gap at
/// which its stick spring is unstretched.
pub const SLIP: usize = 0;
/// Index of the friction work dissipated at a contact point so far, per unit area (N/mm), in its
/// [`LawState::history`].
pub const FRICTION_WORK: usize = 1;

/// Index of the magnitude of the shear `|T_t|` (MPa) a contact point carried at its last
/// evaluation, in its [`LawState::history`] (the start of the next step's friction work).
pub const SHEAR: usize = 2;

/// Contact with Coulomb friction of coefficient `mu` (dimensionless), regularised by a stick
/// spring: normal penalty `k` (MPa/mm) on closure as in [`contact`], and a tangential spring of
/// the same stiffness `k` between the tangential gap `g_t` and the slip `s` of the committed
/// `state`, capped at the Coulomb limit `μ p` (`p = −k g_n`, the contact pressure in MPa).
///
/// The update is the return mapping of rigid-plastic slip (Wriggers, *Computational Contact
/// Mechanics*, §5.2): the trial shear `τ* = k (g_t − s)` is the traction while `|τ*| ≤ μ p`
/// (stick, tangent `∂T_t/∂g_t = k`); beyond, the point slips with `T_t = μ p sign τ*`, the slip
/// moves to `g_t − T_t/k` and the tangent is `∂T_t/∂g_n = −μ k sign τ*` (unsymmetric, so
/// Newton stays quadratic while points slip). An open point (`g_n ≥ 0`) carries nothing and its
/// slip follows the gap. The dissipated work `½ (|T_t|₀ + μ p) |Δs|` (trapezoidal rule from the
/// committed shear [`SHEAR`]) accumulates in the state ([`FRICTION_WORK`]); the recoverable
/// energy is [`contact_stored`].
///
/// The stick spring stands for the elastic compliance of the asperities: with `k` of the order of
/// the law's penalty, stick slips are ~`μ p / k`, below 10⁻³ mm for the pressures of an ENF.
pub fn frictional_contact(gap: &Gap, state: &LawState, k: f64, mu: f64) -> LawEval {
    let mut out = *state;
    if gap[0] >= 0.0 {
        // Open: no traction, and the faces meet again unstressed wherever they are.
        out.history[SLIP] = gap[1];
        out.history[SHEAR] = 0.0;
        return LawEval { traction: Traction::zeros(), tangent: Tangent::zeros(), state: out };
    }
    let (tn, dnn) = (k * gap[0], k);
    let limit = mu * (-tn);
    let s0 = state.history[SLIP];
    let trial = k * (gap[1] - s0);
    let (tt, dtn, dtt) = if trial.abs() <= limit {
        (trial, 0.0, k) // stick
    } else {
        let sign = trial.signum();
        let tt = sign * limit;
        let s1 = gap[1] - tt / k;
        out.history[SLIP] = s1;
        // Trapezoidal rule on the shear over the slip increment (second order in the step, as
        // the ledger's work): from the committed |T_t| to the Coulomb limit.
        out.history[FRICTION_WORK] += 0.5 * (state.history[SHEAR] + limit) * (s1 - s0).abs();
        (tt, -mu * k * sign, 0.0)
    };
    out.history[SHEAR] = tt.abs();
    LawEval { traction: Traction::new(tn, tt), tangent: Tangent::new(dnn, 0.0, dtn, dtt), state: out }
}
