//! The strength-based cohesive zone model (ST-CZM) of Nairn & Aimene (Eng. Fract. Mech. 248 (2021)
//! 107704), as used by Shi & Zhang for inverse identification.
//!
//! Each mode has a complete uniaxial strength model (σ, `u_e`, `u_c`, shape). One damage scalar D
//! is shared by both modes; for each D the secant condition fixes a per-mode opening `δ_m(D)` and
//! the failure surface in displacement space is the ellipse
//! `g(u, D) = (⟨u_n⟩/δ_n(D))² + (u_t/δ_t(D))² − 1 ≤ 0`.
//! Damage grows only to keep `g = 0`, so it starts on `(u_n/u_e,n)² + (u_t/u_e,t)² = 1` and is
//! complete on `(u_n/u_c,n)² + (u_t/u_c,t)² = 1`.

use crate::laws::response::{add_damage_growth, opening, secant};
use crate::laws::root::solve_monotone;
use crate::laws::strength_model::{ModeStrength, StrengthShape};
use czid_core::{CohesiveLaw, Gap, LawEval, LawState, ParameterInfo, Result};
use serde::{Deserialize, Serialize};

const OWNER: &str = "law st_czm";

/// Nairn & Aimene's strength-based cohesive zone model.
///
/// Parameters by meaning, with the symbols of Shi & Zhang's tables (whose `Δu_f` is the *end of
/// the elastic branch* and `Δu_c` the opening where the traction vanishes; the text around their
/// Eq. 1 swaps the two letters):
///
/// | field        | meaning                                   | paper   | unit |
/// |--------------|-------------------------------------------|---------|------|
/// | `strength_n` | normal strength σ_n                       | σ_n,c   | MPa  |
/// | `u_e_n`      | normal opening at the elastic limit       | Δu_n,f  | mm   |
/// | `u_c_n`      | normal opening where traction vanishes    | Δu_n,c  | mm   |
/// | `strength_t` | shear strength σ_t                        | σ_t,c   | MPa  |
/// | `u_e_t`      | slip at the elastic limit                 | Δu_t,f  | mm   |
/// | `u_c_t`      | slip where traction vanishes              | Δu_t,c  | mm   |
///
/// The initial stiffness is `k_m = σ_m / u_e,m` (the tables' `k_i,0`: 27 / 0.00027 = 1e5 MPa/mm),
/// and with the sawtooth shape the pure-mode toughness is `G_m = ½ σ_m u_c,m`.
///
/// State: `damage` is the shared D; `history[0]` and `history[1]` cache the per-mode openings
/// `δ_n(D)`, `δ_t(D)` of the committed damage (zero means "not known yet": they are recomputed,
/// so a state built by hand with only `damage` set is fine).
///
/// ```
/// use czid_core::{CohesiveLaw, Gap, LawState};
/// use czid_models::laws::StCzm;
/// // Shi & Zhang, Table 3.
/// let law = StCzm::sawtooth(27.0, 0.00027, 0.003273, 40.0, 0.00025, 0.003273).unwrap();
/// assert!((law.fracture_energy()[0] - 0.5 * 27.0 * 0.003273).abs() < 1e-15);
/// let eval = law.evaluate(&Gap::new(0.001, 0.0), &LawState::default());
/// assert!(eval.state.damage > 0.0 && eval.state.damage < 1.0);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StCzm {
    /// Normal strength σ_n (MPa); paper σ_n,c.
    pub strength_n: f64,
    /// Normal opening at the end of the elastic branch (mm); paper Δu_n,f (tables).
    pub u_e_n: f64,
    /// Normal opening at which the traction vanishes (mm); paper Δu_n,c (tables).
    pub u_c_n: f64,
    /// Shear strength σ_t (MPa); paper σ_t,c.
    pub strength_t: f64,
    /// Slip at the end of the elastic branch (mm); paper Δu_t,f (tables).
    pub u_e_t: f64,
    /// Slip at which the traction vanishes (mm); paper Δu_t,c (tables).
    pub u_c_t: f64,
    /// Softening shape of the normal strength model (default: sawtooth).
    #[serde(default, skip_serializing_if = "StrengthShape::is_sawtooth")]
    pub shape_n: StrengthShape,
    /// Softening shape of the shear strength model (default: sawtooth).
    #[serde(default, skip_serializing_if = "StrengthShape::is_sawtooth")]
    pub shape_t: StrengthShape,
}

