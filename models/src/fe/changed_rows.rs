//! Which rows of a small-rotation tangent can differ from those of the last one assembled, and of
//! the last one factorised.
//!
//! The tangent is the linear part (beams, springs: the same at every assembly) plus what every
//! interface item scatters into the rows of its unknowns: a point under the nodal rule its
//! stiffness, a segment its Jacobian (the gap gradients being constant). An item whose stiffness
//! or Jacobian is the same to the bit as at the last factorisation adds the same numbers in the
//! same order, so only the rows of items that changed can differ. [`super::span_lu::SpanLu`]
//! looks for the changed rows by comparing the whole band with its last one; told where they can
//! be, it compares those rows alone and finds the same ones; and an assembly into the buffer of
//! the last tangent rebuilds only the rows of items that changed since that one. On the ENF the
//! rows that change lie in the process zone and at contact faces that open or close, a fifth of
//! the band on average.

use czid_core::Tangent;

/// The interface items' stiffnesses at the last assembly of a tangent, the rows each item
/// writes, and the rows of the items that changed since the tangent assembled before and since the
/// last factorisation.
#[derive(Clone, Debug, Default)]
pub(crate) struct ChangedRows {
    /// Per point (nodal rule) and per segment: the first and last row it writes (`None`: none).
    point_rows: Vec<Option<(usize, usize)>>,
    segment_rows: Vec<Option<(usize, usize)>>,
    assembled_points: Vec<Tangent>,
    assembled_segments: Vec<[[Tangent; 2]; 2]>,
    /// The items assembled: those of nodes before this one (the frozen node, see
    /// `Assembler::frozen_from_node`), at the last assembly and at the last factorisation.
    assembled_frozen: usize,
    factorised_frozen: Option<usize>,
    /// The frozen node and the buffer of the tangent assembled before this one.
    previous_frozen: usize,
    previous_buffer: Option<usize>,
    /// The rows of the items whose stiffness changed since the tangent assembled before, and
    /// since the last factorisation (an item that differs from its value then changed at one of
    /// the assemblies since).
    since_last: Option<(usize, usize)>,
    since_factorised: Option<(usize, usize)>,
}

