//! Data reduction of an ENF test: G_IIc from the load curve by closed forms, without a cohesive
//! law, to set beside an identification.
//!
//! The curves a laboratory records for ENF specimens often carry no crack length (the crack tip
//! is closed under shear and hard to see), so both reductions here use only the load, the
//! displacement and the specimen's geometry:
//!
//! * **Beam theory with a calibrated modulus** (`g_iic_beam`): the flexural modulus is calibrated
//!   from the initial compliance `C₀` at the known `a0`, `C₀ = (3a0³ + 2L³)/(8 E b h³) +
//!   3L/(10 G b h)`, so the modulus absorbs whatever the beam formula leaves out at that crack
//!   length (root rotation, the toe compensation's residue); then `G_IIc = 9 P² a0² / (16 b² E h³)`
//!   at the onset load `P`.
//! * **The compliance-based beam method** (CBBM, de Moura and de Morais 2008; `g_iic_cbbm`): the
//!   crack length is the equivalent one `a_e` that reproduces the measured compliance `C = δ/P`
//!   at the onset with the calibrated modulus, `3a_e³ = 8 E b h³ (C − 3L/(10 G b h)) − 2L³`, and
//!   `G_IIc = 9 P² a_e² / (16 b² E h³)`. It counts the process zone's compliance before the
//!   peak, which the first method misses; it is the method of choice when the crack cannot be
//!   seen.
//!
//! The onset is the peak before the first drop (unstable ENF specimens, `a0/L < 0.7`, drop at
//! propagation and may rise again once the crack passes under the loading nose; the later rise is
//! no toughness). Lengths in mm, loads in N, moduli in MPa, G in N/mm.

use czid_core::{CzError, Result};

use crate::enf::Enf;

/// A drop of more than this fraction below the running maximum ends the rise to the onset.
pub const ONSET_DROP: f64 = 0.05;

/// What the data reduction found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnfReduction {
    /// Initial compliance from the straight rise (mm/N).
    pub compliance0: f64,
    /// Flexural modulus calibrated from `compliance0` at `a0` (MPa).
    pub modulus: f64,
    /// Load at the onset of propagation (N) and its displacement (mm).
    pub onset: (f64, f64),
    /// Equivalent crack length at the onset (mm).
    pub equivalent_crack: f64,
    /// G_IIc by beam theory with the calibrated modulus at a0 (N/mm).
    pub g_iic_beam: f64,
    /// G_IIc by the compliance-based beam method (N/mm).
    pub g_iic_cbbm: f64,
}

/// Index of the onset: the largest load before the load first falls more than [`ONSET_DROP`]
/// below its running maximum (the last reading's maximum if it never does).
pub fn onset_index(load: &[f64]) -> usize {
    let mut best = 0;
    for (i, &p) in load.iter().enumerate() {
        if p > load[best] {
            best = i;
        } else if p < (1.0 - ONSET_DROP) * load[best] {
            break;
        }
    }
    best
}

