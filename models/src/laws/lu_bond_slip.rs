//! Bond–slip law of Lu, Teng, Ye & Jiang (Eng. Struct. 27 (2005) 920–937) for FRP plates and sheets
//! bonded to concrete, as a cohesive law with a peeling (normal) behaviour added.
//!
//! # Shear: Lu et al.'s simplified model with a finite initial stiffness
//!
//! Lu et al.'s *simplified* model is
//! `τ = τ_max √(s/s0)` for `s ≤ s0` and `τ = τ_max e^{−α(s/s0 − 1)}` beyond, with
//! `τ_max = 1.5 β_w f_t`, `s0 = 0.0195 β_w f_t` (mm), `G_f = 0.308 β_w² √f_t` (N/mm) and
//! `α = 1/(G_f/(τ_max s0) − 2/3)` so that `∫τ ds = G_f`;
//! `β_w = √((2.25 − b_f/b_c)/(1.25 + b_f/b_c))` and `f_t = 0.395 f_cu^0.55` (MPa, `f_cu` the cube
//! strength).
//!
//! Its square-root branch has an infinite slope at `s = 0`, which a Newton solver cannot use. The
//! ascending branch here is the shifted square root of the form Lu et al. give their *precise*
//! model,
//!
//! `τ = τ_max (√(s/(s0 A) + B²) − B)`, `A = 1 − r`, `B = r / (2(1 − r))`, `r = s_e/s0`,
//! `s_e = τ_max/K0`,
//!
//! which starts with the slope `K0` (the `shear_stiffness`), reaches `τ_max` at `s0` and tends to
//! the simplified model's `τ_max √(s/s0)` as `K0 → ∞` (the difference is of order `s_e/s0`). The
//! peak slip stays the simplified model's `s0`: the precise model's shift of `s0` by the elastic
//! slip and its adhesive/concrete layer stiffnesses are **not** implemented; `K0` is a parameter.
//!
//! # Separation: a finite end of the exponential tail
//!
//! The exponential never reaches zero. The descending branch used here is lowered by a small
//! residual `c τ_max` (field `residual`, default 1e-3) and rescaled so it stays continuous at the
//! peak,
//!
//! `τ = τ_max (e^{−α(s/s0 − 1)} − c) / (1 − c)`,
//!
//! so that it reaches zero at `s_u = s0 (1 + ln(1/c)/α)`, where `D = 1` ("separated"). Its energy is
//! `(τ_max s0/α) (1 − c ln(1/c)/(1 − c))`, and `α` is solved from
//! `W_asc + (τ_max s0/α)(1 − c ln(1/c)/(1 − c)) = G_f`
//! (`W_asc = τ_max s0 (2A/3 + r + rB − B)`, the exact area under the ascending branch), so the
//! law dissipates exactly `G_f` in pure shear. With `K0 → ∞` and `c → 0`, α tends to Lu et al.'s
//! `1/(G_f/(τ_max s0) − 2/3)`; for other values the traction differs from the pure exponential
//! by at most a few `c τ_max` plus the regularisation effect.
//!
//! # Damage, unloading and peeling
//!
//! * **Damage** is the secant-stiffness loss `D = 1 − τ(κ)/(K0 κ)` of the largest effective slip
//!   `κ` reached (`history[0]`). The shifted square root is concave from the origin, so damage
//!   grows from the first slip (no elastic range); at the peak `D = 1 − s_e/s0`, and `D = 1`
//!   exactly at `s_u`. "Softening has started" is `κ ≥ s0` ([`LuBondSlip::peak_slip`]): forward
//!   models that report a process zone should use that, not `D > 0`.
//! * **Unloading and reloading** follow the damaged secant to the origin (Lu et al. give no
//!   unloading rule); `½ T·u` is the stored energy.
//! * **Peeling.** Opening is coupled to slip through the effective slip
//!   `κ = √(u_t² + (λ ⟨u_n⟩)²)` and one shared damage: `T_t = (1 − D(κ)) K0 u_t`,
//!   `T_n = (1 − D(κ)) k_n u_n` in opening and `k_n u_n` (undamaged penalty) in compression. In pure
//!   opening this is Lu's curve scaled to the peel strength σ_n and peel energy G_n:
//!   `T_n(u_n) = (σ_n/τ_max) τ(λ u_n)`, which fixes `λ = (σ_n/τ_max)(G_f/G_n)` and
//!   `k_n = λ K0 σ_n/τ_max`. On a proportional mixed path the energy lies between G_n and G_f.
//!   [`LuBondSlip::from_concrete`] takes σ_n = f_t and G_n = the fib Model Code 2010 fracture
//!   energy of the concrete, `73 f_cm^0.18` N/m: debonding in concrete a few mm below the
//!   adhesive is a concrete fracture in both modes.
//!
//! State: `damage` as above; `history[0]` = κ_max (mm).

