//! Banded matrix storage and an LU factorisation without pivoting.
//!
//! Beam-layer meshes numbered node by node give matrices whose non-zeros lie within a few
//! diagonals of the main one (half-bandwidth 3 for a single layer without axial unknowns,
//! 11 for two layers with all three unknowns per node; 13 and 23 for the continuum models' DCB and
//! ENF meshes with four elements through each arm). A dense band LU on that structure costs
//! `n · bw²` operations with unit-stride inner loops and no index indirection, and its "symbolic
//! analysis" (the band) is fixed by the mesh and reused for every factorisation. (A general sparse
//! LU such as faer's has to do at least the same arithmetic plus index indirection: on the
//! continuum DCB it measured 9 times slower, see the book's "Beam or continuum?" chapter.)
//!
//! No pivoting: the stiffness matrices of this engine are symmetric positive definite except
//! where cohesive softening enters, which only adds small (possibly negative) contributions to a
//! few diagonal 2×2 blocks. A pivot that is tiny relative to its row is reported as
//! [`BandError::SingularPivot`] so the caller can cut the step rather than produce garbage.

/// Square matrix stored by rows over the band `|i - j| <= bw`.
#[derive(Clone, Debug, Default)]
pub struct BandMatrix {
    n: usize,
    bw: usize,
    width: usize,
    data: Vec<f64>,
    /// Reciprocal pivots after factorisation (a triangular solve is a dependency chain; a multiply
    /// is several times shorter than a divide on it).
    inv_pivot: Vec<f64>,
}

/// One row of a [`BandMatrix`] ([`BandMatrix::row_mut`]).
pub struct BandRow<'a> {
    entries: &'a mut [f64],
    /// Position of column `j` in `entries` minus `j`.
    offset: isize,
}

impl BandRow<'_> {
    /// Adds `v` to the entry in column `j`, which must lie within the band.
    #[inline]
    pub fn add(&mut self, j: usize, v: f64) {
        self.entries[(j as isize + self.offset) as usize] += v;
    }

    /// Adds `v[k]` to the entry in column `j + k` for every `k` (all within the band).
    #[inline]
    pub fn add_run(&mut self, j: usize, v: &[f64]) {
        let start = (j as isize + self.offset) as usize;
        for (e, x) in self.entries[start..start + v.len()].iter_mut().zip(v) {
            *e += x;
        }
    }
}

/// A band matrix an assembly writes a tangent into: a general band ([`BandMatrix`]) or the upper
/// band of a symmetric one ([`super::symmetric_band::SymmetricBand`]), so one element routine
/// serves both.
pub trait StiffnessBand {
    /// Whether only the entries on and above the diagonal are kept (a symmetric matrix's band):
    /// [`StiffnessBand::add`] then drops the others, and callers may leave them out.
    const UPPER_ONLY: bool = false;

    /// Adds `v` to entry `(i, j)`, which must lie within the band.
    fn add(&mut self, i: usize, j: usize, v: f64);

    /// Replaces row and column `i` by those of the identity (a prescribed unknown).
    fn set_identity_row_col(&mut self, i: usize);
}

impl StiffnessBand for BandMatrix {
    #[inline]
    fn add(&mut self, i: usize, j: usize, v: f64) {
        BandMatrix::add(self, i, j, v);
    }

    fn set_identity_row_col(&mut self, i: usize) {
        BandMatrix::set_identity_row_col(self, i);
    }
}

/// Why a factorisation failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BandError {
    /// Pivot `row` was zero, not finite, or negligible against the diagonal scale.
    SingularPivot {
        /// Row of the pivot.
        row: usize,
        /// Its value.
        value: f64,
    },
}

impl BandMatrix {
    /// A zero `n × n` matrix with half-bandwidth `bw`.
    pub fn zeros(n: usize, bw: usize) -> Self {
        let width = 2 * bw + 1;
        BandMatrix { n, bw, width, data: vec![0.0; n * width], inv_pivot: vec![0.0; n] }
    }

    /// Order of the matrix.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Restricts factorisations and solves to the leading `m` unknowns (at most the order the
    /// matrix was made with): the rest are held, their couplings to the first `m` ignored. The
    /// storage keeps its size, so [`BandMatrix::set_order`] back to the full order restores it.
    pub fn set_order(&mut self, m: usize) {
        assert!(m >= 1 && m * self.width <= self.data.len(), "order {m} beyond the storage");
        self.n = m;
    }

