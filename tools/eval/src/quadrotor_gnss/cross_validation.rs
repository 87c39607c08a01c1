//! The drift test's two settings (`[navigator.gnss] drift_slack`, `drift_threshold`) chosen
//! leave-one-flight-out: for each flight, the setting with the fewest receiver rejections on the
//! other flights' clean fixes (ties to the most sensitive: the smallest threshold, then the
//! smallest slack), and that flight scored with it. The figure reported is the held-out one.

use serde::Serialize;

/// The candidates: (slack σ, threshold σ), most sensitive first.
pub const CANDIDATES: [(f64, f64); 12] = [
    (0.5, 12.0),
    (1.0, 12.0),
    (2.0, 12.0),
    (0.5, 18.0),
    (1.0, 18.0),
    (2.0, 18.0),
    (0.5, 25.0),
    (1.0, 25.0),
    (2.0, 25.0),
    (0.5, 50.0),
    (1.0, 50.0),
    (2.0, 50.0),
];

/// What one held-out flight was scored with.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Choice {
    /// Index into [`CANDIDATES`].
    pub candidate: usize,
    /// `drift_slack`, σ.
    pub drift_slack: f64,
    /// `drift_threshold`, σ.
    pub drift_threshold: f64,
}

/// For each flight, the candidate chosen on the others; `rejections[f][c]` is flight `f`'s
/// rejection count under candidate `c`.
pub fn choose(rejections: &[Vec<u64>]) -> Vec<Choice> {
    let scores: Vec<Vec<f64>> = rejections
        .iter()
        .map(|r| r.iter().map(|&n| n as f64).collect())
        .collect();
    // Ties go to the earlier candidate: the most sensitive.
    crate::leave_one_out::choose_without_each(&scores)
        .into_iter()
        .map(|candidate| {
            let (drift_slack, drift_threshold) = CANDIDATES[candidate];
            Choice {
                candidate,
                drift_slack,
                drift_threshold,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_held_out_flight_does_not_choose_its_own_setting() {
        // Flight 0 raises alarms under every candidate but the last; the others only under the
        // first. Flight 0 held out: candidates 1.. tie at 0 on the others, the most sensitive (1)
        // wins. Any other held out: flight 0 counts, so only the last candidate is clean.
        let mut r = vec![vec![0u64; CANDIDATES.len()]; 3];
        for count in r[0].iter_mut().take(CANDIDATES.len() - 1) {
            *count = 5;
        }
        r[1][0] = 1;
        r[2][0] = 1;
        let chosen = choose(&r);
        assert_eq!(chosen[0].candidate, 1);
        assert_eq!(chosen[1].candidate, CANDIDATES.len() - 1);
        assert_eq!(chosen[2].candidate, CANDIDATES.len() - 1);
    }
}
