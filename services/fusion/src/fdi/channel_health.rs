//! Channel-health checks on the raw counts and calibrated values of one sensor type: the fast
//! isolation path that works for any N, including N = 4 where parity cannot isolate.
//!
//! - **Saturation**: counts at the converter's rails ([`count_rails`]) for `saturation_samples` consecutive
//!   samples. Whether that is a fault or a genuine over-range is decided by the caller from what
//!   the other channels say (see `monitor`).
//! - **Stuck**: the same count `stuck_samples` times in a row (not at a rail, which is the
//!   saturation check's business) while at least two other usable channels changed within that
//!   window — a frozen converter on a moving or noisy signal.
//! - **Noisy**: over blocks of `noise_window` samples, the mean of (Δz_i/σ_i)² (first differences,
//!   so a steady signal or bias does not count) more than `noise_ratio` times the median of the
//!   other channels' — of the channels along nearly the same axis (within [`PEER_ANGLE_DEG`]) when
//!   there are at least two, since airframe vibration is not isotropic (a quadrotor's is strongest
//!   along the thrust axis) and a channel must not be blamed for the axis it measures. A verdict is available at each block end, so a noise fault is isolated
//!   within two windows.
//!
//! **Stuck false-alarm arithmetic.** A fault-free channel repeats its count L times in a row with
//! probability Σ_k p_k^L per sample, p_k the probability of count k. It is largest when the true
//! value sits on a count (p_0 = P(|ε| < ½ lsb) = erf(1/(2√2 σ))), and is dominated by that term:
//! accelerometer σ = 1.2 lsb → p_0 = 0.3231, p_±1 = 0.2328, p_±2 = 0.0870; gyro σ = 2.2 lsb →
//! p_0 = 0.1798. One hour at 1 kHz with 4 channels is 1.44e7 channel-samples, so the expected
//! number of false stuck declarations is at most 1.44e7 · Σ p_k^L:
//!
//! | L  | accel Σ p_k^L | accel per hour (4 ch) | gyro per hour (4 ch) |
//! |----|---------------|-----------------------|----------------------|
//! | 15 | 4.4e-8        | 0.64                  | 1.4e-4               |
//! | 18 | 1.5e-9        | 0.021                 | 7.3e-7               |
//! | 19 | 4.8e-10       | 0.0069                | 1.3e-7               |
//! | 20 | 1.5e-10       | 0.0022                | 2.3e-8               |
//!
//! The default L = 20 keeps 1 h below 0.01 false alarms with a margin of 4.5 (at σ = 1.0 lsb it
//! would be 0.066 per hour; the "two other channels changed" condition does not help on a quiet
//! signal, where the others change almost every sample). A channel frozen at sample t0 repeats
//! the last good count, so the run reaches 20 at the 19th frozen sample: isolated in ≤ 20 samples.
//! The figures are checked numerically by the test `stuck_false_alarm_arithmetic`.
//!
//! The table is for 1 kHz. The per-sample σ in counts falls with the rate (√rate): at 100 Hz the
//! accelerometers' is 0.38 counts, and a healthy channel repeats its count in runs far longer than
//! 20. The configured `stuck_samples` is therefore a floor: the fuser raises it to
//! [`stuck_run_needed`] for the quietest channel of the type at the configured rate.

use super::chi2::regularized_gamma_p;
use crate::geometry::MAX_CHANNELS;

/// Lowest count of the signed 12-bit converter (the serial protocol's).
pub const COUNT_MIN: i16 = -2048;
/// Highest count of the signed 12-bit converter (the serial protocol's).
pub const COUNT_MAX: i16 = 2047;
/// Resolutions a converter may have, bits.
pub const CONVERTER_BITS: std::ops::RangeInclusive<u8> = 8..=16;

/// The rails of a signed converter of `bits` (8..=16): −2^(bits−1) and 2^(bits−1) − 1.
pub fn count_rails(bits: u8) -> [i16; 2] {
    let half = 1i32 << (bits.clamp(*CONVERTER_BITS.start(), *CONVERTER_BITS.end()) - 1);
    // Within i16 for bits <= 16.
    [(-half) as i16, (half - 1) as i16]
}

/// Expected fault-free stuck declarations per hour, over all channels of one sensor type, that
/// the stuck run length is made to stay below (the configured `stuck_samples` is a floor).
pub const STUCK_FALSE_ALARMS_PER_HOUR: f64 = 0.01;
/// Longest stuck run the derivation asks for: a channel quieter than this allows cannot be told
/// from a frozen one by its counts.
pub const MAX_STUCK_RUN: u32 = 100_000;

