//! Candidate effects: optional extensions of a setup whose null value is the base model.
//!
//! A candidate names the physics it adds, says whether it applies to a setup, lists its
//! parameters (with their null values and a realistic range) and builds the extended setup for
//! given values. At the null values [`CandidateEffect::apply`] must return the setup unchanged:
//! the diagnosis measures the effect as a departure from the fitted base model, and the tests
//! check it for every bundled candidate.
//!
//! Most candidates are not written here at all: a forward model declares its switchable effects
//! ([`czid_core::ForwardModel::effects`]) and the library turns each declaration into a
//! [`Declared`] candidate for the setups whose models declare it. Candidates that change the law
//! rather than a model ([`BridgingTail`]) and a user's own are registered with [`Library::add`].

use crate::identification::Setup;
use czid_core::{CzError, EffectDeclaration, EffectScope, Parameter, ParameterSpace, Result, Sign};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::sync::Arc;

/// A parameter of a candidate effect.
#[derive(Clone, Debug, PartialEq)]
pub struct EffectParameter {
    /// Name, bounds (the realistic range) and unit.
    pub parameter: Parameter,
    /// The value that reproduces the base model.
    pub null: f64,
}

/// An unmodelled physical effect that can be switched on in a setup.
pub trait CandidateEffect: Send + Sync {
    /// Short name, e.g. `machine_compliance`.
    fn name(&self) -> &str;
    /// One sentence on the physics.
    fn describe(&self) -> String;
    /// Whether the effect can extend this setup (the right model types or law, and not already
    /// switched on).
    fn applies(&self, setup: &Setup) -> bool;
    /// The effect's parameters for this setup.
    fn parameters(&self, setup: &Setup) -> Result<Vec<EffectParameter>>;
    /// The setup with the effect at `values` (physical units, one per parameter). At the null
    /// values the result must simulate exactly like `setup`.
    fn apply(&self, setup: &Setup, values: &[f64]) -> Result<Setup>;
    /// A switch rather than a size: its sensitivity is the on − off difference, and a refit keeps
    /// it on.
    fn discrete(&self) -> bool {
        false
    }
    /// Whether a value found on one specimen holds for another of the same material and machine
    /// (false for specimen-specific effects such as a crack-length error).
    fn transferable(&self) -> bool {
        true
    }
    /// Values of a size seen in real tests, drawn from `rng`, to plant the effect in a synthetic
    /// test (`None`: not planted).
    fn plant(&self, _rng: &mut ChaCha8Rng) -> Option<Vec<f64>> {
        None
    }
}

/// A candidate built from an effect that forward models declare: it applies to the experiments
/// of a setup whose models declare an effect of that name, with one value per experiment or one
/// shared by all of them as the declaration says.
#[derive(Clone, Debug)]
pub struct Declared {
    /// The declaration (of the first model that declares the name).
    pub declaration: EffectDeclaration,
    /// Model types (`ForwardModel::name`) the effect is tried on regardless of what they declare
    /// (a user's trial of a field of a bundled model); `None`: the models that declare it.
    pub models: Option<Vec<String>>,
}

impl Declared {
    /// A candidate for the models that declare `declaration`'s name.
    pub fn new(declaration: EffectDeclaration) -> Self {
        Declared { declaration, models: None }
    }

    /// A candidate for a field of the given model types that they do not declare themselves,
    /// e.g. `Declared::on_models(declaration, &["dcb"])` to try an arm modulus error.
    pub fn on_models(declaration: EffectDeclaration, models: &[&str]) -> Self {
        Declared { declaration, models: Some(models.iter().map(|m| m.to_string()).collect()) }
    }

    /// Experiments the effect applies to, in setup order.
    fn experiments(&self, setup: &Setup) -> Vec<String> {
        let name = self.declaration.name;
        let takes = |m: &dyn czid_core::ForwardModel| match &self.models {
            Some(types) => types.iter().any(|t| t == m.name()),
            None => m.effects().iter().any(|d| d.name == name),
        };
        setup.models.iter().filter(|(_, m)| takes(m.as_ref())).map(|(k, _)| k.clone()).collect()
    }

    /// The effect's value in each of `names`, as a parameter space over their paths.
    fn slots(&self, names: &[String]) -> Result<ParameterSpace> {
        let [lo, hi] = self.declaration.range();
        let unit = self.declaration.unit;
        ParameterSpace::new(
            names
                .iter()
                .map(|n| Parameter::new(&format!("models.{n}.{}", self.declaration.field), unit, lo, hi))
                .collect(),
        )
    }

    fn per_experiment(&self) -> bool {
        self.declaration.scope == EffectScope::PerExperiment
    }
}