    /// Half-bandwidth.
    pub fn bandwidth(&self) -> usize {
        self.bw
    }

    /// Copies the leading `self.n()` rows of `other` (same bandwidth, at least as many rows).
    pub(crate) fn copy_leading_from(&mut self, other: &BandMatrix) {
        let len = self.n * self.width;
        self.data[..len].copy_from_slice(&other.data[..len]);
    }

    /// The factors in band rows and the reciprocal pivots, after [`BandMatrix::factorize`].
    pub(crate) fn factors(&self) -> (&[f64], &[f64]) {
        (&self.data[..self.n * self.width], &self.inv_pivot[..self.n])
    }

    /// Row `i`'s stored band, `2 bw + 1` entries: column `j` at position `j + bw − i` (entries
    /// outside the matrix are zero).
    #[inline]
    pub(crate) fn band_row(&self, i: usize) -> &[f64] {
        &self.data[i * self.width..(i + 1) * self.width]
    }

    /// Copies rows `lo..=hi` of `other` (same shape) into `self`.
    pub(crate) fn copy_rows_from(&mut self, other: &BandMatrix, lo: usize, hi: usize) {
        debug_assert_eq!((self.n, self.bw), (other.n, other.bw));
        let range = lo * self.width..(hi + 1) * self.width;
        self.data[range.clone()].copy_from_slice(&other.data[range]);
    }

    /// Where its entries live: two matrices with the same address are the same buffer.
    pub(crate) fn address(&self) -> usize {
        self.data.as_ptr() as usize
    }

    /// Sets every stored entry to zero (keeps the allocation).
    pub fn clear(&mut self) {
        self.data.fill(0.0);
    }

    /// Copies the entries of `other` (same shape) into `self` without allocating.
    pub fn copy_from(&mut self, other: &BandMatrix) {
        debug_assert_eq!((self.n, self.bw), (other.n, other.bw));
        self.data.copy_from_slice(&other.data);
    }

    #[inline]
    fn idx(&self, i: usize, j: usize) -> usize {
        i * self.width + (j + self.bw - i)
    }

