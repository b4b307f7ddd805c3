//! Pareto fronts of (time, error) points: a point is on the front when no other point is at least
//! as fast and at least as accurate, and strictly better in one of the two. Both are minimised.
//! Errors within [`ERROR_TOLERANCE`] of each other count as equal: renders that differ only in
//! floating-point blending order (the trivial reject on or off) are ties, and the faster wins.

/// Relative difference below which two errors are equal.
pub(crate) const ERROR_TOLERANCE: f64 = 1e-3;

/// `a` dominates `b`: no slower, no less accurate, strictly better in time or error.
pub(crate) fn dominates(a: (f64, f64), b: (f64, f64)) -> bool {
    let no_worse = a.1 <= b.1 * (1.0 + ERROR_TOLERANCE);
    let better = a.1 * (1.0 + ERROR_TOLERANCE) < b.1;
    a.0 <= b.0 && no_worse && (a.0 < b.0 || better)
}

fn finite(p: (f64, f64)) -> bool {
    p.0.is_finite() && p.1.is_finite()
}

/// For each point, whether it is on the front of `points`. Equal points are both on it (neither
/// dominates the other); a point with a non-finite coordinate is never on it and dominates nothing.
pub(crate) fn front(points: &[(f64, f64)]) -> Vec<bool> {
    points.iter().map(|&p| finite(p) && !points.iter().any(|&q| finite(q) && dominates(q, p))).collect()
}

/// Indices of the front's points, fastest first (ties by error): the order of its step line.
pub(crate) fn front_order(points: &[(f64, f64)]) -> Vec<usize> {
    let on = front(points);
    let mut ids: Vec<usize> = (0..points.len()).filter(|&i| on[i]).collect();
    ids.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0).then(points[a].1.total_cmp(&points[b].1)));
    ids
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dominance_is_strict_in_one_coordinate() {
        assert!(dominates((1.0, 1.0), (2.0, 2.0)));
        assert!(dominates((1.0, 1.0), (1.0, 2.0)));
        assert!(dominates((1.0, 1.0), (2.0, 1.0)));
        assert!(!dominates((1.0, 1.0), (1.0, 1.0)));
        assert!(!dominates((1.0, 3.0), (2.0, 2.0)));
    }

    #[test]
    fn front_of_a_trade_off() {
        // Faster but worse, slower but better, and two dominated points.
        let p = [(1.0, 0.5), (4.0, 0.1), (2.0, 0.6), (5.0, 0.1), (2.0, 0.2)];
        assert_eq!(front(&p), [true, true, false, false, true]);
        assert_eq!(front_order(&p), [0, 4, 1]);
    }

    #[test]
    fn errors_within_the_tolerance_are_ties() {
        // The slower point is 1e-5 more accurate: noise, not a trade-off.
        let p = [(10.0, 0.211959), (15.0, 0.211954)];
        assert_eq!(front(&p), [true, false]);
        // Same time, errors within the tolerance: both stay.
        assert_eq!(front(&[(10.0, 0.2), (10.0, 0.20001)]), [true, true]);
        // A real improvement is kept.
        assert_eq!(front(&[(10.0, 0.2), (15.0, 0.19)]), [true, true]);
    }

    #[test]
    fn ties_stay_on_the_front_together() {
        let p = [(1.0, 0.5), (1.0, 0.5), (1.0, 0.7), (3.0, 0.5)];
        assert_eq!(front(&p), [true, true, false, false]);
    }

    #[test]
    fn single_and_empty() {
        assert_eq!(front(&[(3.0, 0.2)]), [true]);
        assert!(front(&[]).is_empty());
        assert_eq!(front_order(&[(3.0, 0.2)]), [0]);
    }

    #[test]
    fn non_finite_points_are_ignored() {
        let p = [(f64::NAN, 0.0), (2.0, 0.3), (1.0, f64::INFINITY)];
        assert_eq!(front(&p), [false, true, false]);
    }

    #[test]
    fn zero_error_is_a_valid_point() {
        let p = [(5.0, 0.0), (1.0, 0.1)];
        assert_eq!(front(&p), [true, true]);
    }
}
