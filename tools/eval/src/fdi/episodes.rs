//! Evidence for each false-alarm episode: at the moment the alarm started, did one recorded unit's
//! channel vibrate much harder than the channels along the same axis in the other units? A
//! channel several times noisier than its peers is an anomaly of that unit in the recording
//! (what an injected `noise FACTOR` fault looks like), not an artefact of the detector.

use rins_fusion::Geometry;

use crate::datasets::quadrotor::projection::MAX_CHANNELS;
use serde::Serialize;

use super::layout::Sensor;
use super::prepare::Prepared;

/// Half-width of the window the channels' noise is compared over, s.
pub const EVIDENCE_HALF_WINDOW_S: f64 = 1.0;
/// Channels within this angle of each other are compared (as the fuser's noise-outlier check).
const PEER_ANGLE_DEG: f64 = 30.0;

/// One false-alarm episode of a fault-free run.
#[derive(Debug, Clone, Serialize)]
pub struct AlarmEpisode {
    /// Sensor type of the alarm: `gyro` or `accel`.
    pub sensor: &'static str,
    /// Start of the episode from the start of the trial, s.
    pub at_s: f64,
    /// `parity`, `detected-not-isolated`, or the channel-health reason (`noisy`, …).
    pub reason: &'static str,
    /// The channel whose noise most exceeds its peers' around `at_s`.
    pub loudest_channel: usize,
    /// The recorded IMU that channel comes from (1-based, as the files are named).
    pub loudest_imu: usize,
    /// That channel's first-difference RMS over the median of its peers'.
    pub noise_ratio: f64,
}

/// First-difference RMS of channel `ch` over `rows`.
fn difference_rms(rows: &[[i16; MAX_CHANNELS]], ch: usize) -> f64 {
    let n = rows.len().saturating_sub(1).max(1) as f64;
    let sum: f64 = rows
        .windows(2)
        .map(|w| (f64::from(w[1][ch]) - f64::from(w[0][ch])).powi(2))
        .sum();
    (sum / n).sqrt()
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// The channel around `row` whose noise stands out most from its peers': the channels within
/// [`PEER_ANGLE_DEG`] of it, or all other channels when none is that close (a pyramid).
pub(crate) fn loudest_channel(
    p: &Prepared,
    geometry: &Geometry,
    sensor: Sensor,
    row: usize,
    half_window_rows: usize,
) -> (usize, f64) {
    let rows = match sensor {
        Sensor::Gyro => &p.gyro,
        Sensor::Accel => &p.accel,
    };
    let lo = row.saturating_sub(half_window_rows);
    let hi = (row + half_window_rows).min(rows.len());
    let window = &rows[lo..hi];
    let rms: Vec<f64> = (0..p.n).map(|ch| difference_rms(window, ch)).collect();
    let axes = geometry.axes();
    let cos_peer = PEER_ANGLE_DEG.to_radians().cos();
    let mut best = (0, 0.0);
    for i in 0..p.n {
        let dot = |j: usize| (0..3).map(|k| axes[i][k] * axes[j][k]).sum::<f64>().abs();
        let close: Vec<usize> = (0..p.n).filter(|&j| j != i && dot(j) >= cos_peer).collect();
        let peers = if close.is_empty() {
            (0..p.n).filter(|&j| j != i).collect()
        } else {
            close
        };
        let mut peer_rms: Vec<f64> = peers.iter().map(|&j| rms[j]).collect();
        let ratio = rms[i] / median(&mut peer_rms).max(f64::MIN_POSITIVE);
        if ratio > best.1 {
            best = (i, ratio);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fdi::layout::Layout;

    #[test]
    fn the_channel_vibrating_three_times_harder_than_its_like_axis_peers_is_named() {
        let layout = Layout::Stacked { units: 4 };
        let geometry = layout.geometry().build().expect("stacked geometry");
        // Alternating ±a per row: first-difference RMS 2a. Unit 2's y row (channel 7) at 3×.
        let rows: Vec<[i16; MAX_CHANNELS]> = (0..240)
            .map(|k| {
                let s = if k % 2 == 0 { 1 } else { -1 };
                let mut r = [0i16; MAX_CHANNELS];
                for (ch, v) in r.iter_mut().enumerate().take(12) {
                    *v = s * if ch == 7 { 30 } else { 10 + ch as i16 % 3 };
                }
                r
            })
            .collect();
        let p = Prepared {
            gyro: rows.clone(),
            accel: rows,
            n: 12,
            clipped: 0,
            sigma_hat: [0.0; 2],
            max_bias_removed: [0.0; 2],
        };
        let (ch, ratio) = loudest_channel(&p, &geometry, Sensor::Gyro, 120, 120);
        assert_eq!(ch, 7);
        assert_eq!(layout.unit_of(ch), 2);
        // Peers of the y row: 11 on every unit (ch % 3 == 1) → exactly 30/11.
        assert!((ratio - 30.0 / 11.0).abs() < 1e-9, "{ratio}");
    }
}
