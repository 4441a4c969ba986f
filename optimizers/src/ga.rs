//! The single-population genetic algorithm: MIGA's code with one island (so no migration).

use crate::encoding::Encoding;
use crate::eval::DEFAULT_FAILED_VALUE;
use crate::miga::{Miga, MigaSettings};
use czid_core::Result;
use serde::{Deserialize, Serialize};

/// GA settings: MIGA's operators with Isight's defaults, one population.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GaSettings {
    /// Population size (default 100, MIGA's default total population).
    pub population: usize,
    /// Bits per gene (default 32).
    pub bits_per_gene: u32,
    /// Binary (default) or Gray coding.
    pub encoding: Encoding,
    /// Probability that a pair of parents is crossed (default 1.0).
    pub crossover_rate: f64,
    /// Probability that a bit flips (default 0.01).
    pub mutation_rate: f64,
    /// Best members kept unchanged each generation (default 1).
    pub elite: usize,
    /// Tournament size as a fraction of the population (default 0.5, as MIGA; note that this
    /// makes selection much stronger on one large population than on small islands).
    pub relative_tournament_size: f64,
    /// Value given to failed evaluations (default 1e30).
    pub failed_value: f64,
}

impl Default for GaSettings {
    fn default() -> Self {
        let m = MigaSettings::default();
        GaSettings {
            population: m.islands * m.sub_population,
            bits_per_gene: m.bits_per_gene,
            encoding: m.encoding,
            crossover_rate: m.crossover_rate,
            mutation_rate: m.mutation_rate,
            elite: m.elite,
            relative_tournament_size: m.relative_tournament_size,
            failed_value: DEFAULT_FAILED_VALUE,
        }
    }
}

impl GaSettings {
    /// The equivalent one-island MIGA settings.
    pub fn to_miga(&self) -> MigaSettings {
        MigaSettings {
            islands: 1,
            sub_population: self.population,
            bits_per_gene: self.bits_per_gene,
            encoding: self.encoding,
            crossover_rate: self.crossover_rate,
            mutation_rate: self.mutation_rate,
            elite: self.elite,
            relative_tournament_size: self.relative_tournament_size,
            failed_value: self.failed_value,
            ..MigaSettings::default()
        }
    }
}

/// Builds the GA (registry name `ga`).
pub fn ga(settings: &GaSettings) -> Result<Miga> {
    Miga::named("ga", settings.to_miga()).map_err(|e| match e {
        czid_core::CzError::InvalidParameter { name, value, reason, .. } => {
            let name = if name == "sub_population" { "population".to_string() } else { name };
            czid_core::CzError::InvalidParameter { owner: "optimizer ga".into(), name, value, reason }
        }
        other => other,
    })
}
