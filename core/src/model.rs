//! The forward-model contract.

use crate::effect::EffectDeclaration;
use crate::error::CzError;
use crate::law::CohesiveLaw;
use crate::record::Record;
use crate::regimes::{GenericRegimes, RegimeRule};

/// A simulation that failed part way: the error, and the steps that did converge.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulationFailure {
    /// Why it stopped.
    pub error: CzError,
    /// The converged steps before the failure (possibly empty).
    pub partial: Record,
}

impl std::fmt::Display for SimulationFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} (after {} converged steps)", self.error, self.partial.rows())
    }
}

impl std::error::Error for SimulationFailure {}

/// A simulated test that runs with any cohesive law.
///
/// The model owns its geometry, materials, loading and switchable physical effects; the law is
/// passed per run so that an identification can try thousands of laws on one model (which may
/// cache its mesh and symbolic factorisation across runs, in fields marked `#[serde(skip)]`).
///
/// A model also declares what the diagnosis needs to know about it: its switchable effects
/// ([`ForwardModel::effects`]) and how its tests split into regimes ([`ForwardModel::regimes`]).
///
/// Like laws, models are registered with `typetag`, so a problem file names one by
/// `type = "..."` and users add their own with `#[typetag::serde(name = "my_test")]`.
#[typetag::serde(tag = "type")]
pub trait ForwardModel: Send + Sync + std::fmt::Debug {
    /// Short name, e.g. `"dcb"`.
    fn name(&self) -> &str;

    /// Checks the configuration; returns an error naming the first invalid field.
    fn validate(&self) -> crate::error::Result<()> {
        Ok(())
    }

    /// Runs the test with `law`; returns one row per converged step with at least the columns
    /// of [`crate::columns`] that the model measures.
    fn simulate(&self, law: &dyn CohesiveLaw) -> Result<Record, SimulationFailure>;

    /// Checks that the model resolves `law` (e.g. that its interface elements are shorter than the
    /// law's cohesive zone): an error for a mesh that cannot, notes for a marginal one (default:
    /// nothing to check). Called once on the initial law when a problem is read, not per run.
    fn check_law(&self, law: &dyn CohesiveLaw) -> crate::error::Result<Vec<String>> {
        let _ = law;
        Ok(Vec::new())
    }

    /// A key of what a run takes from `law` (default `None`: every law counts as different).
    /// Runs of this model with laws of one type and equal keys give the same record, or the same
    /// failure, to the bit: a model that loads the interface in pure opening only returns its
    /// law's [`CohesiveLaw::mode_one_key`] and whatever else of the law its run depends on. An
    /// identification evaluates a candidate whose every experiment has the key of one evaluated
    /// before by taking that one's value (the shear branch a DCB cannot see, moved by a genetic
    /// algorithm, does not cost a run).
    fn law_key(&self, law: &dyn CohesiveLaw) -> Option<Vec<u64>> {
        let _ = law;
        None
    }

    /// The model's switchable effects (default: none). Each declared field must exist in the
    /// model's configuration, and at the declared null value the model must simulate exactly as
    /// without the effect; the diagnosis builds its candidate effects from these declarations.
    fn effects(&self) -> Vec<EffectDeclaration> {
        Vec::new()
    }

    /// How the model's tests split into regimes (default: the generic rule of a test that loads,
    /// peaks and softens).
    fn regimes(&self) -> &'static dyn RegimeRule {
        &GenericRegimes
    }

    /// An independent model of the same test and specimen, of higher fidelity and built on other
    /// assumptions (e.g. a continuum model of a beam model), effects carried over (default:
    /// none). The diagnosis runs it at the fitted law to tell the misfit that this model's own
    /// form leaves on any test from the misfit an unmodelled effect makes.
    fn reference(&self) -> Option<Box<dyn ForwardModel>> {
        None
    }

    /// The same model on a coarser discretisation (default: none). The diagnosis runs a
    /// [`ForwardModel::reference`] and, where it has one, its coarsened twin at the fitted law:
    /// the difference of the two is how far the reference itself may sit from a converged
    /// solution, the uncertainty of the model-form floor it estimates.
    fn coarsened(&self) -> Option<Box<dyn ForwardModel>> {
        None
    }
}
