//! Structured meshes of the arms: columns of nodes along the specimen, rows through each layer's
//! thickness, numbered column by column (so the stiffness matrix is banded with a half-bandwidth
//! of about twice the nodes in a column).

use super::quad::Quad;

/// One layer (an arm) of the mesh: the heights of its rows of nodes (mm, bottom to top).
#[derive(Clone, Debug, PartialEq)]
pub struct LayerRows {
    /// Heights of the rows (mm), increasing.
    pub ys: Vec<f64>,
    /// Index of the layer's first node within a column.
    pub offset: usize,
}

/// Layers of quadrilaterals sharing one set of columns.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Positions of the columns (mm), increasing.
    pub xs: Vec<f64>,
    /// The layers, bottom to top; layers do not share nodes (an interface joins them).
    pub layers: Vec<LayerRows>,
    /// Nodes per column.
    pub per_column: usize,
    /// Out-of-plane thickness (the specimen's width, mm).
    pub width: f64,
}

impl Grid {
    /// A grid over columns `xs` of layers whose rows are `layers` (each bottom to top).
    pub fn new(xs: Vec<f64>, layers: Vec<Vec<f64>>, width: f64) -> Grid {
        let mut offset = 0;
        let layers: Vec<LayerRows> = layers
            .into_iter()
            .map(|ys| {
                let l = LayerRows { offset, ys };
                offset += l.ys.len();
                l
            })
            .collect();
        Grid { xs, layers, per_column: offset, width }
    }

    /// Node of layer `l` at column `c`, row `r`.
    pub fn node(&self, l: usize, c: usize, r: usize) -> usize {
        c * self.per_column + self.layers[l].offset + r
    }

    /// Reference position of a node (mm).
    pub fn position(&self, node: usize) -> [f64; 2] {
        let (c, k) = (node / self.per_column, node % self.per_column);
        let l = self.layers.iter().rposition(|l| l.offset <= k).unwrap_or(0);
        [self.xs[c], self.layers[l].ys[k - self.layers[l].offset]]
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.xs.len() * self.per_column
    }

    /// The elements: their four nodes (counter-clockwise) and geometry.
    pub fn elements(&self) -> Vec<([usize; 4], Quad)> {
        let mut out = Vec::new();
        for c in 0..self.xs.len().saturating_sub(1) {
            for (l, layer) in self.layers.iter().enumerate() {
                for r in 0..layer.ys.len().saturating_sub(1) {
                    let n = [
                        self.node(l, c, r),
                        self.node(l, c + 1, r),
                        self.node(l, c + 1, r + 1),
                        self.node(l, c, r + 1),
                    ];
                    let nodes = n.map(|k| self.position(k));
                    out.push((n, Quad { nodes, thickness: self.width }));
                }
            }
        }
        out
    }

    /// Half-bandwidth (in unknowns, two per node) of the stiffness matrix, counting also the
    /// couplings `extra` (pairs of nodes joined by interface points).
    pub fn bandwidth(&self, extra: &[(usize, usize)]) -> usize {
        // Element corners lie at most one column and one row apart.
        let within = self.per_column + 1;
        let across = extra.iter().map(|&(a, b)| a.abs_diff(b)).max().unwrap_or(0);
        2 * within.max(across) + 1
    }
}

/// Column positions over `[x0, x1]` with elements of at most `size` (mm), equal within the span.
pub fn uniform(x0: f64, x1: f64, size: f64) -> Vec<f64> {
    let n = ((x1 - x0) / size - 1e-9).ceil().max(1.0) as usize;
    (0..=n).map(|i| if i == n { x1 } else { x0 + (x1 - x0) * i as f64 / n as f64 }).collect()
}

