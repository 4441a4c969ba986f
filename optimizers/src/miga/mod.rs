//! Multi-island genetic algorithm (MIGA), after Isight's MIGA and the distributed GA of Miki
//! and Hiroyasu: the population is split into islands that evolve separately and exchange
//! individuals every few generations.
//!
//! Each generation, on every island: the `elite` best members survive unchanged; the rest of
//! the island is replaced by children of tournament-selected parents (tournament size
//! `relative_tournament_size × sub_population`), made by two-point crossover (with
//! probability `crossover_rate`) of binary chromosomes and bit mutation (each bit flips with
//! probability `mutation_rate`). Every `migration_interval` generations,
//! `migration_rate × sub_population` emigrants leave each island along the [`Topology`],
//! chosen by the [`EmigrantPolicy`] and placed by the [`ReplacementPolicy`].
//!
//! All random numbers come from one `ChaCha8Rng` on the calling thread; only the children's
//! evaluation runs in parallel, so results are identical for any number of threads.

mod island;
mod migration;
mod topology;

pub use island::Individual;
pub use migration::{EmigrantPolicy, ReplacementPolicy};
pub use topology::Topology;

use crate::encoding::{Codec, Encoding};
use crate::eval::{self, check, evaluate_batch, evaluate_batch_reusing, Known, Tracker, DEFAULT_FAILED_VALUE};
use czid_core::{Budget, CzError, Observer, OptimizationResult, Optimizer, Problem, Result, Snapshot};
use island::{breed, ranked, Operators};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// MIGA settings; the defaults are Isight's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MigaSettings {
    /// Number of islands (default 10).
    pub islands: usize,
    /// Individuals per island (default 10).
    pub sub_population: usize,
    /// Bits per gene (default 32, at most 52).
    pub bits_per_gene: u32,
    /// Binary (default) or Gray coding of genes.
    pub encoding: Encoding,
    /// Probability that a pair of parents is crossed (default 1.0).
    pub crossover_rate: f64,
    /// Probability that a bit flips (default 0.01).
    pub mutation_rate: f64,
    /// Fraction of an island that emigrates at each migration (default 0.5).
    pub migration_rate: f64,
    /// Generations between migrations (default 5).
    pub migration_interval: usize,
    /// Best members of an island kept unchanged each generation (default 1).
    pub elite: usize,
    /// Tournament size as a fraction of the sub-population (default 0.5).
    pub relative_tournament_size: f64,
    /// Where emigrants go (default ring).
    pub topology: Topology,
    /// Which members emigrate (default the best).
    pub emigrants: EmigrantPolicy,
    /// Whom immigrants replace (default the worst).
    pub replacement: ReplacementPolicy,
    /// Value given to failed evaluations (default 1e30, Isight's).
    pub failed_value: f64,
}

impl Default for MigaSettings {
    fn default() -> Self {
        MigaSettings {
            islands: 10,
            sub_population: 10,
            bits_per_gene: 32,
            encoding: Encoding::Binary,
            crossover_rate: 1.0,
            mutation_rate: 0.01,
            migration_rate: 0.5,
            migration_interval: 5,
            elite: 1,
            relative_tournament_size: 0.5,
            topology: Topology::Ring,
            emigrants: EmigrantPolicy::Best,
            replacement: ReplacementPolicy::Worst,
            failed_value: DEFAULT_FAILED_VALUE,
        }
    }
}

impl MigaSettings {
    /// Checks every setting; the error names the offending one.
    pub fn validate(&self) -> Result<()> {
        let o = "optimizer miga";
        check::at_least(o, "islands", self.islands, 1)?;
        check::at_least(o, "sub_population", self.sub_population, 2)?;
        if self.elite >= self.sub_population {
            return Err(CzError::invalid(o, "elite", self.elite as f64, "must be smaller than sub_population"));
        }
        check::unit(o, "crossover_rate", self.crossover_rate)?;
        check::unit(o, "mutation_rate", self.mutation_rate)?;
        check::unit(o, "migration_rate", self.migration_rate)?;
        check::at_least(o, "migration_interval", self.migration_interval, 1)?;
        if !(self.relative_tournament_size > 0.0 && self.relative_tournament_size <= 1.0) {
            return Err(CzError::invalid(
                o,
                "relative_tournament_size",
                self.relative_tournament_size,
                "must be in (0, 1]",
            ));
        }
        check::finite(o, "failed_value", self.failed_value)?;
        Codec::new(self.bits_per_gene, self.encoding, Vec::new()).map(|_| ())
    }

    /// Tournament size in individuals (at least 1).
    pub fn tournament_size(&self) -> usize {
        ((self.relative_tournament_size * self.sub_population as f64).round() as usize).max(1)
    }

    /// Emigrants per island and migration.
    pub fn migrants(&self) -> usize {
        (self.migration_rate * self.sub_population as f64).round() as usize
    }

    /// Evaluations of the initial population.
    pub fn initial_evaluations(&self) -> usize {
        self.islands * self.sub_population
    }

    /// Evaluations per generation after the first (elites are not re-evaluated).
    pub fn evaluations_per_generation(&self) -> usize {
        self.islands * (self.sub_population - self.elite)
    }
}

/// The multi-island GA (registry name `miga`); with one island, the single-population GA
/// (`ga`, see [`crate::ga`](mod@crate::ga)).
#[derive(Clone, Debug)]
pub struct Miga {
    name: &'static str,
    settings: MigaSettings,
}

/// Everything needed to continue a run exactly.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct MigaState {
    optimizer: String,
    dim: usize,
    generation: usize,
    rng: ChaCha8Rng,
    islands: Vec<Vec<Individual>>,
    tracker: Tracker,
}