impl StCzm {
    /// The paper's law (sawtooth in both modes), validated. Arguments in the paper's order
    /// `x = [σ_n, u_e,n, u_c,n, σ_t, u_e,t, u_c,t]`.
    pub fn sawtooth(strength_n: f64, u_e_n: f64, u_c_n: f64, strength_t: f64, u_e_t: f64, u_c_t: f64) -> Result<Self> {
        let law = StCzm {
            strength_n,
            u_e_n,
            u_c_n,
            strength_t,
            u_e_t,
            u_c_t,
            shape_n: StrengthShape::Sawtooth,
            shape_t: StrengthShape::Sawtooth,
        };
        law.validate()?;
        Ok(law)
    }

    /// The same law with other softening shapes, validated.
    pub fn with_shapes(mut self, shape_n: StrengthShape, shape_t: StrengthShape) -> Result<Self> {
        self.shape_n = shape_n;
        self.shape_t = shape_t;
        self.validate()?;
        Ok(self)
    }

    /// The normal-mode strength model.
    pub fn mode_n(&self) -> ModeStrength {
        ModeStrength { strength: self.strength_n, u_e: self.u_e_n, u_c: self.u_c_n, shape: self.shape_n }
    }

    /// The shear-mode strength model.
    pub fn mode_t(&self) -> ModeStrength {
        ModeStrength { strength: self.strength_t, u_e: self.u_e_t, u_c: self.u_c_t, shape: self.shape_t }
    }

    fn stiffness(&self) -> [f64; 2] {
        [self.strength_n / self.u_e_n, self.strength_t / self.u_e_t]
    }

    /// Intact fraction `1 − D` on the failure surface through `(a_n, a_t)` (opening ⟨u_n⟩ and
    /// slip), in `(0, intact_old)`, with the per-mode openings there; `guesses` are nearby openings. The caller guarantees the point lies strictly between the
    /// surface of the committed damage and the complete-failure ellipse, so exactly one root exists.
    /// Solving for `1 − D` rather than `D` keeps the traction's digits near separation.
    fn intact_on_surface(&self, a_n: f64, a_t: f64, intact_old: f64, guesses: (f64, f64)) -> (f64, (f64, f64)) {
        let (mode_n, mode_t) = (self.mode_n(), self.mode_t());
        if self.shape_n == StrengthShape::Sawtooth && self.shape_t == StrengthShape::Sawtooth {
            // δ_m = u_e,m / (p_m + c_m I), p_m = u_e,m/u_c,m, c_m = 1 − p_m, I = 1 − D, turns g = 0 into
            // (A_n²c_n² + A_t²c_t²) I² + 2 (A_n²c_n p_n + A_t²c_t p_t) I + (A_n²p_n² + A_t²p_t² − 1) = 0
            // with A_m = a_m/u_e,m (the D-quadratic of the design notes, rewritten in I). The constant
            // is negative before complete failure, so there is one positive root; this form of it
            // has no cancellation.
            let (an2, at2) = ((a_n / self.u_e_n).powi(2), (a_t / self.u_e_t).powi(2));
            let (pn, pt) = (self.u_e_n / self.u_c_n, self.u_e_t / self.u_c_t);
            let (cn, ct) = (1.0 - pn, 1.0 - pt);
            let quadratic = an2 * cn * cn + at2 * ct * ct;
            let half_linear = an2 * cn * pn + at2 * ct * pt;
            let constant = an2 * pn * pn + at2 * pt * pt - 1.0;
            let discriminant = half_linear * half_linear - quadratic * constant;
            let intact = (-constant / (half_linear + discriminant.sqrt())).clamp(0.0, intact_old);
            return (intact, (mode_n.opening_at_intact(intact), mode_t.opening_at_intact(intact)));
        }
        // g grows with I (the per-mode openings shrink): negative at I = 0, positive at intact_old.
        // Each iterate's openings seed the next iterate's inverse.
        let (mut guess_n, mut guess_t) = guesses;
        let residual = |intact: f64| {
            let (dn, dt) =
                (mode_n.opening_at_intact_near(intact, guess_n), mode_t.opening_at_intact_near(intact, guess_t));
            (guess_n, guess_t) = (dn, dt);
            let g = (a_n / dn).powi(2) + (a_t / dt).powi(2) - 1.0;
            let dg = 2.0
                * (a_n * a_n * mode_n.opening_rate(dn) / dn.powi(3) + a_t * a_t * mode_t.opening_rate(dt) / dt.powi(3));
            (g, dg)
        };
        let intact = solve_monotone(residual, 0.0, intact_old, intact_old, true);
        (intact, (guess_n, guess_t))
    }

