//! Concrete: Hognestad's curve in compression, linear tension softening regularised by the
//! fracture energy over a crack band.
//!
//! **Compression** (strain magnitude `e = −ε`), Hognestad (1951):
//! * parabola `σ = −f_c (2 e/ε_c0 − (e/ε_c0)²)` up to the peak `ε_c0 = 2 f_c/E_c`, so the initial
//!   slope is `E_c`, the same as in tension (no kink at zero strain);
//! * then a straight line through `0.85 f_c` at the crushing strain `ε_cu` (Hognestad took
//!   0.0038; [`Concrete::from_cylinder_strength`] takes EC2's 0.0035, the strain at which section
//!   analysis declares crushing), continued down to zero stress and zero beyond.
//!
//! **Tension**: linear to `f_t` at `ε_t = f_t/E_c`, then linear softening to zero at
//! `ε_f = 2 G_F/(f_t h)`, where `h` is the crack band (the length over which a crack's opening is
//! smeared: the element length, or the crack spacing in a section analysis). The energy
//! dissipated per unit volume is then `½ f_t ε_f = G_F/h`, so a band of length `h` dissipates
//! `G_F` per unit area whatever `h` is (Bažant & Oh's crack band). `ε_f > ε_t` requires
//! `h < 2 E_c G_F/f_t²` (otherwise the curve would snap back).
//!
//! **Unloading** (documented idealisation, elastic-damage): in tension and in compression
//! separately, unloading and reloading run along the secant from the largest strain reached on
//! that side to the origin; no plastic strain. A crack closes fully at zero strain, and
//! compression after cracking meets the compression branch unaffected by the crack (and vice
//! versa). Exact for monotonic loading; a simplification under cycles.
//!
//! History: `history[0]` = largest tensile strain reached (≥ 0), `history[1]` = most compressive
//! strain reached (≤ 0).

use super::{UniaxialMaterial, UniaxialResponse, UniaxialState};
use czid_core::error::require_positive;
use czid_core::{CzError, Result};
use serde::{Deserialize, Serialize};

const OWNER: &str = "material concrete";

/// Fracture energy of concrete from the fib Model Code 2010, `G_F = 73 f_cm^0.18` N/m, returned in
/// N/mm (`f_cm` the mean cylinder strength in MPa).
pub fn model_code_fracture_energy(mean_strength: f64) -> f64 {
    0.073 * mean_strength.powf(0.18)
}

/// Uniaxial concrete (see the [module documentation](self)).
///
/// ```
/// use czid_models::materials::{Concrete, UniaxialMaterial};
/// let concrete = Concrete::from_cylinder_strength(47.0, 150.0).unwrap();
/// // Peak compressive stress at ε_c0 = 2 f_c / E_c.
/// let peak = concrete.peak_strain();
/// assert!((concrete.envelope(-peak) + 47.0).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Concrete {
    /// Compressive (cylinder) strength f_c, a positive number (MPa).
    pub compressive_strength: f64,
    /// Initial modulus E_c (MPa).
    pub elastic_modulus: f64,
    /// Crushing strain ε_cu, a positive number: the compressive strain at which the descending
    /// line passes 0.85 f_c, and at which section analysis takes the concrete as crushed (–).
    pub crushing_strain: f64,
    /// Tensile strength f_t (MPa).
    pub tensile_strength: f64,
    /// Fracture energy G_F (N/mm).
    pub fracture_energy: f64,
    /// Crack band h over which a crack's opening is smeared (mm).
    pub crack_band: f64,
}

impl Concrete {
    /// Concrete of cylinder strength `f'c` (MPa, taken as the mean strength) with crack band
    /// `crack_band` (mm), other properties from standard relations:
    /// * `E_c = 4700 √f'c` (ACI 318, normal-weight concrete);
    /// * `f_t = 0.395 f_cu^0.55` with `f_cu = f'c/0.8` (the relation Lu et al. use in their bond–slip
    ///   model, so the section and the bond law see one concrete; 3.71 MPa at f'c = 47 MPa);
    /// * `G_F = 73 f'c^0.18` N/m (fib Model Code 2010);
    /// * `ε_cu = 0.0035` (EC2, f_ck ≤ 50 MPa).
    pub fn from_cylinder_strength(fc_cylinder: f64, crack_band: f64) -> Result<Self> {
        require_positive(OWNER, "compressive_strength", fc_cylinder)?;
        let concrete = Concrete {
            compressive_strength: fc_cylinder,
            elastic_modulus: 4700.0 * fc_cylinder.sqrt(),
            crushing_strain: 0.0035,
            tensile_strength: 0.395 * (fc_cylinder / 0.8).powf(0.55),
            fracture_energy: model_code_fracture_energy(fc_cylinder),
            crack_band,
        };
        concrete.validate()?;
        Ok(concrete)
    }

