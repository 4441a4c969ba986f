//! A band LU that refactorises only the rows that changed since its last factorisation.
//!
//! **Why.** On the whole mesh, a beam test's tangent changes from one Newton iteration to the next
//! only where interface points change their stiffness: the process zone, and contact faces that
//! open or close. The beams are linear, and elastic or failed points keep their stiffness. Over the
//! factorisations of a run, the rows that changed span 22 % of the unknowns of the ENF-03 example
//! and 11 % of the MMB's (the book's *Forward models → Speed*), and a band LU refactorises all of
//! them every time.
//!
//! **How.** The unknowns are split at `s` into a leading part `[0, s)` and a trailing part
//! `R = [s, n)`. `R` is factorised from its far end (the band LU of the reversed numbering) and its
//! condensed stiffness, a `bw × bw` block, is taken off the leading part's last `bw` rows; the
//! leading part is then factorised from the top. A factor row depends only on the matrix rows
//! before it in its own order of elimination, so each of the two keeps its rows up to the first
//! changed one, counted from its own end, and refactorises only the rest. `s` is put just past
//! the last changed row: a factorisation costs the changed span (and a band of margin), not the
//! whole matrix.
//!
//! Where the trailing part is empty (the first factorisation, or a change in the last row) this is
//! the top-down band LU alone, with the operations of [`BandMatrix::factorize`] in the same order,
//! so its factors are the same to the bit. Otherwise the order of elimination differs, and so do
//! the solutions, by round-off.

use super::banded::{BandError, BandMatrix};

/// The LU factors of the leading `len` rows of a band matrix, grown and cut row by row.
#[derive(Clone, Debug, Default)]
struct Prefix {
    /// Band rows: `L` left of the diagonal, `U` on and right of it.
    data: Vec<f64>,
    inv_pivot: Vec<f64>,
    len: usize,
}

impl Prefix {
    fn reset(&mut self, n: usize, w: usize) {
        self.data.clear();
        self.data.resize(n * w, 0.0);
        self.inv_pivot.clear();
        self.inv_pivot.resize(n, 0.0);
        self.len = 0;
    }

    /// Factorises rows `len..upto`, row `i` of the matrix given by `fill(i, row)`.
    fn extend(
        &mut self,
        bw: usize,
        upto: usize,
        tiny: f64,
        to_row: impl Fn(usize) -> usize,
        mut fill: impl FnMut(usize, &mut [f64]),
    ) -> Result<(), BandError> {
        let w = 2 * bw + 1;
        for i in self.len..upto {
            let (factors, rest) = self.data.split_at_mut(i * w);
            let row = &mut rest[..w];
            fill(i, row);
            eliminate(factors, &self.inv_pivot, bw, i, i, row);
            let pivot = row[bw];
            if !pivot.is_finite() || pivot.abs() <= tiny {
                self.len = i;
                return Err(BandError::SingularPivot { row: to_row(i), value: pivot });
            }
            self.inv_pivot[i] = 1.0 / pivot;
        }
        self.len = upto;
        Ok(())
    }

    /// Checks the kept pivots against the current scale (it moves with the matrix).
    fn check(&self, bw: usize, tiny: f64, to_row: impl Fn(usize) -> usize) -> Result<(), BandError> {
        let w = 2 * bw + 1;
        for i in 0..self.len {
            let pivot = self.data[i * w + bw];
            if !pivot.is_finite() || pivot.abs() <= tiny {
                return Err(BandError::SingularPivot { row: to_row(i), value: pivot });
            }
        }
        Ok(())
    }
}

/// Eliminates `row` (band row `i`, `2 bw + 1` entries) against the pivots `i − bw..hi` whose factor
/// rows `factors` holds, in increasing order, writing the multipliers into `row`'s lower part: the
/// operations a right-looking band LU does on that row, in its order.
#[inline]
fn eliminate(factors: &[f64], inv_pivot: &[f64], bw: usize, i: usize, hi: usize, row: &mut [f64]) {
    let w = 2 * bw + 1;
    for k in i.saturating_sub(bw)..hi {
        let off = k + bw - i;
        let l = row[off] * inv_pivot[k];
        row[off] = l;
        if l != 0.0 {
            let u = &factors[k * w + bw + 1..k * w + w];
            for (a, u) in row[off + 1..off + 1 + bw].iter_mut().zip(u) {
                *a -= l * u;
            }
        }
    }
}

