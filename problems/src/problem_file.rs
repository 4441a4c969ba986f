//! Problem files: a TOML description of an identification.
//!
//! ```toml
//! # Units: N, mm, MPa.
//! [law]                       # the cohesive law and its initial values
//! type = "st_czm"
//! # ... the law's parameters
//!
//! [[experiment]]              # one or more tests sharing the law
//! name = "dcb"
//! [experiment.data]           # see `ExperimentSpec`
//! file = "dcb.csv"            # relative to this file
//! displacement = "opening_mm"
//! load = "load_N"
//! crack = "debonded_mm"
//! crack_measure = "debonded_length"
//! [experiment.model]          # the forward model of this test
//! type = "dcb"
//! # ... geometry, elastic constants, effects
//! [[experiment.event]]        # optional: single measured values (see `crate::event`)
//! kind = "debonded_length_at_onset"
//! value = 436.0
//! unit = "mm"
//!
//! [[parameter]]               # what is identified
//! path = "law.strength_n"     # `law.<key>` or `models.<experiment>.<key>`
//! unit = "MPa"
//! lower = 5.0
//! upper = 60.0
//! scale = "linear"            # or "log"
//!
//! [objective]
//! debonded_length = true      # fit the debonded length too (when the data has it)
//! weights = "balanced"        # or { load = 1.0, debonded_length = 0.5, events = 1.0 }
//!
//! [optimizer]
//! type = "miga"
//! seed = 1
//! budget = 20000              # objective evaluations
//! [optimizer.settings]        # the optimizer's own settings
//!
//! [optimizers.polish]         # optional named alternatives, for `--optimizer polish` and
//! type = "levenberg-marquardt" # `compare --optimizers miga,polish`
//! [optimizers.polish.settings]
//! fd_step = 1e-3
//! ```

use crate::data::{Experiment, ExperimentSpec};
use crate::event::EventSpec;
use crate::identification::{Identification, Setup};
use czid_core::param::duplicate;
use czid_core::{CohesiveLaw, CzError, ForwardModel, Parameter, ParameterSpace, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One test: its data and its forward model.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentEntry {
    /// Name used in reports and parameter paths (default: the data file's stem).
    #[serde(default)]
    pub name: Option<String>,
    /// Where the data is.
    pub data: ExperimentSpec,
    /// The simulated test.
    pub model: Box<dyn ForwardModel>,
    /// Measured events (`[[experiment.event]]`, see [`crate::event`]).
    #[serde(default)]
    pub event: Vec<EventSpec>,
}

/// How the objective's terms are weighted.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Weights {
    /// `"balanced"`: equal contributions at the initial guess (the paper's choice); `"noise"`: each
    /// term in units of its data's noise, so that the objective is χ²
    /// ([`crate::identification::Identification::noise_weights`]).
    Named(String),
    /// Explicit α for the load, debonded-length and event terms.
    Explicit {
        /// α_F.
        load: f64,
        /// α_L.
        #[serde(default = "one")]
        debonded_length: f64,
        /// α_E, for every `[[experiment.event]]` (times its own `weight`).
        #[serde(default = "one")]
        events: f64,
    },
}

fn one() -> f64 {
    1.0
}

impl Default for Weights {
    fn default() -> Self {
        Weights::Named("balanced".into())
    }
}

/// The `[objective]` table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectiveSpec {
    /// Fit the debonded length as well as the load (when the data has it).
    #[serde(default = "yes")]
    pub debonded_length: bool,
    /// Term weights.
    #[serde(default)]
    pub weights: Weights,
}

fn yes() -> bool {
    true
}

impl Default for ObjectiveSpec {
    fn default() -> Self {
        ObjectiveSpec { debonded_length: true, weights: Weights::default() }
    }
}

/// The `[optimizer]` table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OptimizerSpec {
    /// Registered name, e.g. `"miga"`, `"nsga2"`, `"nelder-mead"`, `"hybrid"`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Random seed.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Objective evaluations allowed.
    pub budget: usize,
    /// Stop once the objective reaches this value.
    #[serde(default)]
    pub target: Option<f64>,
    /// The optimizer's own settings (see the Optimizers chapter).
    #[serde(default)]
    pub settings: toml::Table,
}

