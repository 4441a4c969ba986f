//! Symmetric banded matrices and their `L D Lᵀ` factorisation without pivoting.
//!
//! Where every stiffness of a problem is symmetric (the fibre beams' section tangents, the linear
//! layers, springs, and an interface whose damage is held for the step, `diag((1 − D) k)`), only
//! the diagonal and the `bw` entries right of it are stored per row, and the factorisation does
//! `n · bw (bw + 1) / 2` multiply-adds instead of the band LU's `n · bw²`
//! ([`super::banded::BandMatrix`]): half the arithmetic and half the memory to clear and copy.
//! Pivots are checked as there ([`BandError::SingularPivot`]).

use super::banded::{BandError, BandMatrix, StiffnessBand};

/// Symmetric `n × n` matrix stored by rows over the upper band `i ≤ j ≤ i + bw`.
#[derive(Clone, Debug, Default)]
pub struct SymmetricBand {
    n: usize,
    bw: usize,
    /// `bw + 1`: the diagonal and the entries right of it.
    width: usize,
    data: Vec<f64>,
    /// Reciprocal pivots `1/D_kk` after factorisation.
    inv_pivot: Vec<f64>,
}

impl SymmetricBand {
    /// A zero `n × n` matrix with half-bandwidth `bw`.
    pub fn zeros(n: usize, bw: usize) -> Self {
        let width = bw + 1;
        SymmetricBand { n, bw, width, data: vec![0.0; n * width], inv_pivot: vec![0.0; n] }
    }

    /// Order of the matrix.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Half-bandwidth.
    pub fn bandwidth(&self) -> usize {
        self.bw
    }

    /// Copies the entries of `other` (same shape) into `self` without allocating.
    pub fn copy_from(&mut self, other: &SymmetricBand) {
        debug_assert_eq!((self.n, self.bw), (other.n, other.bw));
        self.data.copy_from_slice(&other.data);
    }

    /// The upper band of `a`, which must be symmetric (a symmetric assembly's matrix).
    pub fn upper_of(a: &BandMatrix) -> Self {
        let mut s = SymmetricBand::zeros(a.n(), a.bandwidth());
        for i in 0..s.n {
            for j in i..=(i + s.bw).min(s.n - 1) {
                s.data[i * s.width + (j - i)] = a.get(i, j);
            }
        }
        s
    }

