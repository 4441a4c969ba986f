//! Newton–Raphson iterations with the consistent (unsymmetric) tangent, for one load step under
//! displacement control or under a dissipation constraint.

use czid_core::{CohesiveLaw, LawState};

use super::assembly::{Assembler, FeProblem, InterfaceRule};
use super::banded::{BandError, BandMatrix};
use super::span_lu::SpanLu;

/// Convergence settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonSettings {
    /// Maximum iterations per step before the step is declared failed (and cut).
    pub max_iterations: usize,
    /// Relative residual tolerance: `max |r_i| ≤ tol · max |f_int|` (or the residual's round-off
    /// floor, where stiff elements lift it above that: see [`ROUND_OFF_FLOOR`]).
    pub tolerance: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        NewtonSettings { max_iterations: 20, tolerance: 1e-9 }
    }
}

/// How far above the tolerance a dissipation-constrained solve may end once it has stopped
/// gaining (see [`ROUND_OFF_GAIN`]). The tolerance is relative to the largest internal force, which
/// at a DCB's last ligament is the load of a few newtons, while the stiff arms' element forces
/// there are ten million times larger: their round-off in the residual is a few times the
/// tolerance.
pub const ROUND_OFF_FLOOR: f64 = 10.0;

/// An iteration that reduces the residual by less than this factor, after quadratic convergence
/// has brought it within [`ROUND_OFF_FLOOR`] times the tolerance, has reached the residual's
/// round-off floor.
pub const ROUND_OFF_GAIN: f64 = 10.0;

/// Residual, relative to the scale of the internal forces, below which the next correction
/// reuses the last factorisation (a chord step) instead of assembling and factorising the tangent
/// again. From there the tangent changes little between iterations, so a chord step contracts
/// nearly as a Newton step does.
pub(crate) const CHORD_BELOW: f64 = 1e-3;

/// A chord step must divide the residual by at least `1 / CHORD_CONTRACTION`; otherwise the next
/// correction is a full Newton step.
pub(crate) const CHORD_CONTRACTION: f64 = 0.1;

/// Why a step did not converge.
#[derive(Clone, Debug, PartialEq)]
pub enum StepFailure {
    /// No convergence within the iteration limit.
    NoConvergence,
    /// Tangent singular (or a non-finite pivot).
    Singular,
    /// A law returned a non-finite traction or tangent.
    NonFinite,
}

/// Newton workspace: the tangent, residual and two solution vectors, allocated once per run.
pub struct Newton {
    /// Assembly workspace (constant tangent part, trial law results).
    pub asm: Assembler,
    /// Tangent (as assembled; factorised by `lu` or in place).
    pub k: BandMatrix,
    /// Its factors, where only the rows that changed since the last factorisation are
    /// refactorised (small rotations: the beams are linear and the interface keeps its stiffness
    /// outside the process zone); `None`: `k` is factorised in place (under large rotations every
    /// co-rotational beam changes, and comparing and copying the tangent would only add work).
    lu: Option<SpanLu>,
    /// Internal forces at the last assembly.
    pub f: Vec<f64>,
    r: Vec<f64>,
    b: Vec<f64>,
    fixed_mask: Vec<bool>,
    /// Settings.
    pub settings: NewtonSettings,
    /// Total iterations (assemblies) and factorisations so far, for profiling.
    pub counters: (usize, usize),
    /// Under displacement control, halve a correction that increased the residual and iterate
    /// with secant stiffnesses for a while (on by default).
    pub safeguard: bool,
    /// Unknowns solved for: the first `active`; the others are left out (see
    /// [`Assembler::frozen_from_node`]). All of them by default.
    pub active: usize,
    /// First node left out (`usize::MAX`: none); set with `active`.
    pub frozen_from_node: usize,
    /// Under displacement control, chord steps below [`CHORD_BELOW`] (on by default).
    pub(crate) chord: bool,
    /// Whether the control unknown's row was the identity's at the last factorisation (`None`:
    /// none succeeded since the rows' record was last started).
    factorised_control_held: Option<bool>,
    /// Whether `k` carries the control unknown's identity row and column in rows the last
    /// assembly did not rebuild.
    control_identity_in_k: bool,
}