fn default_seed() -> u64 {
    1
}

/// A named alternative optimizer: `[optimizers.<label>]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OptimizerChoice {
    /// Registered name, as in `[optimizer]`.
    #[serde(rename = "type")]
    pub kind: String,
    /// The optimizer's own settings.
    #[serde(default)]
    pub settings: toml::Table,
}

/// A whole problem file.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProblemFile {
    /// The cohesive law with its initial values.
    pub law: Box<dyn CohesiveLaw>,
    /// The tests.
    pub experiment: Vec<ExperimentEntry>,
    /// The identified parameters.
    #[serde(default)]
    pub parameter: Vec<Parameter>,
    /// Objective options.
    #[serde(default)]
    pub objective: ObjectiveSpec,
    /// Optimizer choice.
    pub optimizer: OptimizerSpec,
    /// Named alternatives, selected by label with `--optimizer` or in `compare`.
    #[serde(default)]
    pub optimizers: BTreeMap<String, OptimizerChoice>,
}

impl ProblemFile {
    /// The registered name and settings that `label` stands for: a named alternative
    /// (`[optimizers.<label>]`), the file's `[optimizer]` when `label` is its type, or else the
    /// registered optimizer `label` with its default settings.
    pub fn optimizer_named(&self, label: &str) -> (String, toml::Value) {
        if let Some(choice) = self.optimizers.get(label) {
            (choice.kind.clone(), toml::Value::Table(choice.settings.clone()))
        } else if label == self.optimizer.kind {
            (label.to_string(), toml::Value::Table(self.optimizer.settings.clone()))
        } else {
            (label.to_string(), toml::Value::Table(Default::default()))
        }
    }
}

/// A problem file read from disk, with its data loaded.
#[derive(Debug)]
pub struct LoadedProblem {
    /// Where it was read from.
    pub path: PathBuf,
    /// Its content.
    pub file: ProblemFile,
    /// The experiments' data, in file order.
    pub experiments: Vec<Experiment>,
    /// What the models said of their meshes against the initial law (see
    /// [`czid_core::ForwardModel::check_law`]).
    pub mesh_notes: Vec<String>,
}

