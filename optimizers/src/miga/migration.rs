//! Which individuals leave an island and whom they replace (pagmo2's `s_policy` and
//! `r_policy`).

use super::island::Individual;
use super::topology::Topology;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// How emigrants are chosen on their home island.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EmigrantPolicy {
    /// The best individuals (copies; the home island keeps them).
    #[default]
    Best,
    /// Individuals drawn at random without replacement.
    Random,
}

/// How immigrants enter the destination island.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReplacementPolicy {
    /// Immigrants replace the worst residents.
    #[default]
    Worst,
    /// Immigrants replace the worst residents only where they are better (pagmo2's
    /// `fair_replace`).
    WorstIfBetter,
    /// Immigrants replace residents drawn at random.
    Random,
}

/// Synchronous migration: emigrants are chosen on every island first, then delivered, so the
/// outcome does not depend on island order. `count` individuals leave each island; a
/// destination receiving from several islands keeps the best `count` of them.
pub fn migrate(
    islands: &mut [Vec<Individual>],
    count: usize,
    topology: Topology,
    emigrants: EmigrantPolicy,
    replacement: ReplacementPolicy,
    rng: &mut ChaCha8Rng,
) {
    let m = islands.len();
    if m < 2 || count == 0 {
        return;
    }
    let mut incoming: Vec<Vec<Individual>> = vec![Vec::new(); m];
    let mut order = Vec::new();
    let mut dest = Vec::new();
    for (i, island) in islands.iter().enumerate() {
        let k = count.min(island.len());
        order.clear();
        order.extend(0..island.len());
        match emigrants {
            EmigrantPolicy::Best => order.sort_by(|&a, &b| island[a].value.total_cmp(&island[b].value)),
            EmigrantPolicy::Random => partial_shuffle(&mut order, k, rng),
        }
        dest.clear();
        topology.destinations(i, m, rng, &mut dest);
        for &j in &dest {
            incoming[j].extend(order[..k].iter().map(|&a| island[a].clone()));
        }
    }
    for (island, mut arrivals) in islands.iter_mut().zip(incoming) {
        arrivals.sort_by(|a, b| a.value.total_cmp(&b.value));
        arrivals.truncate(count.min(island.len()));
        order.clear();
        order.extend(0..island.len());
        match replacement {
            ReplacementPolicy::Worst | ReplacementPolicy::WorstIfBetter => {
                // Worst first; stable so ties go to the later index deterministically.
                order.sort_by(|&a, &b| island[b].value.total_cmp(&island[a].value));
            }
            ReplacementPolicy::Random => partial_shuffle(&mut order, arrivals.len(), rng),
        }
        for (&slot, newcomer) in order.iter().zip(arrivals) {
            if replacement == ReplacementPolicy::WorstIfBetter && newcomer.value >= island[slot].value {
                continue;
            }
            island[slot] = newcomer;
        }
    }
}

/// Puts `k` uniformly drawn distinct elements at the front of `v` (Fisher–Yates prefix).
fn partial_shuffle(v: &mut [usize], k: usize, rng: &mut ChaCha8Rng) {
    for i in 0..k.min(v.len()) {
        let j = rng.random_range(i..v.len());
        v.swap(i, j);
    }
}
