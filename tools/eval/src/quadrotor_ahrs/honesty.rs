//! Whether the filter's σ covers its error, in the first seconds and after: a run that starts in
//! flight must not only converge, it must say how far it is from converged. For every reference
//! row, the tilt error (roll and pitch errors together, with the mounting that scores the flight)
//! over the filter's own σ of its tilt at that time (both horizontal axes together); the RMS of
//! that ratio over a window is 1 for a filter whose σ is right, below 1 for a cautious one, above
//! 1 for an overconfident one. The reference's own error is in the numerator too, so a ratio
//! somewhat above 1 after convergence is the reference's share as much as the filter's.

use super::SETTLE_S;
use super::mounting::{Paired, tilt_error_rad};
use super::run::AttitudeTrace;

/// The windows of time since the run's start, s: the first seconds and the rest.
pub const WINDOWS_S: [(f64, f64); 2] = [(0.0, SETTLE_S), (SETTLE_S, f64::INFINITY)];

/// RMS of error over σ per window of [`WINDOWS_S`]; `None` without rows (or σ) in it.
pub type ErrorOverSigma = [Option<f64>; 2];

/// The ratio's RMS per window for the rows `p` of the run that produced `trace`, started at
/// `start_t_s` (flight time), scored with mounting tilt `tilt_rad`.
pub fn error_over_sigma(
    p: &Paired,
    tilt_rad: [f64; 2],
    trace: &AttitudeTrace,
    start_t_s: f64,
) -> ErrorOverSigma {
    WINDOWS_S.map(|(from, to)| {
        let (sum, n) = (0..p.len())
            .filter(|&k| p.since_start_s[k] >= from && p.since_start_s[k] < to)
            .filter_map(|k| {
                let sigma = trace.tilt_sigma_at(start_t_s + p.since_start_s[k])?;
                (sigma > 0.0).then(|| (tilt_error_rad(p, k, tilt_rad) / sigma).powi(2))
            })
            .fold((0.0, 0usize), |(s, n), r| (s + r, n + 1));
        (n > 0).then(|| (sum / n as f64).sqrt())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rins_navigator::attitude::quaternion_from_euler;

    #[test]
    fn an_error_of_one_sigma_reads_one_and_an_overconfident_filter_more() {
        // Roll off by 1° throughout (alternating in sign, so no mounting removes it); the filter
        // says 2° for the first 5 s, then 0.5°.
        let mut p = Paired::default();
        let mut trace = AttitudeTrace::default();
        for k in 0..200 {
            let t = k as f64 * 0.1;
            let error = if k % 2 == 0 { 1.0_f64 } else { -1.0 }.to_radians();
            let q = quaternion_from_euler(0.1 + error, -0.05, 0.3);
            p.push(t, q, 0.1, -0.05);
            trace.t_s.push(100.0 + t);
            trace.attitude.push(q);
            let sigma = if t < SETTLE_S { 2.0 } else { 0.5 };
            trace.tilt_sigma_rad.push(f64::to_radians(sigma));
        }
        let [first, rest] = error_over_sigma(&p, [0.0; 2], &trace, 100.0);
        assert!((first.unwrap_or(0.0) - 0.5).abs() < 1e-3, "{first:?}");
        assert!((rest.unwrap_or(0.0) - 2.0).abs() < 1e-3, "{rest:?}");
        // Without σ there is nothing to say.
        let none = AttitudeTrace {
            tilt_sigma_rad: Vec::new(),
            ..trace
        };
        assert_eq!(error_over_sigma(&p, [0.0; 2], &none, 100.0), [None, None]);
    }
}