    /// Entry `(i, j)`; zero outside the band.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        if i.abs_diff(j) > self.bw {
            0.0
        } else {
            self.data[self.idx(i, j)]
        }
    }

    /// Adds `v` to entry `(i, j)`, which must lie within the band (a mesh-numbering bug otherwise).
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        debug_assert!(i.abs_diff(j) <= self.bw, "entry ({i},{j}) outside band {}", self.bw);
        let k = self.idx(i, j);
        self.data[k] += v;
    }

    /// Row `i`, for adding several entries to it (the row located once).
    #[inline]
    pub fn row_mut(&mut self, i: usize) -> BandRow<'_> {
        let (w, bw) = (self.width, self.bw);
        BandRow { entries: &mut self.data[i * w..(i + 1) * w], offset: bw as isize - i as isize }
    }

    /// Replaces row and column `i` by those of the identity (a prescribed unknown).
    pub fn set_identity_row_col(&mut self, i: usize) {
        let lo = i.saturating_sub(self.bw);
        let hi = (i + self.bw).min(self.n - 1);
        for j in lo..=hi {
            let a = self.idx(i, j);
            self.data[a] = 0.0;
            let b = self.idx(j, i);
            self.data[b] = 0.0;
        }
        let d = self.idx(i, i);
        self.data[d] = 1.0;
    }

    /// `y = A x`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        match self.bw {
            3 => self.mul_vec_fixed::<3>(x, y),
            5 => self.mul_vec_fixed::<5>(x, y),
            7 => self.mul_vec_fixed::<7>(x, y),
            11 => self.mul_vec_fixed::<11>(x, y),
            // The continuum models' DCB and ENF with four elements through each arm.
            13 => self.mul_vec_fixed::<13>(x, y),
            // The MMB: two arms and the lever's carrier, eight unknowns per node.
            15 => self.mul_vec_fixed::<15>(x, y),
            23 => self.mul_vec_fixed::<23>(x, y),
            _ => self.mul_vec_rows(0..self.n, x, y),
        }
    }

    /// `y = A x` with a fixed half-bandwidth: the rows whose band lies inside the matrix four at
    /// a time (four independent sums, each in the order of [`BandMatrix::mul_vec_rows`], so the
    /// results are the same), the first and last `BW` rows one by one.
    fn mul_vec_fixed<const BW: usize>(&self, x: &[f64], y: &mut [f64]) {
        let n = self.n;
        if n < 2 * BW + 4 {
            return self.mul_vec_rows(0..n, x, y);
        }
        let w = 2 * BW + 1;
        self.mul_vec_rows(0..BW, x, y);
        let mut i = BW;
        while i + 4 <= n - BW {
            let rows = &self.data[i * w..(i + 4) * w];
            let (r0, rest) = rows.split_at(w);
            let (r1, rest) = rest.split_at(w);
            let (r2, r3) = rest.split_at(w);
            let xs = &x[i - BW..i - BW + w + 3];
            let (mut s0, mut s1, mut s2, mut s3) = (0.0, 0.0, 0.0, 0.0);
            for t in 0..w {
                s0 += r0[t] * xs[t];
                s1 += r1[t] * xs[t + 1];
                s2 += r2[t] * xs[t + 2];
                s3 += r3[t] * xs[t + 3];
            }
            y[i] = s0;
            y[i + 1] = s1;
            y[i + 2] = s2;
            y[i + 3] = s3;
            i += 4;
        }
        self.mul_vec_rows(i..n, x, y);
    }

    /// Rows `rows` of `y = A x`.
    fn mul_vec_rows(&self, rows: std::ops::Range<usize>, x: &[f64], y: &mut [f64]) {
        for i in rows {
            let yi = &mut y[i];
            let lo = i.saturating_sub(self.bw);
            let hi = (i + self.bw).min(self.n - 1);
            let row = &self.data[i * self.width..(i + 1) * self.width];
            let mut s = 0.0;
            for j in lo..=hi {
                s += row[j + self.bw - i] * x[j];
            }
            *yi = s;
        }
    }

    /// In-place LU factorisation without pivoting (`L` unit lower, both kept in the band).
    pub fn factorize(&mut self) -> Result<(), BandError> {
        // The common half-bandwidths get a fixed-size inner loop the compiler unrolls.
        match self.bw {
            3 => self.factorize_fixed::<3>(),
            5 => self.factorize_fixed::<5>(),
            7 => self.factorize_fixed::<7>(),
            11 => self.factorize_fixed::<11>(),
            // The continuum models' DCB and ENF with four elements through each arm.
            13 => self.factorize_fixed::<13>(),
            // The MMB: two arms and the lever's carrier, eight unknowns per node.
            15 => self.factorize_fixed::<15>(),
            23 => self.factorize_fixed::<23>(),
            _ => self.factorize_dyn(),
        }
    }

    fn pivot_floor(&self) -> f64 {
        let (n, bw, w) = (self.n, self.bw, self.width);
        let mut scale = 0.0f64;
        for i in 0..n {
            scale = scale.max(self.data[i * w + bw].abs());
        }
        scale * 1e-14
    }

    fn factorize_fixed<const BW: usize>(&mut self) -> Result<(), BandError> {
        let n = self.n;
        let w = 2 * BW + 1;
        let tiny = self.pivot_floor();
        for k in 0..n {
            let pivot = self.data[k * w + BW];
            if !pivot.is_finite() || pivot.abs() <= tiny {
                return Err(BandError::SingularPivot { row: k, value: pivot });
            }
            let inv = 1.0 / pivot;
            self.inv_pivot[k] = inv;
            let mut urow = [0.0; BW];
            urow.copy_from_slice(&self.data[k * w + BW + 1..k * w + 2 * BW + 1]);
            let rows = BW.min(n - 1 - k);
            for r in 1..=rows {
                let i = k + r;
                let base = i * w + (BW - r);
                let l = self.data[base] * inv;
                self.data[base] = l;
                if l != 0.0 {
                    // Entries beyond column n − 1 are zero in the band, so the fixed loop is safe.
                    let row = &mut self.data[base + 1..base + 1 + BW];
                    for (a, u) in row.iter_mut().zip(&urow) {
                        *a -= l * u;
                    }
                }
            }
        }
        Ok(())
    }

    fn factorize_dyn(&mut self) -> Result<(), BandError> {
        let (n, bw, w) = (self.n, self.bw, self.width);
        let tiny = self.pivot_floor();
        for k in 0..n {
            let pivot = self.data[k * w + bw];
            if !pivot.is_finite() || pivot.abs() <= tiny {
                return Err(BandError::SingularPivot { row: k, value: pivot });
            }
            let inv = 1.0 / pivot;
            self.inv_pivot[k] = inv;
            let hi = (k + bw).min(n - 1);
            let (head, tail) = self.data.split_at_mut((k + 1) * w);
            let urow = &head[k * w + bw + 1..k * w + bw + 1 + (hi - k)];
            for i in k + 1..=hi {
                let row = &mut tail[(i - k - 1) * w..(i - k) * w];
                let off = k + bw - i;
                let l = row[off] * inv;
                row[off] = l;
                if l != 0.0 {
                    for (a, u) in row[off + 1..off + 1 + (hi - k)].iter_mut().zip(urow) {
                        *a -= l * u;
                    }
                }
            }
        }
        Ok(())
    }

    /// Solves `A x = b` in place with the factors from [`BandMatrix::factorize`].
    pub fn solve_in_place(&self, b: &mut [f64]) {
        match self.bw {
            3 => self.solve_fixed::<3>(b),
            5 => self.solve_fixed::<5>(b),
            7 => self.solve_fixed::<7>(b),
            11 => self.solve_fixed::<11>(b),
            // The continuum models' DCB and ENF with four elements through each arm.
            13 => self.solve_fixed::<13>(b),
            // The MMB: two arms and the lever's carrier, eight unknowns per node.
            15 => self.solve_fixed::<15>(b),
            23 => self.solve_fixed::<23>(b),
            _ => self.solve_dyn(b),
        }
    }

    /// Solves `A x = b1` and `A y = b2` in place together: the two substitution chains are
    /// independent, so interleaving them hides most of their latency.
    pub fn solve2_in_place(&self, b1: &mut [f64], b2: &mut [f64]) {
        match self.bw {
            3 => self.solve2_fixed::<3>(b1, b2),
            5 => self.solve2_fixed::<5>(b1, b2),
            7 => self.solve2_fixed::<7>(b1, b2),
            11 => self.solve2_fixed::<11>(b1, b2),
            // The continuum models' DCB and ENF with four elements through each arm.
            13 => self.solve2_fixed::<13>(b1, b2),
            // The MMB: two arms and the lever's carrier, eight unknowns per node.
            15 => self.solve2_fixed::<15>(b1, b2),
            23 => self.solve2_fixed::<23>(b1, b2),
            _ => self.solve2_dyn(b1, b2),
        }
    }

    /// The sub-diagonal part of row `i` (`BW` entries) for `i ≥ BW`.
    #[inline(always)]
    fn lower<const BW: usize>(&self, i: usize) -> &[f64; BW] {
        let w = 2 * BW + 1;
        self.data[i * w..i * w + BW].try_into().unwrap()
    }

    /// The super-diagonal part of row `i` (`BW` entries) for `i + BW < n`.
    #[inline(always)]
    fn upper<const BW: usize>(&self, i: usize) -> &[f64; BW] {
        let w = 2 * BW + 1;
        self.data[i * w + BW + 1..(i + 1) * w].try_into().unwrap()
    }

    /// [`BandMatrix::solve_in_place`] with a fixed half-bandwidth: the rows whose band lies inside
    /// the matrix with fixed-length sums (the same sums in the same order as
    /// [`BandMatrix::solve_dyn`]), the others as there.
    fn solve_fixed<const BW: usize>(&self, b: &mut [f64]) {
        let n = self.n;
        if n <= 2 * BW {
            return self.solve_dyn(b);
        }
        self.forward_rows(0..BW, b);
        for i in BW..n {
            let l = self.lower::<BW>(i);
            let x: &[f64; BW] = b[i - BW..i].try_into().unwrap();
            let mut s = 0.0;
            for t in 0..BW {
                s += l[t] * x[t];
            }
            b[i] -= s;
        }
        self.backward_rows(n - BW..n, b);
        for i in (0..n - BW).rev() {
            let u = self.upper::<BW>(i);
            let x: &[f64; BW] = b[i + 1..i + 1 + BW].try_into().unwrap();
            let mut s = 0.0;
            for t in (0..BW).rev() {
                s += u[t] * x[t];
            }
            b[i] = (b[i] - s) * self.inv_pivot[i];
        }
    }

    /// [`BandMatrix::solve2_in_place`] with a fixed half-bandwidth (see
    /// [`BandMatrix::solve_fixed`]).
    fn solve2_fixed<const BW: usize>(&self, b1: &mut [f64], b2: &mut [f64]) {
        let n = self.n;
        if n <= 2 * BW {
            return self.solve2_dyn(b1, b2);
        }
        self.forward_rows(0..BW, b1);
        self.forward_rows(0..BW, b2);
        // The two right-hand sides side by side, so each step of a sum works on both at once.
        let mut xs: Vec<[f64; 2]> = b1.iter().zip(b2.iter()).map(|(a, b)| [*a, *b]).collect();
        for i in BW..n {
            let l = self.lower::<BW>(i);
            let x: &[[f64; 2]; BW] = xs[i - BW..i].try_into().unwrap();
            let mut s = [0.0, 0.0];
            for t in 0..BW {
                s[0] += l[t] * x[t][0];
                s[1] += l[t] * x[t][1];
            }
            xs[i][0] -= s[0];
            xs[i][1] -= s[1];
        }
        for (i, x) in xs.iter().enumerate().skip(n - BW) {
            [b1[i], b2[i]] = *x;
        }
        self.backward_rows(n - BW..n, b1);
        self.backward_rows(n - BW..n, b2);
        for (i, x) in xs.iter_mut().enumerate().skip(n - BW) {
            *x = [b1[i], b2[i]];
        }
        for i in (0..n - BW).rev() {
            let u = self.upper::<BW>(i);
            let x: &[[f64; 2]; BW] = xs[i + 1..i + 1 + BW].try_into().unwrap();
            let mut s = [0.0, 0.0];
            for t in (0..BW).rev() {
                s[0] += u[t] * x[t][0];
                s[1] += u[t] * x[t][1];
            }
            let p = self.inv_pivot[i];
            xs[i] = [(xs[i][0] - s[0]) * p, (xs[i][1] - s[1]) * p];
        }
        for ((a, b), x) in b1.iter_mut().zip(b2.iter_mut()).zip(&xs) {
            [*a, *b] = *x;
        }
    }

    /// Forward substitution over `rows` (in order).
    fn forward_rows(&self, rows: std::ops::Range<usize>, b: &mut [f64]) {
        let (bw, w) = (self.bw, self.width);
        for i in rows {
            let lo = i.saturating_sub(bw);
            let l = &self.data[i * w + lo + bw - i..i * w + bw];
            let s: f64 = l.iter().zip(&b[lo..i]).map(|(a, x)| a * x).sum();
            b[i] -= s;
        }
    }

    /// Back substitution over `rows` (in reverse order). Each row's sum takes the farthest
    /// unknowns first and the one solved just before last: only that last product then waits
    /// for the previous row, instead of the whole chain of additions (which made the back
    /// substitution as slow as the factorisation).
    fn backward_rows(&self, rows: std::ops::Range<usize>, b: &mut [f64]) {
        let (n, bw, w) = (self.n, self.bw, self.width);
        for i in rows.rev() {
            let hi = (i + bw).min(n - 1);
            let u = &self.data[i * w + bw + 1..i * w + bw + 1 + (hi - i)];
            let s = u.iter().zip(&b[i + 1..=hi]).rev().fold(0.0, |s, (a, x)| s + a * x);
            b[i] = (b[i] - s) * self.inv_pivot[i];
        }
    }

    /// [`BandMatrix::solve_in_place`] for any half-bandwidth.
    fn solve_dyn(&self, b: &mut [f64]) {
        self.forward_rows(0..self.n, b);
        self.backward_rows(0..self.n, b);
    }

    /// [`BandMatrix::solve2_in_place`] for any half-bandwidth.
    fn solve2_dyn(&self, b1: &mut [f64], b2: &mut [f64]) {
        let (n, bw, w) = (self.n, self.bw, self.width);
        for i in 0..n {
            let lo = i.saturating_sub(bw);
            let l = &self.data[i * w + lo + bw - i..i * w + bw];
            let (mut s1, mut s2) = (0.0, 0.0);
            for ((a, x1), x2) in l.iter().zip(&b1[lo..i]).zip(&b2[lo..i]) {
                s1 += a * x1;
                s2 += a * x2;
            }
            b1[i] -= s1;
            b2[i] -= s2;
        }
        for i in (0..n).rev() {
            let hi = (i + bw).min(n - 1);
            let u = &self.data[i * w + bw + 1..i * w + bw + 1 + (hi - i)];
            let (mut s1, mut s2) = (0.0, 0.0);
            for ((a, x1), x2) in u.iter().zip(&b1[i + 1..=hi]).zip(&b2[i + 1..=hi]).rev() {
                s1 += a * x1;
                s2 += a * x2;
            }
            b1[i] = (b1[i] - s1) * self.inv_pivot[i];
            b2[i] = (b2[i] - s2) * self.inv_pivot[i];
        }
    }
}

