//! Uniaxial strength models of the ST-CZM: the traction a mode can still carry, `S(δ)`, as its
//! damage state variable `δ` (the largest normalised opening reached) grows from the elastic
//! limit `u_e` to the failure opening `u_c`.
//!
//! The ST-CZM never integrates `S` directly: damage and opening are tied by the secant condition
//! `S(δ) = (1 − D) k δ` with `k = σ / u_e`, i.e. `D(δ) = 1 − u_e s(δ) / δ` for the normalised
//! strength `s = S / σ`. Each shape supplies `s`, its slope, and the inverse map `δ(D)`.

use crate::laws::root::solve_monotone;
use czid_core::error::require_positive;
use czid_core::{CzError, Result};
use serde::{Deserialize, Serialize};

/// Shape of a mode's strength model between the elastic limit `u_e` (traction σ) and the
/// failure opening `u_c` (traction 0).
///
/// In TOML: `shape_n = { kind = "sawtooth" }`, `{ kind = "exponential", alpha = 4.0 }` or
/// `{ kind = "trilinear", kink_fraction = 0.2, kink_strength_ratio = 0.3 }`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum StrengthShape {
    /// Linear softening from σ at `u_e` to 0 at `u_c` (Nairn & Aimene's sawtooth, the paper's law).
    #[default]
    Sawtooth,
    /// Exponential softening `s = (e^{−αx} − e^{−α}) / (1 − e^{−α})`, `x = (δ − u_e)/(u_c − u_e)`:
    /// the exponential law of Abaqus, reaching exactly zero at `u_c`.
    Exponential {
        /// Decay rate α > 0 (dimensionless); α → 0 recovers the sawtooth.
        alpha: f64,
    },
    /// Two linear pieces: from σ at `u_e` to `kink_strength_ratio · σ` at the kink, then to 0 at
    /// `u_c`. A low kink with a long tail mimics fibre bridging.
    Trilinear {
        /// Kink position as a fraction of the softening range, in (0, 1):
        /// `δ_kink = u_e + kink_fraction (u_c − u_e)`.
        kink_fraction: f64,
        /// Traction at the kink divided by the strength, in (0, 1].
        kink_strength_ratio: f64,
    },
}

impl StrengthShape {
    /// The shape as bits, for a law's [`czid_core::CohesiveLaw::mode_one_key`]: its kind, then
    /// its numbers (zeros where it has fewer).
    pub(crate) fn key(&self) -> [u64; 3] {
        match *self {
            StrengthShape::Sawtooth => [0, 0, 0],
            StrengthShape::Exponential { alpha } => [1, alpha.to_bits(), 0],
            StrengthShape::Trilinear { kink_fraction, kink_strength_ratio } => {
                [2, kink_fraction.to_bits(), kink_strength_ratio.to_bits()]
            }
        }
    }

    /// Whether this is the default (sawtooth) shape; such shapes are left out of written files.
    pub fn is_sawtooth(&self) -> bool {
        *self == StrengthShape::Sawtooth
    }

    /// Short name, as written in configuration files.
    pub fn name(&self) -> &'static str {
        match self {
            StrengthShape::Sawtooth => "sawtooth",
            StrengthShape::Exponential { .. } => "exponential",
            StrengthShape::Trilinear { .. } => "trilinear",
        }
    }
}

/// One mode's complete strength model: strength σ (MPa), elastic-limit opening `u_e` (mm),
/// failure opening `u_c` (mm) and shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeStrength {
    /// Peak traction σ (MPa).
    pub strength: f64,
    /// Opening at the end of the elastic branch (mm); initial stiffness `k = σ / u_e`.
    pub u_e: f64,
    /// Opening at which the traction vanishes (mm).
    pub u_c: f64,
    /// Softening shape.
    pub shape: StrengthShape,
}

impl ModeStrength {
    /// Initial stiffness `k = σ / u_e` (MPa/mm).
    pub fn stiffness(&self) -> f64 {
        self.strength / self.u_e
    }

