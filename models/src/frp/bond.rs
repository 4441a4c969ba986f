//! Closed forms for the single-shear pull test of an FRP plate bonded to concrete, the checks the
//! pull-test model is held to.
//!
//! * **Long bond** (bond length beyond the effective length): the debonding load depends only on
//!   the interfacial fracture energy, `P_max = b_f √(2 G_f E_f t_f)`, whatever the shape of the
//!   bond–slip law (energy balance of a crack growing along a plate of axial stiffness `E_f t_f`
//!   on a rigid substrate).
//! * **Chen & Teng (2001)** (J. Struct. Eng. 127(7) 784–791): effective bond length
//!   `L_e = √(E_f t_f/√f'c)` (mm, with MPa), bond-length factor `β_L = sin(π L/(2 L_e))` for
//!   `L < L_e` and 1 beyond, width factor `β_p = √((2 − b_f/b_c)/(1 + b_f/b_c))`, and strength
//!   `P_u = 0.427 β_p β_L √f'c b_f L_e` (N).
//! * **Linear-softening law** (`τ = τ_f (1 − s/s_f)`, rigid substrate): the bond equation
//!   `E_f t_f s'' = τ(s)` gives, for `L` below `π/(2λ)` with `λ² = τ_f/(s_f E_f t_f)`,
//!   `P_max = b_f √(2 G_f E_f t_f) sin(λ L)` (`G_f = ½ τ_f s_f`): the sine of Chen & Teng's
//!   `β_L`, whose `L_e` is this `π/(2λ)` calibrated on tests.
//! * **Any law** ([`BondedJoint::strength_for_law`]): the same bond equation integrated
//!   numerically from the free end (slip `δ`, no strain) to the loaded end,
//!   `P(δ) = b_f E_f t_f s'(L)`, maximised over `δ`.
//!
//! Units N, mm, MPa.

use czid_core::error::require_positive;
use czid_core::{CzError, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

const OWNER: &str = "bonded joint";

/// A single-shear pull test: an FRP plate bonded over `bond_length` to a concrete prism.
///
/// ```
/// use czid_models::frp::bond::BondedJoint;
/// // The paper's plate (100 × 0.999 mm) with E_f = 200 GPa on f'c = 47 MPa concrete.
/// let joint = BondedJoint::new(100.0, 0.999, 200_000.0, 200.0, 47.0, 500.0).unwrap();
/// assert!((joint.effective_bond_length() - 170.7).abs() < 0.1);
/// assert!((joint.long_bond_strength(0.593) - 48_680.0).abs() < 50.0);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BondedJoint {
    /// Plate width b_f (mm).
    pub plate_width: f64,
    /// Plate thickness t_f (mm).
    pub plate_thickness: f64,
    /// Plate modulus E_f (MPa).
    pub plate_modulus: f64,
    /// Width of the concrete b_c (mm).
    pub concrete_width: f64,
    /// Concrete cylinder strength f'c (MPa).
    pub fc_cylinder: f64,
    /// Bonded length L (mm).
    pub bond_length: f64,
}

/// Peak load of a joint for a given bond–slip curve, with where it occurs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BondStrength {
    /// Peak load (N).
    pub load: f64,
    /// Free-end slip at the peak (mm).
    pub free_end_slip: f64,
    /// Loaded-end slip at the peak (mm).
    pub loaded_end_slip: f64,
}

impl BondedJoint {
    /// A validated joint.
    pub fn new(
        plate_width: f64,
        plate_thickness: f64,
        plate_modulus: f64,
        concrete_width: f64,
        fc_cylinder: f64,
        bond_length: f64,
    ) -> Result<Self> {
        let joint =
            BondedJoint { plate_width, plate_thickness, plate_modulus, concrete_width, fc_cylinder, bond_length };
        joint.validate()?;
        Ok(joint)
    }