/// Forward substitution `L y = x` over the first `rows` unknowns of `x` (unit `L` in `factors`).
fn forward(factors: &[f64], bw: usize, rows: usize, x: &mut [f64]) {
    let w = 2 * bw + 1;
    for i in 0..rows {
        let lo = i.saturating_sub(bw);
        let l = &factors[i * w + lo + bw - i..i * w + bw];
        let sum: f64 = l.iter().zip(&x[lo..i]).map(|(a, x)| a * x).sum();
        x[i] -= sum;
    }
}

/// Back substitution `U x = y` over the first `rows` unknowns of `x`; the unknowns after them
/// (up to `x.len()`) are known and enter through `U`'s couplings. Each row's sum takes the farthest
/// unknowns first, so only its last product waits for the row solved before.
fn backward(factors: &[f64], inv_pivot: &[f64], bw: usize, rows: usize, x: &mut [f64]) {
    let w = 2 * bw + 1;
    for i in (0..rows).rev() {
        let hi = (i + bw).min(x.len() - 1);
        let u = &factors[i * w + bw + 1..i * w + bw + 1 + (hi - i)];
        let sum = u.iter().zip(&x[i + 1..=hi]).rev().fold(0.0, |acc, (a, x)| acc + a * x);
        x[i] = (x[i] - sum) * inv_pivot[i];
    }
}

/// Band LU factorisation that refactorises only what changed since the last one (see the module).
#[derive(Clone, Debug, Default)]
pub struct SpanLu {
    n: usize,
    bw: usize,
    /// The matrix last factorised (its band rows), against which the next one is compared.
    reference: Vec<f64>,
    /// Whether the factors are those of `reference` (a failed factorisation leaves them not).
    valid: bool,
    /// Start of the trailing part.
    s: usize,
    /// Rows of `top` that do not hold the trailing part's condensed stiffness.
    top_clean: usize,
    /// Leading part `[0, s)`, with the trailing part's condensed stiffness in its last rows.
    top: Prefix,
    /// Trailing part in reversed numbering (row `i` is row `n − 1 − i`).
    bottom: Prefix,
    /// The leading part's last `bw` rows with the trailing part condensed into them (band rows,
    /// columns from `s` on dropped), and their multipliers against the trailing part's pivots.
    boundary: Vec<f64>,
    boundary_l: Vec<f64>,
    /// Work array of the solves.
    scratch: Vec<f64>,
    /// Where every row is to be refactorised: the band LU itself (its fixed-bandwidth kernels),
    /// whose factors `top` takes over when a later factorisation can keep some.
    full: BandMatrix,
    full_mode: bool,
    /// Rows eliminated since construction (a full band LU eliminates `n` per factorisation).
    pub rows_eliminated: usize,
}

impl SpanLu {
    /// Factorises `a` (its order as set by [`BandMatrix::set_order`]), reusing the factors of the
    /// last matrix for the rows that did not change.
    pub fn factorize(&mut self, a: &BandMatrix) -> Result<(), BandError> {
        self.factorize_within(a, None)
    }

