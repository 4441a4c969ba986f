//! The cohesive-law contract.
//!
//! A cohesive law maps the displacement jump across an interface, the *gap*
//! `[normal opening, tangential slip]` in mm, to the traction `[normal, shear]` in MPa, given the
//! history of the integration point. Laws are stateless values (their parameters); the history lives
//! in a small [`LawState`] that the caller stores per integration point and commits only once a
//! load step has converged.

use crate::error::{CzError, Result};
use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};

/// Displacement jump `[normal opening u_n, tangential slip u_t]` in mm. Positive `u_n` opens.
pub type Gap = Vector2<f64>;
/// Traction `[T_n, T_t]` in MPa, work-conjugate to [`Gap`].
pub type Traction = Vector2<f64>;
/// Consistent tangent `∂T_i/∂u_j` in MPa/mm (row i: traction component, column j: gap component).
/// Generally unsymmetric while damage grows.
pub type Tangent = Matrix2<f64>;

/// History of one integration point.
///
/// `damage` is kept current by every law (0 intact, 1 fully separated) so that forward models can
/// measure debonded and process-zone lengths without knowing the law. `history` holds whatever
/// else a law needs (e.g. the largest effective opening reached); its meaning is the law's own.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct LawState {
    /// Damage D ∈ [0, 1], non-decreasing.
    pub damage: f64,
    /// Law-specific history variables.
    pub history: [f64; 3],
}

/// What a law returns for a trial gap: traction, consistent tangent, and the trial state that
/// becomes the committed state once the step converges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawEval {
    /// Traction (MPa).
    pub traction: Traction,
    /// `∂T/∂u` (MPa/mm).
    pub tangent: Tangent,
    /// Trial history.
    pub state: LawState,
}

/// One parameter of a law, for reports and parameter spaces.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterInfo {
    /// Key in configuration files (also the parameter-space path below `law.`).
    pub name: &'static str,
    /// Current value.
    pub value: f64,
    /// Physical unit, e.g. `"MPa"`, `"mm"`, `"N/mm"`.
    pub unit: &'static str,
    /// One line on what it means.
    pub meaning: &'static str,
}

/// A traction–separation law of a zero-thickness interface.
///
/// Object safe and registered with `typetag`: a `Box<dyn CohesiveLaw>` (de)serialises with a
/// `type = "..."` key, so users add laws in their own crates with
/// `#[typetag::serde(name = "my_law")] impl CohesiveLaw for MyLaw { ... }`.
///
/// Contract (checked for every bundled law by the test suite):
/// * `evaluate` is pure: it never mutates the law and depends only on `gap` and `previous`;
/// * the returned tangent is the derivative of the returned traction with respect to the gap,
///   holding `previous` fixed (the consistent tangent Newton needs);
/// * `state.damage` never decreases and stays in [0, 1];
/// * on pure-mode paths to complete failure, `∫ T du` equals [`CohesiveLaw::fracture_energy`].
#[typetag::serde(tag = "type")]
pub trait CohesiveLaw: Send + Sync + std::fmt::Debug {
    /// Checks the parameters; returns an error naming the first invalid one.
    fn validate(&self) -> Result<()>;

    /// Traction, tangent and trial state at `gap`, starting from the committed state `previous`.
    fn evaluate(&self, gap: &Gap, previous: &LawState) -> LawEval;

    /// Critical energy release rates `[G_Ic, G_IIc]` in N/mm (energy to separate in pure mode).
    fn fracture_energy(&self) -> [f64; 2];

    /// Initial (penalty) stiffnesses `[k_n, k_t]` in MPa/mm.
    fn initial_stiffness(&self) -> [f64; 2];

    /// Pure-mode peak tractions `[σ_n, σ_t]` in MPa.
    fn strength(&self) -> [f64; 2];

    /// The law's parameters with units, in configuration-file order.
    fn parameters(&self) -> Vec<ParameterInfo>;

    /// State of an undamaged point.
    fn initial_state(&self) -> LawState {
        LawState::default()
    }

