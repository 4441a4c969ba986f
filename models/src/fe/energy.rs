//! Energy bookkeeping over converged steps.
//!
//! * External work `W = Σ ½(R_k + R_{k+1})(c_{k+1} − c_k)` (trapezoidal rule on the control
//!   unknown `c` and its reaction `R`).
//! * Elastic energy: exact strain energy of the beams and springs at the converged state plus the
//!   interface's recoverable energy `Σ A_i ψ(g_i, state_i)` ([`czid_core::CohesiveLaw::stored_energy`]).
//! * Dissipated energy: the work done on the interface points, `Σ_i A_i Σ_k ½(T_k + T_{k+1})·(g_{k+1} − g_k)`,
//!   minus their recoverable energy. It is computed point by point, independently of the external
//!   work, so that `W = elastic + dissipated` is a genuine check of equilibrium and of the step size
//!   (the trapezoidal rule is exact on linear pieces of a law, so its error comes only from steps
//!   that straddle a kink of a law).

use czid_core::{CohesiveLaw, Gap, LawEval, LawState, Traction};

use super::interface::{InterfacePoint, PointKind};

/// Running energy totals of the simulated part (N·mm).
#[derive(Clone, Debug, Default)]
pub struct Ledger {
    /// Work of the control reaction.
    pub external_work: f64,
    /// Work done on the interface points (recoverable + dissipated).
    pub interface_work: f64,
    /// Last committed tractions and gaps of the interface points.
    tractions: Vec<Traction>,
    gaps: Vec<Gap>,
}

impl Ledger {
    /// A ledger for `n` interface points, everything at zero.
    pub fn new(n: usize) -> Self {
        Ledger {
            external_work: 0.0,
            interface_work: 0.0,
            tractions: vec![Traction::zeros(); n],
            gaps: vec![Gap::zeros(); n],
        }
    }

    /// Adds the work of a converged step.
    pub fn commit(
        &mut self,
        points: &[InterfacePoint],
        trial: &[LawEval],
        gaps: &[Gap],
        dc: f64,
        r_old: f64,
        r_new: f64,
    ) {
        self.external_work += 0.5 * (r_old + r_new) * dc;
        let mut w = 0.0;
        for (ip, p) in points.iter().enumerate() {
            let t = trial[ip].traction;
            let g = gaps[ip];
            w += p.area * p.factor * 0.5 * (t + self.tractions[ip]).dot(&(g - self.gaps[ip]));
            self.tractions[ip] = t;
            self.gaps[ip] = g;
        }
        self.interface_work += w;
    }
}

/// Recoverable energy of the interface points (N·mm) in the committed `states` at `gaps`.
pub fn interface_stored(
    points: &[InterfacePoint],
    law: &dyn CohesiveLaw,
    states: &[LawState],
    trial: &[LawEval],
    gaps: &[Gap],
) -> f64 {
    let mut e = 0.0;
    for (ip, p) in points.iter().enumerate() {
        let psi = match p.kind {
            PointKind::Cohesive => law.stored_energy(&gaps[ip], &states[ip]),
            // Contact is a linear penalty: ½ T·g.
            PointKind::Contact => 0.5 * trial[ip].traction.dot(&gaps[ip]),
        };
        e += p.area * p.factor * psi;
    }
    e
}
