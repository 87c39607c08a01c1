//! Pure helpers on series: thinning for drawing, splitting at gaps, percentiles and histogram
//! bins.

/// Every `k`-th element of `values`, `k` the smallest step that keeps at most `max` of them (the
/// last element is kept too, so that a series ends where its data ends). A plot of a million
/// points is no more readable than one of a few thousand and takes a hundred times longer.
pub fn thin<T: Copy>(values: &[T], max: usize) -> Vec<T> {
    if values.len() <= max || max < 2 {
        return values.to_vec();
    }
    let step = values.len().div_ceil(max - 1);
    let mut out: Vec<T> = values.iter().step_by(step).copied().collect();
    if !(values.len() - 1).is_multiple_of(step)
        && let Some(last) = values.last()
    {
        out.push(*last);
    }
    out
}

/// `points` cut into runs of finite points: a NaN (or infinite) value ends a run and is not
/// drawn. With `wrap`, a jump larger than it between two neighbours also ends a run (a yaw going
/// from +179° to −179° is not a line across the plot).
pub fn finite_runs(points: &[(f64, f64)], wrap: Option<f64>) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut run: Vec<(f64, f64)> = Vec::new();
    for &(x, y) in points {
        if !x.is_finite() || !y.is_finite() {
            if !run.is_empty() {
                runs.push(std::mem::take(&mut run));
            }
            continue;
        }
        if let (Some(limit), Some(&(_, previous))) = (wrap, run.last())
            && (y - previous).abs() > limit
        {
            runs.push(std::mem::take(&mut run));
        }
        run.push((x, y));
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

/// The `p`-th percentile (0..=100) of `sorted` (ascending, finite) by nearest rank: the smallest
/// value with at least p % of the values at or below it. `None` for no values.
pub fn percentile(sorted: &[f64], p: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let rank = (p.clamp(0.0, 100.0) / 100.0 * sorted.len() as f64).ceil() as usize;
    sorted.get(rank.clamp(1, sorted.len()) - 1).copied()
}

/// Counts of `values` in `bins` equal bins over `lo..hi`; values outside are counted in the
/// first or last bin (a histogram clipped at a percentile keeps its tail, piled at the edge).
/// Non-finite values are left out.
pub fn histogram(values: &[f64], lo: f64, hi: f64, bins: usize) -> Vec<u64> {
    let mut counts = vec![0u64; bins];
    if bins == 0 {
        return counts;
    }
    let width = (hi - lo) / bins as f64;
    for &v in values.iter().filter(|v| v.is_finite()) {
        let index = if width > 0.0 {
            ((v - lo) / width).floor().clamp(0.0, (bins - 1) as f64) as usize
        } else {
            0
        };
        counts[index] += 1;
    }
    counts
}

/// The smallest and largest finite value of `values`, `None` when there is none.
pub fn finite_bounds(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((f64::min(lo, v), f64::max(hi, v))),
        })
}

/// An axis range around `bounds` with a margin, never empty: a constant series gets ±1 around
/// its value, no data at all 0..1.
pub fn padded(bounds: Option<(f64, f64)>) -> (f64, f64) {
    match bounds {
        None => (0.0, 1.0),
        Some((lo, hi)) if hi - lo < 1e-9 => (lo - 1.0, hi + 1.0),
        Some((lo, hi)) => {
            let margin = (hi - lo) * 0.05;
            (lo - margin, hi + margin)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_of_one_to_a_hundred_are_their_ranks() {
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&v, 50.0), Some(50.0));
        assert_eq!(percentile(&v, 99.0), Some(99.0));
        assert_eq!(percentile(&v, 99.9), Some(100.0));
        assert_eq!(percentile(&v, 0.0), Some(1.0));
        assert_eq!(percentile(&v, 100.0), Some(100.0));
        assert_eq!(percentile(&[], 50.0), None);
    }

    #[test]
    fn histogram_bins_and_clips_into_the_edge_bins() {
        let v = [0.5, 1.5, 1.7, 3.9, 4.0, 10.0, -2.0, f64::NAN];
        // Bins [0,1) [1,2) [2,3) [3,4]: 4.0 and 10.0 in the last, -2.0 in the first.
        assert_eq!(histogram(&v, 0.0, 4.0, 4), vec![2, 2, 0, 3]);
        assert_eq!(histogram(&[1.0, 1.0], 1.0, 1.0, 3), vec![2, 0, 0]);
    }

    #[test]
    fn thinning_keeps_at_most_max_and_the_ends() {
        let v: Vec<u32> = (0..100_000).collect();
        let t = thin(&v, 5000);
        assert!(t.len() <= 5000, "{}", t.len());
        assert_eq!(t.first(), Some(&0));
        assert_eq!(t.last(), Some(&99_999));
        assert_eq!(thin(&v[..10], 5000).len(), 10);
    }

    #[test]
    fn nan_and_wrap_split_runs() {
        let p = [
            (0.0, 1.0),
            (1.0, f64::NAN),
            (2.0, 170.0),
            (3.0, 179.0),
            (4.0, -179.0),
            (5.0, -170.0),
        ];
        let runs = finite_runs(&p, Some(180.0));
        assert_eq!(runs.len(), 3, "{runs:?}");
        assert_eq!(runs[0], vec![(0.0, 1.0)]);
        assert_eq!(runs[2], vec![(4.0, -179.0), (5.0, -170.0)]);
        assert_eq!(finite_runs(&p, None).len(), 2);
    }

    #[test]
    fn ranges_skip_nan_and_are_never_empty() {
        assert_eq!(finite_bounds([f64::NAN, 2.0, -1.0]), Some((-1.0, 2.0)));
        assert_eq!(padded(None), (0.0, 1.0));
        assert_eq!(padded(Some((3.0, 3.0))), (2.0, 4.0));
    }
}