    /// Strain magnitude at the compressive peak, `ε_c0 = 2 f_c/E_c`.
    pub fn peak_strain(&self) -> f64 {
        2.0 * self.compressive_strength / self.elastic_modulus
    }

    /// Tensile strain at cracking, `ε_t = f_t/E_c`.
    pub fn cracking_strain(&self) -> f64 {
        self.tensile_strength / self.elastic_modulus
    }

    /// Tensile strain at which the softening branch reaches zero, `ε_f = 2 G_F/(f_t h)`.
    pub fn tension_end_strain(&self) -> f64 {
        2.0 * self.fracture_energy / (self.tensile_strength * self.crack_band)
    }

    /// Slope of the descending compression line (MPa per unit strain magnitude, positive).
    fn descent(&self) -> f64 {
        0.15 * self.compressive_strength / (self.crushing_strain - self.peak_strain())
    }

    /// Envelope stress and slope at `strain` (monotonic loading from zero).
    #[inline]
    fn envelope_with_slope(&self, strain: f64) -> (f64, f64) {
        let (fc, ft, ec) = (self.compressive_strength, self.tensile_strength, self.elastic_modulus);
        if strain >= 0.0 {
            // The end of the softening branch only past cracking (most fibres are elastic).
            let et = self.cracking_strain();
            if strain <= et {
                return (ec * strain, ec);
            }
            let ef = self.tension_end_strain();
            if strain < ef {
                let slope = -ft / (ef - et);
                (ft + slope * (strain - et), slope)
            } else {
                (0.0, 0.0)
            }
        } else {
            let e = -strain;
            let e0 = self.peak_strain();
            if e <= e0 {
                let x = e / e0;
                (-fc * x * (2.0 - x), 2.0 * fc / e0 * (1.0 - x))
            } else {
                let magnitude = fc - self.descent() * (e - e0);
                if magnitude > 0.0 {
                    // σ = −(f_c − m (e − ε_c0)), e = −ε: dσ/dε = −m.
                    (-magnitude, -self.descent())
                } else {
                    (0.0, 0.0)
                }
            }
        }
    }
}

/// A [`Concrete`] with the constants of its curve worked out once, for evaluation in inner loops:
/// [`PreparedConcrete::respond`] gives exactly [`Concrete::respond`]'s results.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedConcrete {
    fc: f64,
    ft: f64,
    ec: f64,
    /// Cracking strain `f_t/E_c`.
    et: f64,
    /// End of tension softening.
    ef: f64,
    /// Slope of the tension softening.
    softening: f64,
    /// Peak strain magnitude `ε_c0`.
    e0: f64,
    /// `2 f_c/ε_c0`, the parabola's slope at zero.
    c2: f64,
    /// Slope of the descending compression line.
    descent: f64,
}

impl Concrete {
    /// The concrete with its constants worked out (see [`PreparedConcrete`]).
    pub fn prepared(&self) -> PreparedConcrete {
        let (fc, ft) = (self.compressive_strength, self.tensile_strength);
        let (et, ef, e0) = (self.cracking_strain(), self.tension_end_strain(), self.peak_strain());
        PreparedConcrete {
            fc,
            ft,
            ec: self.elastic_modulus,
            et,
            ef,
            softening: -ft / (ef - et),
            e0,
            c2: 2.0 * fc / e0,
            descent: self.descent(),
        }
    }
}

impl PreparedConcrete {
    /// [`Concrete::envelope_with_slope`] with the constants at hand.
    #[inline(always)]
    fn envelope_with_slope(&self, strain: f64) -> (f64, f64) {
        if strain >= 0.0 {
            if strain <= self.et {
                (self.ec * strain, self.ec)
            } else if strain < self.ef {
                (self.ft + self.softening * (strain - self.et), self.softening)
            } else {
                (0.0, 0.0)
            }
        } else {
            let e = -strain;
            if e <= self.e0 {
                let x = e / self.e0;
                (-self.fc * x * (2.0 - x), self.c2 * (1.0 - x))
            } else {
                let magnitude = self.fc - self.descent * (e - self.e0);
                if magnitude > 0.0 {
                    (-magnitude, -self.descent)
                } else {
                    (0.0, 0.0)
                }
            }
        }
    }

    /// Exactly [`Concrete::respond`].
    #[inline(always)]
    pub fn respond(&self, strain: f64, previous: &UniaxialState) -> UniaxialResponse {
        let [max_tension, max_compression] = previous.history;
        let mut state = *previous;
        let (stress, tangent) = if strain >= 0.0 && strain > max_tension {
            state.history[0] = strain;
            self.envelope_with_slope(strain)
        } else if strain < 0.0 && strain < max_compression {
            state.history[1] = strain;
            self.envelope_with_slope(strain)
        } else {
            let reached = if strain >= 0.0 { max_tension } else { max_compression };
            let secant = if reached == 0.0 { self.ec } else { self.envelope_with_slope(reached).0 / reached };
            (secant * strain, secant)
        };
        UniaxialResponse { stress, tangent, state }
    }
}

