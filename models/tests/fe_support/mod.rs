//! Shared by the engine and model tests: a private bilinear law (so the engine is tested
//! independently of `crate::laws`) and closed-form references. Expected values come from these
//! formulas, never from the code under test.
#![allow(dead_code)]

use czid_core::{CohesiveLaw, Gap, LawEval, LawState, ParameterInfo, Result, Tangent, Traction};
use nalgebra::Complex;
use serde::{Deserialize, Serialize};

/// Bilinear law on the effective opening `δ = √(⟨u_n⟩² + u_t²)` with equal mode I/II parameters:
/// penalty `k`, damage from `δ0 = σ/k` to `δf = 2 G_c / σ`, secant unloading, no damage in
/// compression.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TestBilinear {
    pub k: f64,
    pub sigma: f64,
    pub gc: f64,
}

impl TestBilinear {
    pub fn new(k: f64, sigma: f64, gc: f64) -> Self {
        TestBilinear { k, sigma, gc }
    }
    fn d0(&self) -> f64 {
        self.sigma / self.k
    }
    fn df(&self) -> f64 {
        2.0 * self.gc / self.sigma
    }
    fn damage(&self, delta: f64) -> f64 {
        let (d0, df) = (self.d0(), self.df());
        if delta <= d0 {
            0.0
        } else if delta >= df {
            1.0
        } else {
            df * (delta - d0) / (delta * (df - d0))
        }
    }
}

#[typetag::serde(name = "fe_test_bilinear")]
impl CohesiveLaw for TestBilinear {
    fn validate(&self) -> Result<()> {
        Ok(())
    }
    fn evaluate(&self, gap: &Gap, previous: &LawState) -> LawEval {
        let (un, ut) = (gap[0], gap[1]);
        let unp = un.max(0.0);
        let delta = (unp * unp + ut * ut).sqrt();
        let kappa_old = previous.history[0];
        let loading = delta > kappa_old && delta > self.d0() && delta < self.df();
        let kappa = kappa_old.max(delta);
        let d = self.damage(kappa).max(previous.damage);
        let k = self.k;
        let tn = if un > 0.0 { (1.0 - d) * k * un } else { k * un };
        let tt = (1.0 - d) * k * ut;
        let mut tan = Tangent::new(if un > 0.0 { (1.0 - d) * k } else { k }, 0.0, 0.0, (1.0 - d) * k);
        if loading {
            let (d0, df) = (self.d0(), self.df());
            let dd = df * d0 / (delta * delta * (df - d0));
            let g = [dd * unp / delta, dd * ut / delta];
            let tvec = [if un > 0.0 { k * un } else { 0.0 }, k * ut];
            for i in 0..2 {
                for j in 0..2 {
                    tan[(i, j)] -= tvec[i] * g[j];
                }
            }
        }
        let mut state = LawState { damage: d, history: [kappa, 0.0, 0.0] };
        if kappa >= self.df() {
            state.damage = 1.0;
        }
        LawEval { traction: Traction::new(tn, tt), tangent: tan, state }
    }
    fn fracture_energy(&self) -> [f64; 2] {
        [self.gc, self.gc]
    }
    fn initial_stiffness(&self) -> [f64; 2] {
        [self.k, self.k]
    }
    fn strength(&self) -> [f64; 2] {
        [self.sigma, self.sigma]
    }
    fn parameters(&self) -> Vec<ParameterInfo> {
        vec![]
    }
}

/// Beam properties of one arm.
#[derive(Clone, Copy, Debug)]
pub struct Arm {
    pub e: f64,
    pub g: f64,
    pub b: f64,
    pub h: f64,
}

impl Arm {
    pub fn ei(&self) -> f64 {
        self.e * self.b * self.h.powi(3) / 12.0
    }
    /// κGA with κ = 5/6.
    pub fn s(&self) -> f64 {
        5.0 / 6.0 * self.g * self.b * self.h
    }
}

/// DCB opening compliance δ/P (mm/N) of two Timoshenko arms of free length `a` on a Winkler
/// foundation of stiffness `kf` per unit length per arm (N/mm²), semi-infinite bonded part.
///
/// Bonded part (x ≥ 0 from the crack front): EI θ'' = −S(w' − θ), S(w'' − θ') = kf w, so
/// EI w'''' − (EI kf/S) w'' + kf w = 0; decaying roots s of EI s⁴ − (EI kf/S) s² + kf = 0, with
/// θ = Σ C (s − kf/(S s)) e^{sx}. The free arm transmits F0 = P and M0 = −P a to the front:
/// EI θ'(0) = P a, S(w'(0) − θ(0)) = −P. The load-point deflection is
/// w(0) − a θ(0) + P a³/(3EI) + P a/S, and the opening is twice that.
/// For S → ∞ this is Kanninen's (1973) formula (checked in `fe_reference_formulas`).
pub fn dcb_compliance_foundation(arm: &Arm, a: f64, kf: f64) -> f64 {
    let (ei, s) = (arm.ei(), arm.s());
    let p = 1.0;
    let bq = ei * kf / s;
    let disc = Complex::new(bq * bq - 4.0 * ei * kf, 0.0).sqrt();
    // The two decaying roots (a conjugate pair, or two real roots when shear dominates).
    let mut roots = [Complex::new(0.0, 0.0); 2];
    for (j, sign) in [1.0, -1.0].into_iter().enumerate() {
        let s2 = (Complex::new(bq, 0.0) + disc * sign) / (2.0 * ei);
        let r = s2.sqrt();
        roots[j] = if r.re > 0.0 { -r } else { r };
    }
    let th = |r: Complex<f64>| r - kf / (s * r);
    let m = |r: Complex<f64>| (r * r - kf / s) * ei;
    let q = |r: Complex<f64>| Complex::new(kf, 0.0) / r;
    // Σ C_j m_j = P a, Σ C_j q_j = −P (complex 2×2, Cramer).
    let (m1, m2, q1, q2) = (m(roots[0]), m(roots[1]), q(roots[0]), q(roots[1]));
    let det = m1 * q2 - m2 * q1;
    let c1 = (q2 * (p * a) - m2 * (-p)) / det;
    let c2 = (m1 * (-p) - q1 * (p * a)) / det;
    let w0 = (c1 + c2).re;
    let th0 = (c1 * th(roots[0]) + c2 * th(roots[1])).re;
    let tip = w0 - a * th0 + p * a.powi(3) / (3.0 * ei) + p * a / s;
    2.0 * tip / p
}

