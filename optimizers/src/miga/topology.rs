//! Where migrants go: the islands' connection graph (pagmo2's `topology`).

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Connection graph between islands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Topology {
    /// Island `i` sends to island `i + 1` (cyclically): slow spread, long-lived diversity.
    #[default]
    Ring,
    /// Every island sends to every other island.
    FullyConnected,
    /// At each migration every island sends to one other island drawn at random.
    Random,
}

impl Topology {
    /// Appends the destinations of island `from` among `islands` to `out`.
    pub fn destinations(self, from: usize, islands: usize, rng: &mut ChaCha8Rng, out: &mut Vec<usize>) {
        if islands < 2 {
            return;
        }
        match self {
            Topology::Ring => out.push((from + 1) % islands),
            Topology::FullyConnected => out.extend((0..islands).filter(|&j| j != from)),
            Topology::Random => {
                // Uniform over the other islands: draw among `islands − 1` and skip `from`.
                let j = rng.random_range(0..islands - 1);
                out.push(if j >= from { j + 1 } else { j });
            }
        }
    }
}