impl Snapshot for MigaState {
    fn to_json(&self) -> Result<String> {
        eval::to_json(self)
    }
}

impl Miga {
    /// A MIGA with validated settings.
    pub fn new(settings: MigaSettings) -> Result<Self> {
        settings.validate()?;
        Ok(Miga { name: "miga", settings })
    }

    pub(crate) fn named(name: &'static str, settings: MigaSettings) -> Result<Self> {
        Ok(Miga { name, ..Miga::new(settings)? })
    }

    /// The settings.
    pub fn settings(&self) -> &MigaSettings {
        &self.settings
    }

    fn codec(&self, problem: &dyn Problem) -> Result<Codec> {
        Codec::new(self.settings.bits_per_gene, self.settings.encoding, eval::checked_bounds(problem)?)
    }

    fn run(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        codec: &Codec,
        mut state: MigaState,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        let s = &self.settings;
        let ops = Operators {
            bits: codec.bits(),
            len_bits: codec.len_bits(),
            crossover_rate: s.crossover_rate,
            mutation_rate: s.mutation_rate,
            elite: s.elite,
            tournament: s.tournament_size(),
        };
        let per_generation = s.evaluations_per_generation();
        let mut genes = Vec::with_capacity(per_generation);
        let mut xs: Vec<Vec<f64>> = Vec::with_capacity(per_generation);
        let mut order = Vec::with_capacity(s.sub_population);
        // The values of the population's members: late in a run about one child in ten is a copy
        // of one of them (a member crossed with itself, no bit mutated), and is not run again.
        let mut known = Known::new();
        while !state.tracker.target_reached(budget) && state.tracker.evaluations + per_generation <= budget.evaluations
        {
            genes.clear();
            for island in &state.islands {
                breed(island, &ops, &mut state.rng, &mut genes);
            }
            xs.resize_with(genes.len(), || vec![0.0; state.dim]);
            for (g, x) in genes.iter().zip(xs.iter_mut()) {
                codec.decode_into(g, x);
            }
            known.clear();
            known.extend(state.islands.iter().flatten().map(|m| (eval::key(&m.x), m.value)));
            let values = evaluate_batch_reusing(problem, &xs, s.failed_value, &mut state.tracker, &known);
            let mut children = genes.drain(..).zip(xs.iter()).zip(values);
            for island in state.islands.iter_mut() {
                ranked(island, &mut order);
                // Elites first (best first), then this island's children in breeding order.
                let mut next: Vec<Individual> = order[..s.elite].iter().map(|&i| island[i].clone()).collect();
                next.extend(children.by_ref().take(s.sub_population - s.elite).map(|((g, x), e)| Individual {
                    genes: g,
                    x: x.clone(),
                    value: e.value,
                }));
                *island = next;
            }
            state.generation += 1;
            if state.islands.len() > 1 && state.generation % s.migration_interval == 0 {
                migration::migrate(
                    &mut state.islands,
                    s.migrants(),
                    s.topology,
                    s.emigrants,
                    s.replacement,
                    &mut state.rng,
                );
            }
            if !eval::report(observer, state.generation, &state.tracker, Some(&state))? {
                break;
            }
        }
        Ok(state.tracker.result(state.dim, Vec::new()))
    }
}

impl Optimizer for Miga {
    fn name(&self) -> &str {
        self.name
    }

    fn check_budget(&self, budget: &Budget) -> Result<()> {
        let needed = self.settings.initial_evaluations();
        if budget.evaluations < needed {
            return Err(CzError::invalid(
                format!("optimizer {}", self.name),
                "budget.evaluations",
                budget.evaluations as f64,
                format!("the initial population alone needs {needed} evaluations"),
            ));
        }
        Ok(())
    }

    fn minimize(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        seed: u64,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        let s = &self.settings;
        let codec = self.codec(problem)?;
        self.check_budget(budget)?;
        let needed = s.initial_evaluations();
        let dim = problem.dim();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mask = codec.mask();
        let genes: Vec<Vec<u64>> =
            (0..needed).map(|_| (0..dim).map(|_| rng.random::<u64>() & mask).collect()).collect();
        let xs: Vec<Vec<f64>> = genes.iter().map(|g| codec.decode(g)).collect();
        let mut tracker = Tracker::default();
        let values = evaluate_batch(problem, &xs, s.failed_value, &mut tracker);
        let mut members =
            genes.into_iter().zip(xs).zip(values).map(|((genes, x), e)| Individual { genes, x, value: e.value });
        let islands = (0..s.islands).map(|_| members.by_ref().take(s.sub_population).collect()).collect();
        let state = MigaState { optimizer: self.name.to_string(), dim, generation: 0, rng, islands, tracker };
        if !eval::report(observer, 0, &state.tracker, Some(&state))? {
            return Ok(state.tracker.result(dim, Vec::new()));
        }
        self.run(problem, budget, &codec, state, observer)
    }

    fn resume(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        state: &str,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        let state: MigaState = eval::from_json(self.name, state)?;
        eval::check_state(self.name, &state.optimizer, state.dim, problem)?;
        let s = &self.settings;
        if state.islands.len() != s.islands || state.islands.iter().any(|i| i.len() != s.sub_population) {
            return Err(CzError::config(
                "checkpoint",
                format!("state's islands do not match settings ({} × {})", s.islands, s.sub_population),
            ));
        }
        let codec = self.codec(problem)?;
        let fits = |i: &Individual| i.genes.len() == state.dim && i.genes.iter().all(|&g| g & !codec.mask() == 0);
        if !state.islands.iter().flatten().all(fits) {
            return Err(CzError::config("checkpoint", "state's chromosomes do not match `bits_per_gene`"));
        }
        self.run(problem, budget, &codec, state, observer)
    }
}