    /// Entry `(i, j)`; zero outside the band.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (i, j) = if i <= j { (i, j) } else { (j, i) };
        if j - i > self.bw {
            0.0
        } else {
            self.data[i * self.width + (j - i)]
        }
    }

    /// Replaces row and column `i` by those of the identity (a prescribed unknown).
    pub fn set_identity_row_col(&mut self, i: usize) {
        let w = self.width;
        for j in i..=(i + self.bw).min(self.n - 1) {
            self.data[i * w + (j - i)] = 0.0;
        }
        for k in i.saturating_sub(self.bw)..i {
            self.data[k * w + (i - k)] = 0.0;
        }
        self.data[i * w] = 1.0;
    }

    /// In-place `L D Lᵀ` factorisation without pivoting: row `k` then holds `D_kk` on the
    /// diagonal (its reciprocal in the pivots) and `L_{k+r,k}` in its `r`-th entry.
    pub fn factorize(&mut self) -> Result<(), BandError> {
        match self.bw {
            // Two beam layers with three unknowns per node (the FRP beam).
            11 => self.factorize_fixed::<11, 12>(),
            _ => self.factorize_rows(0, self.pivot_floor()),
        }
    }

    fn pivot_floor(&self) -> f64 {
        let w = self.width;
        (0..self.n).fold(0.0f64, |m, k| m.max(self.data[k * w].abs())) * 1e-14
    }

    /// [`SymmetricBand::factorize`] with a fixed half-bandwidth `BW` (`W = BW + 1`) for the rows
    /// whose band lies inside the matrix: the trailing update's loops have fixed lengths the
    /// compiler unrolls. The last `BW` rows as for any half-bandwidth.
    fn factorize_fixed<const BW: usize, const W: usize>(&mut self) -> Result<(), BandError> {
        debug_assert_eq!(W, BW + 1);
        let n = self.n;
        let tiny = self.pivot_floor();
        let inner = n.saturating_sub(BW);
        for k in 0..inner {
            let pivot = self.data[k * W];
            if !pivot.is_finite() || pivot.abs() <= tiny {
                return Err(BandError::SingularPivot { row: k, value: pivot });
            }
            let inv = 1.0 / pivot;
            self.inv_pivot[k] = inv;
            let (head, tail) = self.data.split_at_mut((k + 1) * W);
            let row_k: &mut [f64; W] = (&mut head[k * W..]).try_into().unwrap();
            let u = *row_k;
            let tail: &mut [f64] = &mut tail[..BW * W];
            for r in 1..W {
                let l = u[r] * inv;
                row_k[r] = l;
                let target = &mut tail[(r - 1) * W..r * W];
                for t in 0..W - r {
                    target[t] -= l * u[r + t];
                }
            }
        }
        self.factorize_rows(inner, tiny)
    }

    /// Rows `start..n` of the factorisation (those before done), pivots floored at `tiny`.
    fn factorize_rows(&mut self, start: usize, tiny: f64) -> Result<(), BandError> {
        let (n, bw, w) = (self.n, self.bw, self.width);
        let mut urow = vec![0.0; bw];
        for k in start..n {
            let pivot = self.data[k * w];
            if !pivot.is_finite() || pivot.abs() <= tiny {
                return Err(BandError::SingularPivot { row: k, value: pivot });
            }
            let inv = 1.0 / pivot;
            self.inv_pivot[k] = inv;
            let rows = bw.min(n - 1 - k);
            let (head, tail) = self.data.split_at_mut((k + 1) * w);
            let row_k = &mut head[k * w + 1..k * w + 1 + bw];
            urow.copy_from_slice(row_k);
            // Row k + r loses l · (row k's entries from column k + r on), l = A_{k,k+r} / D_kk.
            for r in 1..=rows {
                let l = urow[r - 1] * inv;
                row_k[r - 1] = l;
                if l != 0.0 {
                    let target = &mut tail[(r - 1) * w..(r - 1) * w + (bw + 1 - r)];
                    for (a, u) in target.iter_mut().zip(&urow[r - 1..]) {
                        *a -= l * u;
                    }
                }
            }
        }
        Ok(())
    }

    /// Solves `A x = b` in place with the factors from [`SymmetricBand::factorize`].
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let (n, bw, w) = (self.n, self.bw, self.width);
        // L y = b, column by column; then D z = y.
        for k in 0..n {
            let hi = bw.min(n - 1 - k);
            let bk = b[k];
            if bk != 0.0 {
                let l = &self.data[k * w + 1..k * w + 1 + hi];
                for (x, a) in b[k + 1..k + 1 + hi].iter_mut().zip(l) {
                    *x -= a * bk;
                }
            }
            b[k] = bk * self.inv_pivot[k];
        }
        // Lᵀ x = z, row by row.
        for k in (0..n).rev() {
            let hi = bw.min(n - 1 - k);
            let l = &self.data[k * w + 1..k * w + 1 + hi];
            let s = l.iter().zip(&b[k + 1..k + 1 + hi]).rev().fold(0.0, |s, (a, x)| s + a * x);
            b[k] -= s;
        }
    }

    /// Solves `A x = b1` and `A y = b2` in place together (their substitution chains interleaved).
    pub fn solve2_in_place(&self, b1: &mut [f64], b2: &mut [f64]) {
        match self.bw {
            11 => self.solve2_fixed::<11, 12>(b1, b2),
            _ => self.solve2_dyn(b1, b2),
        }
    }

    /// [`SymmetricBand::solve2_in_place`] with a fixed half-bandwidth (`W = BW + 1`): the rows
    /// whose band lies inside the matrix with fixed-length loops, the same sums in the same order
    /// as [`SymmetricBand::solve2_dyn`].
    fn solve2_fixed<const BW: usize, const W: usize>(&self, b1: &mut [f64], b2: &mut [f64]) {
        let n = self.n;
        if n <= 2 * BW {
            return self.solve2_dyn(b1, b2);
        }
        let row = |k: usize| -> &[f64; BW] { self.data[k * W + 1..(k + 1) * W].try_into().unwrap() };
        for k in 0..n - BW {
            let (x1, x2) = (b1[k], b2[k]);
            let l = row(k);
            let y1: &mut [f64; BW] = (&mut b1[k + 1..k + 1 + BW]).try_into().unwrap();
            let y2: &mut [f64; BW] = (&mut b2[k + 1..k + 1 + BW]).try_into().unwrap();
            for t in 0..BW {
                y1[t] -= l[t] * x1;
                y2[t] -= l[t] * x2;
            }
            b1[k] = x1 * self.inv_pivot[k];
            b2[k] = x2 * self.inv_pivot[k];
        }
        self.forward2_rows(n - BW..n, b1, b2);
        self.backward2_rows(n - BW..n, b1, b2);
        for k in (0..n - BW).rev() {
            let l = row(k);
            let x1: &[f64; BW] = b1[k + 1..k + 1 + BW].try_into().unwrap();
            let x2: &[f64; BW] = b2[k + 1..k + 1 + BW].try_into().unwrap();
            let (mut s1, mut s2) = (0.0, 0.0);
            for t in (0..BW).rev() {
                s1 += l[t] * x1[t];
                s2 += l[t] * x2[t];
            }
            b1[k] -= s1;
            b2[k] -= s2;
        }
    }

    /// [`SymmetricBand::solve2_in_place`] for any half-bandwidth.
    fn solve2_dyn(&self, b1: &mut [f64], b2: &mut [f64]) {
        self.forward2_rows(0..self.n, b1, b2);
        self.backward2_rows(0..self.n, b1, b2);
    }

    /// `L y = b` and `D z = y` for the unknowns `rows` (those before done), both right-hand sides.
    fn forward2_rows(&self, rows: std::ops::Range<usize>, b1: &mut [f64], b2: &mut [f64]) {
        let (n, bw, w) = (self.n, self.bw, self.width);
        for k in rows {
            let hi = bw.min(n - 1 - k);
            let (x1, x2) = (b1[k], b2[k]);
            let l = &self.data[k * w + 1..k * w + 1 + hi];
            for ((y1, y2), a) in b1[k + 1..k + 1 + hi].iter_mut().zip(b2[k + 1..k + 1 + hi].iter_mut()).zip(l) {
                *y1 -= a * x1;
                *y2 -= a * x2;
            }
            b1[k] = x1 * self.inv_pivot[k];
            b2[k] = x2 * self.inv_pivot[k];
        }
    }

    /// `Lᵀ x = z` for the unknowns `rows` (those after done), in reverse order; each sum takes
    /// the farthest unknowns first, so only its last product waits for the previous row
    /// (see `BandMatrix`'s back substitution).
    fn backward2_rows(&self, rows: std::ops::Range<usize>, b1: &mut [f64], b2: &mut [f64]) {
        let (n, bw, w) = (self.n, self.bw, self.width);
        for k in rows.rev() {
            let hi = bw.min(n - 1 - k);
            let l = &self.data[k * w + 1..k * w + 1 + hi];
            let (mut s1, mut s2) = (0.0, 0.0);
            for ((a, x1), x2) in l.iter().zip(&b1[k + 1..k + 1 + hi]).zip(&b2[k + 1..k + 1 + hi]).rev() {
                s1 += a * x1;
                s2 += a * x2;
            }
            b1[k] -= s1;
            b2[k] -= s2;
        }
    }
}

