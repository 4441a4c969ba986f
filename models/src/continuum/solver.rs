//! The linear solver of the continuum models: the band LU the beam engine uses, or faer's sparse
//! LU. Both see the same matrix through [`System`]; the book's "Beam or continuum?" chapter
//! gives their measured times on the continuum DCB, and the faster is the default.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use serde::{Deserialize, Serialize};

use crate::fe::banded::BandMatrix;

/// Which factorisation solves the Newton systems.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverKind {
    /// Dense LU over the band of the column-by-column numbering (no pivoting; the default: it
    /// measured faster on these meshes, see the book).
    #[default]
    Band,
    /// faer's sparse LU (supernodal, partial pivoting), its symbolic analysis done once per run.
    Sparse,
}

/// A square matrix assembled entry by entry, factorised and solved.
pub struct System {
    store: Store,
}

enum Store {
    Band(BandMatrix),
    Sparse(Box<SparseStore>),
}

struct SparseStore {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    symbolic: Option<SymbolicLu<usize>>,
    lu: Option<Lu<usize, f64>>,
}

impl SparseStore {
    fn index(&self, i: usize, j: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[j], self.col_ptr[j + 1]);
        self.row_idx[a..b].binary_search(&i).ok().map(|k| a + k)
    }
}

impl System {
    /// An `n × n` system whose non-zeros lie within half-bandwidth `bw` and, for the sparse
    /// solver, on the symmetric pattern `couplings` (each list: the unknowns coupled to one
    /// unknown, itself included).
    pub fn new(kind: SolverKind, n: usize, bw: usize, couplings: impl Fn(usize) -> Vec<usize>) -> System {
        let store = match kind {
            SolverKind::Band => Store::Band(BandMatrix::zeros(n, bw)),
            SolverKind::Sparse => {
                let mut col_ptr = vec![0];
                let mut row_idx = Vec::new();
                for j in 0..n {
                    let mut rows = couplings(j);
                    rows.sort_unstable();
                    rows.dedup();
                    row_idx.extend(rows);
                    col_ptr.push(row_idx.len());
                }
                let values = vec![0.0; row_idx.len()];
                Store::Sparse(Box::new(SparseStore { n, col_ptr, row_idx, values, symbolic: None, lu: None }))
            }
        };
        System { store }
    }

    /// Stored entries (the band's, or the sparse pattern's).
    pub fn stored(&self) -> usize {
        match &self.store {
            Store::Band(b) => b.n() * (2 * b.bandwidth() + 1),
            Store::Sparse(s) => s.values.len(),
        }
    }

    /// Sets every entry to zero.
    pub fn clear(&mut self) {
        match &mut self.store {
            Store::Band(b) => b.clear(),
            Store::Sparse(s) => s.values.fill(0.0),
        }
    }

    /// Takes the entries of `other` (a system of the same pattern).
    pub fn copy_from(&mut self, other: &System) {
        match (&mut self.store, &other.store) {
            (Store::Band(a), Store::Band(b)) => a.copy_from(b),
            (Store::Sparse(a), Store::Sparse(b)) => a.values.copy_from_slice(&b.values),
            _ => unreachable!("systems of one problem share their storage"),
        }
    }

    /// `y = A x` (before factorisation).
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        match &self.store {
            Store::Band(b) => b.mul_vec(x, y),
            Store::Sparse(s) => {
                y.fill(0.0);
                for j in 0..s.n {
                    for p in s.col_ptr[j]..s.col_ptr[j + 1] {
                        y[s.row_idx[p]] += s.values[p] * x[j];
                    }
                }
            }
        }
    }

    /// Adds `v` to entry `(i, j)` (which must be in the pattern).
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        match &mut self.store {
            Store::Band(b) => b.add(i, j, v),
            Store::Sparse(s) => {
                let k = s.index(i, j).expect("entry outside the sparse pattern");
                s.values[k] += v;
            }
        }
    }

    /// Entry `(i, j)`, zero outside the pattern.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        match &self.store {
            Store::Band(b) => {
                if i.abs_diff(j) <= b.bandwidth() {
                    b.get(i, j)
                } else {
                    0.0
                }
            }
            Store::Sparse(s) => s.index(i, j).map_or(0.0, |k| s.values[k]),
        }
    }

    /// The unknowns that may couple with `i` (its row and column in the pattern).
    pub fn neighbours(&self, i: usize) -> std::ops::Range<usize> {
        match &self.store {
            Store::Band(b) => i.saturating_sub(b.bandwidth())..(i + b.bandwidth() + 1).min(b.n()),
            Store::Sparse(s) => {
                let rows = &s.row_idx[s.col_ptr[i]..s.col_ptr[i + 1]];
                rows[0]..rows[rows.len() - 1] + 1
            }
        }
    }

    /// Replaces row and column `i` by those of the identity (a prescribed unknown).
    pub fn set_identity(&mut self, i: usize) {
        match &mut self.store {
            Store::Band(b) => b.set_identity_row_col(i),
            Store::Sparse(s) => {
                // The pattern is symmetric: the rows of column i are the columns of row i.
                for p in s.col_ptr[i]..s.col_ptr[i + 1] {
                    let r = s.row_idx[p];
                    s.values[p] = if r == i { 1.0 } else { 0.0 };
                    if r != i {
                        if let Some(k) = s.index(i, r) {
                            s.values[k] = 0.0;
                        }
                    }
                }
            }
        }
    }

    /// Factorises in place; `Err` names why (a singular pivot: the step is cut).
    pub fn factor(&mut self) -> Result<(), String> {
        match &mut self.store {
            Store::Band(b) => b.factorize().map_err(|e| format!("{e:?}")),
            Store::Sparse(s) => {
                let pattern = SymbolicSparseColMatRef::new_checked(s.n, s.n, &s.col_ptr, None, &s.row_idx);
                if s.symbolic.is_none() {
                    s.symbolic = Some(SymbolicLu::try_new(pattern).map_err(|e| format!("{e:?}"))?);
                }
                let sym = s.symbolic.clone().expect("analysed above");
                let lu = Lu::try_new_with_symbolic(sym, SparseColMatRef::new(pattern, &s.values))
                    .map_err(|e| format!("{e:?}"))?;
                s.lu = Some(lu);
                Ok(())
            }
        }
    }

    /// Solves two right-hand sides with the factors, in place (the same results as two
    /// [`System::solve`]s; the band's two substitutions interleaved).
    pub fn solve2(&self, b1: &mut [f64], b2: &mut [f64]) {
        match &self.store {
            Store::Band(m) => m.solve2_in_place(b1, b2),
            Store::Sparse(_) => {
                self.solve(b1);
                self.solve(b2);
            }
        }
    }

    /// Solves with the factors, in place.
    pub fn solve(&self, b: &mut [f64]) {
        match &self.store {
            Store::Band(m) => m.solve_in_place(b),
            Store::Sparse(s) => {
                let n = b.len();
                if let Some(lu) = &s.lu {
                    lu.solve_in_place(faer::MatMut::from_column_major_slice_mut(b, n, 1));
                }
            }
        }
    }
}
