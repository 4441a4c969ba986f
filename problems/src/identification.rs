//! An identification problem: a shared cohesive law, one forward model per experiment, the
//! parameters to identify, and the composite objective, presented to optimizers as a
//! [`Problem`] on the unit cube.

use czid_core::objective::balanced_weights;
use czid_core::{
    columns, CohesiveLaw, ColumnResponse, CompositeObjective, Curve, CzError, Evaluation, ForwardModel, ObjectiveTerm,
    ParameterSpace, Problem, Record, Result,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;
use std::collections::{BTreeMap, BTreeSet, HashMap, VecDeque};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use crate::data::Experiment;

/// What is simulated: one law shared by every experiment's forward model.
///
/// Parameter paths point into this structure: `law.<field>` for the law, and
/// `models.<experiment>.<field>` for an experiment's model.
#[derive(Debug, Serialize, Deserialize)]
pub struct Setup {
    /// The cohesive law being identified.
    pub law: Box<dyn CohesiveLaw>,
    /// Forward model per experiment name.
    pub models: BTreeMap<String, Box<dyn ForwardModel>>,
}

impl Setup {
    /// Validates the law and every model.
    pub fn validate(&self) -> Result<()> {
        self.law.validate()?;
        self.models.values().try_for_each(|m| m.validate())
    }

    /// A deep copy (through serde, as laws and models are trait objects).
    pub fn duplicate(&self) -> Result<Setup> {
        czid_core::param::duplicate(self, "setup")
    }
}

/// Which responses an experiment contributes to the objective.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Term {
    /// Load against displacement (φ_F).
    #[serde(rename = "F")]
    Load,
    /// Debonded length against displacement (φ_L).
    #[serde(rename = "L")]
    DebondedLength,
    /// A measured event: one value of the run (φ_E, see [`crate::event`]).
    #[serde(rename = "E")]
    Event,
}

/// The objective term's name of event `event` of experiment `experiment`, e.g.
/// `E:beam:debonded_length_at_onset`.
pub fn event_term_name(experiment: &str, event: &str) -> String {
    format!("{}:{experiment}:{event}", Term::Event.symbol())
}

/// A term's root-mean-square error at the identified parameters ([`Identification::term_errors`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RmsError {
    /// Root-mean-square of test minus model over the test's readings.
    pub value: f64,
    /// Its unit (`N` or `mm`).
    pub unit: String,
    /// In % of the largest reading of the test's curve.
    pub percent_of_peak: f64,
}

impl Term {
    /// Short name used in reports: `F` or `L`, as in the paper.
    pub fn symbol(self) -> &'static str {
        match self {
            Term::Load => "F",
            Term::DebondedLength => "L",
            Term::Event => "E",
        }
    }

    /// What it is, in words.
    pub fn noun(self) -> &'static str {
        match self {
            Term::Load => "load",
            Term::DebondedLength => "debonded length",
            Term::Event => "event",
        }
    }

    /// Its unit (an event's is its own: N or mm).
    pub fn unit(self) -> &'static str {
        match self {
            Term::Load => "N",
            Term::DebondedLength => "mm",
            Term::Event => "N or mm",
        }
    }

    /// The record column a curve term is read from (against [`columns::DISPLACEMENT`]); events
    /// read their own (`None`).
    pub fn column(self) -> Option<&'static str> {
        match self {
            Term::Load => Some(columns::LOAD),
            Term::DebondedLength => Some(columns::DEBONDED_LENGTH),
            Term::Event => None,
        }
    }

    /// The simulated response a curve term is compared with: its column against the
    /// displacement (the same for identification and diagnosis); `None` for events (each has
    /// its own, [`crate::event::MeasuredEvent::response`]).
    pub fn response(self) -> Option<ColumnResponse> {
        self.column().map(|c| ColumnResponse::new(columns::DISPLACEMENT, c))
    }
}

impl std::fmt::Display for Term {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.symbol())
    }
}