    /// Checks every value; errors name the offending one.
    pub fn validate(&self) -> Result<()> {
        require_positive(OWNER, "plate_width", self.plate_width)?;
        require_positive(OWNER, "plate_thickness", self.plate_thickness)?;
        require_positive(OWNER, "plate_modulus", self.plate_modulus)?;
        require_positive(OWNER, "concrete_width", self.concrete_width)?;
        require_positive(OWNER, "fc_cylinder", self.fc_cylinder)?;
        require_positive(OWNER, "bond_length", self.bond_length)?;
        if self.plate_width > self.concrete_width {
            return Err(CzError::invalid(
                OWNER,
                "plate_width",
                self.plate_width,
                format!("must not exceed the concrete width {}", self.concrete_width),
            ));
        }
        Ok(())
    }

    /// Axial stiffness per unit width `E_f t_f` (N/mm).
    pub fn plate_stiffness(&self) -> f64 {
        self.plate_modulus * self.plate_thickness
    }

    /// `P_max = b_f √(2 G_f E_f t_f)` (N) for an interfacial fracture energy `g_f` (N/mm).
    pub fn long_bond_strength(&self, g_f: f64) -> f64 {
        self.plate_width * (2.0 * g_f * self.plate_stiffness()).sqrt()
    }

    /// Chen & Teng's effective bond length `L_e = √(E_f t_f/√f'c)` (mm).
    pub fn effective_bond_length(&self) -> f64 {
        (self.plate_stiffness() / self.fc_cylinder.sqrt()).sqrt()
    }

    /// Chen & Teng's bond-length factor: `sin(π L/(2 L_e))` below `L_e`, 1 beyond.
    pub fn bond_length_factor(&self) -> f64 {
        let ratio = self.bond_length / self.effective_bond_length();
        if ratio >= 1.0 {
            1.0
        } else {
            (0.5 * PI * ratio).sin()
        }
    }

    /// Chen & Teng's width factor `β_p = √((2 − b_f/b_c)/(1 + b_f/b_c))`.
    pub fn width_factor(&self) -> f64 {
        let ratio = self.plate_width / self.concrete_width;
        ((2.0 - ratio) / (1.0 + ratio)).sqrt()
    }

    /// Chen & Teng's bond strength `P_u = 0.427 β_p β_L √f'c b_f L_e` (N).
    pub fn chen_teng_strength(&self) -> f64 {
        0.427
            * self.width_factor()
            * self.bond_length_factor()
            * self.fc_cylinder.sqrt()
            * self.plate_width
            * self.effective_bond_length()
    }

    /// Exact peak load (N) on a rigid substrate for the linear-softening law
    /// `τ = τ_f (1 − s/s_f)`: `b_f √(2 G_f E_f t_f) sin(λ min(L, π/(2λ)))`,
    /// `λ = √(τ_f/(s_f E_f t_f))`.
    pub fn linear_softening_strength(&self, peak_stress: f64, final_slip: f64) -> Result<f64> {
        require_positive(OWNER, "peak_stress", peak_stress)?;
        require_positive(OWNER, "final_slip", final_slip)?;
        let lambda = (peak_stress / (final_slip * self.plate_stiffness())).sqrt();
        let g_f = 0.5 * peak_stress * final_slip;
        Ok(self.long_bond_strength(g_f) * (lambda * self.bond_length).min(0.5 * PI).sin())
    }

    /// Loaded-end force and slip for free-end slip `delta`: RK4 on `s'' = τ(s)/(E_f t_f)` over
    /// `steps` steps from `s = δ, s' = 0`.
    fn shoot(&self, bond_stress: &dyn Fn(f64) -> f64, delta: f64, steps: usize) -> (f64, f64) {
        let stiffness = self.plate_stiffness();
        let h = self.bond_length / steps as f64;
        let (mut s, mut v) = (delta, 0.0);
        let f = |s: f64| bond_stress(s) / stiffness;
        for _ in 0..steps {
            let (k1s, k1v) = (v, f(s));
            let (k2s, k2v) = (v + 0.5 * h * k1v, f(s + 0.5 * h * k1s));
            let (k3s, k3v) = (v + 0.5 * h * k2v, f(s + 0.5 * h * k2s));
            let (k4s, k4v) = (v + h * k3v, f(s + h * k3s));
            s += h / 6.0 * (k1s + 2.0 * k2s + 2.0 * k3s + k4s);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        }
        (self.plate_width * stiffness * v, s)
    }