impl StiffnessBand for SymmetricBand {
    const UPPER_ONLY: bool = true;

    /// Adds `v` to entry `(i, j)` when `j ≥ i`. An entry below the diagonal is not stored: the
    /// caller adds a symmetric matrix, whose mirror entry `(j, i)` carries the same value.
    #[inline]
    fn add(&mut self, i: usize, j: usize, v: f64) {
        if j >= i {
            debug_assert!(j - i <= self.bw, "entry ({i},{j}) outside band {}", self.bw);
            self.data[i * self.width + (j - i)] += v;
        }
    }

    fn set_identity_row_col(&mut self, i: usize) {
        SymmetricBand::set_identity_row_col(self, i);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric band matrix with some zeros in the band, and its general-band copy.
    fn matrices(n: usize, bw: usize) -> (SymmetricBand, BandMatrix) {
        let mut s = SymmetricBand::zeros(n, bw);
        let mut g = BandMatrix::zeros(n, bw);
        for i in 0..n {
            for j in i..=(i + bw).min(n - 1) {
                let v = if i == j { 10.0 * bw as f64 } else { ((i * 7 + j * 3) % 11) as f64 / 7.0 - 0.6 };
                if i == j {
                    s.add(i, i, v);
                    g.add(i, i, v);
                } else if (i + 2 * j) % 5 != 0 {
                    // Both halves, as a symmetric assembly adds them.
                    for (a, b) in [(i, j), (j, i)] {
                        s.add(a, b, v);
                        g.add(a, b, v);
                    }
                }
            }
        }
        (s, g)
    }

    #[test]
    fn ldlt_solves_what_the_band_lu_solves() {
        for (n, bw) in [(60, 3), (45, 7), (70, 11), (23, 11), (5, 11), (40, 4)] {
            let (mut s, mut g) = matrices(n, bw);
            for i in 0..n {
                for j in 0..n {
                    assert_eq!(s.get(i, j), g.get(i, j));
                }
            }
            let u = SymmetricBand::upper_of(&g);
            assert_eq!(u.data, s.data);
            s.set_identity_row_col(n / 2);
            g.set_identity_row_col(n / 2);
            let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let mut y = vec![0.0; n];
            g.mul_vec(&x, &mut y);
            s.factorize().unwrap();
            g.factorize().unwrap();
            let (mut a1, mut a2) = (y.clone(), x.clone());
            s.solve2_in_place(&mut a1, &mut a2);
            let mut a3 = y.clone();
            s.solve_in_place(&mut a3);
            let (mut b1, mut b2) = (y.clone(), x.clone());
            g.solve2_in_place(&mut b1, &mut b2);
            assert_eq!(a1, a3);
            let (mut c1, mut c2) = (y.clone(), x.clone());
            s.solve2_dyn(&mut c1, &mut c2);
            assert_eq!((&a1, &a2), (&c1, &c2));
            for i in 0..n {
                assert!((a1[i] - x[i]).abs() < 1e-12, "{n} {bw} {i}: {} {}", a1[i], x[i]);
                assert!((a2[i] - b2[i]).abs() < 1e-12 * b2[i].abs().max(1.0));
            }
        }
    }

    #[test]
    fn a_zero_pivot_is_reported() {
        let mut s = SymmetricBand::zeros(4, 1);
        for i in 0..4 {
            s.add(i, i, 1.0);
        }
        s.add(2, 2, -1.0);
        assert!(matches!(s.factorize(), Err(BandError::SingularPivot { row: 2, .. })));
    }
}