impl Newton {
    /// Workspace for problem `p`.
    pub fn new(p: &FeProblem, law: &dyn CohesiveLaw, settings: NewtonSettings) -> Self {
        Self::with_rule(p, law, settings, InterfaceRule::Nodal)
    }

    /// [`Newton::new`] with the interface integrated by `rule`.
    pub fn with_rule(p: &FeProblem, law: &dyn CohesiveLaw, settings: NewtonSettings, rule: InterfaceRule) -> Self {
        let asm = Assembler::with_rule(p, law, rule);
        let n = asm.n();
        let mut fixed_mask = vec![false; n];
        for &d in &p.fixed {
            fixed_mask[d] = true;
        }
        Newton {
            k: BandMatrix::zeros(n, p.mesh.bandwidth()),
            lu: (!p.large_rotation).then(SpanLu::default),
            asm,
            f: vec![0.0; n],
            r: vec![0.0; n],
            b: vec![0.0; n],
            fixed_mask,
            settings,
            counters: (0, 0),
            safeguard: true,
            active: n,
            frozen_from_node: usize::MAX,
            chord: true,
            factorised_control_held: None,
            control_identity_in_k: false,
        }
    }

    /// Assembles the internal forces, and the tangent into `k` with `tangent`, rebuilt only where
    /// the interface changed where `k` holds the last one ([`Assembler::assemble_reusing`]);
    /// `control_held`: the control unknown's row will be the identity's (displacement control).
    /// Where `k` carries the control's identity row from a displacement-controlled iteration, a
    /// dissipation-controlled one, which solves for the control, assembles it whole.
    #[allow(clippy::too_many_arguments)]
    fn assemble(
        &mut self,
        p: &FeProblem,
        law: &dyn CohesiveLaw,
        states: &[LawState],
        q: &[f64],
        secant: bool,
        tangent: bool,
        control_held: bool,
    ) -> Result<(), StepFailure> {
        self.counters.0 += 1;
        self.asm.frozen_from_node = self.frozen_from_node;
        let reuse = control_held || !self.control_identity_in_k;
        let k = tangent.then_some(&mut self.k);
        let ok = self.asm.assemble_reusing(p, law, states, q, k, &mut self.f, secant, reuse);
        if tangent && !self.asm.tangent_reused {
            self.control_identity_in_k = false;
        }
        if ok {
            Ok(())
        } else {
            Err(StepFailure::NonFinite)
        }
    }

