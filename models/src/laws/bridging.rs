//! Bridging (R-curve) law: a short, strong bilinear law for the matrix plus a long, weak bilinear
//! tail for fibre bridging, superposed as in Dávila, Rose & Camanho (Int. J. Fract. 158 (2009) 211).
//!
//! Both parts see the same gap and keep their own damage, so tractions, tangents and energies add:
//! in pure mode `G_c = G_matrix + G_bridging`, and at a fixed mixity `B` each part contributes its
//! own mixed-mode toughness `G_c,part(B)`. The superposition is the trilinear law of Dávila et al.
//! when both parts reach their strengths at the same opening, i.e. when their penalties split the
//! total in the ratio of their strengths (both modes): see [`Bridging::trilinear`].

use crate::laws::bilinear::Bilinear;
use czid_core::{CohesiveLaw, CzError, Gap, LawEval, LawState, ParameterInfo, Result};
use serde::{Deserialize, Serialize};

/// Superposition of a matrix law and a bridging law.
///
/// State: `history[0]` and `history[1]` hold the matrix and bridging damages; `damage` is their
/// stiffness-weighted mean, i.e. exactly one minus the secant-stiffness ratio of the combined law,
/// which reaches 1 only when both parts have failed.
///
/// ```
/// use czid_core::CohesiveLaw;
/// use czid_models::laws::{Bilinear, Bridging};
/// let matrix = Bilinear::bk(5e4, 30.0, 40.0, 0.25, 0.8, 2.0).unwrap();
/// let fibres = Bilinear::bk(1e3, 2.0, 3.0, 0.5, 0.9, 2.0).unwrap();
/// let law = Bridging::new(matrix, fibres).unwrap();
/// assert!((law.fracture_energy()[0] - 0.75).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bridging {
    /// Short, strong part (matrix cracking).
    pub matrix: Bilinear,
    /// Long, weak part (fibre bridging).
    pub bridging: Bilinear,
}

impl Bridging {
    /// A validated superposition of two bilinear laws.
    pub fn new(matrix: Bilinear, bridging: Bilinear) -> Result<Self> {
        let law = Bridging { matrix, bridging };
        law.validate()?;
        Ok(law)
    }

    /// Dávila, Rose & Camanho's trilinear law: total penalty `penalty`, strengths and toughnesses
    /// per part; the penalty is split in the ratio of the parts' strengths so that both reach their
    /// peaks at the same opening (peak traction = sum of strengths). This needs the same strength
    /// ratio in both modes (`bridging.strength_n / matrix.strength_n = bridging.strength_t /
    /// matrix.strength_t`); `matrix` and `bridging` give `(strength_n, strength_t, g_ic, g_iic)`.
    pub fn trilinear(penalty: f64, matrix: [f64; 4], bridging: [f64; 4], eta: f64) -> Result<Self> {
        let share = bridging[0] / (matrix[0] + bridging[0]);
        let share_t = bridging[1] / (matrix[1] + bridging[1]);
        if !(share.is_finite() && share_t.is_finite())
            || (share - share_t).abs() > 1e-9 * share.abs().max(share_t.abs())
        {
            return Err(CzError::invalid(
                "law bridging",
                "bridging.strength_t",
                bridging[1],
                "a trilinear law needs the same bridging/matrix strength ratio in both modes",
            ));
        }
        let part = |k: f64, p: [f64; 4]| Bilinear::bk(k, p[0], p[1], p[2], p[3], eta);
        Bridging::new(part(penalty * (1.0 - share), matrix)?, part(penalty * share, bridging)?)
    }

    /// A bilinear law with a long, weak bilinear tail for fibre bridging: the tail has strength
    /// `strength` (MPa; 0 is the law itself) and final opening `opening` (mm); it peaks at the
    /// matrix's onset opening (its penalty and shear strength scale with `strength / σ_n`), so its
    /// shape is fixed by `opening` and its size by `strength`; its toughness is `strength ·
    /// opening / 2` in mode I, and in mode II in the matrix's ratio `G_IIc / G_Ic`.
    pub fn bilinear_with_tail(matrix: &Bilinear, strength: f64, opening: f64) -> Result<Self> {
        if !(strength > 0.0 && opening > 0.0) {
            return Err(CzError::invalid(
                "law bridging",
                "bridging",
                strength.min(opening),
                "tail strength and opening must be positive",
            ));
        }
        let ratio = strength / matrix.strength_n;
        let g_b = 0.5 * strength * opening;
        let tail = Bilinear {
            penalty: matrix.penalty * ratio,
            strength_n: strength,
            strength_t: matrix.strength_t * ratio,
            g_ic: g_b,
            g_iic: matrix.g_iic * g_b / matrix.g_ic,
            ..matrix.clone()
        };
        Bridging::new(matrix.clone(), tail)
    }