/// One experiment's data and objective.
#[derive(Debug)]
struct Fit {
    name: String,
    objective: CompositeObjective,
    kinds: Vec<Term>,
    /// Factor on each term's weight (an event's `weight`; 1 for curves).
    factors: Vec<f64>,
    /// Each term's stated noise: a curve's `load_noise` or `length_noise`, an event's
    /// `uncertainty` (N or mm); `None` where none is given (a curve's is then estimated from its
    /// readings).
    uncertainties: Vec<Option<f64>>,
    /// Unit of each term.
    units: Vec<&'static str>,
}

/// The runs of a setup's experiments: a record per experiment (partial when a run stopped part
/// way) and the messages of the runs that stopped.
#[derive(Debug)]
pub struct Runs {
    /// Record per experiment.
    pub records: BTreeMap<String, Record>,
    /// Messages of runs that failed part way, `experiment: why`.
    pub failures: Vec<String>,
    /// The experiments whose run failed part way.
    pub failed: BTreeSet<String>,
}

/// Simulates the experiments `names` of `setup`, in parallel (each run is independent, so the
/// result does not depend on the number of threads). A run that fails part way is kept with its
/// converged steps (an objective then holds its last value), and its message is reported; a run
/// with fewer than two steps, or an experiment without a model, is an error. Identifications and
/// diagnoses both simulate through here.
pub fn simulate_experiments(setup: &Setup, names: &[&str]) -> Result<Runs> {
    let runs: Vec<Result<(Record, Option<String>)>> = names
        .par_iter()
        .map(|name| {
            let model = setup
                .models
                .get(*name)
                .ok_or_else(|| CzError::config(format!("experiment `{name}`"), "has no forward model in the setup"))?;
            match model.simulate(setup.law.as_ref()) {
                Ok(r) => Ok((r, None)),
                Err(f) if f.partial.rows() >= 2 => {
                    let message = format!("{name}: {f}");
                    Ok((f.partial, Some(message)))
                }
                Err(f) => Err(CzError::Simulation(format!("{name}: {f}"))),
            }
        })
        .collect();
    let mut out = Runs { records: BTreeMap::new(), failures: Vec::new(), failed: BTreeSet::new() };
    for (name, run) in names.iter().zip(runs) {
        let (record, failure) = run?;
        if failure.is_some() {
            out.failed.insert(name.to_string());
        }
        out.failures.extend(failure);
        out.records.insert(name.to_string(), record);
    }
    Ok(out)
}

/// The result of simulating one candidate.
#[derive(Debug)]
pub struct Outcome {
    /// Objective value and parts.
    pub evaluation: Evaluation,
    /// Simulation record per experiment (possibly partial when a run failed part way).
    pub records: BTreeMap<String, Record>,
    /// Messages of runs that failed part way.
    pub failures: Vec<String>,
    /// The experiments whose run failed part way (their records end where the run stopped).
    pub failed: BTreeSet<String>,
}

impl Outcome {
    /// The record `experiment` is scored on: its own, or for a run that failed part way the one
    /// [`scored_as_broken`] makes of it.
    pub fn scored(&self, experiment: &str) -> Cow<'_, Record> {
        let record = &self.records[experiment];
        if self.failed.contains(experiment) {
            Cow::Owned(scored_as_broken(record))
        } else {
            Cow::Borrowed(record)
        }
    }
}

