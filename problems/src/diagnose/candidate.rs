//! Candidate effects: optional extensions of a setup whose null value is the base model.
//!
//! A candidate names the physics it adds, says whether it applies to a setup, lists its
//! parameters (with their null values and a realistic range) and builds the extended setup for
//! given values. At the null values [`CandidateEffect::apply`] must return the setup unchanged:
//! the diagnosis measures the effect as a departure from the fitted base model, and the tests
//! check it for every bundled candidate.
//!
//! Three generic kinds cover the bundled library, so that a new one is a table entry:
//! [`ModelField`] (a number in the models' configuration, e.g. `effects.machine_compliance`),
//! [`ModelFlag`] (a switch, e.g. `effects.large_rotation`) and [`BridgingTail`] (the law swapped
//! for a superposed law with a fibre-bridging tail of zero amplitude at the null).

use crate::identification::Setup;
use czid_core::{CzError, Parameter, Result};
use serde_json::{json, Value};

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
}

fn to_tree(setup: &Setup) -> Result<Value> {
    serde_json::to_value(setup).map_err(|e| CzError::config("setup", e.to_string()))
}

fn from_tree(tree: Value, owner: &str) -> Result<Setup> {
    let s: Setup =
        serde_json::from_value(tree).map_err(|e| CzError::config(format!("candidate `{owner}`"), e.to_string()))?;
    s.validate().map_err(|e| CzError::config(format!("candidate `{owner}`"), e.to_string()))?;
    Ok(s)
}

fn walk<'a>(v: &'a mut Value, path: &str) -> Option<&'a mut Value> {
    path.split('.').try_fold(v, |node, key| node.get_mut(key))
}

fn number(v: f64, owner: &str) -> Result<Value> {
    serde_json::Number::from_f64(v)
        .map(Value::Number)
        .ok_or_else(|| CzError::invalid(format!("candidate `{owner}`"), "value", v, "must be finite"))
}

/// Experiments whose model type is one of `models`, in setup order.
fn matching(setup: &Setup, models: &[String]) -> Vec<String> {
    setup.models.iter().filter(|(_, m)| models.iter().any(|t| t == m.name())).map(|(k, _)| k.clone()).collect()
}

/// A number in the forward models' configuration whose null value is the base model, e.g.
/// `effects.machine_compliance` of a DCB.
#[derive(Clone, Debug)]
pub struct ModelField {
    /// Candidate name.
    pub name: String,
    /// The physics, in one sentence.
    pub description: String,
    /// Model types (`ForwardModel::name`) it applies to.
    pub models: Vec<String>,
    /// Dotted path inside a model's configuration.
    pub field: String,
    /// Unit of the value.
    pub unit: String,
    /// Null value (the base model).
    pub null: f64,
    /// Realistic range.
    pub lower: f64,
    /// Realistic range.
    pub upper: f64,
    /// One value per experiment (specimen-specific) rather than one for all.
    pub per_experiment: bool,
}

impl ModelField {
    /// A field shared by every matching experiment (same machine, same material).
    pub fn shared(name: &str, description: &str, models: &[&str], field: &str, unit: &str, range: [f64; 2]) -> Self {
        ModelField {
            name: name.into(),
            description: description.into(),
            models: models.iter().map(|s| s.to_string()).collect(),
            field: field.into(),
            unit: unit.into(),
            null: 0.0,
            lower: range[0],
            upper: range[1],
            per_experiment: false,
        }
    }

    /// One value per experiment (a property of each specimen).
    pub fn per_experiment(mut self) -> Self {
        self.per_experiment = true;
        self
    }
}