    /// Peak load for the bond–slip curve `bond_stress(s)` (MPa at slip s in mm), on a rigid
    /// substrate: the largest loaded-end force over free-end slips from `1e-9 separation_slip` to
    /// `separation_slip` (the slip at which the curve has vanished; beyond it the free end has
    /// debonded and the joint carries nothing), by a logarithmic scan and a golden-section search.
    /// `steps` RK4 steps along the bond (2000 is ample for 1e-5 relative accuracy on smooth curves).
    pub fn strength_for_law(
        &self,
        bond_stress: &dyn Fn(f64) -> f64,
        separation_slip: f64,
        steps: usize,
    ) -> Result<BondStrength> {
        self.validate()?;
        require_positive(OWNER, "separation_slip", separation_slip)?;
        if steps < 10 {
            return Err(CzError::invalid(OWNER, "steps", steps as f64, "must be at least 10"));
        }
        let load = |log_delta: f64| self.shoot(bond_stress, separation_slip * log_delta.exp(), steps).0;
        let (from, to) = ((1e-9f64).ln(), 0.0);
        let samples = 240;
        let grid: Vec<f64> = (0..=samples).map(|i| from + (to - from) * i as f64 / samples as f64).collect();
        let loads: Vec<f64> = grid.iter().map(|&x| load(x)).collect();
        let best = (0..loads.len()).max_by(|&i, &j| loads[i].total_cmp(&loads[j])).unwrap_or(0);
        if !loads[best].is_finite() {
            return Err(CzError::Simulation(format!("{OWNER}: the bond equation did not stay finite")));
        }
        // Golden-section search between the neighbours of the best sample.
        let (mut a, mut b) = (grid[best.saturating_sub(1)], grid[(best + 1).min(samples)]);
        let ratio = 0.5 * (5f64.sqrt() - 1.0);
        let (mut c, mut d) = (b - ratio * (b - a), a + ratio * (b - a));
        let (mut fc, mut fd) = (load(c), load(d));
        for _ in 0..60 {
            if fc > fd {
                b = d;
                d = c;
                fd = fc;
                c = b - ratio * (b - a);
                fc = load(c);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + ratio * (b - a);
                fd = load(d);
            }
        }
        let x = if fc.max(fd) >= loads[best] {
            if fc > fd {
                c
            } else {
                d
            }
        } else {
            grid[best]
        };
        let delta = separation_slip * x.exp();
        let (load, loaded_end_slip) = self.shoot(bond_stress, delta, steps);
        Ok(BondStrength { load, free_end_slip: delta, loaded_end_slip })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::LuBondSlip;

    /// The paper's plate (100 × 0.999 mm, E_f = 200 GPa, our choice) on f'c = 47 MPa concrete
    /// 200 mm wide.
    fn paper_joint(bond_length: f64) -> BondedJoint {
        BondedJoint::new(100.0, 0.999, 200_000.0, 200.0, 47.0, bond_length).unwrap()
    }

    #[test]
    fn closed_forms_at_the_papers_plate() {
        let joint = paper_joint(500.0);
        // L_e = √(200 000 · 0.999 / √47) = √(199 800 / 6.855655) = √29 144.0 = 170.72 mm.
        assert!((joint.effective_bond_length() - 170.72).abs() < 0.01, "{}", joint.effective_bond_length());
        // G_f = 0.593 N/mm: P_max = 100 √(2 · 0.593 · 199 800) = 100 √236 962.8 = 48 678.8 N.
        assert!((joint.long_bond_strength(0.593) - 48_678.8).abs() < 0.1, "{}", joint.long_bond_strength(0.593));
        // Chen & Teng: β_p = √((2 − ½)/(1 + ½)) = 1, β_L = 1,
        // P_u = 0.427 · √47 · 100 · 170.72 = 0.427 · 6.855655 · 17 072 = 49 975 N.
        assert_eq!(joint.width_factor(), 1.0);
        assert_eq!(joint.bond_length_factor(), 1.0);
        assert!((joint.chen_teng_strength() - 49_975.0).abs() < 5.0, "{}", joint.chen_teng_strength());
        // Short bonds: β_L = sin(π L / (2 L_e)); L = L_e/2 gives sin(π/4), L = 100 mm
        // sin(π · 100 / 341.43) = sin(0.92013) = 0.79568.
        let half = paper_joint(0.5 * joint.effective_bond_length());
        assert!((half.bond_length_factor() - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
        assert!((paper_joint(100.0).bond_length_factor() - 0.795_68).abs() < 1e-5);
        // A plate as wide as the concrete: β_p = √(1/2).
        let wide = BondedJoint { plate_width: 200.0, ..joint };
        assert!((wide.width_factor() - 0.5f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn shooting_reproduces_the_linear_softening_closed_form() {
        // τ = τ_f (1 − s/s_f): τ_f = 6 MPa, s_f = 0.2 mm (G_f = 0.6 N/mm);
        // λ = √(6 / (0.2 · 199 800)) = 0.012 254 /mm, π/(2λ) = 128.2 mm.
        let (tau_f, s_f) = (6.0, 0.2);
        let law = |s: f64| if s < s_f { tau_f * (1.0 - s / s_f) } else { 0.0 };
        let lambda = (tau_f / (s_f * 199_800.0)).sqrt();
        let full = 100.0 * (2.0 * 0.6 * 199_800.0f64).sqrt();
        for length in [20.0, 60.0, 100.0, 128.0, 300.0] {
            let joint = paper_joint(length);
            let exact = full * (lambda * length).min(0.5 * PI).sin();
            let closed = joint.linear_softening_strength(tau_f, s_f).unwrap();
            assert!((closed - exact).abs() < 1e-9 * exact);
            let shot = joint.strength_for_law(&law, s_f, 4000).unwrap();
            assert!((shot.load - exact).abs() < 2e-4 * exact, "L = {length}: {} vs {exact}", shot.load);
        }
    }

    #[test]
    fn lu_law_reaches_the_long_bond_strength_and_drops_for_short_bonds() {
        let law = LuBondSlip::from_concrete(47.0, 100.0, 200.0, 1000.0).unwrap();
        let stress = |s: f64| law.bond_stress(s);
        let long = paper_joint(600.0);
        let p_max = long.long_bond_strength(law.g_f);
        let strength = long.strength_for_law(&stress, law.separation_slip(), 4000).unwrap();
        assert!((strength.load / p_max - 1.0).abs() < 1e-3, "{} vs {p_max}", strength.load);
        // Shorter bonds carry less, monotonically, following Chen & Teng's β_L = sin(π L/(2 L_e))
        // to within 0.08. Measured P(L)/P_max at L/L_e = 0.1, 0.25, 0.5, 0.75, 1, 1.25, 1.5:
        // 0.193, 0.455, 0.761, 0.911, 0.970, 0.991, 0.998 (β_L: 0.156, 0.383, 0.707, 0.924, 1, 1,
        // 1). Lu's law transfers load faster near the loaded end than Chen & Teng's calibration
        // (higher ratios for short bonds), and its exponential tail makes it approach the plateau
        // more slowly (97 % at L_e, 99 % at 1.25 L_e).
        let l_e = long.effective_bond_length();
        let mut previous = 0.0;
        for fraction in [0.1, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5] {
            let joint = paper_joint(fraction * l_e);
            let ratio = joint.strength_for_law(&stress, law.separation_slip(), 4000).unwrap().load / p_max;
            let beta = joint.bond_length_factor();
            assert!(ratio > previous, "{fraction}: {ratio}");
            assert!((ratio - beta).abs() < 0.08, "L = {fraction} L_e: {ratio} vs β_L {beta}");
            previous = ratio;
        }
    }

    #[test]
    fn invalid_joints_are_named() {
        let e = BondedJoint::new(300.0, 1.0, 2e5, 200.0, 47.0, 100.0).unwrap_err().to_string();
        assert!(e.contains("`plate_width`"), "{e}");
        let e = BondedJoint::new(100.0, 1.0, 2e5, 200.0, 47.0, -1.0).unwrap_err().to_string();
        assert!(e.contains("`bond_length`"), "{e}");
        let joint = paper_joint(100.0);
        assert!(joint.linear_softening_strength(0.0, 0.2).unwrap_err().to_string().contains("`peak_stress`"));
        assert!(joint.strength_for_law(&|_| 1.0, 0.2, 5).unwrap_err().to_string().contains("`steps`"));
    }
}