/// How a run that failed part way is scored: as if the specimen had broken just beyond the last
/// state the run reached (every column but the displacement drops to zero there), so that each
/// reading it did not reach costs its full value. Holding the last state instead, as a run that
/// simply ends before the data does is scored, made a failing run cheaper than a complete one
/// wherever the test's load stays near the last value reached (an ENF after its unstable jump):
/// an optimizer then goes where runs fail. A record without a displacement column is returned
/// as it is.
///
/// ```
/// use czid_core::{columns, Record};
/// use czid_problems::identification::scored_as_broken;
///
/// let mut run = Record::new(&[(columns::DISPLACEMENT, "mm"), (columns::LOAD, "N")]);
/// run.push(&[0.0, 0.0]);
/// run.push(&[1.0, 50.0]); // the run failed here
/// let scored = scored_as_broken(&run);
/// let load = scored.curve(columns::DISPLACEMENT, columns::LOAD).unwrap();
/// // Readings before the failure are interpolated as before; beyond it the run predicts nothing.
/// assert_eq!(load.sample(&[0.5, 2.0]), vec![25.0, 0.0]);
/// ```
pub fn scored_as_broken(record: &Record) -> Record {
    let mut out = record.clone();
    let Ok(x) = record.column(columns::DISPLACEMENT) else { return out };
    let Some(&last) = x.last() else { return out };
    let beyond = last + (1e-9 * last.abs()).max(1e-12);
    let row: Vec<f64> =
        record.columns().iter().map(|c| if c.name == columns::DISPLACEMENT { beyond } else { 0.0 }).collect();
    out.push(&row);
    out
}

/// An identification problem over the unit cube.
#[derive(Debug)]
pub struct Identification {
    setup: Setup,
    space: ParameterSpace,
    fits: Vec<Fit>,
    /// Evaluations of recent candidates by what their runs took from them.
    answered: Mutex<Answered>,
    /// Evaluations answered so from another candidate's.
    shared: AtomicUsize,
}

/// Memory the evaluations kept for reuse may take (bytes): on the paper's DCB about 1,000 of
/// them, which hold nearly all the candidates a genetic algorithm makes again (most within the
/// last hundred evaluations).
const ANSWERED_BYTES: usize = 16 << 20;

/// Recent evaluations by the key of what their runs took from the candidate
/// ([`Identification::key`]), the oldest forgotten first.
#[derive(Debug, Default)]
struct Answered {
    by_key: HashMap<Vec<u64>, Evaluation>,
    order: VecDeque<Vec<u64>>,
    bytes: usize,
}

impl Answered {
    fn size(key: &[u64], e: &Evaluation) -> usize {
        8 * (2 * key.len() + e.objectives.len() + e.residuals.len() + 1)
    }

    fn insert(&mut self, key: Vec<u64>, e: Evaluation) {
        let size = Answered::size(&key, &e);
        if size > ANSWERED_BYTES || self.by_key.contains_key(&key) {
            return;
        }
        while self.bytes + size > ANSWERED_BYTES {
            let Some(old) = self.order.pop_front() else { break };
            if let Some(gone) = self.by_key.remove(&old) {
                self.bytes -= Answered::size(&old, &gone);
            }
        }
        self.bytes += size;
        self.order.push_back(key.clone());
        self.by_key.insert(key, e);
    }

    fn clear(&mut self) {
        *self = Answered::default();
    }
}

