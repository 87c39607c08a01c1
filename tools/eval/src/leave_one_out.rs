//! Leave-one-out choice of a setting: for each trial, the candidate with the smallest total score
//! on the other trials (ties to the earlier candidate), so no trial is scored with a setting it
//! helped choose.

/// `scores[trial][candidate]` (smaller is better; every row as long as the first). Returns, per
/// trial, the index of the candidate chosen without it. With one trial, the choice falls back to
/// that trial's own scores (there is nothing else to learn from); with no candidates, 0.
pub fn choose_without_each(scores: &[Vec<f64>]) -> Vec<usize> {
    let candidates = scores.first().map_or(0, Vec::len);
    (0..scores.len())
        .map(|held_out| {
            let others: Vec<&Vec<f64>> = if scores.len() > 1 {
                scores
                    .iter()
                    .enumerate()
                    .filter(|(t, _)| *t != held_out)
                    .map(|(_, s)| s)
                    .collect()
            } else {
                scores.iter().collect()
            };
            choose_on(&others, candidates)
        })
        .collect()
}

/// The candidate with the smallest total over all `scores` (what a configuration learnt on every
/// trial would use).
pub fn choose_on_all(scores: &[Vec<f64>]) -> usize {
    let candidates = scores.first().map_or(0, Vec::len);
    choose_on(&scores.iter().collect::<Vec<_>>(), candidates)
}

fn choose_on(rows: &[&Vec<f64>], candidates: usize) -> usize {
    let total = |c: usize| -> f64 {
        rows.iter()
            .map(|r| r.get(c).copied().unwrap_or(f64::INFINITY))
            // A candidate that diverged (NaN) on a trial is as bad as it gets.
            .map(|v| if v.is_nan() { f64::INFINITY } else { v })
            .sum()
    };
    let mut best = 0;
    for c in 1..candidates {
        if total(c) < total(best) {
            best = c;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_held_out_trial_does_not_choose_its_own_setting() {
        // Trial 0 prefers candidate 1 strongly; trials 1 and 2 prefer candidate 0 a little.
        let scores = vec![vec![9.0, 1.0], vec![1.0, 2.0], vec![1.0, 2.0]];
        assert_eq!(choose_without_each(&scores), vec![0, 1, 1]);
        assert_eq!(choose_on_all(&scores), 1);
        // Ties go to the earlier candidate; NaN loses.
        assert_eq!(choose_on_all(&[vec![1.0, 1.0]]), 0);
        assert_eq!(choose_on_all(&[vec![f64::NAN, 5.0]]), 1);
        assert_eq!(choose_without_each(&[vec![3.0, 2.0]]), vec![1]);
        assert!(choose_without_each(&[]).is_empty());
    }
}