use crate::laws::response::{add_damage_growth, opening, secant};
use crate::materials::concrete::model_code_fracture_energy;
use czid_core::error::require_positive;
use czid_core::{CohesiveLaw, CzError, Gap, LawEval, LawState, ParameterInfo, Result};
use serde::{Deserialize, Serialize};

const OWNER: &str = "law lu_bond_slip";

fn default_residual() -> f64 {
    LuBondSlip::DEFAULT_RESIDUAL
}

/// Lu et al.'s (2005) FRP-to-concrete bond–slip law (simplified model with a finite initial
/// stiffness), with shared-damage peeling; see the [module documentation](self) for the equations.
///
/// | field             | meaning                                                     | unit   |
/// |-------------------|-------------------------------------------------------------|--------|
/// | `tau_max`         | peak bond stress τ_max = 1.5 β_w f_t                          | MPa    |
/// | `peak_slip`       | slip at the peak s0 = 0.0195 β_w f_t                          | mm     |
/// | `g_f`             | interfacial fracture energy G_f = 0.308 β_w² √f_t             | N/mm   |
/// | `shear_stiffness` | initial slope K0 of the bond–slip curve                      | MPa/mm |
/// | `peel_strength`   | peak normal (peeling) traction σ_n                           | MPa    |
/// | `peel_energy`     | energy to separate in pure opening G_n                       | N/mm   |
/// | `residual`        | fraction c of τ_max at which the tail is cut (default 1e-3)  | –      |
///
/// ```
/// use czid_core::CohesiveLaw;
/// use czid_models::laws::LuBondSlip;
/// // f'c = 47 MPa, 100 mm plate on a 200 mm wide beam, K0 = 1000 MPa/mm.
/// let law = LuBondSlip::from_concrete(47.0, 100.0, 200.0, 1000.0).unwrap();
/// assert!((law.tau_max - 5.57).abs() < 0.01);
/// assert!((law.fracture_energy()[1] - 0.593).abs() < 0.001);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LuBondSlip {
    /// Peak bond (shear) stress τ_max (MPa).
    pub tau_max: f64,
    /// Slip at the peak bond stress s0 (mm).
    pub peak_slip: f64,
    /// Interfacial fracture energy G_f, the area under the bond–slip curve (N/mm).
    pub g_f: f64,
    /// Initial shear stiffness K0 (MPa/mm): the slope of the bond–slip curve at zero slip.
    pub shear_stiffness: f64,
    /// Peak normal (peeling) traction σ_n in pure opening (MPa).
    pub peel_strength: f64,
    /// Energy to separate in pure opening G_n (N/mm).
    pub peel_energy: f64,
    /// Residual c: the exponential tail is lowered by `c τ_max` so it ends at a finite slip
    /// (dimensionless, in (0, 0.1]; default 1e-3).
    #[serde(default = "default_residual")]
    pub residual: f64,
}

/// Constants of the shear curve derived from the parameters.
#[derive(Clone, Copy, Debug)]
struct Shape {
    /// `A = 1 − s_e/s0`.
    a: f64,
    /// `B = r/(2(1 − r))`.
    b: f64,
    /// Exponent of the descending branch.
    alpha: f64,
    /// Slip at which the traction vanishes (mm).
    separation: f64,
}

impl LuBondSlip {
    /// Default residual c: the tail ends where Lu's exponential has fallen to 0.1 % of τ_max.
    pub const DEFAULT_RESIDUAL: f64 = 1e-3;
    /// Ratio of cylinder to cube compressive strength, `f'c = 0.8 f_cu` (normal-strength
    /// concrete; the ratio used to turn the paper's cylinder strength into Lu et al.'s `f_cu`).
    pub const CYLINDER_TO_CUBE: f64 = 0.8;

