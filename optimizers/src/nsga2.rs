//! NSGA-II (Deb, Pratap, Agarwal & Meyarivan 2002), real coded as in the authors' reference
//! code: binary tournament by crowded comparison, simulated binary crossover (SBX) and
//! polynomial mutation with the bounded variants, fast non-dominated sorting, crowding
//! distance, and (μ + λ) elitist survival.
//!
//! It minimises [`Evaluation::objectives`] (or `[value]` for single-objective problems),
//! returns the final non-dominated set in [`OptimizationResult::pareto`] and, as `best`, the
//! evaluated point with the lowest composite `value` (for a positively weighted composite
//! this point is non-dominated among everything evaluated).

use crate::eval::{self, check, evaluate_batch, Tracker, DEFAULT_FAILED_VALUE};
use czid_core::{Budget, CzError, Evaluation, Observer, OptimizationResult, Optimizer, Problem, Result, Snapshot};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// NSGA-II settings; defaults are Deb et al.'s.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Nsga2Settings {
    /// Population size, a multiple of 4 (default 100).
    pub population: usize,
    /// Probability that a pair of parents is crossed (default 0.9).
    pub crossover_probability: f64,
    /// SBX distribution index η_c (default 20).
    pub crossover_eta: f64,
    /// Probability that a variable is mutated (default `1/n`, written as absent).
    pub mutation_probability: Option<f64>,
    /// Polynomial mutation distribution index η_m (default 20).
    pub mutation_eta: f64,
    /// Value given to every objective of a failed evaluation (default 1e30).
    pub failed_value: f64,
}

impl Default for Nsga2Settings {
    fn default() -> Self {
        Nsga2Settings {
            population: 100,
            crossover_probability: 0.9,
            crossover_eta: 20.0,
            mutation_probability: None,
            mutation_eta: 20.0,
            failed_value: DEFAULT_FAILED_VALUE,
        }
    }
}

impl Nsga2Settings {
    /// Checks every setting; the error names the offending one.
    pub fn validate(&self) -> Result<()> {
        let o = "optimizer nsga2";
        if self.population < 4 || self.population % 4 != 0 {
            return Err(CzError::invalid(o, "population", self.population as f64, "must be a positive multiple of 4"));
        }
        check::unit(o, "crossover_probability", self.crossover_probability)?;
        check::positive(o, "crossover_eta", self.crossover_eta)?;
        if let Some(p) = self.mutation_probability {
            check::unit(o, "mutation_probability", p)?;
        }
        check::positive(o, "mutation_eta", self.mutation_eta)?;
        check::finite(o, "failed_value", self.failed_value)
    }
}

/// NSGA-II (registry name `nsga2`).
#[derive(Clone, Debug)]
pub struct Nsga2 {
    settings: Nsga2Settings,
}

/// A population member.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Member {
    x: Vec<f64>,
    f: Vec<f64>,
    value: f64,
    rank: usize,
    crowding: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
struct Nsga2State {
    optimizer: String,
    dim: usize,
    generation: usize,
    rng: ChaCha8Rng,
    population: Vec<Member>,
    tracker: Tracker,
}

impl Snapshot for Nsga2State {
    fn to_json(&self) -> Result<String> {
        // Infinite crowding distances (front extremes) are not JSON numbers; distances are
        // never negative, so −1 stands for +∞ in the file.
        let mut copy = self.clone();
        copy.population.iter_mut().filter(|m| m.crowding.is_infinite()).for_each(|m| m.crowding = -1.0);
        eval::to_json(&copy)
    }
}

impl Nsga2 {
    /// NSGA-II with validated settings.
    pub fn new(settings: Nsga2Settings) -> Result<Self> {
        settings.validate()?;
        Ok(Nsga2 { settings })
    }

    fn members(&self, xs: Vec<Vec<f64>>, evals: Vec<Evaluation>) -> Vec<Member> {
        xs.into_iter()
            .zip(evals)
            .map(|(x, e)| {
                let f = if e.objectives.is_empty() { vec![e.value] } else { e.objectives };
                Member { x, f, value: e.value, rank: 0, crowding: 0.0 }
            })
            .collect()
    }