/// The non-zero entries of a matrix by rows, in column order: its product with a vector skips
/// the band's zeros, with the same sums as [`BandMatrix::mul_vec`] (a zero entry adds nothing).
#[derive(Clone, Debug, Default)]
pub struct RowSparse {
    /// Row `i`'s entries are `start[i]..start[i + 1]`.
    start: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
}

impl RowSparse {
    /// The non-zero entries of `a`.
    pub fn from_band(a: &BandMatrix) -> Self {
        let mut r = RowSparse { start: vec![0], cols: Vec::new(), vals: Vec::new() };
        for i in 0..a.n {
            let (lo, hi) = (i.saturating_sub(a.bw), (i + a.bw).min(a.n - 1));
            for j in lo..=hi {
                let v = a.get(i, j);
                if v != 0.0 {
                    r.cols.push(j);
                    r.vals.push(v);
                }
            }
            r.start.push(r.cols.len());
        }
        r
    }

    /// `y = A x`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        for (yi, w) in y.iter_mut().zip(self.start.windows(2)) {
            let mut s = 0.0;
            for (v, &j) in self.vals[w[0]..w[1]].iter().zip(&self.cols[w[0]..w[1]]) {
                s += v * x[j];
            }
            *yi = s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A diagonally dominant band matrix with some zeros in the band.
    fn matrix(n: usize, bw: usize) -> BandMatrix {
        let mut a = BandMatrix::zeros(n, bw);
        for i in 0..n {
            for j in i.saturating_sub(bw)..=(i + bw).min(n - 1) {
                let v = if i == j { 10.0 * bw as f64 } else { ((i * 7 + j * 3) % 11) as f64 / 7.0 - 0.6 };
                if (i + 2 * j) % 5 != 0 || i == j {
                    a.add(i, j, v);
                }
            }
        }
        a
    }