/// Column positions over `[x0, x1]` growing geometrically (ratio `growth`) from `fine` at `x1`
/// towards `x0`, up to `coarse` (mm): the cracked arms, fine at the crack front only.
pub fn graded_towards_end(x0: f64, x1: f64, fine: f64, coarse: f64, growth: f64) -> Vec<f64> {
    let mut sizes = Vec::new();
    let (mut left, mut s) = (x1 - x0, fine);
    while left > 1e-12 {
        let step = s.min(coarse).min(left);
        sizes.push(step);
        left -= step;
        s *= growth;
    }
    // Spread a sliver at the far end over the far half of the elements (the coarse ones) rather
    // than keep it; the fine elements at the front keep their size.
    if sizes.len() > 1 && *sizes.last().unwrap() < 0.5 * sizes[sizes.len() - 2] {
        let sliver = sizes.pop().unwrap();
        let half = sizes.len() / 2;
        let n = (sizes.len() - half) as f64;
        sizes[half..].iter_mut().for_each(|v| *v += sliver / n);
    }
    let mut xs = vec![x1];
    for s in sizes {
        xs.push(xs.last().unwrap() - s);
    }
    *xs.last_mut().unwrap() = x0;
    xs.reverse();
    xs
}

/// Column positions over `[x0, x1]` growing geometrically from `fine` at `x0` towards `x1`, up
/// to `coarse` (mm): the mirror image of [`graded_towards_end`].
pub fn graded_from_start(x0: f64, x1: f64, fine: f64, coarse: f64, growth: f64) -> Vec<f64> {
    let mirrored = graded_towards_end(0.0, x1 - x0, fine, coarse, growth);
    let mut xs: Vec<f64> = mirrored.iter().rev().map(|&x| x0 + (x1 - x0) - x).collect();
    xs[0] = x0;
    *xs.last_mut().expect("at least two columns") = x1;
    xs
}

/// Row heights from `y0` to `y1` in `n` equal elements.
pub fn rows(y0: f64, y1: f64, n: usize) -> Vec<f64> {
    graded_rows(y0, y1, n, 1.0)
}

/// Row heights from `y0` to `y1` in `n` elements, each `growth` times as thick as the one before
/// (`growth < 1`: thinning towards `y1`).
pub fn graded_rows(y0: f64, y1: f64, n: usize, growth: f64) -> Vec<f64> {
    let weights: Vec<f64> = (0..n).map(|i| growth.powi(i as i32)).collect();
    let total: f64 = weights.iter().sum();
    let mut ys = vec![y0];
    let mut acc = 0.0;
    for (i, w) in weights.iter().enumerate() {
        acc += w;
        ys.push(if i + 1 == n { y1 } else { y0 + (y1 - y0) * acc / total });
    }
    ys
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn graded_columns_span_the_interval_finely_at_the_front() {
        let xs = graded_towards_end(0.0, 50.0, 0.1, 1.0, 1.2);
        assert_eq!(xs[0], 0.0);
        assert_eq!(*xs.last().unwrap(), 50.0);
        assert!((xs[xs.len() - 1] - xs[xs.len() - 2] - 0.1).abs() < 1e-9);
        assert!(xs.windows(2).all(|w| w[1] > w[0] && w[1] - w[0] <= 1.0 + 0.1));
    }

    #[test]
    fn graded_rows_grow_by_the_ratio() {
        let ys = graded_rows(0.0, 15.0, 4, 2.0);
        assert_eq!(ys, vec![0.0, 1.0, 3.0, 7.0, 15.0]);
        let down = graded_rows(0.0, 15.0, 4, 0.5);
        assert!((down[4] - down[3] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn numbering_is_by_columns() {
        let g = Grid::new(vec![0.0, 1.0, 2.0], vec![rows(0.0, 1.0, 2), rows(1.0, 2.0, 1)], 1.0);
        assert_eq!(g.per_column, 5);
        assert_eq!(g.node(1, 2, 1), 14);
        assert_eq!(g.position(14), [2.0, 2.0]);
        assert_eq!(g.elements().len(), 6);
        assert_eq!(g.bandwidth(&[]), 13);
    }
}