    /// A validated law from its parameters (residual c at its default).
    pub fn new(
        tau_max: f64,
        peak_slip: f64,
        g_f: f64,
        shear_stiffness: f64,
        peel_strength: f64,
        peel_energy: f64,
    ) -> Result<Self> {
        let law = LuBondSlip {
            tau_max,
            peak_slip,
            g_f,
            shear_stiffness,
            peel_strength,
            peel_energy,
            residual: Self::DEFAULT_RESIDUAL,
        };
        law.validate()?;
        Ok(law)
    }

    /// Lu et al.'s law for a plate of width `plate_width` (b_f, mm) bonded to concrete of
    /// cylinder strength `fc_cylinder` (f'c, MPa) and width `concrete_width` (b_c, mm), with
    /// initial shear stiffness `shear_stiffness` (K0, MPa/mm).
    ///
    /// `f_cu = f'c / 0.8` ([`Self::CYLINDER_TO_CUBE`]), `f_t = 0.395 f_cu^0.55`,
    /// `τ_max = 1.5 β_w f_t`, `s0 = 0.0195 β_w f_t`, `G_f = 0.308 β_w² √f_t`; peeling:
    /// σ_n = f_t and G_n = `73 f'c^0.18` N/m (fib Model Code 2010, f'c taken as the mean strength).
    pub fn from_concrete(
        fc_cylinder: f64,
        plate_width: f64,
        concrete_width: f64,
        shear_stiffness: f64,
    ) -> Result<Self> {
        require_positive(OWNER, "fc_cylinder", fc_cylinder)?;
        let beta_w = Self::width_factor(plate_width, concrete_width)?;
        let f_t = Self::tensile_strength(fc_cylinder / Self::CYLINDER_TO_CUBE);
        Self::new(
            1.5 * beta_w * f_t,
            0.0195 * beta_w * f_t,
            0.308 * beta_w * beta_w * f_t.sqrt(),
            shear_stiffness,
            f_t,
            model_code_fracture_energy(fc_cylinder),
        )
    }

    /// Lu et al.'s width ratio factor `β_w = √((2.25 − b_f/b_c)/(1.25 + b_f/b_c))`; requires
    /// `0 < b_f ≤ b_c` (a plate wider than the concrete is not bonded to it).
    pub fn width_factor(plate_width: f64, concrete_width: f64) -> Result<f64> {
        require_positive(OWNER, "plate_width", plate_width)?;
        require_positive(OWNER, "concrete_width", concrete_width)?;
        if plate_width > concrete_width {
            return Err(CzError::invalid(
                OWNER,
                "plate_width",
                plate_width,
                format!("must not exceed the concrete width b_c = {concrete_width} mm"),
            ));
        }
        let ratio = plate_width / concrete_width;
        Ok(((2.25 - ratio) / (1.25 + ratio)).sqrt())
    }

    /// Concrete tensile strength of Lu et al., `f_t = 0.395 f_cu^0.55` (MPa, `f_cu` the cube
    /// strength in MPa).
    pub fn tensile_strength(cube_strength: f64) -> f64 {
        0.395 * cube_strength.powf(0.55)
    }

    /// Lu et al.'s exponent of the simplified model, `α = 1/(G_f/(τ_max s0) − 2/3)` (the law's own
    /// [`Self::alpha`] tends to it as K0 → ∞ and c → 0).
    pub fn simplified_alpha(&self) -> f64 {
        1.0 / (self.g_f / (self.tau_max * self.peak_slip) - 2.0 / 3.0)
    }

    /// Elastic slip `s_e = τ_max/K0` (mm).
    pub fn elastic_slip(&self) -> f64 {
        self.tau_max / self.shear_stiffness
    }

    /// Energy under the ascending branch, `τ_max s0 (2A/3 + r + rB − B)` (N/mm).
    pub fn ascending_energy(&self) -> f64 {
        let r = self.elastic_slip() / self.peak_slip;
        let (a, b) = (1.0 - r, r / (2.0 * (1.0 - r)));
        // ∫₀^{s0} τ_max (√(s/(s0 A) + B²) − B) ds = τ_max s0 [(2/3) A ((1 + B)³ − B³) − B], using
        // 1/A + B² = (1 + B)²; expanded with A B = r/2 so that r → 0 loses no digits.
        self.tau_max * self.peak_slip * (2.0 * a / 3.0 + r + r * b - b)
    }