impl CandidateEffect for Declared {
    fn name(&self) -> &str {
        self.declaration.name
    }
    fn describe(&self) -> String {
        self.declaration.description.into()
    }
    fn applies(&self, setup: &Setup) -> bool {
        let names = self.experiments(setup);
        let null = self.declaration.null();
        !names.is_empty() && self.slots(&names).and_then(|s| s.read(setup)).is_ok_and(|v| v.iter().all(|&x| x == null))
    }
    fn parameters(&self, setup: &Setup) -> Result<Vec<EffectParameter>> {
        let d = &self.declaration;
        let [lo, hi] = d.range();
        let labels: Vec<String> = if self.per_experiment() && !d.is_switch() {
            self.experiments(setup).iter().map(|n| format!("models.{n}.{}", d.field)).collect()
        } else {
            vec![format!("models.*.{}", d.field)]
        };
        Ok(labels
            .into_iter()
            .map(|path| EffectParameter { parameter: Parameter::new(&path, d.unit, lo, hi), null: d.null() })
            .collect())
    }
    fn apply(&self, setup: &Setup, values: &[f64]) -> Result<Setup> {
        let owner = || format!("candidate `{}`", self.declaration.name);
        let names = self.experiments(setup);
        let per = self.per_experiment() && !self.declaration.is_switch();
        let expected = if per { names.len() } else { 1 };
        if values.len() != expected {
            return Err(CzError::config(owner(), format!("{} values for {expected} parameters", values.len())));
        }
        let each: Vec<f64> = (0..names.len()).map(|i| if per { values[i] } else { values[0] }).collect();
        let extended = self.slots(&names)?.apply(setup, &each).map_err(|e| CzError::config(owner(), e.to_string()))?;
        extended.validate().map_err(|e| CzError::config(owner(), e.to_string()))?;
        Ok(extended)
    }
    fn discrete(&self) -> bool {
        self.declaration.is_switch()
    }
    fn transferable(&self) -> bool {
        self.declaration.scope == EffectScope::Shared
    }
    fn plant(&self, rng: &mut ChaCha8Rng) -> Option<Vec<f64>> {
        if self.declaration.is_switch() {
            return Some(vec![1.0]);
        }
        let t = self.declaration.typical?;
        let [lo, hi] = t.magnitude;
        // The sign is drawn before the magnitude (a benchmark's cases are reproducible draw by draw).
        Some(vec![match t.sign {
            Sign::Positive => rng.random_range(lo..hi),
            Sign::Negative => -rng.random_range(lo..hi),
            Sign::Either => {
                let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
                sign * rng.random_range(lo..hi)
            }
        }])
    }
}

/// Fibre bridging (an R-curve): the bilinear law becomes the matrix part of a `bridging` law whose
/// bridging part is a long, weak bilinear tail. Parameters: the tail's strength σ_b (MPa; 0 is the
/// base law itself) and its final opening δ_b (mm). The tail peaks at the matrix's onset opening,
/// so its shape is fixed by δ_b and its size scales with σ_b; its toughness is `σ_b δ_b / 2`.
/// In DCB models the debonded length then follows the matrix crack (what a camera sees), not the
/// end of the bridging zone.
#[derive(Clone, Debug)]
pub struct BridgingTail {
    /// Largest tail strength considered (MPa).
    pub max_strength: f64,
    /// Initial final opening of the tail (mm).
    pub opening: f64,
    /// Range of the final opening (mm).
    pub opening_range: [f64; 2],
}

impl Default for BridgingTail {
    fn default() -> Self {
        BridgingTail { max_strength: 3.0, opening: 1.0, opening_range: [0.2, 5.0] }
    }
}

impl CandidateEffect for BridgingTail {
    fn name(&self) -> &str {
        "fibre_bridging"
    }
    fn describe(&self) -> String {
        "fibre bridging behind the crack front (a rising R-curve): a long, weak cohesive tail added to the law".into()
    }
    fn applies(&self, setup: &Setup) -> bool {
        setup.law.with_bridging_tail(0.0, self.opening).is_some()
    }
    fn parameters(&self, _setup: &Setup) -> Result<Vec<EffectParameter>> {
        Ok(vec![
            EffectParameter {
                parameter: Parameter::new("law.bridging.strength_n", "MPa", 0.0, self.max_strength),
                null: 0.0,
            },
            EffectParameter {
                parameter: Parameter::new(
                    "law.bridging.final_opening",
                    "mm",
                    self.opening_range[0],
                    self.opening_range[1],
                ),
                null: self.opening,
            },
        ])
    }
    fn apply(&self, setup: &Setup, values: &[f64]) -> Result<Setup> {
        let owner = || format!("candidate `{}`", self.name());
        let (&strength, &opening) = match values {
            [s, o] => (s, o),
            _ => return Err(CzError::config(owner(), "needs 2 values (strength, opening)")),
        };
        let law = setup
            .law
            .with_bridging_tail(strength, opening)
            .ok_or_else(|| CzError::config(owner(), "the law has no fibre-bridging extension"))?
            .map_err(|e| CzError::config(owner(), e.to_string()))?;
        let mut extended = setup.duplicate()?;
        extended.law = law;
        extended.validate().map_err(|e| CzError::config(owner(), e.to_string()))?;
        Ok(extended)
    }
    fn plant(&self, rng: &mut ChaCha8Rng) -> Option<Vec<f64>> {
        // Tails of 0.3–1.5 MPa over 0.5–2 mm openings: 0.1–1.5 N/mm of extra toughness.
        Some(vec![rng.random_range(0.3..1.5), rng.random_range(0.5..2.0)])
    }
}