impl CandidateEffect for ModelField {
    fn name(&self) -> &str {
        &self.name
    }
    fn describe(&self) -> String {
        self.description.clone()
    }
    fn applies(&self, setup: &Setup) -> bool {
        let names = matching(setup, &self.models);
        let Ok(mut tree) = to_tree(setup) else { return false };
        !names.is_empty()
            && names.iter().all(|n| {
                walk(&mut tree, &format!("models.{n}.{}", self.field)).and_then(|v| v.as_f64()) == Some(self.null)
            })
    }
    fn parameters(&self, setup: &Setup) -> Result<Vec<EffectParameter>> {
        let names = matching(setup, &self.models);
        let labels: Vec<String> = if self.per_experiment {
            names.iter().map(|n| format!("models.{n}.{}", self.field)).collect()
        } else {
            vec![format!("models.*.{}", self.field)]
        };
        labels
            .into_iter()
            .map(|path| {
                Ok(EffectParameter {
                    parameter: Parameter::new(&path, &self.unit, self.lower, self.upper),
                    null: self.null,
                })
            })
            .collect()
    }
    fn apply(&self, setup: &Setup, values: &[f64]) -> Result<Setup> {
        let names = matching(setup, &self.models);
        let expected = if self.per_experiment { names.len() } else { 1 };
        if values.len() != expected {
            return Err(CzError::config(
                format!("candidate `{}`", self.name),
                format!("{} values for {expected} parameters", values.len()),
            ));
        }
        let mut tree = to_tree(setup)?;
        for (i, n) in names.iter().enumerate() {
            let v = if self.per_experiment { values[i] } else { values[0] };
            let slot = walk(&mut tree, &format!("models.{n}.{}", self.field)).ok_or_else(|| {
                CzError::config(format!("candidate `{}`", self.name), format!("model `{n}` has no `{}`", self.field))
            })?;
            *slot = number(v, &self.name)?;
        }
        from_tree(tree, &self.name)
    }
    fn transferable(&self) -> bool {
        !self.per_experiment
    }
}

/// A switch in the forward models' configuration, off in the base model (e.g.
/// `effects.large_rotation`).
#[derive(Clone, Debug)]
pub struct ModelFlag {
    /// Candidate name.
    pub name: String,
    /// The physics, in one sentence.
    pub description: String,
    /// Model types it applies to.
    pub models: Vec<String>,
    /// Dotted path of the boolean inside a model's configuration.
    pub field: String,
}