/// Whether two tangents are the same to the bit (`==` would take `−0` for `0` and never a NaN
/// for itself).
fn same(a: &Tangent, b: &Tangent) -> bool {
    a.iter().zip(b.iter()).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn widen(range: &mut Option<(usize, usize)>, rows: Option<(usize, usize)>) {
    if let Some((lo, hi)) = rows {
        *range = Some(range.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
    }
}

impl ChangedRows {
    /// For `point_rows.len()` points and `segment_rows.len()` segments writing those rows.
    pub(crate) fn new(point_rows: Vec<Option<(usize, usize)>>, segment_rows: Vec<Option<(usize, usize)>>) -> Self {
        let (np, ns) = (point_rows.len(), segment_rows.len());
        ChangedRows {
            point_rows,
            segment_rows,
            assembled_points: vec![Tangent::zeros(); np],
            assembled_segments: vec![[[Tangent::zeros(); 2]; 2]; ns],
            assembled_frozen: usize::MAX,
            factorised_frozen: None,
            previous_frozen: usize::MAX,
            previous_buffer: None,
            since_last: None,
            since_factorised: None,
        }
    }

    /// A tangent's assembly starts, with the items of nodes before `frozen_from_node`.
    pub(crate) fn start(&mut self, frozen_from_node: usize) {
        self.previous_frozen = self.assembled_frozen;
        self.assembled_frozen = frozen_from_node;
        self.since_last = None;
    }

    /// Point `ip` scatters the stiffness `d`.
    #[inline]
    pub(crate) fn point(&mut self, ip: usize, d: &Tangent) {
        if !same(&self.assembled_points[ip], d) {
            self.changed(self.point_rows[ip]);
            self.assembled_points[ip] = *d;
        }
    }

    /// Segment `is` scatters the Jacobian `jac`.
    #[inline]
    pub(crate) fn segment(&mut self, is: usize, jac: &[[Tangent; 2]; 2]) {
        let old = &self.assembled_segments[is];
        if (0..2).any(|i| (0..2).any(|j| !same(&old[i][j], &jac[i][j]))) {
            self.changed(self.segment_rows[is]);
            self.assembled_segments[is] = *jac;
        }
    }

    fn changed(&mut self, rows: Option<(usize, usize)>) {
        widen(&mut self.since_last, rows);
        widen(&mut self.since_factorised, rows);
    }

    /// Whether the tangent being assembled goes into the buffer at `address` that holds the one
    /// assembled before, with the same frozen node; `address` is this one's from now on.
    pub(crate) fn last_buffer(&mut self, address: usize, frozen_from_node: usize) -> bool {
        let same = self.previous_buffer == Some(address) && self.previous_frozen == frozen_from_node;
        self.previous_buffer = Some(address);
        same
    }

    /// The rows of the items whose stiffness changed since the tangent assembled before (`None`:
    /// none did).
    pub(crate) fn rows_since_last_assembly(&self) -> Option<(usize, usize)> {
        self.since_last
    }

    /// The rows point `ip` writes (`None` under the segment rule or without unknowns).
    pub(crate) fn point_rows(&self, ip: usize) -> Option<(usize, usize)> {
        self.point_rows[ip]
    }

    /// The rows segment `is` writes.
    pub(crate) fn segment_rows(&self, is: usize) -> Option<(usize, usize)> {
        self.segment_rows[is]
    }

    /// Point `ip`'s stiffness in the last tangent.
    pub(crate) fn assembled_point(&self, ip: usize) -> Tangent {
        self.assembled_points[ip]
    }

    /// Segment `is`'s Jacobian in the last tangent.
    pub(crate) fn assembled_segment(&self, is: usize) -> &[[Tangent; 2]; 2] {
        &self.assembled_segments[is]
    }

    /// The last assembled tangent was factorised.
    pub(crate) fn factorised(&mut self) {
        self.since_factorised = None;
        self.factorised_frozen = Some(self.assembled_frozen);
    }

    /// Its factorisation failed (or another matrix was factorised): no rows are known unchanged.
    pub(crate) fn forget(&mut self) {
        self.factorised_frozen = None;
    }

    /// The first and last row of the last assembled tangent that can differ from the last
    /// factorised one (`Some(None)`: none can), or `None` if that is not known (no factorisation
    /// yet, or another frozen node: other items assembled).
    pub(crate) fn rows(&self) -> Option<Option<(usize, usize)>> {
        (self.factorised_frozen == Some(self.assembled_frozen)).then_some(self.since_factorised)
    }
}

#[cfg(test)]
mod tests {
    use czid_core::CohesiveLaw;

    use crate::enf::Enf;
    use crate::fe::assembly::{Assembler, InterfaceRule};
    use crate::fe::banded::BandMatrix;

    #[test]
    fn the_rows_named_hold_every_row_that_changed_and_little_more() {
        // ENF-03's whole mesh assembled at rest, then with the upper arm slid past the interface's
        // elastic limit over the first 2 mm of the ligament: the rows of the second tangent that
        // differ from the first lie in the range the record names, which spans a few nodes.
        let (enf, law) = Enf::hartlen_enf03_identified();
        let (p, _) = enf.problem(&law).unwrap();
        let mut asm = Assembler::with_rule(&p, &law, InterfaceRule::Segments);
        let n = asm.n();
        let states = vec![law.initial_state(); p.points.len()];
        let (mut k0, mut k1) = (BandMatrix::zeros(n, p.mesh.bandwidth()), BandMatrix::zeros(n, p.mesh.bandwidth()));
        let mut f = vec![0.0; n];
        let rest = vec![0.0; n];
        assert!(asm.assemble(&p, &law, &states, &rest, Some(&mut k0), &mut f, false));
        asm.changed.factorised();
        assert_eq!(asm.changed.rows(), Some(None), "nothing assembled since the factorisation");
        let mut q = rest.clone();
        let slid: Vec<usize> =
            (0..p.mesh.x.len()).filter(|&i| p.mesh.x[i] > enf.a0 && p.mesh.x[i] < enf.a0 + 2.0).collect();
        for &i in &slid {
            q[p.mesh.dofs(1, i)[0]] = 1e-3; // mm: three times the slip at the elastic limit
        }
        assert!(asm.assemble(&p, &law, &states, &q, Some(&mut k1), &mut f, false));
        let changed: Vec<usize> = (0..n).filter(|&i| k0.band_row(i) != k1.band_row(i)).collect();
        let (lo, hi) = asm.changed.rows().unwrap().expect("rows changed");
        assert!(!changed.is_empty());
        assert!(changed.iter().all(|&i| lo <= i && i <= hi), "changed rows {changed:?} outside {lo}..={hi}");
        let per_node = n / p.mesh.x.len();
        println!(
            "{} rows changed, {}..={} named ({} of {n} rows), {} nodes slid",
            changed.len(),
            lo,
            hi,
            hi + 1 - lo,
            slid.len()
        );
        assert!(hi + 1 - lo <= (slid.len() + 4) * per_node, "the range spans the slid nodes and their neighbours only");
    }
}
