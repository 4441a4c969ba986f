//! Crack measures from the damage at the cohesive points.
//!
//! A point switches from intact to debonded at once, so counting tributary lengths would make the
//! crack length a staircase. The debonded front is placed instead by extrapolating the damage
//! deficit `1 − D` of the two points ahead of it (smooth there) to `1 − threshold`, and the
//! process zone's front by extrapolating the damage of its last two points to zero; both are
//! clamped between the last point inside and the first outside.

/// Lengths along the interface (mm).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CrackMeasures {
    /// Crack growth: from the crack origin to the debonded front (mm).
    pub debonded: f64,
    /// From the debonded front to the front of the damaged zone (mm).
    pub process_zone: f64,
    /// Position of the debonded front, the origin while nothing has debonded (mm).
    pub tip: f64,
}

/// Measures from points at `xs` (increasing, from the crack origin) with damage `d`.
pub fn measure(xs: &[f64], d: &[f64], threshold: f64, origin: f64) -> CrackMeasures {
    let n = xs.len();
    let debonded = d.iter().take_while(|&&v| v >= threshold).count();
    let tip = if debonded == 0 {
        origin
    } else if debonded == n {
        xs[n - 1]
    } else {
        let (k, o) = (debonded - 1, debonded);
        let mut front = xs[k];
        if o + 1 < n {
            let (q1, q2) = (1.0 - d[o], 1.0 - d[o + 1]);
            let slope = (q2 - q1) / (xs[o + 1] - xs[o]);
            if slope > 0.0 {
                front = (xs[o] - (q1 - (1.0 - threshold)) / slope).clamp(xs[k], xs[o]);
            }
        }
        front
    };
    let damaged = debonded + d[debonded..].iter().take_while(|&&v| v > 0.0).count();
    let zone_front = if damaged == debonded {
        tip
    } else if damaged == n {
        xs[n - 1]
    } else {
        let k = damaged - 1;
        let mut front = xs[k];
        if k >= 1 && k > debonded {
            let slope = (d[k] - d[k - 1]) / (xs[k] - xs[k - 1]);
            if slope < 0.0 {
                front = (xs[k] - d[k] / slope).clamp(xs[k], xs[k + 1]);
            }
        }
        front
    };
    CrackMeasures { debonded: (tip - origin).max(0.0), process_zone: (zone_front - tip).max(0.0), tip }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fronts_move_continuously_with_the_damage() {
        let xs = [0.0, 1.0, 2.0, 3.0, 4.0];
        // Deficit ahead of the failed point: 0.2 at x = 1, 0.4 at x = 2 → front at x = 0.
        let m = measure(&xs, &[1.0, 0.8, 0.6, 0.0, 0.0], 1.0, 0.0);
        assert!(m.tip.abs() < 1e-12 && m.debonded.abs() < 1e-12, "{m:?}");
        let m = measure(&xs, &[1.0, 0.9, 0.6, 0.0, 0.0], 1.0, 0.0);
        assert!((m.tip - (1.0 - 0.1 / 0.3)).abs() < 1e-12, "{m:?}");
        // Damage 0.9, 0.6 extrapolates to zero at x = 2 + 0.6 / 0.3 = 4, clamped to 3.
        assert!((m.tip + m.process_zone - 3.0).abs() < 1e-12, "{m:?}");
        let intact = measure(&xs, &[0.0; 5], 1.0, 0.0);
        assert_eq!(intact, CrackMeasures::default());
    }
}