    /// [`SpanLu::factorize`] told that only rows `lo..=hi` of `a` can differ from the last matrix
    /// (`Some(None)`: none can; `None`: any): the changed rows are looked for there alone, and
    /// they are the ones a search of every row finds (checked in debug builds).
    pub(crate) fn factorize_within(
        &mut self,
        a: &BandMatrix,
        within: Option<Option<(usize, usize)>>,
    ) -> Result<(), BandError> {
        let (n, bw) = (a.n(), a.bandwidth());
        let w = 2 * bw + 1;
        if n != self.n || bw != self.bw || self.reference.len() != n * w {
            self.n = n;
            self.bw = bw;
            self.reference.clear();
            self.reference.resize(n * w, 0.0);
            self.valid = false;
            // The parts are allocated at the first split.
            (self.top.len, self.bottom.len) = (0, 0);
            self.s = n;
            self.top_clean = 0;
            self.full = BandMatrix::zeros(n, bw);
            self.full_mode = false;
        }
        // Bit for bit (an OR of XORs, which vectorises; a row is short).
        let same = |i: usize| {
            let diff = a.band_row(i).iter().zip(&self.reference[i * w..(i + 1) * w]);
            diff.fold(0u64, |acc, (x, y)| acc | (x.to_bits() ^ y.to_bits())) == 0
        };
        let (first, last) = if self.valid {
            let (lo, hi) = match within {
                None => (0, n),
                Some(None) => (0, 0),
                Some(Some((lo, hi))) => (lo.min(n), (hi + 1).min(n)),
            };
            debug_assert!(
                (0..lo).chain(hi..n).all(same),
                "a row outside {lo}..{hi} changed since the last factorisation"
            );
            match (lo..hi).find(|&i| !same(i)) {
                None => return Ok(()),
                Some(first) => (first, (first..hi).rev().find(|&i| !same(i)).unwrap_or(first)),
            }
        } else {
            (0, n - 1)
        };
        for i in first..=last {
            self.reference[i * w..(i + 1) * w].copy_from_slice(a.band_row(i));
        }
        self.valid = false;
        // A trailing part of a band or less is not worth its condensation.
        let s = if n - 1 - last > bw { last + 1 } else { n };
        // Where most rows changed, the band LU's fixed-bandwidth kernels refactorise them faster
        // than a split would (co-rotational beams change every row); with nothing to keep and
        // nothing to split off (a first factorisation) it is the band LU anyway.
        if 2 * (last + 1 - first) >= n || s == n && first == 0 {
            self.full.copy_leading_from(a);
            self.full.factorize()?;
            self.rows_eliminated += n;
            (self.full_mode, self.valid, self.s) = (true, true, n);
            return Ok(());
        }
        // The pivots' floor, as the band LU's: relative to the largest diagonal entry.
        let mut scale = 0.0f64;
        for i in 0..n {
            scale = scale.max(a.band_row(i)[bw].abs());
        }
        let tiny = scale * 1e-14;
        let nb_rows = if s < n { bw.min(s) } else { 0 };
        if self.top.data.len() != n * w {
            self.top.reset(n, w);
            self.bottom.reset(n, w);
            self.boundary = vec![0.0; bw * w];
            self.boundary_l = vec![0.0; bw * bw];
        }
        if self.full_mode {
            let (factors, inv) = self.full.factors();
            self.top.data[..n * w].copy_from_slice(factors);
            self.top.inv_pivot[..n].copy_from_slice(inv);
            (self.top.len, self.top_clean, self.bottom.len, self.full_mode) = (n, n, 0, false);
        }
        // What each part keeps: the top its rows before the first change that hold neither the
        // old nor the new trailing part's condensed stiffness; the bottom its rows after the last
        // change.
        let keep_top = first.min(self.top_clean).min(self.top.len).min(s - nb_rows);
        let keep_bottom = (n - 1 - last).min(self.bottom.len);
        self.top.len = keep_top;
        self.bottom.len = keep_bottom.min(n - s);
        self.s = s;
        let rev = |i: usize| n - 1 - i;
        self.top.check(bw, tiny, |i| i)?;
        self.bottom.check(bw, tiny, rev)?;
        let reference = &self.reference;
        let reversed = |i: usize, row: &mut [f64]| {
            for (x, y) in row.iter_mut().zip(reference[rev(i) * w..(rev(i) + 1) * w].iter().rev()) {
                *x = *y;
            }
        };
        let nb = n - s;
        self.rows_eliminated += (nb - self.bottom.len) + (s - self.top.len);
        self.bottom.extend(bw, nb, tiny, rev, reversed)?;
        if nb > 0 {
            // The boundary rows (reversed: nb..nb + bw) eliminated against the bottom's pivots;
            // what is left right of them (the leading part's columns) is their condensed row.
            let mut row = vec![0.0; w];
            for r in 0..bw.min(s) {
                let i = nb + r;
                reversed(i, &mut row);
                eliminate(&self.bottom.data, &self.bottom.inv_pivot, bw, i, nb, &mut row);
                let lo = i.saturating_sub(bw);
                for k in lo..nb {
                    self.boundary_l[r * bw + (k + bw - nb)] = row[k + bw - i];
                }
                // Back to the leading part's numbering, columns from `s` on (reversed: < nb) dropped.
                let out = &mut self.boundary[r * w..(r + 1) * w];
                for (o, v) in out.iter_mut().zip(row.iter().rev()) {
                    *o = *v;
                }
                let keep = nb + bw - i; // reversed offsets below this are columns < nb
                for o in out.iter_mut().rev().take(keep) {
                    *o = 0.0;
                }
            }
        }
        let boundary = &self.boundary;
        let leading = |i: usize, row: &mut [f64]| {
            if nb > 0 && i >= s - nb_rows {
                // Boundary row r: reversed row nb + r is leading row s − 1 − r.
                let r = s - 1 - i;
                row.copy_from_slice(&boundary[r * w..(r + 1) * w]);
            } else {
                row.copy_from_slice(&reference[i * w..(i + 1) * w]);
            }
        };
        self.top.extend(bw, s, tiny, |i| i, leading)?;
        self.top_clean = if nb > 0 { s - nb_rows } else { s };
        self.valid = true;
        Ok(())
    }