    fn run(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        bounds: &[(f64, f64)],
        mut state: Nsga2State,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        let s = &self.settings;
        let n = s.population;
        let pm = s.mutation_probability.unwrap_or(1.0 / state.dim as f64);
        let mut perm: Vec<usize> = (0..n).collect();
        while !state.tracker.target_reached(budget) && state.tracker.evaluations + n <= budget.evaluations {
            // Selection and variation, as in Deb's code: two shuffles, each individual takes part in
            // two tournaments per shuffle; each four tournament winners give four children.
            let mut children: Vec<Vec<f64>> = Vec::with_capacity(n);
            for _ in 0..2 {
                // From the identity each time (as Deb's code), so the state is only the rng.
                perm.iter_mut().enumerate().for_each(|(i, p)| *p = i);
                perm.shuffle(&mut state.rng);
                for q in perm.chunks_exact(4) {
                    let p1 = tournament(&state.population, q[0], q[1], &mut state.rng);
                    let p2 = tournament(&state.population, q[2], q[3], &mut state.rng);
                    let (mut c1, mut c2) = (state.population[p1].x.clone(), state.population[p2].x.clone());
                    sbx(&mut c1, &mut c2, bounds, s.crossover_probability, s.crossover_eta, &mut state.rng);
                    polynomial_mutation(&mut c1, bounds, pm, s.mutation_eta, &mut state.rng);
                    polynomial_mutation(&mut c2, bounds, pm, s.mutation_eta, &mut state.rng);
                    children.push(c1);
                    children.push(c2);
                }
            }
            let evals = evaluate_batch(problem, &children, s.failed_value, &mut state.tracker);
            let mut combined = std::mem::take(&mut state.population);
            combined.extend(self.members(children, evals));
            state.population = survive(combined, n);
            state.generation += 1;
            if !eval::report(observer, state.generation, &state.tracker, Some(&state))? {
                break;
            }
        }
        let pareto = state
            .population
            .iter()
            .filter(|m| m.rank == 0)
            .map(|m| {
                let objectives = if problem.objectives() > 1 { m.f.clone() } else { Vec::new() };
                (m.x.clone(), Evaluation { value: m.value, objectives, residuals: Vec::new() })
            })
            .collect();
        Ok(state.tracker.result(state.dim, pareto))
    }
}

impl Optimizer for Nsga2 {
    fn name(&self) -> &str {
        "nsga2"
    }