    fn weights(&self) -> (f64, f64) {
        let total = self.matrix.penalty + self.bridging.penalty;
        (self.matrix.penalty / total, self.bridging.penalty / total)
    }
}

/// Pure-mode traction of a bilinear part at opening `x` (monotonic loading).
fn pure_mode_traction(part: &Bilinear, mode: usize, x: f64) -> f64 {
    let (onset, final_opening) = part.onset_and_final_opening(mode as f64);
    if x <= onset {
        part.penalty * x
    } else if x >= final_opening {
        0.0
    } else {
        part.penalty * onset * (final_opening - x) / (final_opening - onset)
    }
}

#[typetag::serde(name = "bridging")]
impl CohesiveLaw for Bridging {
    fn validate(&self) -> Result<()> {
        let prefix = |e: CzError, part: &str| match e {
            CzError::InvalidParameter { name, value, reason, .. } => {
                CzError::invalid("law bridging", format!("{part}.{name}"), value, reason)
            }
            other => other,
        };
        self.matrix.validate().map_err(|e| prefix(e, "matrix"))?;
        self.bridging.validate().map_err(|e| prefix(e, "bridging"))
    }

    fn evaluate(&self, gap: &Gap, previous: &LawState) -> LawEval {
        let (t_m, k_m, d_m) = self.matrix.respond(gap, previous.history[0]);
        let (t_b, k_b, d_b) = self.bridging.respond(gap, previous.history[1]);
        let (w_m, w_b) = self.weights();
        let mut history = previous.history;
        history[0] = d_m;
        history[1] = d_b;
        // Exactly 1 only when both parts are exactly 1.
        let damage = if d_m >= 1.0 && d_b >= 1.0 { 1.0 } else { (w_m * d_m + w_b * d_b).min(1.0) };
        LawEval { traction: t_m + t_b, tangent: k_m + k_b, state: LawState { damage, history } }
    }

    /// The failure of the part that fails first (the matrix, for a bridging tail): a kink inside
    /// the combined law; the other part's failure is the law's complete failure.
    fn inner_kinks(&self) -> usize {
        1
    }

    fn beyond_inner_kink(&self, state: &LawState, _k: usize) -> bool {
        state.history[0] >= 1.0 || state.history[1] >= 1.0
    }

    fn fracture_energy(&self) -> [f64; 2] {
        let (a, b) = (self.matrix.fracture_energy(), self.bridging.fracture_energy());
        [a[0] + b[0], a[1] + b[1]]
    }

    fn initial_stiffness(&self) -> [f64; 2] {
        let k = self.matrix.penalty + self.bridging.penalty;
        [k, k]
    }

    /// Peak of the summed pure-mode curves, found among the parts' break points (both parts are
    /// piecewise linear, so the sum peaks at one of them).
    fn strength(&self) -> [f64; 2] {
        let mut peak = [0.0; 2];
        for (mode, slot) in peak.iter_mut().enumerate() {
            let (a0, af) = self.matrix.onset_and_final_opening(mode as f64);
            let (b0, bf) = self.bridging.onset_and_final_opening(mode as f64);
            for x in [a0, af, b0, bf] {
                let t = pure_mode_traction(&self.matrix, mode, x) + pure_mode_traction(&self.bridging, mode, x);
                *slot = f64::max(*slot, t);
            }
        }
        peak
    }

    /// The matrix's failure (inner kink 0) is the crack a camera sees; the fibres behind it
    /// still bridge.
    fn visible_front_kink(&self) -> Option<usize> {
        Some(0)
    }

    fn parameters(&self) -> Vec<ParameterInfo> {
        const MATRIX: [&str; 6] =
            ["matrix.penalty", "matrix.strength_n", "matrix.strength_t", "matrix.g_ic", "matrix.g_iic", "matrix.eta"];
        const BRIDGING: [&str; 6] = [
            "bridging.penalty",
            "bridging.strength_n",
            "bridging.strength_t",
            "bridging.g_ic",
            "bridging.g_iic",
            "bridging.eta",
        ];
        let rename = |list: Vec<ParameterInfo>, names: [&'static str; 6]| {
            list.into_iter().zip(names).map(|(p, name)| ParameterInfo { name, ..p })
        };
        rename(self.matrix.parameters(), MATRIX).chain(rename(self.bridging.parameters(), BRIDGING)).collect()
    }
}