impl UniaxialMaterial for Concrete {
    fn validate(&self) -> Result<()> {
        require_positive(OWNER, "compressive_strength", self.compressive_strength)?;
        require_positive(OWNER, "elastic_modulus", self.elastic_modulus)?;
        require_positive(OWNER, "crushing_strain", self.crushing_strain)?;
        require_positive(OWNER, "tensile_strength", self.tensile_strength)?;
        require_positive(OWNER, "fracture_energy", self.fracture_energy)?;
        require_positive(OWNER, "crack_band", self.crack_band)?;
        let peak = self.peak_strain();
        if self.crushing_strain <= peak {
            return Err(CzError::invalid(
                OWNER,
                "crushing_strain",
                self.crushing_strain,
                format!("must exceed the peak strain 2 f_c/E_c = {peak:e}"),
            ));
        }
        if self.tensile_strength >= self.compressive_strength {
            return Err(CzError::invalid(
                OWNER,
                "tensile_strength",
                self.tensile_strength,
                "must be below the compressive strength",
            ));
        }
        let limit = 2.0 * self.elastic_modulus * self.fracture_energy / self.tensile_strength.powi(2);
        if self.crack_band >= limit {
            return Err(CzError::invalid(
                OWNER,
                "crack_band",
                self.crack_band,
                format!(
                    "must be below 2 E_c G_F/f_t² = {limit} mm, else the tension softening would snap back; \
                     use a shorter band (element length) or a larger fracture energy"
                ),
            ));
        }
        Ok(())
    }