    /// Checks this mode's parameters; `suffix` is `"n"` or `"t"` and names them as in files.
    pub(crate) fn validate(&self, owner: &str, suffix: &str) -> Result<()> {
        require_positive(owner, &format!("strength_{suffix}"), self.strength)?;
        require_positive(owner, &format!("u_e_{suffix}"), self.u_e)?;
        require_positive(owner, &format!("u_c_{suffix}"), self.u_c)?;
        if self.u_c <= self.u_e {
            return Err(CzError::invalid(
                owner,
                format!("u_c_{suffix}"),
                self.u_c,
                format!(
                    "u_c_{suffix} must exceed u_e_{suffix} = {} (failure opening beyond the elastic limit)",
                    self.u_e
                ),
            ));
        }
        match self.shape {
            StrengthShape::Sawtooth => Ok(()),
            StrengthShape::Exponential { alpha } => require_positive(owner, &format!("shape_{suffix}.alpha"), alpha),
            StrengthShape::Trilinear { kink_fraction, kink_strength_ratio } => {
                let name = format!("shape_{suffix}.kink_fraction");
                require_positive(owner, &name, kink_fraction)?;
                if kink_fraction >= 1.0 {
                    return Err(CzError::invalid(
                        owner,
                        name,
                        kink_fraction,
                        "must be below 1 (kink inside the softening range)",
                    ));
                }
                let name = format!("shape_{suffix}.kink_strength_ratio");
                require_positive(owner, &name, kink_strength_ratio)?;
                if kink_strength_ratio > 1.0 {
                    return Err(CzError::invalid(
                        owner,
                        name,
                        kink_strength_ratio,
                        "must not exceed 1 (softening only)",
                    ));
                }
                Ok(())
            }
        }
    }

    /// Normalised strength `s = S/σ` and its slope `ds/dδ` (1/mm) at an opening in `[u_e, u_c]`.
    pub fn normalized_strength(&self, opening: f64) -> (f64, f64) {
        let span = self.u_c - self.u_e;
        match self.shape {
            StrengthShape::Sawtooth => ((self.u_c - opening) / span, -1.0 / span),
            StrengthShape::Exponential { alpha } => {
                let x = (opening - self.u_e) / span;
                let decay = (-alpha * x).exp();
                // e^{−αx} − e^{−α} written without cancellation for small α and without overflow for large α.
                let denominator = (-alpha).exp_m1();
                let s = decay * (-alpha * (1.0 - x)).exp_m1() / denominator;
                let slope = alpha * decay / (span * denominator);
                (s, slope)
            }
            StrengthShape::Trilinear { kink_fraction, kink_strength_ratio } => {
                let kink = self.u_e + kink_fraction * span;
                if opening <= kink {
                    let slope = (kink_strength_ratio - 1.0) / (kink - self.u_e);
                    (1.0 + slope * (opening - self.u_e), slope)
                } else {
                    let slope = -kink_strength_ratio / (self.u_c - kink);
                    (kink_strength_ratio + slope * (opening - kink), slope)
                }
            }
        }
    }

    /// Damage reached when the mode's state variable is `opening`: `D = 1 − u_e s(δ)/δ`.
    pub fn damage_at_opening(&self, opening: f64) -> f64 {
        if opening <= self.u_e {
            return 0.0;
        }
        if opening >= self.u_c {
            return 1.0;
        }
        1.0 - self.u_e * self.normalized_strength(opening).0 / opening
    }

    /// The opening `δ(D)` at which the secant `(1 − D) k` meets the strength model (inverse of
    /// [`ModeStrength::damage_at_opening`]); `δ(0) = u_e`, `δ(1) = u_c`.
    pub fn opening_at_damage(&self, damage: f64) -> f64 {
        self.opening_at_intact(1.0 - damage)
    }

    /// [`ModeStrength::opening_at_damage`] in terms of the intact fraction `1 − D`, which keeps its
    /// digits near separation where `D` itself rounds to 1.
    pub fn opening_at_intact(&self, intact: f64) -> f64 {
        self.opening_at_intact_near(intact, self.u_e)
    }