/// Reduces an ENF curve (displacement from a compensated zero, mm; load, N) of the specimen
/// `enf` (its `a0`, `half_span`, `width`, `h` and `material.g13` are used). `band` is the load
/// range of the straight rise as fractions of the onset load (e.g. `[0.2, 0.6]`), where the
/// initial compliance is fitted.
pub fn reduce(enf: &Enf, displacement: &[f64], load: &[f64], band: [f64; 2]) -> Result<EnfReduction> {
    let owner = "ENF data reduction";
    if displacement.len() != load.len() || load.len() < 3 {
        return Err(CzError::config(owner, "needs at least 3 readings, as many displacements as loads"));
    }
    let [lo, hi] = band;
    if !(lo > 0.0 && lo < hi && hi < 1.0) {
        return Err(CzError::config(owner, format!("band [{lo}, {hi}] must hold 0 < min < max < 1")));
    }
    let k = onset_index(load);
    let (p, d) = (load[k], displacement[k]);
    // The slope of the straight rise, through the origin of the compensated curve.
    let rise: Vec<(f64, f64)> =
        (0..=k).filter(|&i| load[i] >= lo * p && load[i] <= hi * p).map(|i| (displacement[i], load[i])).collect();
    if rise.len() < 3 {
        return Err(CzError::config(owner, format!("{} reading(s) in the band, 3 are needed", rise.len())));
    }
    let compliance0 = rise.iter().map(|(x, y)| x * y).sum::<f64>() / rise.iter().map(|(_, y)| y * y).sum::<f64>();
    let (a0, l, b, h, g) = (enf.a0, enf.half_span, enf.width, enf.h, enf.material.g13);
    let shear = 3.0 * l / (10.0 * g * b * h);
    let bending0 = compliance0 - shear;
    if bending0.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(CzError::config(
            owner,
            format!(
                "the initial compliance {compliance0:.4e} mm/N is below the shear part {shear:.4e}: check the units"
            ),
        ));
    }
    let modulus = (3.0 * a0.powi(3) + 2.0 * l.powi(3)) / (8.0 * b * h.powi(3) * bending0);
    let stiffness = 16.0 * b * b * modulus * h.powi(3);
    let g_iic_beam = 9.0 * p * p * a0 * a0 / stiffness;
    let c = d / p;
    let cube = (8.0 * modulus * b * h.powi(3) * (c - shear) - 2.0 * l.powi(3)) / 3.0;
    let equivalent_crack = cube.max(0.0).cbrt();
    let g_iic_cbbm = 9.0 * p * p * equivalent_crack.powi(2) / stiffness;
    Ok(EnfReduction { compliance0, modulus, onset: (p, d), equivalent_crack, g_iic_beam, g_iic_cbbm })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_beam_theory_curve_gives_back_its_modulus_and_crack_length() {
        // A straight rise with the beam-theory compliance of a 19.3 GPa specimen to 1000 N.
        let enf = Enf::hartlen_enf03();
        let c = enf.beam_compliance(enf.a0);
        let load: Vec<f64> = (0..=100).map(|i| 10.0 * i as f64).chain([800.0]).collect();
        let disp: Vec<f64> = load.iter().map(|p| c * p).collect();
        let r = reduce(&enf, &disp, &load, [0.2, 0.6]).unwrap();
        assert_eq!(r.onset.0, 1000.0);
        assert!((r.modulus / 19_300.0 - 1.0).abs() < 1e-12, "{}", r.modulus);
        assert!((r.equivalent_crack / enf.a0 - 1.0).abs() < 1e-12, "{}", r.equivalent_crack);
        // G = 9 P² a² / (16 b² E h³) by hand: 9e6 · 34.7² / (16 · 625 · 19300 · 2.7³).
        let by_hand = 9.0e6 * 34.7 * 34.7 / (16.0 * 625.0 * 19_300.0 * 2.7f64.powi(3));
        assert!((r.g_iic_beam / by_hand - 1.0).abs() < 1e-12);
        assert!((r.g_iic_cbbm / by_hand - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_onset_is_the_peak_before_the_first_drop_not_a_later_rise() {
        assert_eq!(onset_index(&[0.0, 5.0, 10.0, 9.8, 12.0, 8.0, 20.0]), 4);
        assert_eq!(onset_index(&[0.0, 5.0, 10.0]), 2);
    }

    #[test]
    fn bad_input_is_refused_with_what_is_wrong() {
        let enf = Enf::hartlen_enf03();
        let e = reduce(&enf, &[0.0, 1.0], &[0.0, 1.0], [0.2, 0.6]).unwrap_err().to_string();
        assert!(e.contains("at least 3"), "{e}");
        let e = reduce(&enf, &[0.0, 1.0, 2.0], &[0.0, 1.0, 2.0], [0.6, 0.2]).unwrap_err().to_string();
        assert!(e.contains("band"), "{e}");
    }
}
