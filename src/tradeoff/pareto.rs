//! The Pareto front of points to be minimised in both coordinates.

/// Whether `a` dominates `b`: no worse in both, better in one.
pub fn dominates(a: (f64, f64), b: (f64, f64)) -> bool {
    a.0 <= b.0 && a.1 <= b.1 && (a.0 < b.0 || a.1 < b.1)
}

/// For each point, whether no other point dominates it (`None` points are
/// never on the front and dominate nothing). Equal points are all on it.
pub fn front(points: &[Option<(f64, f64)>]) -> Vec<bool> {
    points
        .iter()
        .map(|p| match p {
            Some(p) if p.0.is_finite() && p.1.is_finite() => !points
                .iter()
                .flatten()
                .any(|q| q.0.is_finite() && q.1.is_finite() && dominates(*q, *p)),
            _ => false,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_is_what_nothing_dominates() {
        let pts = [
            Some((1.0, 5.0)),
            Some((2.0, 2.0)),
            Some((3.0, 2.0)), // dominated by (2, 2)
            Some((4.0, 1.0)),
            None,
            Some((2.0, 2.0)), // equal to a front point: on the front too
            Some((0.5, f64::NAN)),
        ];
        assert_eq!(front(&pts), [true, true, false, true, false, true, false]);
        assert!(!dominates((1.0, 1.0), (1.0, 1.0)));
    }
}
