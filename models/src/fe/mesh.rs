//! Meshes of beam layers on a shared axial grid, and their numbering of unknowns.
//!
//! Every layer is a straight Timoshenko beam along `x` whose centroid sits at height `y`. All
//! layers use the nodes of one grid `x[0] < x[1] < ...` (a layer may span a sub-range), so an
//! interface between two layers pairs nodes with the same index. Unknowns are numbered node by
//! node (all layers of node 0, then node 1, ...), which keeps the half-bandwidth at
//! `2 × (unknowns per node) − 1` whatever the length: the band solver's cost grows linearly with
//! the number of elements.

use czid_core::{CzError, Result};

/// Marks an unknown that does not exist (axial displacement of a layer without axial unknowns).
pub const NONE: usize = usize::MAX;

/// Shear correction factor of a rectangular section (Timoshenko, parabolic shear stress).
pub const SHEAR_FACTOR: f64 = 5.0 / 6.0;

/// Rectangular cross-section and the moduli the beam sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    /// Axial modulus (MPa): E11 in plane stress, E11/(1 − ν13 ν31) in plane strain.
    pub e: f64,
    /// Transverse shear modulus G13 (MPa).
    pub g: f64,
    /// Width (mm).
    pub b: f64,
    /// Thickness (mm).
    pub h: f64,
}

impl Section {
    /// Axial stiffness EA (N).
    pub fn ea(&self) -> f64 {
        self.e * self.b * self.h
    }
    /// Bending stiffness EI (N·mm²).
    pub fn ei(&self) -> f64 {
        self.e * self.b * self.h.powi(3) / 12.0
    }
    /// Shear stiffness κGA (N).
    pub fn ga(&self) -> f64 {
        SHEAR_FACTOR * self.g * self.b * self.h
    }
}

/// One beam layer.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Section and moduli.
    pub section: Section,
    /// Height of the centroid (mm) in the undeformed configuration.
    pub y: f64,
    /// Whether the layer carries axial unknowns. A single layer loaded only transversely with
    /// small rotations never stretches, so dropping them is exact there and shrinks the band.
    pub axial: bool,
    /// First node of the layer (index into [`Mesh::x`]).
    pub first: usize,
    /// Last node of the layer (inclusive).
    pub last: usize,
}

/// Nodes, layers and the numbering of unknowns.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Axial node coordinates (mm), strictly increasing.
    pub x: Vec<f64>,
    /// The layers.
    pub layers: Vec<Layer>,
    /// Extra scalar unknowns numbered first (e.g. an actuator behind a machine spring).
    pub extra: usize,
    dofs: Vec<[usize; 3]>,
    n_dofs: usize,
    bandwidth: usize,
}

impl Mesh {
    /// Numbers the unknowns of `layers` on the grid `x`, with `extra` scalar unknowns first.
    pub fn new(x: Vec<f64>, layers: Vec<Layer>, extra: usize) -> Result<Self> {
        if x.len() < 2 {
            return Err(CzError::Simulation("a mesh needs at least two nodes".into()));
        }
        if x.windows(2).any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater)) {
            return Err(CzError::Simulation("mesh nodes must be strictly increasing".into()));
        }
        for (k, l) in layers.iter().enumerate() {
            if l.first >= l.last || l.last >= x.len() {
                return Err(CzError::Simulation(format!("layer {k} spans an invalid node range")));
            }
        }
        let nl = layers.len();
        let mut dofs = vec![[NONE; 3]; nl * x.len()];
        let mut next = extra;
        let mut max_per_node = 0;
        for i in 0..x.len() {
            let start = next;
            for (k, l) in layers.iter().enumerate() {
                if i < l.first || i > l.last {
                    continue;
                }
                let d = &mut dofs[i * nl + k];
                if l.axial {
                    d[0] = next;
                    next += 1;
                }
                d[1] = next;
                d[2] = next + 1;
                next += 2;
            }
            max_per_node = max_per_node.max(next - start);
        }
        // Neighbouring nodes couple at most 2 × (unknowns per node) − 1 apart; extra unknowns
        // couple to the first node only (checked by the band matrix in debug builds).
        let bandwidth = (2 * max_per_node).max(extra + max_per_node + 1) - 1;
        Ok(Mesh { x, layers, extra, dofs, n_dofs: next, bandwidth })
    }

    /// Unknowns `[u, w, θ]` of `layer` at `node` ([`NONE`] where absent).
    #[inline]
    pub fn dofs(&self, layer: usize, node: usize) -> [usize; 3] {
        self.dofs[node * self.layers.len() + layer]
    }

    /// Number of unknowns.
    pub fn n_dofs(&self) -> usize {
        self.n_dofs
    }

    /// Half-bandwidth of the global matrices.
    pub fn bandwidth(&self) -> usize {
        self.bandwidth
    }
}

/// Node coordinates covering `[x0, x1]` with `n` equal elements.
pub fn uniform(x0: f64, x1: f64, n: usize) -> Vec<f64> {
    let n = n.max(1);
    (0..=n).map(|i| if i == n { x1 } else { x0 + (x1 - x0) * i as f64 / n as f64 }).collect()
}

/// Grid through the breakpoints `points` (increasing), each segment split into elements no
/// longer than the matching entry of `sizes` (`sizes.len() == points.len() − 1`).
///
/// Element counts are `ceil(length / size)`: nodes move continuously with the breakpoints (so
/// responses are smooth in geometric parameters) except where a count changes.
pub fn graded(points: &[f64], sizes: &[f64]) -> Vec<f64> {
    let mut x = vec![points[0]];
    for (seg, size) in points.windows(2).zip(sizes) {
        let len = seg[1] - seg[0];
        let n = ((len / size) - 1e-9).ceil().max(1.0) as usize;
        x.extend(uniform(seg[0], seg[1], n).into_iter().skip(1));
    }
    x
}