impl LoadedProblem {
    /// Reads a problem file, checks it and loads its data. Errors name the file and, for syntax
    /// and key errors, the line and column.
    pub fn read(path: &Path) -> Result<Self> {
        let shown = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| CzError::Io { path: shown.clone(), message: e.to_string() })?;
        Self::parse(&text, path)
    }

    /// Reads a problem file with some values replaced, e.g. `("law.strength_n", "20")` or
    /// `("models.dcb.effects.large_rotation", "true")`: paths as in `[[parameter]]` (`law.*`,
    /// `models.<experiment>.*`), plus `model.*` (a file with one top-level `[model]`), `objective.*`,
    /// `optimizer.*` and `optimizers.<label>.*`. Values are TOML (numbers, booleans, quoted strings).
    pub fn read_with(path: &Path, overrides: &[(String, String)]) -> Result<Self> {
        let shown = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| CzError::Io { path: shown.clone(), message: e.to_string() })?;
        if overrides.is_empty() {
            return Self::parse(&text, path);
        }
        let edited = with_overrides(&text, &shown, overrides)?;
        Self::parse(&edited, path).map_err(|e| Self::blame_override(&text, overrides).unwrap_or(e))
    }

    /// The first `--set` after which `text` no longer reads as a problem file, with what is wrong
    /// (the line numbers of the rebuilt file would mean nothing to the user).
    fn blame_override(text: &str, overrides: &[(String, String)]) -> Option<CzError> {
        czid_models::registry::ensure_linked();
        let mut doc: toml::Table = toml::from_str(text).ok()?;
        for (key, raw) in overrides {
            let value = toml::from_str::<toml::Table>(&format!("v = {raw}")).ok()?.remove("v")?;
            set_path(&mut doc, key, value).ok()?;
            let edited = toml::to_string(&doc).ok()?;
            if let Err(e) = toml::from_str::<ProblemFile>(&edited) {
                return Some(CzError::config(format!("--set {key}={raw}"), e.message().trim_end().to_string()));
            }
        }
        None
    }

    /// Parses problem-file text; `path` locates relative data files and names errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        czid_models::registry::ensure_linked();
        let shown = path.display().to_string();
        let file: ProblemFile = toml::from_str(text).map_err(|e| {
            // A wrong type inside a law or model is reported against its table (they are read
            // through their `type` tag): name the key as well.
            let at = wrong_type_key(text, e.message()).map(|k| format!("\n(the value is at {k})")).unwrap_or_default();
            CzError::config(&shown, format!("{}{at}", e.to_string().trim_end()))
        })?;
        file.law.validate().map_err(|e| CzError::config(format!("{shown}, [law]"), e.to_string()))?;
        if file.experiment.is_empty() {
            return Err(CzError::config(&shown, "at least one [[experiment]] is needed"));
        }
        if file.optimizer.budget == 0 {
            return Err(CzError::config(format!("{shown}, [optimizer]"), "budget must be at least 1 evaluation"));
        }
        // Optimizer names and settings are checked now, not after the data is loaded and a run set up.
        let choices = std::iter::once(("[optimizer]".to_string(), &file.optimizer.kind, &file.optimizer.settings))
            .chain(file.optimizers.iter().map(|(label, c)| (format!("[optimizers.{label}]"), &c.kind, &c.settings)));
        for (table, kind, settings) in choices {
            czid_optimizers::registry::optimizer_from_config(kind, &toml::Value::Table(settings.clone()))
                .map_err(|e| CzError::config(format!("{shown}, {table}"), e.to_string()))?;
        }
        let base = path.parent().unwrap_or(Path::new("."));
        let mut experiments = Vec::new();
        let mut names = Vec::new();
        let mut mesh_notes = Vec::new();
        for (i, entry) in file.experiment.iter().enumerate() {
            let owner = format!("{shown}, experiment {}: model", i + 1);
            entry.model.validate().map_err(|e| CzError::config(&owner, e.to_string()))?;
            let notes = entry.model.check_law(file.law.as_ref()).map_err(|e| CzError::config(&owner, e.to_string()))?;
            mesh_notes.extend(notes.into_iter().map(|n| format!("experiment {}: {n}", i + 1)));
            let mut data = entry.data.load(base)?;
            if let Some(n) = &entry.name {
                data.name = n.clone();
            }
            let last = data.load.x().last().copied().unwrap_or(0.0);
            for (j, ev) in entry.event.iter().enumerate() {
                let owner = format!("{shown}, experiment {}, event {}", i + 1, j + 1);
                let measured = ev.check(&owner, last)?;
                if data.events.iter().any(|e| e.name == measured.name) {
                    return Err(CzError::config(
                        &owner,
                        format!("two events of this experiment are named `{}`; give each a `name`", measured.name),
                    ));
                }
                data.events.push(measured);
            }
            if names.contains(&data.name) {
                return Err(CzError::config(
                    &shown,
                    format!("two experiments are named `{}`; give each a `name`", data.name),
                ));
            }
            names.push(data.name.clone());
            experiments.push(data);
        }
        ParameterSpace::new(file.parameter.clone()).map_err(|e| CzError::config(&shown, e.to_string()))?;
        Ok(LoadedProblem { path: path.to_path_buf(), file, experiments, mesh_notes })
    }

    /// Leaves the named experiments out (their data and models), e.g. to calibrate on the others
    /// and predict these with [`crate::predict`]. Unknown names, or leaving nothing, are errors.
    pub fn leave_out(&mut self, names: &[String]) -> Result<()> {
        let shown = self.path.display().to_string();
        let have: Vec<String> = self.experiments.iter().map(|e| e.name.clone()).collect();
        if let Some(unknown) = names.iter().find(|n| !have.contains(n)) {
            return Err(CzError::config(
                format!("{shown}, --leave-out"),
                format!("no experiment is named `{unknown}`; the experiments are: {}", have.join(", ")),
            ));
        }
        if have.iter().all(|n| names.contains(n)) {
            return Err(CzError::config(format!("{shown}, --leave-out"), "every experiment would be left out"));
        }
        let keep: Vec<bool> = have.iter().map(|n| !names.contains(n)).collect();
        let mut flags = keep.iter();
        self.file.experiment.retain(|_| *flags.next().expect("one flag per experiment"));
        let mut flags = keep.iter();
        self.experiments.retain(|_| *flags.next().expect("one flag per experiment"));
        Ok(())
    }

    /// What reading the data left out, one line per experiment that lost rows (e.g.
    /// `dcb01: rows dropped: 12 whose displacement does not increase`), for the user to see.
    pub fn reading_notes(&self) -> Vec<String> {
        let dropped = self.experiments.iter().filter_map(|e| e.dropped.describe().map(|d| format!("{}: {d}", e.name)));
        dropped.chain(self.mesh_notes.iter().cloned()).collect()
    }

    /// The identification problem this file describes (weights set as the file asks).
    pub fn identification(&self) -> Result<Identification> {
        let shown = self.path.display().to_string();
        let setup = self.setup()?;
        let space = ParameterSpace::new(self.file.parameter.clone())?;
        if space.dim() == 0 {
            return Err(CzError::config(&shown, "no [[parameter]] to identify"));
        }
        let x0 = space.read(&setup).map_err(|e| CzError::config(&shown, e.to_string()))?;
        space.check_within(&x0).map_err(|e| CzError::config(&shown, e.to_string()))?;
        let mut id = Identification::new(setup, space, &self.experiments, self.file.objective.debonded_length)?;
        match &self.file.objective.weights {
            Weights::Named(n) if n == "balanced" => id.balance_weights()?,
            Weights::Named(n) if n == "noise" => id.noise_weights()?,
            Weights::Named(n) => {
                return Err(CzError::config(
                    format!("{shown}, [objective] weights"),
                    format!(
                        "`{n}` is not a weighting; use \"balanced\", \"noise\" or {{ load = .., debonded_length = .. }}"
                    ),
                ))
            }
            Weights::Explicit { load, debonded_length, events } => {
                id.set_weights(*load, *debonded_length)?;
                id.set_event_weight(*events)?;
            }
        }
        Ok(id)
    }

    /// The law and models with their initial values.
    pub fn setup(&self) -> Result<Setup> {
        // Trait objects are copied through serde; the file itself stays untouched.
        let law: Box<dyn CohesiveLaw> = duplicate(&self.file.law, "problem")?;
        let mut models = BTreeMap::new();
        for (entry, data) in self.file.experiment.iter().zip(&self.experiments) {
            models.insert(data.name.clone(), duplicate(&entry.model, "problem")?);
        }
        Ok(Setup { law, models })
    }
}