    /// Solves `A x = b` in place with the factors of the last [`SpanLu::factorize`].
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        if self.full_mode {
            return self.full.solve_in_place(b);
        }
        let (n, bw, s) = (self.n, self.bw, self.s);
        let nb = n - s;
        // The trailing part in its own (reversed) numbering, followed by the leading part's last
        // `bw` unknowns it couples to, also reversed: its substitutions then run over contiguous
        // memory.
        let y = &mut self.scratch;
        y.clear();
        y.extend(b[s..n].iter().rev());
        forward(&self.bottom.data, bw, nb, y);
        // Its condensation into the boundary rows (reversed `nb + r` is leading `s − 1 − r`).
        if nb > 0 {
            for r in 0..bw.min(s) {
                let lo = (nb + r).saturating_sub(bw);
                let l = &self.boundary_l[r * bw + (lo + bw - nb)..(r + 1) * bw];
                let sum: f64 = l.iter().zip(&y[lo..nb]).map(|(a, x)| a * x).sum();
                b[s - 1 - r] -= sum;
            }
        }
        // Leading part, forward and backward.
        forward(&self.top.data, bw, s, &mut b[..s]);
        backward(&self.top.data, &self.top.inv_pivot, bw, s, &mut b[..s]);
        if nb == 0 {
            return;
        }
        // Trailing part, backward: its rows' couplings to the leading part use the solution there.
        y.extend(b[s.saturating_sub(bw)..s].iter().rev());
        backward(&self.bottom.data, &self.bottom.inv_pivot, bw, nb, y);
        for (bi, yi) in b[s..n].iter_mut().zip(y[..nb].iter().rev()) {
            *bi = *yi;
        }
    }

    /// Solves `A x = b1` and `A y = b2` in place.
    pub fn solve2_in_place(&mut self, b1: &mut [f64], b2: &mut [f64]) {
        if self.full_mode {
            return self.full.solve2_in_place(b1, b2);
        }
        self.solve_in_place(b1);
        self.solve_in_place(b2);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A diagonally dominant band matrix, its entries shifted by `seed` in the rows `changed`.
    fn matrix(n: usize, bw: usize, changed: std::ops::Range<usize>, seed: f64) -> BandMatrix {
        let mut a = BandMatrix::zeros(n, bw);
        for i in 0..n {
            for j in i.saturating_sub(bw)..=(i + bw).min(n - 1) {
                let mut v = if i == j { 10.0 * bw as f64 } else { ((i * 7 + j * 3) % 11) as f64 / 7.0 - 0.6 };
                if changed.contains(&i) && changed.contains(&j) {
                    v += seed * (((i + 2 * j) % 5) as f64 - 2.0) / 3.0;
                }
                if (i + 2 * j) % 5 != 0 || i == j {
                    a.add(i, j, v);
                }
            }
        }
        a
    }

    fn rhs(n: usize) -> Vec<f64> {
        (0..n).map(|i| (i as f64 * 0.37).sin()).collect()
    }

    /// The solution by the plain band LU.
    fn reference_solution(a: &BandMatrix) -> Vec<f64> {
        let mut lu = a.clone();
        lu.factorize().unwrap();
        let mut x = rhs(a.n());
        lu.solve_in_place(&mut x);
        x
    }

    #[test]
    fn a_first_factorisation_is_the_band_lu_to_the_bit() {
        for (n, bw) in [(60, 3), (70, 11), (23, 11), (80, 15)] {
            let a = matrix(n, bw, 0..0, 0.0);
            let mut lu = SpanLu::default();
            lu.factorize(&a).unwrap();
            let mut x = rhs(n);
            lu.solve_in_place(&mut x);
            assert_eq!(x, reference_solution(&a));
            assert_eq!(lu.rows_eliminated, n);
        }
    }

    #[test]
    fn changed_spans_anywhere_give_the_band_lus_solutions_and_eliminate_only_their_rows() {
        for (n, bw) in [(90, 3), (120, 11), (150, 15)] {
            let mut lu = SpanLu::default();
            lu.factorize(&matrix(n, bw, 0..0, 0.0)).unwrap();
            // A span moving through the matrix, one at its start, one at its end, one that
            // covers it all, and one too short to split.
            let spans = [(40, 60), (45, 66), (50, 70), (30, 50), (0, 10), (n - 8, n), (0, n), (60, 62), (61, 63)];
            let mut previous = (0, 0);
            let mut split = false;
            for (step, &(lo, hi)) in spans.iter().enumerate() {
                let a = matrix(n, bw, lo..hi, 1.0 + step as f64);
                let before = lu.rows_eliminated;
                lu.factorize(&a).unwrap();
                let mut x = rhs(n);
                lu.solve_in_place(&mut x);
                let want = reference_solution(&a);
                let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (i, (xi, wi)) in x.iter().zip(&want).enumerate() {
                    assert!((xi - wi).abs() <= 1e-12 * scale, "n {n} bw {bw} span {lo}..{hi} row {i}: {xi} vs {wi}");
                }
                // The rows that differ from the last matrix are those of this span and the last;
                // each is eliminated again, and for a change inside, little more: the band's
                // margin and the trailing part's move (a split after a change reaching the end
                // also factorises the trailing part).
                let (from, to) = if previous == (0, 0) { (lo, hi) } else { (lo.min(previous.0), hi.max(previous.1)) };
                previous = (lo, hi);
                let done = lu.rows_eliminated - before;
                assert!(done >= to - from, "{done} rows for the rows {from}..{to}");
                let inside = to + bw + 1 < n;
                if split && from >= 30 && inside {
                    assert!(done <= (to - from) + 2 * bw + 10, "{done} rows for the rows {from}..{to} of {n}");
                }
                split = inside;
                // Solved again with nothing changed: no row eliminated, the same solution.
                let before = lu.rows_eliminated;
                lu.factorize(&a).unwrap();
                assert_eq!(lu.rows_eliminated, before);
                let mut y = rhs(n);
                lu.solve_in_place(&mut y);
                assert_eq!(x, y);
            }
        }
    }

    #[test]
    fn two_right_hand_sides_and_a_changed_order_are_solved_as_by_the_band_lu() {
        let (n, bw) = (100, 11);
        let mut lu = SpanLu::default();
        lu.factorize(&matrix(n, bw, 0..0, 0.0)).unwrap();
        let a = matrix(n, bw, 40..55, 2.0);
        lu.factorize(&a).unwrap();
        let (mut b1, mut b2) = (rhs(n), vec![1.0; n]);
        lu.solve2_in_place(&mut b1, &mut b2);
        let mut full = a.clone();
        full.factorize().unwrap();
        let (mut c1, mut c2) = (rhs(n), vec![1.0; n]);
        full.solve2_in_place(&mut c1, &mut c2);
        for (x, y) in b1.iter().zip(&c1).chain(b2.iter().zip(&c2)) {
            assert!((x - y).abs() <= 1e-12 * y.abs().max(1.0), "{x} vs {y}");
        }
        // The leading 70 unknowns alone: a new order starts again from the top.
        let mut a70 = a.clone();
        a70.set_order(70);
        lu.factorize(&a70).unwrap();
        let mut x = rhs(70);
        lu.solve_in_place(&mut x);
        assert_eq!(x, reference_solution(&a70));
    }

    #[test]
    fn a_singular_pivot_is_reported_at_its_row_and_the_next_factorisation_starts_afresh() {
        let (n, bw) = (80, 5);
        let mut lu = SpanLu::default();
        let good = matrix(n, bw, 0..0, 0.0);
        lu.factorize(&good).unwrap();
        let mut bad = good.clone();
        bad.add(50, 50, f64::NAN);
        // Only row 50 changed: the split path finds it.
        assert!(matches!(lu.factorize(&bad), Err(BandError::SingularPivot { row: 50, .. })));
        lu.factorize(&good).unwrap();
        let mut x = rhs(n);
        lu.solve_in_place(&mut x);
        assert_eq!(x, reference_solution(&good));
    }
}