    /// The fraction of `τ_max s0/α` that the lowered tail keeps, `1 − c ln(1/c)/(1 − c)`.
    fn tail_fraction(&self) -> f64 {
        let c = self.residual;
        1.0 - c * (1.0 / c).ln() / (1.0 - c)
    }

    fn shape(&self) -> Shape {
        let r = self.elastic_slip() / self.peak_slip;
        let alpha = self.tau_max * self.peak_slip * self.tail_fraction() / (self.g_f - self.ascending_energy());
        Shape {
            a: 1.0 - r,
            b: r / (2.0 * (1.0 - r)),
            alpha,
            separation: self.peak_slip * (1.0 + (1.0 / self.residual).ln() / alpha),
        }
    }

    /// Exponent α of the descending branch, solved so the law dissipates exactly `G_f`.
    pub fn alpha(&self) -> f64 {
        self.shape().alpha
    }

    /// Slip `s_u` at which the traction vanishes and damage reaches 1 (mm).
    pub fn separation_slip(&self) -> f64 {
        self.shape().separation
    }

    /// Ratio λ converting a normal opening into an equivalent slip, `(σ_n/τ_max)(G_f/G_n)`.
    pub fn normal_scale(&self) -> f64 {
        self.peel_strength / self.tau_max * (self.g_f / self.peel_energy)
    }

    /// Normal (peeling) stiffness `k_n = λ K0 σ_n/τ_max` (MPa/mm), also the compression penalty.
    pub fn peel_stiffness(&self) -> f64 {
        self.normal_scale() * self.shear_stiffness * self.peel_strength / self.tau_max
    }

    /// Bond stress (MPa) on the monotonic envelope at slip `s` (mm): the bond–slip curve.
    pub fn bond_stress(&self, slip: f64) -> f64 {
        let s = slip.abs();
        slip.signum() * self.intact_fraction(s, &self.shape()).0 * self.shear_stiffness * s
    }

    /// Intact fraction `1 − D = τ(κ)/(K0 κ)` and its derivative with respect to κ.
    fn intact_fraction(&self, kappa: f64, shape: &Shape) -> (f64, f64) {
        let s0 = self.peak_slip;
        if kappa <= 0.0 {
            return (1.0, 0.0);
        }
        if kappa <= s0 {
            // τ = τ_max x/(R + B) with x = κ/(s0 A), R = √(x + B²); τ_max/(K0 s0 A) = 2B, so
            // 1 − D = 2B/(R + B), free of the cancellation in √(x + B²) − B.
            let (a, b) = (shape.a, shape.b);
            let root = (kappa / (s0 * a) + b * b).sqrt();
            let intact = 2.0 * b / (root + b);
            let derivative = -intact / (root + b) / (2.0 * root) / (s0 * a);
            return (intact, derivative);
        }
        if kappa >= shape.separation {
            return (0.0, 0.0);
        }
        let c = self.residual;
        let e = (-shape.alpha * (kappa / s0 - 1.0)).exp();
        let tau = self.tau_max * (e - c) / (1.0 - c);
        let dtau = -self.tau_max * shape.alpha * e / (s0 * (1.0 - c));
        let k0 = self.shear_stiffness;
        (tau / (k0 * kappa), (dtau * kappa - tau) / (k0 * kappa * kappa))
    }
}

