//! Quality indicators for Pareto-front approximations.

/// Inverted generational distance: the mean, over the reference points, of the Euclidean
/// distance to the nearest point of `front`. `+∞` for an empty front.
pub fn igd(front: &[[f64; 2]], reference: &[[f64; 2]]) -> f64 {
    if front.is_empty() || reference.is_empty() {
        return f64::INFINITY;
    }
    let total: f64 = reference
        .iter()
        .map(|r| {
            front.iter().map(|p| (p[0] - r[0]).powi(2) + (p[1] - r[1]).powi(2)).fold(f64::INFINITY, f64::min).sqrt()
        })
        .sum();
    total / reference.len() as f64
}

/// Hypervolume (area) dominated by `front` and bounded by the reference point `reference`,
/// for minimisation of two objectives. Points not strictly dominating the reference point
/// add nothing.
pub fn hypervolume_2d(front: &[[f64; 2]], reference: [f64; 2]) -> f64 {
    let mut pts: Vec<[f64; 2]> = front.iter().copied().filter(|p| p[0] < reference[0] && p[1] < reference[1]).collect();
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    // Sweep in f1: each point adds the strip between its f2 and the lowest f2 seen so far.
    let mut area = 0.0;
    let mut floor = reference[1];
    for p in pts {
        if p[1] < floor {
            area += (reference[0] - p[0]) * (floor - p[1]);
            floor = p[1];
        }
    }
    area
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hypervolume_of_known_sets() {
        assert_eq!(hypervolume_2d(&[[0.5, 0.5]], [1.0, 1.0]), 0.25);
        let hv = hypervolume_2d(&[[0.0, 0.5], [0.5, 0.0], [0.6, 0.6]], [1.0, 1.0]);
        assert!((hv - 0.75).abs() < 1e-15);
        assert_eq!(igd(&[[0.0, 0.0]], &[[3.0, 4.0]]), 5.0);
    }
}