    /// The per-mode openings `δ_m` at the committed damage: cached in `history[0..2]` by earlier
    /// evaluations (the inverse of an exponential strength model is iterative), else computed.
    fn committed_openings(&self, previous: &LawState, intact_old: f64) -> (f64, f64) {
        let [dn, dt, _] = previous.history;
        if dn > 0.0 && dt > 0.0 {
            (dn, dt)
        } else {
            (self.mode_n().opening_at_intact(intact_old), self.mode_t().opening_at_intact(intact_old))
        }
    }
}

#[typetag::serde(name = "st_czm")]
impl CohesiveLaw for StCzm {
    fn validate(&self) -> Result<()> {
        self.mode_n().validate(OWNER, "n")?;
        self.mode_t().validate(OWNER, "t")
    }

    fn evaluate(&self, gap: &Gap, previous: &LawState) -> LawEval {
        let stiffness = self.stiffness();
        let damage_old = previous.damage.clamp(0.0, 1.0);
        let (a_n, a_t) = (opening(gap), gap.y);
        let respond = |intact: f64, openings: [f64; 2]| {
            let (traction, tangent) = secant(stiffness, intact, gap);
            let history = [openings[0], openings[1], previous.history[2]];
            LawEval { traction, tangent, state: LawState { damage: 1.0 - intact, history } }
        };
        if damage_old >= 1.0 {
            return respond(0.0, [self.u_c_n, self.u_c_t]);
        }
        let intact_old = 1.0 - damage_old;
        let (dn_old, dt_old) = self.committed_openings(previous, intact_old);
        if (a_n / self.u_c_n).powi(2) + (a_t / self.u_c_t).powi(2) >= 1.0 {
            return respond(0.0, [self.u_c_n, self.u_c_t]);
        }
        if (a_n / dn_old).powi(2) + (a_t / dt_old).powi(2) <= 1.0 {
            // Inside the current surface (or at the origin): elastic on the damaged secant.
            return respond(intact_old, [dn_old, dt_old]);
        }
        let (intact, (dn, dt)) = self.intact_on_surface(a_n, a_t, intact_old, (dn_old, dt_old));
        let (mode_n, mode_t) = (self.mode_n(), self.mode_t());
        // ∂D/∂u = −g_u/g_D from g(u, D(u)) = 0, with g_D = −2 Σ a_m² δ_m'/δ_m³ and δ' = dδ/dD.
        let g_d = a_n * a_n * mode_n.opening_rate(dn) / dn.powi(3) + a_t * a_t * mode_t.opening_rate(dt) / dt.powi(3);
        let gradient = [a_n / (dn * dn) / g_d, a_t / (dt * dt) / g_d];
        let mut eval = respond(intact, [dn, dt]);
        add_damage_growth(&mut eval.tangent, stiffness, gap, gradient);
        eval
    }