    /// Debug builds: the tangent about to be factorised is the whole assembly's, identity rows
    /// and columns included, to the bit.
    #[cfg(debug_assertions)]
    fn check_tangent(&self, p: &FeProblem, control_held: bool) {
        if p.large_rotation {
            return;
        }
        // The identity rows were set at the full order (the factorisation's may be smaller).
        let mut whole = self.k.clone();
        whole.set_order(self.asm.n());
        self.asm.rebuild_rows(p, &mut whole, (0, self.asm.n() - 1));
        for &d in &p.fixed {
            whole.set_identity_row_col(d);
        }
        if control_held {
            whole.set_identity_row_col(p.control);
        }
        for i in 0..self.asm.n() {
            let (a, b) = (self.k.band_row(i), whole.band_row(i));
            assert!(
                a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()),
                "row {i} of the tangent rebuilt where it changed differs from the whole assembly's"
            );
        }
    }

    /// Factorises the tangent and solves for the residual `r` in place (and for `b` with `both`).
    /// `control_held`: the control unknown's row and column are the identity's (displacement
    /// control), which the rows known unchanged since the last factorisation presume as well.
    fn factorize_and_solve(&mut self, both: bool, control_held: bool) -> Result<(), BandError> {
        match self.lu.as_mut() {
            Some(lu) => {
                let within =
                    if self.factorised_control_held == Some(control_held) { self.asm.changed.rows() } else { None };
                let done = lu.factorize_within(&self.k, within);
                if done.is_ok() {
                    self.asm.changed.factorised();
                    self.factorised_control_held = Some(control_held);
                } else {
                    self.asm.changed.forget();
                    self.factorised_control_held = None;
                }
                done.inspect(|_| match both {
                    true => lu.solve2_in_place(&mut self.r, &mut self.b),
                    false => lu.solve_in_place(&mut self.r),
                })
            }
            None => self.k.factorize().inspect(|_| match both {
                true => self.k.solve2_in_place(&mut self.r, &mut self.b),
                false => self.k.solve_in_place(&mut self.r),
            }),
        }
    }

    /// Solves for the residual `r` in place with the last factors (a chord step), over the
    /// unknowns they were made for.
    fn solve_factored(&mut self) {
        match self.lu.as_mut() {
            Some(lu) => lu.solve_in_place(&mut self.r),
            None => {
                let n = self.k.n();
                self.k.set_order(self.active);
                self.k.solve_in_place(&mut self.r);
                self.k.set_order(n);
            }
        }
    }

    fn scale(&self) -> f64 {
        self.f.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300)
    }

    /// Solves for equilibrium with the control unknown held at `q[p.control]` (already set in the
    /// predictor `q`). On success `q` is the converged state, `self.f` its internal forces and
    /// `self.asm.trial` its law results; returns the number of corrections that factorised a
    /// tangent (the chord steps between them are not counted: a step is as hard as the tangents
    /// it needed, and the path's step control reads it so, as it did before chord steps).
    pub fn solve_displacement(
        &mut self,
        p: &FeProblem,
        law: &dyn CohesiveLaw,
        states: &[LawState],
        q: &mut [f64],
    ) -> Result<usize, StepFailure> {
        let mut stalled = false;
        // Safeguard against branch cycling: a correction that increased the residual is halved,
        // and the next iterations use the secant stiffness of the cohesive points (a fixed-point
        // iteration that converges monotonically while the active set settles) before Newton
        // resumes.
        let mut r_prev = f64::INFINITY;
        let mut alpha = 1.0f64;
        let mut secant_left = 0usize;
        let mut it = 0usize;
        let max_it = self.settings.max_iterations;
        // Whether the next correction reuses the last factorisation (a chord step), and the
        // residual of the last one that did.
        let mut chord = false;
        let mut chord_from = f64::INFINITY;
        let mut chords = 0usize;
        let mut chord_failed = false;
        while it <= max_it {
            let secant = secant_left > 0;
            self.assemble(p, law, states, q, secant, !chord, true)?;
            let scale = self.scale();
            let tol = self.settings.tolerance * scale;
            let mut rmax = 0.0f64;
            for i in 0..q.len() {
                let v = if self.fixed_mask[i] || i == p.control || i >= self.active { 0.0 } else { self.f[i] };
                self.r[i] = -v;
                rmax = rmax.max(v.abs());
            }
            if !rmax.is_finite() {
                return Err(StepFailure::NonFinite);
            }
            // Very stiff penalties make the residual's round-off floor exceed the tolerance; a
            // correction at round-off level with a small residual is then as converged as it gets.
            if rmax <= tol || (stalled && rmax <= 1e4 * tol) {
                return Ok(it - chords);
            }
            if self.safeguard && rmax > r_prev && alpha > 0.3 {
                alpha *= 0.5;
                for (qi, di) in q.iter_mut().zip(&self.b) {
                    *qi -= alpha * di;
                }
                secant_left = 4;
                it += 1;
                chord = false;
                continue;
            }
            if it >= max_it {
                break;
            }
            it += 1;
            secant_left = secant_left.saturating_sub(1);
            r_prev = rmax;
            alpha = 1.0;
            let rel = rmax / scale;
            if chord && rel > CHORD_CONTRACTION * chord_from {
                // The chord does not contract: full Newton steps from here to the end of the step
                // (the tangent was not assembled, so assemble again). Chord and Newton steps
                // alternating would cycle where contact points change state (friction sticking
                // and slipping).
                chord = false;
                chord_failed = true;
                self.assemble(p, law, states, q, secant, true, true)?;
            }
            if chord {
                chord_from = rel;
                chords += 1;
                self.solve_factored();
            } else {
                for &d in &p.fixed {
                    self.k.set_identity_row_col(d);
                }
                self.k.set_identity_row_col(p.control);
                self.control_identity_in_k = true;
                self.counters.1 += 1;
                let n = self.k.n();
                self.k.set_order(self.active);
                #[cfg(debug_assertions)]
                self.check_tangent(p, true);
                let factorized = self.factorize_and_solve(false, true);
                self.k.set_order(n);
                factorized.map_err(|_| StepFailure::Singular)?;
            }
            // The next correction reuses these factors where the residual is small, unless they
            // are of a secant iteration matrix.
            chord = self.chord && !chord_failed && rel <= CHORD_BELOW && !secant;
            let (mut dmax, mut qmax) = (0.0f64, 0.0f64);
            for ((qi, di), bi) in q.iter_mut().zip(&self.r).zip(self.b.iter_mut()) {
                *qi += di;
                *bi = *di;
                dmax = dmax.max(di.abs());
                qmax = qmax.max(qi.abs());
            }
            stalled = dmax <= 1e-12 * qmax;
        }
        Err(StepFailure::NoConvergence)
    }

    /// Solves for equilibrium under the dissipation constraint of Gutiérrez (2004) / Verhoosel
    /// et al. (2009): the control unknown is free and loaded by the load factor `λ`, and
    /// `½ (λ₀ (c − c₀) − (λ − λ₀) c₀) = τ` fixes the energy released in the step. `q` and `lambda`
    /// hold the predictor on entry and the converged state on success.
    #[allow(clippy::too_many_arguments)]
    pub fn solve_dissipation(
        &mut self,
        p: &FeProblem,
        law: &dyn CohesiveLaw,
        states: &[LawState],
        q: &mut [f64],
        lambda: &mut f64,
        c0: f64,
        lambda0: f64,
        tau: f64,
    ) -> Result<usize, StepFailure> {
        let ic = p.control;
        let mut r_prev = f64::INFINITY;
        for it in 0..=self.settings.max_iterations {
            self.assemble(p, law, states, q, false, true, false)?;
            let tol = self.settings.tolerance * self.scale();
            let mut rmax = 0.0f64;
            for i in 0..q.len() {
                let mut v = if self.fixed_mask[i] || i >= self.active { 0.0 } else { self.f[i] };
                if i == ic {
                    v -= *lambda;
                }
                self.r[i] = -v;
                rmax = rmax.max(v.abs());
            }
            let g = 0.5 * (lambda0 * (q[ic] - c0) - (*lambda - lambda0) * c0) - tau;
            if !rmax.is_finite() || !g.is_finite() {
                return Err(StepFailure::NonFinite);
            }
            // At the round-off floor (a residual within a few tolerances that the last correction
            // no longer reduced) the state is as converged as it gets: without this, a stiff
            // specimen's last ligament could not be followed at all, whatever the increment.
            let floor = it >= 2 && rmax <= ROUND_OFF_FLOOR * tol && rmax * ROUND_OFF_GAIN > r_prev;
            r_prev = rmax;
            if (rmax <= tol || floor) && g.abs() <= 1e-9 * tau.abs().max(1e-300) {
                return Ok(it);
            }
            if it == self.settings.max_iterations {
                break;
            }
            for &d in &p.fixed {
                self.k.set_identity_row_col(d);
            }
            self.counters.1 += 1;
            self.b.fill(0.0);
            self.b[ic] = 1.0;
            let n = self.k.n();
            self.k.set_order(self.active);
            #[cfg(debug_assertions)]
            self.check_tangent(p, false);
            let factorized = self.factorize_and_solve(true, false);
            self.k.set_order(n);
            factorized.map_err(|_| StepFailure::Singular)?;
            // Bordering: Δq = a + Δλ b, with the constraint linearised in (c, λ).
            let den = 0.5 * lambda0 * self.b[ic] - 0.5 * c0;
            if den == 0.0 || !den.is_finite() {
                return Err(StepFailure::Singular);
            }
            let dl = (-g - 0.5 * lambda0 * self.r[ic]) / den;
            for i in 0..q.len() {
                q[i] += self.r[i] + dl * self.b[i];
            }
            *lambda += dl;
        }
        Err(StepFailure::NoConvergence)
    }
}