/// Noise wider than this many counts is scored by a bound instead of the exact sum.
const WIDE_NOISE_COUNTS: f64 = 64.0;

/// P(|ε| < x) for ε ~ N(0, σ²) with σ = 1 and x ≥ 0: erf(x/√2).
fn within(x: f64) -> f64 {
    regularized_gamma_p(0.5, x * x / 2.0)
}

/// The probability that a fault-free channel with white noise σ (`sigma_counts`, in counts,
/// before rounding) whose true value sits on a count repeats one count `run` times in a row:
/// Σ_k p_k^run with p_k = P(k − ½ < ε < k + ½). A true value on a count is the worst case.
pub fn repeat_run_probability(sigma_counts: f64, run: u32) -> f64 {
    if sigma_counts <= 0.0 {
        return 1.0;
    }
    let central = within(0.5 / sigma_counts);
    if sigma_counts > WIDE_NOISE_COUNTS {
        // Σ p_k^run ≤ (max p_k)^(run−1) · Σ p_k ≤ p_0^(run−1): a conservative bound that stays
        // cheap where the exact sum would need millions of terms (or overflow the count).
        return central.powf(f64::from(run.saturating_sub(1)));
    }
    let mut total = central.powf(f64::from(run));
    // The terms fall off as exp(−k²/2σ²): 8σ + 1 counts either side is far past double precision.
    let reach = (8.0 * sigma_counts).ceil() as i32 + 1;
    for k in 1..=reach {
        let p = 0.5
            * (within((f64::from(k) + 0.5) / sigma_counts)
                - within((f64::from(k) - 0.5) / sigma_counts));
        total += 2.0 * p.max(0.0).powf(f64::from(run));
    }
    total
}

/// The shortest run of identical counts that a fault-free channel of white noise `sigma_counts`
/// (counts) shows less often than [`STUCK_FALSE_ALARMS_PER_HOUR`] over `channel_samples_per_hour`
/// (channels × rate × 3600), at most [`MAX_STUCK_RUN`]. At 1 kHz the default block needs 19 (its
/// accelerometers' σ is 1.2 counts); at 100 Hz, where their σ is 0.38 counts, 88.
pub fn stuck_run_needed(sigma_counts: f64, channel_samples_per_hour: f64) -> u32 {
    let budget = STUCK_FALSE_ALARMS_PER_HOUR / channel_samples_per_hour.max(1.0);
    // The probability falls geometrically with the run: double, then bisect.
    let ok = |run: u32| repeat_run_probability(sigma_counts, run) <= budget;
    let mut hi = 2u32;
    while !ok(hi) {
        if hi >= MAX_STUCK_RUN {
            return MAX_STUCK_RUN;
        }
        hi = (hi * 2).min(MAX_STUCK_RUN);
    }
    let mut lo = hi / 2;
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if ok(mid) { hi = mid } else { lo = mid }
    }
    hi
}

/// Thresholds of the channel-health checks (validated by the configuration).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HealthSettings {
    /// Samples in a row at a converter rail before a channel counts as saturated.
    pub saturation_samples: u32,
    /// The converter's lowest and highest counts (see [`count_rails`]).
    pub rails: [i16; 2],
    /// Identical counts in a row that make a channel stuck.
    pub stuck_samples: u32,
    /// Block length of the noise-outlier check, samples.
    pub noise_window: u32,
    /// A channel is noisy when its first-difference variance exceeds this multiple of the median of
    /// the other channels'.
    pub noise_ratio: f64,
}

/// What the checks found on one sample (bit i = channel i).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HealthFindings {
    /// At a rail now.
    pub at_rail: u32,
    /// At a rail for at least `saturation_samples` samples.
    pub saturated: u32,
    /// Frozen while others moved.
    pub stuck: u32,
    /// Noise outliers (only at the end of a noise block).
    pub noisy: u32,
    /// A noise block ended on this sample (`noisy` is a fresh verdict).
    pub noise_verdict: bool,
    /// With a verdict: the largest channel noise level over `noise_ratio` times its peers'
    /// median (above 1 = a noise outlier), the margin of the check; 0 without a verdict.
    pub noise_peak: f64,
}

/// Channels whose axes are at most this far apart (either sense) are compared with each other in
/// the noise-outlier check, °.
pub const PEER_ANGLE_DEG: f64 = 30.0;