/// Kanninen's DCB compliance (Euler–Bernoulli arms on a Winkler foundation of stiffness `kf`
/// per length), plus optionally the arms' shear deflection `2 a/(κ G b h)`.
pub fn kanninen(arm: &Arm, a: f64, kf: f64, shear: bool) -> f64 {
    let ei = arm.ei();
    let l = (kf / (4.0 * ei)).powf(0.25);
    let la = l * a;
    let bend = 2.0 * a.powi(3) / (3.0 * ei) * (1.0 + 3.0 / la + 3.0 / (la * la) + 1.5 / la.powi(3));
    bend + if shear { 2.0 * a / arm.s() } else { 0.0 }
}

/// Clamped Timoshenko cantilever pair: δ/P = 2(a³/(3EI) + a/(κGbh)).
pub fn clamped(arm: &Arm, a: f64) -> f64 {
    2.0 * (a.powi(3) / (3.0 * arm.ei()) + a / arm.s())
}

/// Williams' corrected-beam-theory crack-length correction χh for a DCB arm.
pub fn chi_h(e11: f64, e22: f64, g13: f64, h: f64) -> f64 {
    let gam = 1.18 * (e11 * e22).sqrt() / g13;
    let r = gam / (1.0 + gam);
    ((e11 / (11.0 * g13)) * (3.0 - 2.0 * r * r)).sqrt() * h
}

/// Limit of [`dcb_compliance_foundation`] for a rigid foundation: the arms are clamped in
/// deflection but their sections still rotate in the bonded part against shear, θ = θ0 e^{−x/ℓ},
/// ℓ = √(EI/S), θ0 = −P a ℓ/EI: δ/P = 2(a³/(3EI) + a/S + a² ℓ/EI). For S → ∞ this is the clamped
/// cantilever.
pub fn rigid_foundation(arm: &Arm, a: f64) -> f64 {
    let l = (arm.ei() / arm.s()).sqrt();
    clamped(arm, a) + 2.0 * a * a * l / arm.ei()
}

/// Propagation branch of corrected beam theory, as (δ, P) for an effective crack length `ae`:
/// C = 8 ae³/(E b h³) [+ 12 ae/(5 G b h) with `shear`], G = P² C'/(2b) = G_c.
pub fn cbt_branch(arm: &Arm, ae: f64, gc: f64) -> (f64, f64) {
    cbt_branch_s(arm, ae, gc, false)
}

/// [`cbt_branch`] with the optional shear term.
pub fn cbt_branch_s(arm: &Arm, ae: f64, gc: f64, shear: bool) -> (f64, f64) {
    let (e, g, b, h) = (arm.e, arm.g, arm.b, arm.h);
    let sh = if shear { 1.0 } else { 0.0 };
    let c = 8.0 * ae.powi(3) / (e * b * h.powi(3)) + sh * 12.0 * ae / (5.0 * g * b * h);
    let dc = 24.0 * ae * ae / (e * b * h.powi(3)) + sh * 12.0 / (5.0 * g * b * h);
    let p = (2.0 * b * gc / dc).sqrt();
    (c * p, p)
}

/// Load on the CBT propagation branch at opening `delta` (bisection on the crack length).
pub fn cbt_load_at(arm: &Arm, delta: f64, gc: f64) -> f64 {
    let (mut lo, mut hi) = (1e-3, 1e4);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if cbt_branch(arm, mid, gc).0 < delta {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    cbt_branch(arm, 0.5 * (lo + hi), gc).1
}

/// Linear interpolation of `y(x)` at `xq` on the first branch where x crosses xq.
pub fn interp(x: &[f64], y: &[f64], xq: f64) -> f64 {
    for i in 1..x.len() {
        if (x[i - 1] - xq) * (x[i] - xq) <= 0.0 && x[i] != x[i - 1] {
            let t = (xq - x[i - 1]) / (x[i] - x[i - 1]);
            return y[i - 1] + t * (y[i] - y[i - 1]);
        }
    }
    f64::NAN
}