/// One entry of a [`Library`].
#[derive(Clone)]
enum Entry {
    /// A registered candidate.
    Candidate(Arc<dyn CandidateEffect>),
    /// Every effect the setup's forward models declare.
    Declared,
}

/// The candidates a diagnosis draws from: the effects the forward models declare, the law
/// extensions (fibre bridging) and any candidate registered by the user.
#[derive(Clone)]
pub struct Library {
    entries: Vec<Entry>,
}

impl Library {
    /// An empty library (not even the declared effects).
    pub fn empty() -> Self {
        Library { entries: Vec::new() }
    }

    /// The bundled library: fibre bridging (for laws that have a bridging extension), then every
    /// effect the setup's forward models declare.
    pub fn builtin() -> Self {
        Library { entries: vec![Entry::Candidate(Arc::new(BridgingTail::default())), Entry::Declared] }
    }

    /// Registers a candidate (a later one with the same name replaces the earlier).
    pub fn add(&mut self, candidate: impl CandidateEffect + 'static) -> &mut Self {
        self.add_boxed(Box::new(candidate))
    }

    /// Registers a boxed candidate.
    pub fn add_boxed(&mut self, candidate: Box<dyn CandidateEffect>) -> &mut Self {
        let candidate: Arc<dyn CandidateEffect> = Arc::from(candidate);
        self.entries.retain(|e| !matches!(e, Entry::Candidate(c) if c.name() == candidate.name()));
        self.entries.push(Entry::Candidate(candidate));
        self
    }

    /// Adds every effect the setup's forward models declare (once, where [`Library::builtin`] has
    /// them), e.g. after starting from [`Library::empty`].
    pub fn with_declared(&mut self) -> &mut Self {
        if !self.entries.iter().any(|e| matches!(e, Entry::Declared)) {
            self.entries.push(Entry::Declared);
        }
        self
    }

    /// Every candidate for `setup`, in library order: registered candidates, and where the
    /// library holds the declared effects, one candidate per effect name the setup's models
    /// declare (a registered candidate of the same name takes its place).
    pub fn all(&self, setup: &Setup) -> Vec<Arc<dyn CandidateEffect>> {
        let registered: Vec<&str> = self
            .entries
            .iter()
            .filter_map(|e| match e {
                Entry::Candidate(c) => Some(c.name()),
                Entry::Declared => None,
            })
            .collect();
        let mut out: Vec<Arc<dyn CandidateEffect>> = Vec::new();
        for e in &self.entries {
            match e {
                Entry::Candidate(c) => out.push(c.clone()),
                Entry::Declared => {
                    for d in setup.models.values().flat_map(|m| m.effects()) {
                        if !registered.contains(&d.name) && !out.iter().any(|c| c.name() == d.name) {
                            out.push(Arc::new(Declared::new(d)));
                        }
                    }
                }
            }
        }
        out
    }

    /// Names of the candidates for `setup`, in library order.
    pub fn names(&self, setup: &Setup) -> Vec<String> {
        self.all(setup).iter().map(|c| c.name().to_string()).collect()
    }

    /// The named candidates for `setup` (all when `names` is empty); an unknown name is an error
    /// listing the known ones.
    pub fn select(&self, setup: &Setup, names: &[String]) -> Result<Vec<Arc<dyn CandidateEffect>>> {
        let all = self.all(setup);
        if names.is_empty() {
            return Ok(all);
        }
        names
            .iter()
            .map(|n| {
                all.iter().find(|c| c.name() == n).cloned().ok_or_else(|| {
                    let known: Vec<&str> = all.iter().map(|c| c.name()).collect();
                    CzError::config(
                        "--candidates",
                        format!("unknown candidate `{n}`; candidates for this problem: {}", known.join(", ")),
                    )
                })
            })
            .collect()
    }
}