/// For every channel, the mask of the other channels within [`PEER_ANGLE_DEG`] of its axis.
fn peer_masks(axes: &[[f64; 3]]) -> [u32; MAX_CHANNELS] {
    let cos_limit = PEER_ANGLE_DEG.to_radians().cos();
    let mut peers = [0u32; MAX_CHANNELS];
    for (i, a) in axes.iter().enumerate().take(MAX_CHANNELS) {
        for (j, b) in axes.iter().enumerate().take(MAX_CHANNELS) {
            let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            if i != j && dot.abs() >= cos_limit {
                peers[i] |= 1 << j;
            }
        }
    }
    peers
}

/// Run lengths and noise accumulators of the channels of one sensor type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelHealth {
    n: usize,
    settings: HealthSettings,
    inv_variance: [f64; MAX_CHANNELS],
    /// Channels along nearly the same axis, per channel (see [`PEER_ANGLE_DEG`]).
    peers: [u32; MAX_CHANNELS],
    last_counts: [i16; MAX_CHANNELS],
    /// Identical counts in a row ending now (0 = no history).
    same_run: [u32; MAX_CHANNELS],
    /// Samples in a row at a rail ending now.
    rail_run: [u32; MAX_CHANNELS],
    prev_z: [f64; MAX_CHANNELS],
    /// Channels whose `prev_z` belongs to the previous sample.
    have_prev: u32,
    diff_sum: [f64; MAX_CHANNELS],
    diff_count: [u32; MAX_CHANNELS],
    block_samples: u32,
}

impl ChannelHealth {
    /// Health state of the channels along `axes` (unit vectors, one per channel) with configured
    /// noise variances `variances` (SI²).
    pub fn new(
        axes: &[[f64; 3]],
        variances: &[f64; MAX_CHANNELS],
        settings: HealthSettings,
    ) -> Self {
        Self {
            n: axes.len().min(MAX_CHANNELS),
            settings,
            inv_variance: variances.map(|v| if v > 0.0 { 1.0 / v } else { 0.0 }),
            peers: peer_masks(axes),
            last_counts: [0; MAX_CHANNELS],
            same_run: [0; MAX_CHANNELS],
            rail_run: [0; MAX_CHANNELS],
            prev_z: [0.0; MAX_CHANNELS],
            have_prev: 0,
            diff_sum: [0.0; MAX_CHANNELS],
            diff_count: [0; MAX_CHANNELS],
            block_samples: 0,
        }
    }

    /// Runs the checks on one sample. `usable`: channels that are valid and in service; the
    /// others are not judged and their histories restart when they come back.
    pub fn check(
        &mut self,
        counts: &[i16],
        z: &[f64; MAX_CHANNELS],
        usable: u32,
    ) -> HealthFindings {
        let mut found = HealthFindings::default();
        let s = self.settings;
        for (i, &zi) in z.iter().enumerate().take(self.n) {
            let bit = 1u32 << i;
            let Some(&c) = counts.get(i).filter(|_| usable & bit != 0) else {
                self.same_run[i] = 0;
                self.rail_run[i] = 0;
                self.have_prev &= !bit;
                continue;
            };
            self.same_run[i] = if self.same_run[i] > 0 && c == self.last_counts[i] {
                self.same_run[i].saturating_add(1)
            } else {
                1
            };
            self.last_counts[i] = c;
            if c == s.rails[0] || c == s.rails[1] {
                self.rail_run[i] = self.rail_run[i].saturating_add(1);
                found.at_rail |= bit;
                if self.rail_run[i] >= s.saturation_samples {
                    found.saturated |= bit;
                }
            } else {
                self.rail_run[i] = 0;
            }
            if self.have_prev & bit != 0 {
                let d = zi - self.prev_z[i];
                self.diff_sum[i] += d * d * self.inv_variance[i];
                self.diff_count[i] += 1;
            }
            self.prev_z[i] = zi;
            self.have_prev |= bit;
        }
        // Stuck: long run, not at a rail, and at least two other usable channels moved within
        // the run's window (their own runs are shorter than the window).
        for i in 0..self.n {
            let bit = 1u32 << i;
            if usable & bit == 0 || self.same_run[i] < s.stuck_samples || found.at_rail & bit != 0 {
                continue;
            }
            let moved = (0..self.n)
                .filter(|&j| j != i && usable & (1 << j) != 0)
                .filter(|&j| self.same_run[j] < s.stuck_samples)
                .count();
            if moved >= 2 {
                found.stuck |= bit;
            }
        }
        self.block_samples += 1;
        if self.block_samples >= s.noise_window {
            found.noise_verdict = true;
            (found.noisy, found.noise_peak) = self.noise_outliers(usable);
            self.block_samples = 0;
            self.diff_sum = [0.0; MAX_CHANNELS];
            self.diff_count = [0; MAX_CHANNELS];
        }
        found
    }