    fn fracture_energy(&self) -> [f64; 2] {
        [self.mode_n().fracture_energy(), self.mode_t().fracture_energy()]
    }

    fn initial_stiffness(&self) -> [f64; 2] {
        self.stiffness()
    }

    /// The sawtooth's opening on its strength surface, `δ = u_e/(p + c I)`, makes the traction
    /// `K I δ = K (u_e − p δ)/c` linear in the opening; the exponential shape's is not.
    fn opening_path_piecewise_linear(&self) -> bool {
        self.shape_n == StrengthShape::Sawtooth
    }

    fn strength(&self) -> [f64; 2] {
        [self.strength_n, self.strength_t]
    }

    /// The normal branch and both shapes: at zero slip the shear terms of the strength surface,
    /// `(a_t/δ_t)²`, are exact zeros, and the shear branch enters nothing else of the normal
    /// response (the shear shape is in the key all the same: it may add inner kinks).
    fn mode_one_key(&self) -> Option<Vec<u64>> {
        let mut key = vec![self.strength_n.to_bits(), self.u_e_n.to_bits(), self.u_c_n.to_bits()];
        key.extend(self.shape_n.key());
        key.extend(self.shape_t.key());
        Some(key)
    }

    fn parameters(&self) -> Vec<ParameterInfo> {
        let mut list = vec![
            ParameterInfo {
                name: "strength_n",
                value: self.strength_n,
                unit: "MPa",
                meaning: "normal strength (paper σ_n,c)",
            },
            ParameterInfo {
                name: "u_e_n",
                value: self.u_e_n,
                unit: "mm",
                meaning: "normal opening at the elastic limit (paper Δu_n,f)",
            },
            ParameterInfo {
                name: "u_c_n",
                value: self.u_c_n,
                unit: "mm",
                meaning: "normal opening where traction vanishes (paper Δu_n,c)",
            },
            ParameterInfo {
                name: "strength_t",
                value: self.strength_t,
                unit: "MPa",
                meaning: "shear strength (paper σ_t,c)",
            },
            ParameterInfo {
                name: "u_e_t",
                value: self.u_e_t,
                unit: "mm",
                meaning: "slip at the elastic limit (paper Δu_t,f)",
            },
            ParameterInfo {
                name: "u_c_t",
                value: self.u_c_t,
                unit: "mm",
                meaning: "slip where traction vanishes (paper Δu_t,c)",
            },
        ];
        shape_parameters(
            &mut list,
            self.shape_n,
            ["shape_n.alpha", "shape_n.kink_fraction", "shape_n.kink_strength_ratio"],
        );
        shape_parameters(
            &mut list,
            self.shape_t,
            ["shape_t.alpha", "shape_t.kink_fraction", "shape_t.kink_strength_ratio"],
        );
        list
    }
}

fn shape_parameters(list: &mut Vec<ParameterInfo>, shape: StrengthShape, names: [&'static str; 3]) {
    match shape {
        StrengthShape::Sawtooth => {}
        StrengthShape::Exponential { alpha } => list.push(ParameterInfo {
            name: names[0],
            value: alpha,
            unit: "-",
            meaning: "exponential softening decay rate",
        }),
        StrengthShape::Trilinear { kink_fraction, kink_strength_ratio } => {
            list.push(ParameterInfo {
                name: names[1],
                value: kink_fraction,
                unit: "-",
                meaning: "kink position as a fraction of the softening range",
            });
            list.push(ParameterInfo {
                name: names[2],
                value: kink_strength_ratio,
                unit: "-",
                meaning: "traction at the kink over the strength",
            });
        }
    }
}