impl Identification {
    /// Builds the problem. Each experiment compares its load curve and, when it has one and
    /// `use_debonded_length` is set, its debonded-length curve; weights start at 1.
    pub fn new(
        setup: Setup,
        space: ParameterSpace,
        experiments: &[Experiment],
        use_debonded_length: bool,
    ) -> Result<Self> {
        setup.validate()?;
        let mut fits = Vec::new();
        for e in experiments {
            if !setup.models.contains_key(&e.name) {
                return Err(CzError::config(
                    format!("experiment `{}`", e.name),
                    "has no forward model (each experiment needs a `model` table)",
                ));
            }
            let curve = |t: Term| Box::new(t.response().expect("a curve term"));
            // The load, or the mid-span moment (the paper's moment–deflection curve of a beam).
            let mut terms = vec![ObjectiveTerm {
                name: format!("F:{}", e.name),
                response: Box::new(ColumnResponse::new(columns::DISPLACEMENT, e.ordinate.column())),
                data: e.load.clone(),
                weight: 1.0,
            }];
            let mut kinds = vec![Term::Load];
            let mut units = vec![e.ordinate.unit()];
            if let (true, Some(l)) = (use_debonded_length, &e.debonded_length) {
                if l.norm() > 0.0 {
                    terms.push(ObjectiveTerm {
                        name: format!("L:{}", e.name),
                        response: curve(Term::DebondedLength),
                        data: l.clone(),
                        weight: 1.0,
                    });
                    kinds.push(Term::DebondedLength);
                    units.push(Term::DebondedLength.unit());
                }
            }
            let mut factors = vec![1.0; terms.len()];
            let mut uncertainties: Vec<Option<f64>> =
                kinds.iter().map(|k| if *k == Term::Load { e.noise.load } else { e.noise.debonded_length }).collect();
            for ev in &e.events {
                // One reading; its abscissa is not used by an event response.
                terms.push(ObjectiveTerm {
                    name: event_term_name(&e.name, &ev.name),
                    response: ev.response.boxed(),
                    data: Curve::new(vec![0.0], vec![ev.value])?,
                    weight: ev.weight,
                });
                kinds.push(Term::Event);
                factors.push(ev.weight);
                uncertainties.push(ev.uncertainty);
                units.push(ev.unit());
            }
            let objective = CompositeObjective::new(terms)?;
            fits.push(Fit { name: e.name.clone(), objective, kinds, factors, uncertainties, units });
        }
        // Fail early, with the path named, if a parameter does not exist in the setup.
        space.read(&setup)?;
        Ok(Identification { setup, space, fits, answered: Mutex::default(), shared: AtomicUsize::new(0) })
    }

    /// The parameter space.
    pub fn space(&self) -> &ParameterSpace {
        &self.space
    }

    /// The base setup (initial values).
    pub fn setup(&self) -> &Setup {
        &self.setup
    }

    /// Initial values of the parameters, read from the setup.
    pub fn initial(&self) -> Result<Vec<f64>> {
        self.space.read(&self.setup)
    }

    /// Term kinds present, in the order [`Evaluation::objectives`] reports them.
    pub fn term_kinds(&self) -> Vec<Term> {
        let mut kinds = vec![Term::Load];
        for k in [Term::DebondedLength, Term::Event] {
            if self.fits.iter().any(|f| f.kinds.contains(&k)) {
                kinds.push(k);
            }
        }
        kinds
    }

    /// Sets the weights so that, at the initial values, every term of every experiment contributes
    /// equally and the objective is 1 (the paper's choice of α); an event's term then has its
    /// `weight` times that.
    pub fn balance_weights(&mut self) -> Result<()> {
        self.forget_answers();
        let x0 = self.initial()?;
        let outcome = self.simulate(&x0)?;
        let parts: Vec<Vec<f64>> = self
            .fits
            .iter()
            .map(|fit| Ok(fit.objective.evaluate(&outcome.scored(&fit.name))?.terms))
            .collect::<Result<_>>()?;
        // One balance over every experiment's terms side by side.
        let all: Vec<f64> = parts.iter().flatten().copied().collect();
        let mut weights = balanced_weights(&all).into_iter();
        for (fit, parts) in self.fits.iter_mut().zip(parts) {
            let w: Vec<f64> = weights.by_ref().take(parts.len()).zip(&fit.factors).map(|(w, f)| w * f).collect();
            fit.objective.set_weights(&w)?;
        }
        Ok(())
    }