    /// Recoverable (elastic) energy per unit area stored at `gap` in `state` (N/mm).
    ///
    /// The default, `½ T·u`, is exact for laws that unload along the secant to the origin and
    /// for a linear compression penalty; laws with other unloading must override it. Forward models
    /// compute dissipated energy as work done minus this.
    fn stored_energy(&self, gap: &Gap, state: &LawState) -> f64 {
        0.5 * self.evaluate(gap, state).traction.dot(gap)
    }

    /// The inner kink ([`CohesiveLaw::inner_kinks`]) at which the crack that an observer sees
    /// lies, when that is not complete failure (default `None`: the visible crack is where the law
    /// has failed completely). A law whose damage reaches 1 only long after the visible crack has
    /// passed (fibres still bridging behind a matrix crack) names the kink where its matrix fails,
    /// and a forward model that records a crack length places the front there.
    fn visible_front_kink(&self) -> Option<usize> {
        None
    }

    /// Number of kinks in the response between damage onset and complete failure that the damage
    /// does not mark (default 0), such as one part of a superposed law failing while another
    /// still carries load. The interface integration places a front at each, as at onset and
    /// complete failure, so that the forces stay exact and smooth while such a kink crosses an
    /// element: without it, the kink moves point by point and a steep law snaps back at each.
    fn inner_kinks(&self) -> usize {
        0
    }

    /// Whether the traction along a pure opening path (zero slip), on the loading envelope, is
    /// linear between the kinks the integrators place breakpoints at (damage onset, the inner
    /// kinks, complete failure), as for linear softening (default `false`). The work done on a
    /// point over a step is then integrated by the trapezoidal rule on each piece, which is exact
    /// there, instead of sampling the law between the kinks.
    fn opening_path_piecewise_linear(&self) -> bool {
        false
    }

    /// Whether `state` lies beyond inner kink `k` (`k <` [`CohesiveLaw::inner_kinks`]) along its
    /// loading path: `false` before it, `true` from it on, never back.
    fn beyond_inner_kink(&self, state: &LawState, k: usize) -> bool {
        let _ = (state, k);
        false
    }

    /// A key of the law's response to pure opening (default `None`: not known). Two laws of one
    /// type with equal keys agree to the bit, at every gap `(g_n, 0)` reached through such gaps
    /// from the initial state, on the normal traction, the damage, the tangent's normal entry and
    /// the stored energy, and give a zero shear traction and finite values elsewhere; the normal
    /// components of [`CohesiveLaw::fracture_energy`], [`CohesiveLaw::strength`] and
    /// [`CohesiveLaw::initial_stiffness`] are equal too. The key holds the bits of every value
    /// that response depends on: for a law whose modes interact only through the mode mix, those
    /// of its normal branch. A test that opens the interface without shearing it (a symmetric
    /// DCB) then runs alike with either law, whatever their shear branches, and an identification
    /// answers the one from the other ([`crate::ForwardModel::law_key`]).
    fn mode_one_key(&self) -> Option<Vec<u64>> {
        None
    }

    /// The law with a fibre-bridging tail added (an R-curve): a long, weak part of strength
    /// `strength` (MPa) that vanishes at opening `opening` (mm), superposed on this law; `None`
    /// when the law has no such extension (default). At `strength = 0` the law itself.
    fn with_bridging_tail(&self, strength: f64, opening: f64) -> Option<Result<Box<dyn CohesiveLaw>>> {
        let _ = (strength, opening);
        None
    }
}

/// Reads a law from TOML (a table with a `type` key) and validates it.
///
/// ```
/// # use czid_core::law_from_toml;
/// let err = law_from_toml("type = \"no_such_law\"").unwrap_err();
/// assert!(err.to_string().contains("no_such_law"));
/// ```
pub fn law_from_toml(text: &str) -> Result<Box<dyn CohesiveLaw>> {
    let law: Box<dyn CohesiveLaw> =
        toml::from_str(text).map_err(|e| CzError::config("law", e.to_string().trim_end().to_string()))?;
    law.validate()?;
    Ok(law)
}

/// Writes a law as a TOML table with its `type` key.
pub fn law_to_toml(law: &dyn CohesiveLaw) -> Result<String> {
    toml::to_string(law).map_err(|e| CzError::config("law", e.to_string()))
}