    #[inline]
    fn respond(&self, strain: f64, previous: &UniaxialState) -> UniaxialResponse {
        let [max_tension, max_compression] = previous.history;
        let mut state = *previous;
        let (stress, tangent) = if strain >= 0.0 && strain > max_tension {
            state.history[0] = strain;
            self.envelope_with_slope(strain)
        } else if strain < 0.0 && strain < max_compression {
            state.history[1] = strain;
            self.envelope_with_slope(strain)
        } else {
            // Inside the largest excursion on this side: the secant to the origin.
            let reached = if strain >= 0.0 { max_tension } else { max_compression };
            let secant =
                if reached == 0.0 { self.elastic_modulus } else { self.envelope_with_slope(reached).0 / reached };
            (secant * strain, secant)
        };
        UniaxialResponse { stress, tangent, state }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn concrete() -> Concrete {
        Concrete::from_cylinder_strength(47.0, 150.0).unwrap()
    }

    /// Composite Simpson integral of `f` over `[a, b]` with `n` (even) intervals.
    fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
        let h = (b - a) / n as f64;
        let inner: f64 = (1..n).map(|i| f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 }).sum();
        (f(a) + f(b) + inner) * h / 3.0
    }

    #[test]
    fn standard_relations_at_47_mpa() {
        let c = concrete();
        // E_c = 4700 √47 = 4700 · 6.85565 = 32 221.6 MPa; f_t = 0.395 (47/0.8)^0.55 = 3.71 MPa; G_F = 0.073 · 47^0.18.
        assert!((c.elastic_modulus - 32_221.6).abs() < 0.05, "{}", c.elastic_modulus);
        assert!((c.tensile_strength - 3.71).abs() < 0.005, "{}", c.tensile_strength);
        assert!((c.fracture_energy - 0.073 * 47f64.powf(0.18)).abs() < 1e-15);
        assert!((c.fracture_energy - 0.146).abs() < 0.001, "{}", c.fracture_energy);
    }

    #[test]
    fn hognestad_peak_and_crushing_point() {
        let c = concrete();
        let e0 = 2.0 * 47.0 / c.elastic_modulus;
        assert_eq!(c.envelope(-e0), -47.0);
        // The parabola's maximum: stress on either side is smaller in magnitude.
        assert!(c.envelope(-0.99 * e0) > -47.0 && c.envelope(-1.01 * e0) > -47.0);
        // Half the peak strain: f_c (2·½ − ¼) = 0.75 f_c.
        assert!((c.envelope(-0.5 * e0) + 0.75 * 47.0).abs() < 1e-12);
        assert!((c.envelope(-0.0035) + 0.85 * 47.0).abs() < 1e-9);
        // Initial slope E_c on both sides of zero.
        let h = 1e-9;
        assert!(((c.envelope(h) - c.envelope(-h)) / (2.0 * h) / c.elastic_modulus - 1.0).abs() < 1e-6);
        // Far beyond crushing the line has reached zero.
        assert_eq!(c.envelope(-0.05), 0.0);
    }

    #[test]
    fn tension_softening_dissipates_fracture_energy_over_the_band() {
        for band in [25.0, 100.0, 150.0, 400.0] {
            let c = Concrete { crack_band: band, ..concrete() };
            let (et, ef) = (c.cracking_strain(), c.tension_end_strain());
            assert!((ef - 2.0 * c.fracture_energy / (c.tensile_strength * band)).abs() < 1e-18);
            // The curve is piecewise linear: integrate each piece exactly with Simpson.
            let area = simpson(|e| c.envelope(e), 0.0, et, 2) + simpson(|e| c.envelope(e), et, ef, 2);
            let expected = c.fracture_energy / band;
            assert!((area - expected).abs() < 1e-12 * expected, "band {band}: {area} vs {expected}");
            assert_eq!(c.envelope(1.01 * ef), 0.0);
            assert!((c.envelope(et) - c.tensile_strength).abs() < 1e-12);
        }
    }

    #[test]
    fn tangent_matches_finite_differences_on_every_branch() {
        let c = concrete();
        let virgin = UniaxialState::default();
        let unloaded = c.respond(2.0 * c.cracking_strain(), &virgin).state;
        let unloaded = c.respond(-0.003, &unloaded).state;
        for (strain, state) in [
            (0.5 * c.cracking_strain(), virgin),
            (1.7 * c.cracking_strain(), virgin),
            (-0.3 * c.peak_strain(), virgin),
            (-1.1 * c.peak_strain(), virgin),
            (1.2 * c.cracking_strain(), unloaded),
            (-0.002, unloaded),
        ] {
            let h = 1e-7 * strain.abs();
            let r = c.respond(strain, &state);
            let fd = (c.respond(strain + h, &state).stress - c.respond(strain - h, &state).stress) / (2.0 * h);
            assert!((r.tangent - fd).abs() <= 1e-6 * fd.abs().max(1.0), "{strain}: {} vs {fd}", r.tangent);
        }
    }

    #[test]
    fn unloading_follows_the_secant_and_cracks_close() {
        let c = concrete();
        let strain = 3.0 * c.cracking_strain();
        let loaded = c.respond(strain, &UniaxialState::default());
        assert_eq!(loaded.state.history, [strain, 0.0]);
        let half = c.respond(0.5 * strain, &loaded.state);
        assert!((half.stress - 0.5 * loaded.stress).abs() < 1e-12);
        assert_eq!(half.state, loaded.state);
        // Closed crack: compression at the initial stiffness.
        let closed = c.respond(-1e-5, &loaded.state);
        assert!((closed.tangent / c.elastic_modulus - (1.0 - 1e-5 / c.peak_strain())).abs() < 1e-12);
        // Reloading past the largest strain rejoins the envelope.
        let beyond = c.respond(1.1 * strain, &half.state);
        assert_eq!(beyond.stress, c.envelope(1.1 * strain));
    }

    #[test]
    fn prepared_concrete_gives_the_same_results() {
        for band in [10.0, 150.0] {
            let c = Concrete { crack_band: band, ..concrete() };
            let prepared = c.prepared();
            let (et, e0) = (c.cracking_strain(), c.peak_strain());
            let strains: Vec<f64> =
                (-400..=400).map(|i| i as f64 * 0.01 * e0).chain((0..200).map(|i| i as f64 * 0.1 * et)).collect();
            let mut states = vec![UniaxialState::default()];
            for &s in &[0.5 * et, 3.0 * et, 40.0 * et, -0.5 * e0, -1.5 * e0, -3.0 * e0] {
                let last = *states.last().unwrap();
                states.push(c.respond(s, &last).state);
                states.push(c.respond(s, &UniaxialState::default()).state);
            }
            for state in &states {
                for &s in &strains {
                    assert_eq!(prepared.respond(s, state), c.respond(s, state), "{s} from {state:?}");
                }
            }
        }
    }

    #[test]
    fn invalid_parameters_are_named() {
        let c = concrete();
        let message = |c: Concrete| c.validate().unwrap_err().to_string();
        assert!(message(Concrete { crack_band: 1000.0, ..c.clone() }).contains("`crack_band`"));
        assert!(message(Concrete { crushing_strain: 0.002, ..c.clone() }).contains("`crushing_strain`"));
        assert!(message(Concrete { tensile_strength: -1.0, ..c.clone() }).contains("`tensile_strength`"));
        assert!(message(Concrete { elastic_modulus: f64::NAN, ..c.clone() }).contains("`elastic_modulus`"));
        assert!(Concrete::from_cylinder_strength(0.0, 100.0).is_err());
        let text = serde_json::to_string(&c).unwrap().replace("crack_band", "crack_bnd");
        assert!(serde_json::from_str::<Concrete>(&text).unwrap_err().to_string().contains("crack_bnd"));
    }
}