#[typetag::serde(name = "lu_bond_slip")]
impl CohesiveLaw for LuBondSlip {
    fn validate(&self) -> Result<()> {
        require_positive(OWNER, "tau_max", self.tau_max)?;
        require_positive(OWNER, "peak_slip", self.peak_slip)?;
        require_positive(OWNER, "g_f", self.g_f)?;
        require_positive(OWNER, "shear_stiffness", self.shear_stiffness)?;
        require_positive(OWNER, "peel_strength", self.peel_strength)?;
        require_positive(OWNER, "peel_energy", self.peel_energy)?;
        require_positive(OWNER, "residual", self.residual)?;
        if self.residual > 0.1 {
            return Err(CzError::invalid(
                OWNER,
                "residual",
                self.residual,
                "must be at most 0.1 (the tail is cut where the traction is a small fraction of τ_max)",
            ));
        }
        let elastic_slip = self.elastic_slip();
        if elastic_slip >= self.peak_slip {
            return Err(CzError::invalid(
                OWNER,
                "shear_stiffness",
                self.shear_stiffness,
                format!(
                    "too low: the elastic slip τ_max/K0 = {elastic_slip:e} mm must be below the peak slip s0 = {} mm; \
                     K0 must exceed τ_max/s0 = {:e} MPa/mm",
                    self.peak_slip,
                    self.tau_max / self.peak_slip
                ),
            ));
        }
        let ascending = self.ascending_energy();
        if self.g_f <= ascending {
            return Err(CzError::invalid(
                OWNER,
                "g_f",
                self.g_f,
                format!(
                    "must exceed the energy under the ascending branch, {ascending:e} N/mm (about ⅔ τ_max s0): \
                     no descending branch would be left"
                ),
            ));
        }
        Ok(())
    }

    fn evaluate(&self, gap: &Gap, previous: &LawState) -> LawEval {
        let shape = self.shape();
        let lambda = self.normal_scale();
        let stiffness = [self.peel_stiffness(), self.shear_stiffness];
        let scaled_opening = lambda * opening(gap);
        let kappa = (gap.y * gap.y + scaled_opening * scaled_opening).sqrt();
        let kappa_old = previous.history[0];
        let result = |intact: f64, kappa_max: f64| {
            let (traction, tangent) = secant(stiffness, intact, gap);
            let mut history = previous.history;
            history[0] = kappa_max;
            // Damage cannot fall below the committed one, even for a hand-made state.
            let damage = (1.0 - intact).max(previous.damage).clamp(0.0, 1.0);
            LawEval { traction, tangent, state: LawState { damage, history } }
        };
        if previous.damage >= 1.0 {
            return result(0.0, kappa_old.max(kappa));
        }
        if kappa <= kappa_old {
            // Unloading or reloading below the largest slip reached: the damaged secant.
            return result(self.intact_fraction(kappa_old, &shape).0, kappa_old);
        }
        let (intact, slope) = self.intact_fraction(kappa, &shape);
        let mut eval = result(intact, kappa);
        if kappa > 0.0 && slope != 0.0 {
            // ∂D/∂u = −(d(1 − D)/dκ) ∂κ/∂u, ∂κ/∂u = [λ² ⟨u_n⟩, u_t]/κ.
            let gradient = [-slope * lambda * scaled_opening / kappa, -slope * gap.y / kappa];
            add_damage_growth(&mut eval.tangent, stiffness, gap, gradient);
        }
        eval
    }

    fn fracture_energy(&self) -> [f64; 2] {
        [self.peel_energy, self.g_f]
    }

    fn initial_stiffness(&self) -> [f64; 2] {
        [self.peel_stiffness(), self.shear_stiffness]
    }

    fn strength(&self) -> [f64; 2] {
        [self.peel_strength, self.tau_max]
    }

    fn parameters(&self) -> Vec<ParameterInfo> {
        vec![
            ParameterInfo { name: "tau_max", value: self.tau_max, unit: "MPa", meaning: "peak bond stress τ_max" },
            ParameterInfo { name: "peak_slip", value: self.peak_slip, unit: "mm", meaning: "slip at the peak s0" },
            ParameterInfo { name: "g_f", value: self.g_f, unit: "N/mm", meaning: "interfacial fracture energy G_f" },
            ParameterInfo {
                name: "shear_stiffness",
                value: self.shear_stiffness,
                unit: "MPa/mm",
                meaning: "initial bond stiffness K0",
            },
            ParameterInfo {
                name: "peel_strength",
                value: self.peel_strength,
                unit: "MPa",
                meaning: "peak peeling traction σ_n",
            },
            ParameterInfo {
                name: "peel_energy",
                value: self.peel_energy,
                unit: "N/mm",
                meaning: "energy to separate in pure opening G_n",
            },
            ParameterInfo {
                name: "residual",
                value: self.residual,
                unit: "-",
                meaning: "fraction of τ_max at which the exponential tail is cut",
            },
        ]
    }
}