    /// Weights every term by its data's noise, so that the objective is χ², the sum of the squared
    /// residuals in units of the noise: `α_i = ||y_i||² / σ_i²` (the term is `||y − ŷ||² / ||y||²`),
    /// with `σ_i` a curve's stated `load_noise` or `length_noise` (estimated from its own readings
    /// where not given, [`czid_core::noise::estimate`]) and an event's stated `uncertainty` (times
    /// the event's own `weight`). Unlike weights balanced at the initial guess, these do not depend
    /// on the guess, and they let a precise test (a pull test's load cell) count for what it is
    /// worth beside a coarse one (debonded lengths read with a ruler). An event without an
    /// `uncertainty` is an error.
    pub fn noise_weights(&mut self) -> Result<()> {
        self.forget_answers();
        for fit in &mut self.fits {
            let mut w = Vec::with_capacity(fit.kinds.len());
            for (((term, kind), factor), u) in
                fit.objective.terms().iter().zip(&fit.kinds).zip(&fit.factors).zip(&fit.uncertainties)
            {
                let sigma = match (kind, u) {
                    (_, Some(u)) => *u,
                    (Term::Event, None) => return Err(CzError::config(
                        format!("[objective] weights = \"noise\", event `{}`", term.name),
                        "has no `uncertainty`: give the reading's standard uncertainty (N or mm), or use \"balanced\"",
                    )),
                    (k, _) => czid_core::noise::estimate(term.data.x(), term.data.y(), *k == Term::DebondedLength),
                };
                let norm = term.data.norm();
                if !(sigma > 0.0 && sigma.is_finite()) {
                    return Err(CzError::config(
                        format!("[objective] weights = \"noise\", `{}`", term.name),
                        format!("its noise ({sigma:e}) is not a positive number: use \"balanced\" or explicit weights"),
                    ));
                }
                w.push(factor * (norm / sigma).powi(2));
            }
            fit.objective.set_weights(&w)?;
        }
        Ok(())
    }

    /// Sets α_E of every event term (times the event's own `weight`); the curve terms keep theirs.
    pub fn set_event_weight(&mut self, alpha_e: f64) -> Result<()> {
        self.forget_answers();
        for fit in &mut self.fits {
            let mut w = fit.objective.weights();
            for ((w, k), f) in w.iter_mut().zip(&fit.kinds).zip(&fit.factors) {
                if *k == Term::Event {
                    *w = alpha_e * f;
                }
            }
            fit.objective.set_weights(&w)?;
        }
        if self.weights().iter().all(|(_, w)| *w == 0.0) {
            return Err(CzError::config("[objective] weights", "every compared response has weight 0"));
        }
        Ok(())
    }

    /// Sets the weights of the load and debonded-length terms (α_F, α_L) for every experiment.
    pub fn set_weights(&mut self, alpha_f: f64, alpha_l: f64) -> Result<()> {
        self.forget_answers();
        for fit in &mut self.fits {
            let w: Vec<f64> = fit
                .kinds
                .iter()
                .zip(&fit.factors)
                .map(|(k, f)| match k {
                    Term::Load => alpha_f,
                    Term::DebondedLength => alpha_l,
                    Term::Event => *f,
                })
                .collect();
            fit.objective.set_weights(&w)?;
        }
        // With every weight zero the objective is 0 everywhere and any parameters "fit".
        if self.weights().iter().all(|(_, w)| *w == 0.0) {
            return Err(CzError::config(
                "[objective] weights",
                format!(
                    "every compared response has weight 0 (load = {alpha_f}, debonded_length = {alpha_l}), so the \
                     objective is 0 whatever the parameters; give the load a positive weight"
                ),
            ));
        }
        Ok(())
    }

    /// Current weights per experiment and term, e.g. `("F:dcb", 0.8)`.
    pub fn weights(&self) -> Vec<(String, f64)> {
        self.fits.iter().flat_map(|f| f.objective.terms().iter().map(|t| (t.name.clone(), t.weight))).collect()
    }

    /// The setup with physical parameter values `x` written in.
    pub fn configure(&self, x: &[f64]) -> Result<Setup> {
        let setup: Setup = self.space.apply(&self.setup, x)?;
        setup.validate()?;
        Ok(setup)
    }