impl CandidateEffect for ModelFlag {
    fn name(&self) -> &str {
        &self.name
    }
    fn describe(&self) -> String {
        self.description.clone()
    }
    fn applies(&self, setup: &Setup) -> bool {
        let names = matching(setup, &self.models);
        let Ok(mut tree) = to_tree(setup) else { return false };
        !names.is_empty()
            && names.iter().all(|n| {
                walk(&mut tree, &format!("models.{n}.{}", self.field)).and_then(|v| v.as_bool()) == Some(false)
            })
    }
    fn parameters(&self, _setup: &Setup) -> Result<Vec<EffectParameter>> {
        let path = format!("models.*.{}", self.field);
        Ok(vec![EffectParameter { parameter: Parameter::new(&path, "on/off", 0.0, 1.0), null: 0.0 }])
    }
    fn apply(&self, setup: &Setup, values: &[f64]) -> Result<Setup> {
        let on = values.first().is_some_and(|v| *v >= 0.5);
        let mut tree = to_tree(setup)?;
        for n in matching(setup, &self.models) {
            let slot = walk(&mut tree, &format!("models.{n}.{}", self.field)).ok_or_else(|| {
                CzError::config(format!("candidate `{}`", self.name), format!("model `{n}` has no `{}`", self.field))
            })?;
            *slot = Value::Bool(on);
        }
        from_tree(tree, &self.name)
    }
    fn discrete(&self) -> bool {
        true
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
        to_tree(setup).ok().and_then(|t| t["law"]["type"].as_str().map(|s| s == "bilinear")).unwrap_or(false)
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
        let owner = self.name();
        let (&strength, &opening) = match values {
            [s, o] => (s, o),
            _ => return Err(CzError::config(format!("candidate `{owner}`"), "needs 2 values (strength, opening)")),
        };
        if strength == 0.0 {
            // The null: the base law itself, not a superposition with an empty part.
            return setup.duplicate();
        }
        if !(strength > 0.0 && opening > 0.0) {
            return Err(CzError::invalid(
                format!("candidate `{owner}`"),
                "law.bridging",
                strength.min(opening),
                "tail strength and opening must be positive",
            ));
        }
        let mut tree = to_tree(setup)?;
        let mut matrix = tree["law"].clone();
        let m = matrix
            .as_object_mut()
            .ok_or_else(|| CzError::config(format!("candidate `{owner}`"), "law is not a table"))?;
        m.remove("type");
        let get = |k: &str| m.get(k).and_then(|v| v.as_f64()).unwrap_or(f64::NAN);
        let (k, sn, st, gi, gii) = (get("penalty"), get("strength_n"), get("strength_t"), get("g_ic"), get("g_iic"));
        let ratio = strength / sn;
        let g_b = 0.5 * strength * opening;
        let mut tail = Value::Object(m.clone());
        tail["penalty"] = number(k * ratio, owner)?;
        tail["strength_n"] = number(strength, owner)?;
        tail["strength_t"] = number(st * ratio, owner)?;
        tail["g_ic"] = number(g_b, owner)?;
        tail["g_iic"] = number(gii * g_b / gi, owner)?;
        tree["law"] = json!({ "type": "bridging", "matrix": matrix, "bridging": tail });
        // A measured crack length is the visible (matrix) crack tip, with fibres still bridging
        // behind it. The superposed law reports complete failure only where the tail has failed
        // too, so the DCB's debonded front is moved to where the matrix fails: its combined
        // damage there is D* = 1 − t_b(δ_c) / ((K_m + K_b) δ_c), δ_c the matrix's final opening
        // (the damage grows monotonically with the opening, so the front at D* is the matrix's).
        let dc = 2.0 * gi / sn;
        let d0 = sn / k;
        let tb = if dc < opening { strength * (opening - dc) / (opening - d0) } else { 0.0 };
        // Levels from 1 − 10⁻⁶ on would mean complete failure of both parts to the engine; just
        // below it the front lies within a hair of the matrix's failure opening.
        let level = (1.0 - tb / (k * (1.0 + ratio) * dc)).min(1.0 - 1.0001e-6);
        let names = matching(setup, &["dcb".to_string()]);
        for n in names {
            if let Some(t) = walk(&mut tree, &format!("models.{n}.control.damage_threshold")) {
                // Only the default (complete failure) is replaced; a level chosen by the user stays.
                if t.as_f64().is_some_and(|v| v >= 1.0 - 1.0001e-6) {
                    *t = number(level, owner)?;
                }
            }
        }
        from_tree(tree, owner)
    }
}

/// A table entry of a [`ModelField`] candidate: name, description, field, unit, range, per
/// experiment.
type Entry = (&'static str, &'static str, &'static str, &'static str, [f64; 2], bool);

/// The candidates a diagnosis draws from: the bundled ones plus any registered by the user.
pub struct Library {
    candidates: Vec<Box<dyn CandidateEffect>>,
}

impl Library {
    /// An empty library.
    pub fn empty() -> Self {
        Library { candidates: Vec::new() }
    }