/// Where the value named by a serde "invalid type: string \"40\", expected f64" message sits in
/// the file: `key \`law.strength_n\`, line 7`, when one key holds that value.
fn wrong_type_key(text: &str, message: &str) -> Option<String> {
    let rest = message.strip_prefix("invalid type: ")?;
    let (found, _) = rest.split_once(", expected")?;
    let wanted: toml::Value = if let Some(q) = found.strip_prefix("string ") {
        toml::Value::String(q.trim_matches('"').to_string())
    } else if let Some(b) = found.strip_prefix("boolean `") {
        toml::Value::Boolean(b.trim_end_matches('`') == "true")
    } else {
        return None;
    };
    let doc: toml::Table = toml::from_str(text).ok()?;
    let mut hits = Vec::new();
    find_value(&toml::Value::Table(doc), &wanted, String::new(), &mut hits);
    let [key] = hits.as_slice() else { return None };
    let leaf = key.rsplit('.').next()?;
    let line = text.lines().position(|l| {
        let l = l.trim_start();
        l.starts_with(leaf) && l[leaf.len()..].trim_start().starts_with('=')
    });
    Some(match line {
        Some(n) => format!("key `{key}`, line {}", n + 1),
        None => format!("key `{key}`"),
    })
}

fn find_value(node: &toml::Value, wanted: &toml::Value, path: String, hits: &mut Vec<String>) {
    match node {
        toml::Value::Table(t) => {
            for (k, v) in t {
                let p = if path.is_empty() { k.clone() } else { format!("{path}.{k}") };
                find_value(v, wanted, p, hits);
            }
        }
        toml::Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                find_value(v, wanted, format!("{path}[{i}]"), hits);
            }
        }
        v if v == wanted => hits.push(path),
        _ => {}
    }
}

