//! Binary and Gray encodings of a bounded real vector, one machine word per gene.
//!
//! A gene of `b` bits holds an integer `k ∈ [0, 2^b − 1]` mapped linearly onto `[lo, hi]`:
//! `x = lo + (hi − lo) k / (2^b − 1)`, so both bounds are representable. Gray coding makes
//! neighbouring integers differ by one bit (smaller jumps under bit mutation).

use czid_core::{CzError, Result};
use serde::{Deserialize, Serialize};

/// How a gene's bits represent its integer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Encoding {
    /// Plain binary (Isight's MIGA).
    #[default]
    Binary,
    /// Reflected binary Gray code.
    Gray,
}

/// Largest supported bits per gene: every integer up to `2^52` is exact in an `f64`.
pub const MAX_BITS_PER_GENE: u32 = 52;

/// Maps chromosomes (one `u64` per gene, low `bits` used) to points of the box and back.
#[derive(Clone, Debug, PartialEq)]
pub struct Codec {
    bits: u32,
    encoding: Encoding,
    bounds: Vec<(f64, f64)>,
    mask: u64,
}

impl Codec {
    /// A codec for `bounds` with `bits` per gene.
    pub fn new(bits: u32, encoding: Encoding, bounds: Vec<(f64, f64)>) -> Result<Self> {
        if bits == 0 || bits > MAX_BITS_PER_GENE {
            return Err(CzError::invalid(
                "optimizer encoding",
                "bits_per_gene",
                bits as f64,
                format!("must be in 1..={MAX_BITS_PER_GENE}"),
            ));
        }
        Ok(Codec { bits, encoding, bounds, mask: (1u64 << bits) - 1 })
    }

    /// Bits per gene.
    pub fn bits(&self) -> u32 {
        self.bits
    }

    /// Total chromosome length in bits.
    pub fn len_bits(&self) -> usize {
        self.bits as usize * self.bounds.len()
    }

    /// Mask of a gene's used bits.
    pub fn mask(&self) -> u64 {
        self.mask
    }

    /// Decodes `genes` into `x` (same length).
    pub fn decode_into(&self, genes: &[u64], x: &mut [f64]) {
        let scale = self.mask as f64;
        for ((g, xi), &(lo, hi)) in genes.iter().zip(x.iter_mut()).zip(&self.bounds) {
            let k = match self.encoding {
                Encoding::Binary => g & self.mask,
                Encoding::Gray => gray_to_binary(g & self.mask),
            };
            *xi = if k == self.mask { hi } else { lo + (hi - lo) * (k as f64 / scale) };
        }
    }

    /// Decodes into a new vector.
    pub fn decode(&self, genes: &[u64]) -> Vec<f64> {
        let mut x = vec![0.0; genes.len()];
        self.decode_into(genes, &mut x);
        x
    }

    /// The chromosome whose decoded point is nearest to `x` (clamped into the box).
    pub fn encode(&self, x: &[f64]) -> Vec<u64> {
        x.iter()
            .zip(&self.bounds)
            .map(|(&xi, &(lo, hi))| {
                let t = if hi > lo { ((xi - lo) / (hi - lo)).clamp(0.0, 1.0) } else { 0.0 };
                let k = (t * self.mask as f64).round() as u64;
                match self.encoding {
                    Encoding::Binary => k,
                    Encoding::Gray => k ^ (k >> 1),
                }
            })
            .collect()
    }
}

/// Inverse of `k ^ (k >> 1)`: prefix XOR of the higher bits.
fn gray_to_binary(mut g: u64) -> u64 {
    let mut shift = 1;
    while shift < 64 {
        g ^= g >> shift;
        shift <<= 1;
    }
    g
}

/// Swaps bits `[start, end)` of two chromosomes viewed as one string of `bits`-bit genes
/// (gene 0 first, least significant bit first within a gene): the exchange step of
/// two-point crossover.
pub fn swap_bit_range(a: &mut [u64], b: &mut [u64], bits: u32, start: usize, end: usize) {
    let bits = bits as usize;
    let mut pos = start;
    while pos < end {
        let gene = pos / bits;
        let lo = pos % bits;
        let hi = (end - gene * bits).min(bits);
        let width = hi - lo;
        let mask = if width == 64 { u64::MAX } else { ((1u64 << width) - 1) << lo };
        let diff = (a[gene] ^ b[gene]) & mask;
        a[gene] ^= diff;
        b[gene] ^= diff;
        pos += width;
    }
}

/// Flips bit `pos` of a chromosome of `bits`-bit genes.
pub fn flip_bit(genes: &mut [u64], bits: u32, pos: usize) {
    let bits = bits as usize;
    genes[pos / bits] ^= 1u64 << (pos % bits);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gray_round_trip_and_bounds() {
        for enc in [Encoding::Binary, Encoding::Gray] {
            let c = Codec::new(8, enc, vec![(-1.0, 3.0), (0.0, 1.0)]).unwrap();
            for x in [[-1.0, 0.0], [3.0, 1.0], [0.5, 0.25]] {
                let g = c.encode(&x);
                let y = c.decode(&g);
                assert!((y[0] - x[0]).abs() <= 4.0 / 255.0 && (y[1] - x[1]).abs() <= 1.0 / 255.0);
            }
            assert_eq!(c.decode(&c.encode(&[3.0, 1.0])), vec![3.0, 1.0]);
        }
        for k in 0..1000u64 {
            assert_eq!(gray_to_binary(k ^ (k >> 1)), k);
        }
    }

    #[test]
    fn swap_range_matches_bitwise_definition() {
        let bits = 5;
        let a0 = vec![0b10101u64, 0b00111, 0b11000];
        let b0 = vec![0b01010u64, 0b11100, 0b00111];
        for start in 0..15 {
            for end in start..=15 {
                let (mut a, mut b) = (a0.clone(), b0.clone());
                swap_bit_range(&mut a, &mut b, bits, start, end);
                for p in 0..15 {
                    let get = |v: &[u64]| (v[p / 5] >> (p % 5)) & 1;
                    let (ea, eb) = if p >= start && p < end { (get(&b0), get(&a0)) } else { (get(&a0), get(&b0)) };
                    assert_eq!((get(&a), get(&b)), (ea, eb));
                }
            }
        }
    }
}