    #[test]
    fn fixed_bandwidth_paths_give_the_general_results() {
        for (n, bw) in [(60, 3), (61, 5), (45, 7), (70, 11), (23, 11), (80, 15), (40, 4)] {
            let a = matrix(n, bw);
            let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let mut y = vec![0.0; n];
            let mut y_rows = vec![0.0; n];
            a.mul_vec(&x, &mut y);
            a.mul_vec_rows(0..n, &x, &mut y_rows);
            assert_eq!(y, y_rows);
            let mut y_sparse = vec![0.0; n];
            RowSparse::from_band(&a).mul_vec(&x, &mut y_sparse);
            assert_eq!(y, y_sparse);
            let mut lu = a.clone();
            lu.factorize().unwrap();
            let (mut b1, mut b2) = (y.clone(), x.clone());
            lu.solve2_in_place(&mut b1, &mut b2);
            let (mut c1, mut c2) = (y.clone(), x.clone());
            lu.solve2_dyn(&mut c1, &mut c2);
            assert_eq!((&b1, &b2), (&c1, &c2));
            let mut d = y.clone();
            lu.solve_in_place(&mut d);
            let mut e = y.clone();
            lu.solve_dyn(&mut e);
            assert_eq!(d, e);
            assert_eq!(b1, d);
            for (xi, di) in x.iter().zip(&d) {
                assert!((xi - di).abs() < 1e-12, "{xi} {di}");
            }
        }
    }
}
