//! One island's generation: elitism, tournament selection, two-point crossover and bit
//! mutation on binary chromosomes.

use crate::encoding::{flip_bit, swap_bit_range};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// A member of an island: its chromosome, the decoded point and its (penalised) value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Individual {
    /// One word per gene.
    pub genes: Vec<u64>,
    /// Decoded point.
    pub x: Vec<f64>,
    /// Objective value (failed evaluations carry the failure penalty).
    pub value: f64,
}

/// The breeding operators' parameters, resolved from the settings.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Operators {
    pub bits: u32,
    pub len_bits: usize,
    pub crossover_rate: f64,
    pub mutation_rate: f64,
    pub elite: usize,
    pub tournament: usize,
}

/// Indices of `island` sorted best first (stable, so ties keep their order).
pub(crate) fn ranked(island: &[Individual], order: &mut Vec<usize>) {
    order.clear();
    order.extend(0..island.len());
    order.sort_by(|&a, &b| island[a].value.total_cmp(&island[b].value));
}

/// Appends `island.len() − elite` children of `island` to `out`.
pub(crate) fn breed(island: &[Individual], ops: &Operators, rng: &mut ChaCha8Rng, out: &mut Vec<Vec<u64>>) {
    let wanted = island.len() - ops.elite;
    let mut made = 0;
    while made < wanted {
        let mut a = island[tournament(island, ops.tournament, rng)].genes.clone();
        let mut b = island[tournament(island, ops.tournament, rng)].genes.clone();
        if ops.len_bits >= 2 && rng.random::<f64>() < ops.crossover_rate {
            // Two cut points between bits; the segment between them is exchanged.
            let c1 = rng.random_range(1..ops.len_bits);
            let c2 = rng.random_range(1..ops.len_bits);
            swap_bit_range(&mut a, &mut b, ops.bits, c1.min(c2), c1.max(c2));
        }
        mutate(&mut a, ops, rng);
        mutate(&mut b, ops, rng);
        out.push(a);
        made += 1;
        if made < wanted {
            out.push(b);
            made += 1;
        }
    }
}

/// Tournament selection: the best of `size` members drawn with replacement.
fn tournament(island: &[Individual], size: usize, rng: &mut ChaCha8Rng) -> usize {
    let mut best = rng.random_range(0..island.len());
    for _ in 1..size {
        let c = rng.random_range(0..island.len());
        if island[c].value < island[best].value {
            best = c;
        }
    }
    best
}

/// Flips each bit independently with probability `mutation_rate`. The gaps between flipped
/// bits are drawn from their geometric law, which is the same process as one Bernoulli draw
/// per bit at a cost proportional to the number of flips.
fn mutate(genes: &mut [u64], ops: &Operators, rng: &mut ChaCha8Rng) {
    let p = ops.mutation_rate;
    if p <= 0.0 {
        return;
    }
    if p >= 1.0 {
        (0..ops.len_bits).for_each(|pos| flip_bit(genes, ops.bits, pos));
        return;
    }
    let log_q = (-p).ln_1p();
    let mut pos = 0usize;
    loop {
        let u = 1.0 - rng.random::<f64>(); // in (0, 1]
        let skip = (u.ln() / log_q).floor();
        if skip >= (ops.len_bits - pos) as f64 {
            return;
        }
        pos += skip as usize;
        flip_bit(genes, ops.bits, pos);
        pos += 1;
        if pos >= ops.len_bits {
            return;
        }
    }
}