    /// [`ModeStrength::opening_at_intact`] with a first guess for the shapes that need an
    /// iterative inverse (exponential): a nearby earlier solution cuts the Newton steps to one or two.
    pub(crate) fn opening_at_intact_near(&self, intact: f64, guess: f64) -> f64 {
        if intact >= 1.0 {
            return self.u_e;
        }
        if intact <= 0.0 {
            return self.u_c;
        }
        match self.shape {
            // u_e / (1 − D (1 − u_e/u_c)) = u_e / (u_e/u_c + (1 − u_e/u_c)(1 − D)).
            StrengthShape::Sawtooth => {
                let ratio = self.u_e / self.u_c;
                self.u_e / (ratio + (1.0 - ratio) * intact)
            }
            StrengthShape::Trilinear { kink_fraction, .. } => {
                // On a linear piece s = a + bδ the secant condition (1 − D)δ = u_e (a + bδ) is linear in δ.
                let kink = self.u_e + kink_fraction * (self.u_c - self.u_e);
                let piece_at =
                    if intact >= self.u_e * self.normalized_strength(kink).0 / kink { self.u_e } else { self.u_c };
                let (s, b) = self.normalized_strength(piece_at);
                let a = s - b * piece_at;
                self.u_e * a / (intact - self.u_e * b)
            }
            StrengthShape::Exponential { alpha } => {
                // With t = e^{−αx} the strength is linear, s = (t − e^{−α}) / (1 − e^{−α}), and the secant
                // condition (1 − D)δ = u_e s reads F(t) = I (u_e − (L/α) ln t) − u_e s(t) = 0 on
                // [e^{−α}, 1]: decreasing and convex with curvature only from I (L/α) ln t, which is
                // mild for any α, so Newton needs two or three steps. One Newton step on the residual
                // in δ then restores the last digits lost to t's narrow range when α is small.
                let span = self.u_c - self.u_e;
                let floor = (-alpha).exp();
                let range = -(-alpha).exp_m1();
                let scale = span / alpha;
                let residual_t = |t: f64| {
                    (
                        intact * (self.u_e - scale * t.ln()) - self.u_e * (t - floor) / range,
                        -intact * scale / t - self.u_e / range,
                    )
                };
                let start = (-alpha * (guess - self.u_e) / span).exp();
                let t = solve_monotone(residual_t, floor, 1.0, start, false);
                let opening = (self.u_e - scale * t.ln()).clamp(self.u_e, self.u_c);
                let (s, slope) = self.normalized_strength(opening);
                let polished = opening - (intact * opening - self.u_e * s) / (intact - self.u_e * slope);
                if polished.is_finite() {
                    polished.clamp(self.u_e, self.u_c)
                } else {
                    opening
                }
            }
        }
    }

    /// `dδ/dD` at an opening in `[u_e, u_c]`: the inverse of `dD/dδ = u_e (s − δ s')/δ²`, Nairn's
    /// ratio function `φ/(k δ²)` with `φ = S − δ S'` (Eq. 12 of Shi & Zhang).
    pub fn opening_rate(&self, opening: f64) -> f64 {
        let (s, slope) = self.normalized_strength(opening);
        opening * opening / (self.u_e * (s - opening * slope))
    }

    /// Energy to separate in this pure mode, `∫₀^{u_c} S dδ` (N/mm).
    pub fn fracture_energy(&self) -> f64 {
        let elastic = 0.5 * self.strength * self.u_e;
        let span = self.u_c - self.u_e;
        let softening = match self.shape {
            StrengthShape::Sawtooth => 0.5 * self.strength * span,
            // σ L (1/α − e^{−α}/(1 − e^{−α})) = σ L (1/α − 1/(e^α − 1)); a series near α = 0.
            StrengthShape::Exponential { alpha } => {
                let mean = if alpha < 1e-4 {
                    0.5 - alpha / 12.0 + alpha.powi(3) / 720.0
                } else {
                    1.0 / alpha - 1.0 / alpha.exp_m1()
                };
                self.strength * span * mean
            }
            StrengthShape::Trilinear { kink_fraction, kink_strength_ratio } => {
                let first = kink_fraction * span;
                0.5 * self.strength * ((1.0 + kink_strength_ratio) * first + kink_strength_ratio * (span - first))
            }
        };
        elastic + softening
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shapes() -> [StrengthShape; 4] {
        [
            StrengthShape::Sawtooth,
            StrengthShape::Exponential { alpha: 3.0 },
            StrengthShape::Exponential { alpha: 40.0 },
            StrengthShape::Trilinear { kink_fraction: 0.2, kink_strength_ratio: 0.3 },
        ]
    }

    #[test]
    fn opening_and_damage_maps_are_inverse() {
        for shape in shapes() {
            let mode = ModeStrength { strength: 27.0, u_e: 0.00027, u_c: 0.003273, shape };
            assert!((mode.normalized_strength(mode.u_e).0 - 1.0).abs() < 1e-12);
            assert!(mode.normalized_strength(mode.u_c).0.abs() < 1e-12);
            for i in 1..200 {
                let damage = i as f64 / 200.0;
                let opening = mode.opening_at_damage(damage);
                assert!((mode.damage_at_opening(opening) - damage).abs() < 1e-12, "{shape:?} at D = {damage}");
                // dδ/dD against a central difference of δ(D).
                let h = 1e-6;
                let fd = (mode.opening_at_damage(damage + h) - mode.opening_at_damage(damage - h)) / (2.0 * h);
                let rate = mode.opening_rate(opening);
                if (damage - mode.damage_at_opening(mode.u_e + 0.2 * (mode.u_c - mode.u_e))).abs() > 1e-3 {
                    assert!((fd - rate).abs() < 1e-6 * rate, "{shape:?} at D = {damage}: {fd} vs {rate}");
                }
            }
        }
    }
}