    /// Channels whose mean normalised squared difference over the block exceeds `noise_ratio`
    /// times the median of the other eligible channels' (at least two others needed): its peers
    /// along the same axis when two or more are eligible, otherwise all. Also the largest ratio
    /// of a level to its bound (see [`HealthFindings::noise_peak`]).
    fn noise_outliers(&self, usable: u32) -> (u32, f64) {
        let min_count = (self.settings.noise_window / 2).max(1);
        let mut level = [0.0; MAX_CHANNELS];
        let mut eligible = 0u32;
        for (i, l) in level.iter_mut().enumerate().take(self.n) {
            if usable & (1 << i) != 0 && self.diff_count[i] >= min_count {
                *l = self.diff_sum[i] / f64::from(self.diff_count[i]);
                eligible |= 1 << i;
            }
        }
        let mut noisy = 0;
        let mut peak: f64 = 0.0;
        for (i, &li) in level.iter().enumerate().take(self.n) {
            if eligible & (1 << i) == 0 {
                continue;
            }
            let peers = self.peers[i] & eligible;
            let compared = if peers.count_ones() >= 2 {
                peers
            } else {
                eligible & !(1 << i)
            };
            let mut others = [0.0; MAX_CHANNELS];
            let mut k = 0;
            for j in (0..self.n).filter(|&j| compared & (1 << j) != 0) {
                others[k] = level[j];
                k += 1;
            }
            if k < 2 {
                continue;
            }
            let others = &mut others[..k];
            others.sort_unstable_by(f64::total_cmp);
            let median = if k % 2 == 1 {
                others[k / 2]
            } else {
                0.5 * (others[k / 2 - 1] + others[k / 2])
            };
            let bound = self.settings.noise_ratio * median;
            if li > bound {
                noisy |= 1 << i;
            }
            if bound > 0.0 {
                peak = peak.max(li / bound);
            }
        }
        (noisy, peak)
    }

