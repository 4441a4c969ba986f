//! Node-block algebra of the window: `D × D` blocks and `D`-vectors as arrays, and the LU
//! factors of a block.

/// Node blocks: every node carries `D` unknowns, nodes with fewer padded with unknowns of unit
/// stiffness coupled to nothing (they stay zero).
pub(super) type Blk<const D: usize> = [[f64; D]; D];
/// A node's unknowns, or the forces on them.
pub(super) type Vct<const D: usize> = [f64; D];

/// The zero block.
pub(super) fn zb<const D: usize>() -> Blk<D> {
    [[0.0; D]; D]
}

/// `A B`.
#[inline(always)]
pub(super) fn blk_mul<const D: usize>(a: &Blk<D>, b: &Blk<D>) -> Blk<D> {
    let mut o = zb::<D>();
    for i in 0..D {
        for l in 0..D {
            let v = a[i][l];
            for j in 0..D {
                o[i][j] += v * b[l][j];
            }
        }
    }
    o
}

/// `A v`.
#[inline(always)]
pub(super) fn blk_vec<const D: usize>(a: &Blk<D>, v: &Vct<D>) -> Vct<D> {
    // Column by column: every row's sum is taken in the same order as row by row (the result is
    // the same to the bit), and the rows' sums advance together instead of one after another.
    let mut o = [0.0; D];
    for j in 0..D {
        let vj = v[j];
        for i in 0..D {
            o[i] += a[i][j] * vj;
        }
    }
    o
}

/// LU factors of a node block with partial pivoting.
#[derive(Clone, Copy)]
pub(super) struct Lu<const D: usize> {
    pub(super) m: Blk<D>,
    pub(super) perm: [usize; D],
}

impl<const D: usize> Lu<D> {
    /// The factors of `a`, or `None` where it is singular.
    pub(super) fn new(a: &Blk<D>) -> Option<Lu<D>> {
        let mut lu = Lu { m: *a, perm: [0; D] };
        lu.factorize().then_some(lu)
    }

    /// Factorises the block held in `m` in place; `false` (and `m` partly eliminated) where it is
    /// singular. In place, because a block of the MMB's seven unknowns per node is 392 bytes: built
    /// in a local and moved into its slot, every factorisation cost two more copies.
    pub(super) fn factorize(&mut self) -> bool {
        let (m, perm) = (&mut self.m, &mut self.perm);
        for (i, p) in perm.iter_mut().enumerate() {
            *p = i;
        }
        let scale = (0..D).fold(0.0f64, |s, i| s.max(m[i][i].abs())).max(1e-300);
        for k in 0..D {
            let mut piv = k;
            for i in k + 1..D {
                if m[i][k].abs() > m[piv][k].abs() {
                    piv = i;
                }
            }
            if m[piv][k].abs() <= 1e-14 * scale || !m[piv][k].is_finite() {
                return false;
            }
            if piv != k {
                m.swap(k, piv);
                perm.swap(k, piv);
            }
            let inv = 1.0 / m[k][k];
            // The rows below the pivot's, each against the pivot row's part right of the
            // diagonal (slices: no index checks in the inner loop).
            let (top, below) = m.split_at_mut(k + 1);
            let pivot_row = &top[k][k + 1..];
            for row in below {
                let l = row[k] * inv;
                row[k] = l;
                for (x, p) in row[k + 1..].iter_mut().zip(pivot_row) {
                    *x -= l * p;
                }
            }
            m[k][k] = inv;
        }
        true
    }

    #[inline(always)]
    pub(super) fn solve(&self, b: &Vct<D>) -> Vct<D> {
        let mut x = [0.0; D];
        for i in 0..D {
            x[i] = b[self.perm[i]];
        }
        for i in 0..D {
            for j in 0..i {
                x[i] -= self.m[i][j] * x[j];
            }
        }
        for i in (0..D).rev() {
            for j in i + 1..D {
                x[i] -= self.m[i][j] * x[j];
            }
            x[i] *= self.m[i][i];
        }
        x
    }

    /// `A⁻¹ B`: [`Lu::solve`] on all of `B`'s columns at once. Every column sees the operations
    /// of `solve` in its order (the result is the same to the bit); a row operation spans a row of
    /// `B`, of fixed length, where the column-by-column loops gathered each column first.
    pub(super) fn solve_blk(&self, b: &Blk<D>) -> Blk<D> {
        let mut x = zb::<D>();
        for i in 0..D {
            x[i] = b[self.perm[i]];
        }
        for i in 0..D {
            let mut xi = x[i];
            for (j, xj) in x.iter().enumerate().take(i) {
                let l = self.m[i][j];
                for c in 0..D {
                    xi[c] -= l * xj[c];
                }
            }
            x[i] = xi;
        }
        for i in (0..D).rev() {
            let mut xi = x[i];
            for (j, xj) in x.iter().enumerate().skip(i + 1) {
                let u = self.m[i][j];
                for c in 0..D {
                    xi[c] -= u * xj[c];
                }
            }
            let p = self.m[i][i];
            for v in xi.iter_mut() {
                *v *= p;
            }
            x[i] = xi;
        }
        x
    }
}

/// `A += B`.
pub(super) fn add<const D: usize>(a: &mut Blk<D>, b: &Blk<D>) {
    for i in 0..D {
        for j in 0..D {
            a[i][j] += b[i][j];
        }
    }
}

/// `A −= B`.
pub(super) fn sub<const D: usize>(a: &mut Blk<D>, b: &Blk<D>) {
    for i in 0..D {
        for j in 0..D {
            a[i][j] -= b[i][j];
        }
    }
}

/// `−A`.
pub(super) fn neg<const D: usize>(a: &Blk<D>) -> Blk<D> {
    let mut o = *a;
    for row in o.iter_mut() {
        for v in row.iter_mut() {
            *v = -*v;
        }
    }
    o
}

/// `a += b`.
pub(super) fn addv<const D: usize>(a: &mut Vct<D>, b: &Vct<D>) {
    for i in 0..D {
        a[i] += b[i];
    }
}

/// `a·b`.
pub(super) fn dot<const D: usize>(a: &Vct<D>, b: &Vct<D>) -> f64 {
    (0..D).map(|i| a[i] * b[i]).sum()
}