    fn check_budget(&self, budget: &Budget) -> Result<()> {
        let n = self.settings.population;
        if budget.evaluations < n {
            return Err(CzError::invalid(
                "optimizer nsga2",
                "budget.evaluations",
                budget.evaluations as f64,
                format!("the initial population alone needs {n} evaluations"),
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
        let n = self.settings.population;
        let bounds = eval::checked_bounds(problem)?;
        self.check_budget(budget)?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let xs: Vec<Vec<f64>> =
            (0..n).map(|_| bounds.iter().map(|&(lo, hi)| lo + (hi - lo) * rng.random::<f64>()).collect()).collect();
        let mut tracker = Tracker::default();
        let evals = evaluate_batch(problem, &xs, self.settings.failed_value, &mut tracker);
        let population = survive(self.members(xs, evals), n);
        let state =
            Nsga2State { optimizer: "nsga2".into(), dim: problem.dim(), generation: 0, rng, population, tracker };
        if !eval::report(observer, 0, &state.tracker, Some(&state))? {
            return self.run(problem, &Budget::evaluations(0), &bounds, state, observer);
        }
        self.run(problem, budget, &bounds, state, observer)
    }

    fn resume(
        &self,
        problem: &dyn Problem,
        budget: &Budget,
        state: &str,
        observer: &mut dyn Observer,
    ) -> Result<OptimizationResult> {
        let mut state: Nsga2State = eval::from_json("nsga2", state)?;
        eval::check_state("nsga2", &state.optimizer, state.dim, problem)?;
        if state.population.len() != self.settings.population {
            return Err(CzError::config("checkpoint", "state's population size does not match settings"));
        }
        let bounds = eval::checked_bounds(problem)?;
        state.population.iter_mut().filter(|m| m.crowding < 0.0).for_each(|m| m.crowding = f64::INFINITY);
        self.run(problem, budget, &bounds, state, observer)
    }
}

/// Crowded-comparison binary tournament: lower rank wins, then larger crowding distance, then
/// a fair coin (as in Deb's code).
fn tournament(pop: &[Member], a: usize, b: usize, rng: &mut ChaCha8Rng) -> usize {
    let (ma, mb) = (&pop[a], &pop[b]);
    if ma.rank != mb.rank {
        return if ma.rank < mb.rank { a } else { b };
    }
    if ma.crowding != mb.crowding {
        return if ma.crowding > mb.crowding { a } else { b };
    }
    if rng.random::<f64>() <= 0.5 {
        a
    } else {
        b
    }
}

/// Simulated binary crossover with the bounded spread of Deb's reference code.
fn sbx(c1: &mut [f64], c2: &mut [f64], bounds: &[(f64, f64)], p: f64, eta: f64, rng: &mut ChaCha8Rng) {
    if rng.random::<f64>() > p {
        return;
    }
    for i in 0..c1.len() {
        if rng.random::<f64>() > 0.5 {
            continue;
        }
        let (x1, x2) = (c1[i], c2[i]);
        if (x1 - x2).abs() <= 1e-14 {
            continue;
        }
        let (y1, y2) = if x1 < x2 { (x1, x2) } else { (x2, x1) };
        let (yl, yu) = bounds[i];
        let u = rng.random::<f64>();
        let betaq = |beta: f64| {
            let alpha = 2.0 - beta.powf(-(eta + 1.0));
            if u <= 1.0 / alpha {
                (u * alpha).powf(1.0 / (eta + 1.0))
            } else {
                (1.0 / (2.0 - u * alpha)).powf(1.0 / (eta + 1.0))
            }
        };
        let b1 = betaq(1.0 + 2.0 * (y1 - yl) / (y2 - y1));
        let b2 = betaq(1.0 + 2.0 * (yu - y2) / (y2 - y1));
        let n1 = (0.5 * ((y1 + y2) - b1 * (y2 - y1))).clamp(yl, yu);
        let n2 = (0.5 * ((y1 + y2) + b2 * (y2 - y1))).clamp(yl, yu);
        if rng.random::<f64>() <= 0.5 {
            c1[i] = n2;
            c2[i] = n1;
        } else {
            c1[i] = n1;
            c2[i] = n2;
        }
    }
}

/// Polynomial mutation, bounded variant of Deb's reference code.
fn polynomial_mutation(x: &mut [f64], bounds: &[(f64, f64)], p: f64, eta: f64, rng: &mut ChaCha8Rng) {
    for (xi, &(yl, yu)) in x.iter_mut().zip(bounds) {
        if rng.random::<f64>() > p || yu <= yl {
            continue;
        }
        let y = *xi;
        let d1 = (y - yl) / (yu - yl);
        let d2 = (yu - y) / (yu - yl);
        let r = rng.random::<f64>();
        let pow = 1.0 / (eta + 1.0);
        let dq = if r <= 0.5 {
            let v = 2.0 * r + (1.0 - 2.0 * r) * (1.0 - d1).powf(eta + 1.0);
            v.powf(pow) - 1.0
        } else {
            let v = 2.0 * (1.0 - r) + 2.0 * (r - 0.5) * (1.0 - d2).powf(eta + 1.0);
            1.0 - v.powf(pow)
        };
        *xi = (y + dq * (yu - yl)).clamp(yl, yu);
    }
}

fn dominates(a: &[f64], b: &[f64]) -> bool {
    let mut strictly = false;
    for (x, y) in a.iter().zip(b) {
        if x > y {
            return false;
        }
        strictly |= x < y;
    }
    strictly
}

/// Fast non-dominated sorting: the fronts as index lists, best first.
fn fronts(pop: &[Member]) -> Vec<Vec<usize>> {
    let n = pop.len();
    let mut dominated_by_me: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut count = vec![0usize; n];
    for p in 0..n {
        for q in p + 1..n {
            if dominates(&pop[p].f, &pop[q].f) {
                dominated_by_me[p].push(q);
                count[q] += 1;
            } else if dominates(&pop[q].f, &pop[p].f) {
                dominated_by_me[q].push(p);
                count[p] += 1;
            }
        }
    }
    let mut fronts = Vec::new();
    let mut current: Vec<usize> = (0..n).filter(|&p| count[p] == 0).collect();
    while !current.is_empty() {
        let mut next = Vec::new();
        for &p in &current {
            for &q in &dominated_by_me[p] {
                count[q] -= 1;
                if count[q] == 0 {
                    next.push(q);
                }
            }
        }
        next.sort_unstable();
        fronts.push(std::mem::replace(&mut current, next));
    }
    fronts
}

/// Crowding distances of the members `front` of `pop`.
fn crowding(pop: &mut [Member], front: &[usize]) {
    for &i in front {
        pop[i].crowding = 0.0;
    }
    if front.len() <= 2 {
        front.iter().for_each(|&i| pop[i].crowding = f64::INFINITY);
        return;
    }
    let m = pop[front[0]].f.len();
    let mut order = front.to_vec();
    for k in 0..m {
        order.sort_by(|&a, &b| pop[a].f[k].total_cmp(&pop[b].f[k]));
        let (lo, hi) = (pop[order[0]].f[k], pop[order[order.len() - 1]].f[k]);
        pop[order[0]].crowding = f64::INFINITY;
        pop[order[order.len() - 1]].crowding = f64::INFINITY;
        let range = hi - lo;
        if !(range > 0.0 && range.is_finite()) {
            continue;
        }
        for w in 1..order.len() - 1 {
            let d = (pop[order[w + 1]].f[k] - pop[order[w - 1]].f[k]) / range;
            pop[order[w]].crowding += d;
        }
    }
}

/// (μ + λ) survival: whole fronts while they fit, then the least crowded of the next front.
/// Ranks and crowding distances of the survivors are set for the next tournaments.
fn survive(mut pop: Vec<Member>, n: usize) -> Vec<Member> {
    let fronts = fronts(&pop);
    let mut keep = Vec::with_capacity(n);
    for (rank, front) in fronts.iter().enumerate() {
        front.iter().for_each(|&i| pop[i].rank = rank);
        crowding(&mut pop, front);
        if keep.len() + front.len() <= n {
            keep.extend_from_slice(front);
        } else {
            let mut last = front.clone();
            // Stable sort keeps index order among equal distances: deterministic.
            last.sort_by(|&a, &b| pop[b].crowding.total_cmp(&pop[a].crowding));
            keep.extend_from_slice(&last[..n - keep.len()]);
        }
        if keep.len() == n {
            break;
        }
    }
    keep.sort_unstable();
    let mut slots: Vec<Option<Member>> = pop.into_iter().map(Some).collect();
    keep.into_iter().filter_map(|i| slots[i].take()).collect()
}