    /// Restarts the histories of `channel` (after it is returned to service).
    pub fn forget(&mut self, channel: usize) {
        if channel < MAX_CHANNELS {
            self.same_run[channel] = 0;
            self.rail_run[channel] = 0;
            self.have_prev &= !(1 << channel);
            self.diff_sum[channel] = 0.0;
            self.diff_count[channel] = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    #[test]
    fn stuck_run_follows_the_noise_in_counts() {
        // The table above: accelerometer σ = 1.2 counts, L = 20 → Σ p_k^L = 1.5e-10.
        let p = repeat_run_probability(1.2, 20);
        assert!((1.2e-10..1.9e-10).contains(&p), "{p}");
        // 1 h at 1 kHz on 4 channels: 19 is the first run below 0.01 per hour (0.0069).
        assert_eq!(stuck_run_needed(1.214, 4.0 * 1000.0 * 3600.0), 19);
        // At 100 Hz the same block's accelerometers have σ = 0.38 counts.
        let slow = stuck_run_needed(0.384, 4.0 * 100.0 * 3600.0);
        assert!((80..100).contains(&slow), "{slow}");
        assert!(repeat_run_probability(0.384, slow) * 1.44e6 <= STUCK_FALSE_ALARMS_PER_HOUR);
        assert!(repeat_run_probability(0.384, slow - 1) * 1.44e6 > STUCK_FALSE_ALARMS_PER_HOUR);
        // A noiseless channel cannot be judged by its counts.
        assert_eq!(stuck_run_needed(0.0, 1e7), MAX_STUCK_RUN);
    }

    #[test]
    fn wide_noise_is_bounded_not_summed() {
        // Just above the switch the bound p_0^(L−1) must not be below the exact sum.
        let sigma = WIDE_NOISE_COUNTS * 1.01;
        for run in [2, 3, 5] {
            let central = within(0.5 / sigma);
            let mut exact = central.powf(f64::from(run));
            for k in 1..=600 {
                let p = 0.5
                    * (within((f64::from(k) + 0.5) / sigma) - within((f64::from(k) - 0.5) / sigma));
                exact += 2.0 * p.max(0.0).powf(f64::from(run));
            }
            let bound = repeat_run_probability(sigma, run);
            assert!(
                bound >= exact && bound < 200.0 * exact,
                "{run}: {bound} vs {exact}"
            );
        }
        // Absurdly wide or infinite noise (a tiny full scale) answers at once with a short run.
        assert_eq!(stuck_run_needed(1e300, 1e7), 2);
        assert_eq!(stuck_run_needed(f64::INFINITY, 1e7), 2);
    }

    #[test]
    fn rails_follow_the_bits() {
        assert_eq!(count_rails(12), [COUNT_MIN, COUNT_MAX]);
        assert_eq!(count_rails(16), [i16::MIN, i16::MAX]);
        assert_eq!(count_rails(8), [-128, 127]);
    }

    const SETTINGS: HealthSettings = HealthSettings {
        saturation_samples: 5,
        rails: [COUNT_MIN, COUNT_MAX],
        stuck_samples: 20,
        noise_window: 200,
        noise_ratio: 25.0,
    };

    /// Noise verdict after one window of white noise with per-channel σ `sigma` (configured σ 1).
    fn noisy_after_a_window(axes: &[[f64; 3]], sigma: &[f64]) -> u32 {
        verdict_after_a_window(axes, sigma).noisy
    }

    fn verdict_after_a_window(axes: &[[f64; 3]], sigma: &[f64]) -> HealthFindings {
        let mut health = ChannelHealth::new(axes, &[1.0; MAX_CHANNELS], SETTINGS);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let usable = (1u32 << axes.len()) - 1;
        for _ in 0..SETTINGS.noise_window {
            let mut z = [0.0; MAX_CHANNELS];
            let mut counts = [0i16; MAX_CHANNELS];
            for i in 0..axes.len() {
                let e: f64 = StandardNormal.sample(&mut rng);
                z[i] = sigma[i] * e;
                counts[i] = (z[i] * 100.0).round() as i16;
            }
            let found = health.check(&counts[..axes.len()], &z, usable);
            if found.noise_verdict {
                return found;
            }
            assert_eq!(found.noise_peak, 0.0, "a margin only with a verdict");
        }
        panic!("no verdict within one window");
    }

    fn three_triads() -> Vec<[f64; 3]> {
        (0..3)
            .flat_map(|_| [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
            .collect()
    }

    #[test]
    fn vibration_along_one_axis_is_not_blamed_on_its_channels() {
        // Every z channel sees 6× the noise of the x/y channels (variance 36 > 25 × the median
        // of all others): compared with their z peers they are alike.
        let sigma = [1.0, 1.0, 6.0, 1.0, 1.0, 6.0, 1.0, 1.0, 6.0];
        assert_eq!(noisy_after_a_window(&three_triads(), &sigma), 0);
    }

    #[test]
    fn a_noisy_channel_stands_out_among_its_peers() {
        let mut sigma = [1.0, 1.0, 6.0, 1.0, 1.0, 6.0, 1.0, 1.0, 6.0];
        sigma[5] = 60.0;
        assert_eq!(noisy_after_a_window(&three_triads(), &sigma), 1 << 5);
    }

    #[test]
    fn the_margin_is_the_loudest_channel_over_its_bound() {
        // Channel 5 at 3× its z peers' σ: variance ratio 9 against the bound 25, margin ≈ 0.36
        // (the block's 200 samples estimate each variance within about ±10 % each).
        let mut sigma = [1.0, 1.0, 6.0, 1.0, 1.0, 6.0, 1.0, 1.0, 6.0];
        sigma[5] = 18.0;
        let found = verdict_after_a_window(&three_triads(), &sigma);
        assert_eq!(found.noisy, 0);
        assert!(
            (found.noise_peak - 9.0 / 25.0).abs() < 0.1,
            "{}",
            found.noise_peak
        );
        // At 6× its peers: ratio 36 > 25, flagged, margin above 1.
        sigma[5] = 36.0;
        let found = verdict_after_a_window(&three_triads(), &sigma);
        assert_eq!(found.noisy, 1 << 5);
        assert!(
            (found.noise_peak - 36.0 / 25.0).abs() < 0.3,
            "{}",
            found.noise_peak
        );
    }

    #[test]
    fn without_peers_every_other_channel_is_the_reference() {
        // Seed pyramid: no two axes within 30°, so each channel is compared with all others.
        let a = 28.7f64.to_radians();
        let axes: Vec<[f64; 3]> = (0..4)
            .map(|i| {
                let b = (45.0 + 90.0 * i as f64).to_radians();
                [a.cos() * b.cos(), a.cos() * b.sin(), a.sin()]
            })
            .collect();
        assert_eq!(peer_masks(&axes)[..4], [0; 4]);
        assert_eq!(noisy_after_a_window(&axes, &[1.0, 1.0, 10.0, 1.0]), 1 << 2);
        let peers = peer_masks(&three_triads());
        assert_eq!(peers[2], (1 << 5) | (1 << 8));
    }
}