    /// The bundled candidates: for the DCB and ENF (ranges realistic for coupon-size specimens,
    /// arms of 1–5 mm, cracks of 20–100 mm) and for the FRP-strengthened beam (`frp_beam`,
    /// laboratory beams with bonded plates). Each applies only to its models.
    pub fn builtin() -> Self {
        let beams = ["dcb", "enf"];
        let mut lib = Library::empty();
        lib.add(BridgingTail::default());
        lib.add(ModelFlag {
            name: "large_rotation".into(),
            description: "large rotations of the arms (geometric non-linearity at large openings)".into(),
            models: vec!["dcb".into()],
            field: "effects.large_rotation".into(),
        });
        lib.add(ModelField::shared(
            "root_compliance",
            "root rotation at the crack front: through-thickness compliance of the arms (elastic foundation)",
            &beams,
            "effects.root_compliance",
            "mm/MPa",
            [0.0, 1e-3],
        ));
        lib.add(ModelField::shared(
            "machine_compliance",
            "compliance of the machine and load train in series with the specimen",
            &beams,
            "effects.machine_compliance",
            "mm/N",
            [0.0, 1e-2],
        ));
        lib.add(
            ModelField::shared(
                "crack_length_offset",
                "initial crack length different from the nominal one (blunt insert, misread pre-crack)",
                &beams,
                "effects.crack_length_offset",
                "mm",
                [-5.0, 5.0],
            )
            .per_experiment(),
        );
        lib.add(
            ModelField::shared(
                "displacement_offset",
                "displacement zero offset: seating of the grips or hinges (a toe)",
                &beams,
                "effects.displacement_offset",
                "mm",
                [-1.0, 1.0],
            )
            .per_experiment(),
        );
        lib.add(ModelField::shared(
            "shear_compliance",
            "more shear deformation of the arms than the nominal G13 gives",
            &beams,
            "effects.shear_compliance",
            "1/MPa",
            [0.0, 1e-3],
        ));
        // The FRP-strengthened beam: one table entry per switchable effect of the model.
        let frp = ["frp_beam"];
        let entries: [Entry; 5] = [
            (
                "adhesive_compliance",
                "shear compliance of the adhesive layer in series with the bond law",
                "effects.adhesive_shear_compliance",
                "mm/MPa",
                [0.0, 2e-3],
                false,
            ),
            (
                "adhesive_normal_compliance",
                "normal (peeling) compliance of the adhesive layer",
                "effects.adhesive_normal_compliance",
                "mm/MPa",
                [0.0, 1e-3],
                false,
            ),
            (
                "shrinkage_strain",
                "concrete shrinkage (or swelling) after bonding, prestressing the bond",
                "effects.shrinkage_strain",
                "-",
                [-4e-4, 2e-4],
                false,
            ),
            (
                "steel_hardening",
                "a different hardening modulus of the bars after yield",
                "effects.steel_hardening_offset",
                "MPa",
                [-1500.0, 3000.0],
                false,
            ),
            (
                "deflection_offset",
                "seating of the supports (a toe of the load–deflection curve)",
                "effects.deflection_offset",
                "mm",
                [0.0, 2.0],
                true,
            ),
        ];
        for (name, description, field, unit, range, per_experiment) in entries {
            let c = ModelField::shared(name, description, &frp, field, unit, range);
            lib.add(if per_experiment { c.per_experiment() } else { c });
        }
        lib
    }

    /// Registers a candidate (a later one with the same name replaces the earlier).
    pub fn add(&mut self, candidate: impl CandidateEffect + 'static) -> &mut Self {
        self.add_boxed(Box::new(candidate))
    }

    /// Registers a boxed candidate.
    pub fn add_boxed(&mut self, candidate: Box<dyn CandidateEffect>) -> &mut Self {
        self.candidates.retain(|c| c.name() != candidate.name());
        self.candidates.push(candidate);
        self
    }

    /// Names, in registration order.
    pub fn names(&self) -> Vec<&str> {
        self.candidates.iter().map(|c| c.name()).collect()
    }

    /// All candidates.
    pub fn all(&self) -> Vec<&dyn CandidateEffect> {
        self.candidates.iter().map(|c| c.as_ref()).collect()
    }

    /// The named candidates (all when `names` is empty); an unknown name is an error listing the
    /// known ones.
    pub fn select(&self, names: &[String]) -> Result<Vec<&dyn CandidateEffect>> {
        if names.is_empty() {
            return Ok(self.all());
        }
        names
            .iter()
            .map(|n| {
                self.candidates.iter().find(|c| c.name() == n).map(|c| c.as_ref()).ok_or_else(|| {
                    CzError::config(
                        "--candidates",
                        format!("unknown candidate `{n}`; known candidates: {}", self.names().join(", ")),
                    )
                })
            })
            .collect()
    }
}