    /// Simulates every experiment at physical values `x` and evaluates the objective.
    ///
    /// A run that fails part way is scored on its converged steps and, beyond them, as a broken
    /// specimen ([`scored_as_broken`]), so the optimizer sees a large but finite value; a run with
    /// fewer than two steps is an error.
    pub fn simulate(&self, x: &[f64]) -> Result<Outcome> {
        self.simulate_setup(&self.configure(x)?)
    }

    /// [`Identification::simulate`] of a configured setup.
    fn simulate_setup(&self, setup: &Setup) -> Result<Outcome> {
        let kinds = self.term_kinds();
        let names: Vec<&str> = self.fits.iter().map(|f| f.name.as_str()).collect();
        let Runs { records, failures, failed } = simulate_experiments(setup, &names)?;
        let mut outcome = Outcome {
            evaluation: Evaluation { value: 0.0, objectives: Vec::new(), residuals: Vec::new() },
            records,
            failures,
            failed,
        };
        let mut objectives = vec![0.0; kinds.len()];
        let mut residuals = Vec::new();
        let mut value = 0.0;
        for fit in &self.fits {
            let record = outcome.scored(&fit.name);
            let v = fit.objective.evaluate(&record)?;
            for ((kind, part), term) in fit.kinds.iter().zip(&v.terms).zip(fit.objective.terms()) {
                let slot = kinds.iter().position(|k| k == kind).expect("kinds cover every term");
                objectives[slot] += term.weight * part;
            }
            value += v.value;
            residuals.extend(fit.objective.residuals(&record)?);
        }
        outcome.evaluation = Evaluation { value, objectives, residuals };
        Ok(outcome)
    }

    /// How many evaluations were answered from another candidate's, whose runs take the same from
    /// it ([`ForwardModel::law_key`]), instead of running the forward models.
    pub fn shared_evaluations(&self) -> usize {
        self.shared.load(Ordering::Relaxed)
    }

    /// Forgets the evaluations kept for reuse: made with the old weights, they are no longer this
    /// problem's.
    fn forget_answers(&mut self) {
        self.answered.get_mut().unwrap_or_else(|e| e.into_inner()).clear();
    }

    /// The setup at unit-cube point `u` and its [`Identification::key`].
    fn prepare(&self, u: &[f64]) -> Result<(Setup, Option<Vec<u64>>)> {
        let x = self.space.from_unit(u);
        let setup = self.configure(&x)?;
        let key = self.key(&setup, &x);
        Ok((setup, key))
    }

    /// The evaluation of `setup`: kept from a candidate with the same `key`, or run (the time
    /// the runs take added to `nanos`, ns) and kept.
    fn answer(&self, setup: &Setup, key: Option<Vec<u64>>, nanos: &AtomicU64) -> Result<Evaluation> {
        let answered = || self.answered.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(e) = key.as_ref().and_then(|k| answered().by_key.get(k).cloned()) {
            self.shared.fetch_add(1, Ordering::Relaxed);
            return Ok(e);
        }
        let t = Instant::now();
        let e = self.simulate_setup(setup).map(|o| o.evaluation);
        nanos.fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
        if let (Some(k), Ok(e)) = (key, &e) {
            answered().insert(k, e.clone());
        }
        e
    }

    /// [`Problem::evaluate_batch`], with the time its runs take added to `nanos` (ns). Candidates
    /// with equal keys are run once, by the first of them.
    pub(crate) fn evaluate_batch_timed(&self, us: &[Vec<f64>], nanos: &AtomicU64) -> Vec<Result<Evaluation>> {
        let prepared: Vec<Result<(Setup, Option<Vec<u64>>)>> = us.par_iter().map(|u| self.prepare(u)).collect();
        let source: Vec<Option<usize>> = {
            let mut first: HashMap<&[u64], usize> = HashMap::new();
            prepared
                .iter()
                .enumerate()
                .map(|(k, p)| match p {
                    Ok((_, Some(key))) => Some(*first.entry(key.as_slice()).or_insert(k)).filter(|&f| f != k),
                    _ => None,
                })
                .collect()
        };
        let mut out: Vec<Option<Result<Evaluation>>> = prepared
            .into_par_iter()
            .zip(&source)
            .map(|(p, from)| from.is_none().then(|| p.and_then(|(setup, key)| self.answer(&setup, key, nanos))))
            .collect();
        for (k, from) in source.iter().enumerate() {
            if let Some(f) = *from {
                self.shared.fetch_add(1, Ordering::Relaxed);
                out[k] = out[f].clone();
            }
        }
        out.into_iter().map(|e| e.expect("every candidate answered")).collect()
    }