/// `text` (of the file `shown`) with the values of `overrides` replaced, as
/// [`LoadedProblem::read_with`] describes; the same for model files (`[law]` and one `[model]`).
pub fn with_overrides(text: &str, shown: &str, overrides: &[(String, String)]) -> Result<String> {
    let mut doc: toml::Table = toml::from_str(text).map_err(|e| CzError::config(shown, e.to_string().trim_end()))?;
    for (key, raw) in overrides {
        let value: toml::Value =
            toml::from_str::<toml::Table>(&format!("v = {raw}")).ok().and_then(|mut t| t.remove("v")).ok_or_else(
                || CzError::config(format!("--set {key}"), format!("`{raw}` is not a TOML value (quote strings)")),
            )?;
        set_path(&mut doc, key, value).map_err(|m| CzError::config(format!("--set {key}"), m))?;
    }
    toml::to_string(&doc).map_err(|e| CzError::config(shown, e.to_string()))
}

/// Sets `key` (a parameter-style path) in a problem-file document.
fn set_path(doc: &mut toml::Table, key: &str, value: toml::Value) -> std::result::Result<(), String> {
    let mut parts: Vec<&str> = key.split('.').collect();
    let mut node: &mut toml::Table = match parts.first().copied() {
        Some("law") | Some("objective") | Some("optimizer") => {
            let head = parts.remove(0);
            doc.get_mut(head).and_then(|v| v.as_table_mut()).ok_or(format!("the file has no [{head}] table"))?
        }
        Some("optimizers") => {
            parts.remove(0);
            doc.entry("optimizers")
                .or_insert_with(|| toml::Value::Table(Default::default()))
                .as_table_mut()
                .ok_or("`optimizers` is not a table of named optimizers".to_string())?
        }
        // A file for `czid simulate` with one top-level [model] and no experiments.
        Some("model") if parts.len() > 1 => {
            parts.remove(0);
            doc.get_mut("model").and_then(|v| v.as_table_mut()).ok_or(
                "the file has no top-level [model] table (the models of [[experiment]] tables are models.<experiment>.…)",
            )?
        }
        Some("models") if parts.len() > 2 => {
            let name = parts[1].to_string();
            parts.drain(..2);
            let why = if doc.contains_key("model") {
                "the file has no [[experiment]]: its one [model] is reached as model.…"
            } else {
                "the file has no [[experiment]]"
            };
            let experiments = doc.get_mut("experiment").and_then(|v| v.as_array_mut()).ok_or(why)?;
            let entry = experiments
                .iter_mut()
                .filter_map(|e| e.as_table_mut())
                .find(|e| {
                    let explicit = e.get("name").and_then(|n| n.as_str()).map(str::to_string);
                    let stem = e
                        .get("data")
                        .and_then(|d| d.get("file"))
                        .and_then(|f| f.as_str())
                        .and_then(|f| Path::new(f).file_stem().map(|s| s.to_string_lossy().into_owned()));
                    explicit.or(stem).as_deref() == Some(name.as_str())
                })
                .ok_or(format!("no experiment named `{name}`"))?;
            entry.get_mut("model").and_then(|v| v.as_table_mut()).ok_or("the experiment has no model table")?
        }
        _ => {
            return Err(
                "paths start with law., models.<experiment>., model. (a file with one top-level [model]), objective., optimizer. or optimizers.<label>.".into()
            )
        }
    };
    let last = parts.pop().ok_or("incomplete path")?;
    for p in parts {
        node = node
            .entry(p.to_string())
            .or_insert_with(|| toml::Value::Table(Default::default()))
            .as_table_mut()
            .ok_or(format!("`{p}` is not a table"))?;
    }
    node.insert(last.to_string(), value);
    Ok(())
}