    /// What the runs of `setup` (configured at `x`) take from the candidate, where every
    /// experiment's model can say ([`ForwardModel::law_key`]): the models' keys of the law, then
    /// the values of the parameters outside the law. `None` where a model cannot say.
    fn key(&self, setup: &Setup, x: &[f64]) -> Option<Vec<u64>> {
        let mut key = Vec::new();
        for fit in &self.fits {
            let k = setup.models.get(&fit.name)?.law_key(setup.law.as_ref())?;
            key.push(k.len() as u64);
            key.extend(k);
        }
        for (p, v) in self.space.parameters().iter().zip(x) {
            if !p.path.starts_with("law.") {
                key.push(v.to_bits());
            }
        }
        Some(key)
    }

    /// Unweighted `||φ||²` per experiment and term, e.g. `("F:dcb", 1.2e-4)`.
    pub fn term_values(&self, outcome: &Outcome) -> Result<Vec<(String, f64)>> {
        let mut out = Vec::new();
        for fit in &self.fits {
            let v = fit.objective.evaluate(&outcome.scored(&fit.name))?;
            out.extend(fit.objective.terms().iter().zip(v.terms).map(|(t, s)| (t.name.clone(), s)));
        }
        Ok(out)
    }

    /// Root-mean-square error of each experiment's terms in the data's own unit (N for the load,
    /// mm for the debonded length) and in % of the data's peak: the misfit as a test engineer
    /// reads it. From `||φ||² = Σ(y − ŷ)² / Σy²`, `rms = √(||φ||² Σy² / n)`.
    pub fn term_errors(&self, outcome: &Outcome) -> Result<Vec<(String, RmsError)>> {
        let mut out = Vec::new();
        for fit in &self.fits {
            let v = fit.objective.evaluate(&outcome.scored(&fit.name))?;
            for ((term, unit), misfit) in fit.objective.terms().iter().zip(&fit.units).zip(v.terms) {
                let y = term.data.y();
                let mean_square = y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64;
                let peak = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let value = (misfit * mean_square).sqrt();
                let percent_of_peak = if peak > 0.0 { 100.0 * value / peak } else { f64::NAN };
                out.push((term.name.clone(), RmsError { value, unit: unit.to_string(), percent_of_peak }));
            }
        }
        Ok(out)
    }
}

impl Problem for Identification {
    fn dim(&self) -> usize {
        self.space.dim()
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(0.0, 1.0); self.space.dim()]
    }

    /// A candidate whose runs take from it what an earlier one's took (every experiment's
    /// [`ForwardModel::law_key`], the parameters outside the law) gets that one's evaluation: the
    /// runs would give the same records to the bit.
    fn evaluate(&self, u: &[f64]) -> Result<Evaluation> {
        let (setup, key) = self.prepare(u)?;
        self.answer(&setup, key, &AtomicU64::new(0))
    }

    /// [`Identification::evaluate`] for a batch, where a candidate with the key of an earlier
    /// one in the batch takes that one's evaluation too.
    fn evaluate_batch(&self, us: &[Vec<f64>]) -> Vec<Result<Evaluation>> {
        self.evaluate_batch_timed(us, &AtomicU64::new(0))
    }

    fn objectives(&self) -> usize {
        self.term_kinds().len()
    }
}
