//! Stance (zero-velocity) detection for a foot-mounted unit (docs/design.md §6.5; \[R2\], \[R3\], \[R4\]).
//!
//! Three detectors over a trailing window of the last `window` samples:
//! * `thresholds` — every sample of the window has `| |f| − g | < accel_tolerance` and
//!   `|ω| < gyro_max` (the magnitude tests of \[R2\] and \[R3\]);
//! * `fsr` — the foot-pressure reading of the latest sample exceeds `threshold` (\[R3\]);
//! * `shoe` — the stance hypothesis likelihood test (Skog et al.):
//!   `T = (1/W) Σ ( |y_a − g ȳ_a/|ȳ_a||²/σ_a² + |y_ω|²/σ_ω² ) < γ`, with `ȳ_a` the window's mean
//!   specific force;
//! * `ared` — the angular rate energy detector of the same evaluation: SHOE's rate term alone,
//!   `T = (1/W) Σ |y_ω|²/σ_ω² < γ`.
//!
//! A trailing window delays the decision by half a window (12 ms for W = 5 at 200 Hz), which
//! costs nothing in a stance phase of 100 ms or more, and keeps the detector causal for the live
//! pipeline.

use crate::checks::positive;
use serde::{Deserialize, Serialize};

/// Longest window the detector keeps, samples.
pub const MAX_WINDOW: usize = 64;
/// Largest `min_samples`.
pub const MAX_MIN_SAMPLES: usize = 10_000;

/// Which test decides stance, with its parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum StanceTest {
    /// Magnitude thresholds: stance while `|f|` is close to g and `|ω|` is small [R2, R3].
    Thresholds {
        /// Largest `| |f| − g |`, m/s².
        accel_tolerance_mps2: f64,
        /// Largest `|ω|`, rad/s.
        gyro_max_rps: f64,
    },
    /// A foot-pressure sensor \[R3\].
    Fsr {
        /// Normalised foot pressure (0..1) above which the foot is on the ground.
        threshold: f64,
    },
    /// The SHOE detector \[R4\] (docs/design.md §6.5).
    Shoe {
        /// Accelerometer noise σ, m/s².
        accel_sigma_mps2: f64,
        /// Gyro noise σ, rad/s.
        gyro_sigma_rps: f64,
        /// Threshold γ on T.
        threshold: f64,
    },
    /// The angular rate energy detector (Skog et al.): SHOE without its specific-force term.
    Ared {
        /// Gyro noise σ, rad/s.
        gyro_sigma_rps: f64,
        /// Threshold γ on T.
        threshold: f64,
    },
}

/// Detector settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StanceConfig {
    /// Window length W, samples (1..=MAX_WINDOW).
    pub window: usize,
    /// The test and its parameters.
    pub detector: StanceTest,
    /// Consecutive positive decisions before stance is declared (1 = at once). The heel strike
    /// can pass the test for a sample or two while the foot still moves; a zero-velocity update
    /// there pulls the position back along the whole stride through the velocity–position
    /// correlation, so brief detections are not trusted.
    pub min_samples: usize,
    /// SHOE and ARED: after this many samples without stance (0: never), the threshold is raised by
    /// `raise_factor` until a window passes the unraised threshold again. A walk finds stance
    /// every second; a run or a fast turn on the spot can go on for many seconds without a window
    /// as quiet as a walking stance, and with no zero-velocity update at all the solution is
    /// lost within seconds.
    pub raise_after_samples: usize,
    /// Factor on the SHOE or ARED threshold while raised (≥ 1).
    pub raise_factor: f64,
    /// SHOE and ARED: the threshold follows the gait, `γ · (E / 1 (rad/s)²)^gait_exponent`, with `E`
    /// the mean of `|ω|²` over the last `gait_time_constant_s` (exponentially weighted). A run's
    /// stance is never as quiet as a walk's, and a foot standing still is quieter than either,
    /// so one fixed γ is too strict for the one or too lax for the other. 0: a fixed threshold.
    pub gait_exponent: f64,
    /// Time constant of the gait's mean `|ω|²`, s.
    pub gait_time_constant_s: f64,
}

/// Largest `gait_exponent`.
pub const MAX_GAIT_EXPONENT: f64 = 2.0;
/// Largest `gait_time_constant_s`, s.
pub const MAX_GAIT_TIME_CONSTANT_S: f64 = 60.0;
/// The gait's mean `|ω|²` before any sample, (rad/s)²: the threshold starts at γ.
const GAIT_ENERGY_START: f64 = 1.0;
/// Floor of the gait's mean `|ω|²`, (rad/s)²: a unit lying still for minutes does not drive the
/// threshold to nothing.
const GAIT_ENERGY_FLOOR: f64 = 1e-6;

impl Default for StanceConfig {
    /// SHOE with the noise figures and threshold used for every foot-mounted data set.
    fn default() -> Self {
        Self {
            window: 5,
            min_samples: 1,
            raise_after_samples: 0,
            raise_factor: 1.0,
            gait_exponent: 0.0,
            gait_time_constant_s: 1.0,
            detector: StanceTest::Shoe {
                accel_sigma_mps2: 0.01,
                gyro_sigma_rps: 0.1_f64.to_radians(),
                threshold: 1.0e7,
            },
        }
    }
}

impl StanceConfig {
    /// `(field, value)` of the first out-of-range parameter.
    pub fn check(&self) -> Result<(), (&'static str, f64)> {
        if !(1..=MAX_WINDOW).contains(&self.window) {
            return Err(("window", self.window as f64));
        }
        if !(1..=MAX_MIN_SAMPLES).contains(&self.min_samples) {
            return Err(("min_samples", self.min_samples as f64));
        }
        if !(self.raise_factor.is_finite() && self.raise_factor >= 1.0) {
            return Err(("raise_factor", self.raise_factor));
        }
        if !(0.0..=MAX_GAIT_EXPONENT).contains(&self.gait_exponent) {
            return Err(("gait_exponent", self.gait_exponent));
        }
        if !(self.gait_time_constant_s > 0.0
            && self.gait_time_constant_s <= MAX_GAIT_TIME_CONSTANT_S)
        {
            return Err(("gait_time_constant_s", self.gait_time_constant_s));
        }
        match self.detector {
            StanceTest::Thresholds {
                accel_tolerance_mps2,
                gyro_max_rps,
            } => {
                positive("accel_tolerance_mps2", accel_tolerance_mps2)?;
                positive("gyro_max_rps", gyro_max_rps)
            }
            StanceTest::Fsr { threshold } => positive("threshold", threshold),
            StanceTest::Shoe {
                accel_sigma_mps2,
                gyro_sigma_rps,
                threshold,
            } => {
                positive("accel_sigma_mps2", accel_sigma_mps2)?;
                positive("gyro_sigma_rps", gyro_sigma_rps)?;
                positive("threshold", threshold)
            }
            StanceTest::Ared {
                gyro_sigma_rps,
                threshold,
            } => {
                positive("gyro_sigma_rps", gyro_sigma_rps)?;
                positive("threshold", threshold)
            }
        }
    }
}

/// One sample as the detector keeps it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Entry {
    gyro: [f64; 3],
    accel: [f64; 3],
}

fn norm(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Stance detector over a ring of the last samples. Allocation-free.
#[derive(Debug, Clone)]
pub struct StanceDetector {
    config: StanceConfig,
    ring: [Entry; MAX_WINDOW],
    /// Samples held (≤ window).
    len: usize,
    /// Next slot to write.
    head: usize,
    last_statistic: f64,
    /// Consecutive positive decisions so far.
    run: usize,
    /// Samples since the last stance decision.
    since_stance: usize,
    /// The SHOE threshold is raised (see [`StanceConfig::raise_after_samples`]).
    raised: bool,
    /// The gait's mean `|ω|²`, (rad/s)² (see [`StanceConfig::gait_exponent`]).
    gait_energy: f64,
    /// The SHOE threshold of the last decision before any raise, adapted to the gait.
    last_threshold: f64,
}

impl StanceDetector {
    /// A detector with `config` (checked by [`StanceConfig::check`] beforehand; the window is
    /// clamped to 1..=MAX_WINDOW here as well).
    pub fn new(config: StanceConfig) -> Self {
        let mut config = config;
        config.window = config.window.clamp(1, MAX_WINDOW);
        Self {
            config,
            ring: [Entry::default(); MAX_WINDOW],
            len: 0,
            head: 0,
            last_statistic: f64::NAN,
            run: 0,
            since_stance: 0,
            raised: false,
            gait_energy: GAIT_ENERGY_START,
            last_threshold: f64::NAN,
        }
    }

    /// The SHOE threshold of the last decision, adapted to the gait and not raised (NaN before
    /// the window fills or for the other detectors).
    pub fn last_threshold(&self) -> f64 {
        self.last_threshold
    }

    /// The test statistic of the last decision (SHOE's T, the largest magnitude excess for the
    /// thresholds, the pressure for FSR).
    pub fn last_statistic(&self) -> f64 {
        self.last_statistic
    }

    /// Adds a sample (rate rad/s, specific force m/s², optional foot pressure 0..1) taken `dt_s`
    /// after the previous one and decides whether the foot is in stance; `gravity` is the local
    /// g, m/s². False until the window is full.
    pub fn push(
        &mut self,
        gyro: [f64; 3],
        accel: [f64; 3],
        pressure: Option<f64>,
        gravity: f64,
        dt_s: f64,
    ) -> bool {
        let energy: f64 = gyro.iter().map(|x| x * x).sum();
        if energy.is_finite() && dt_s.is_finite() && dt_s > 0.0 {
            let k = (dt_s / self.config.gait_time_constant_s).min(1.0);
            self.gait_energy += k * (energy - self.gait_energy);
        }
        let scale = if self.raised {
            self.config.raise_factor
        } else {
            1.0
        };
        let positive = self.test(gyro, accel, pressure, gravity, scale);
        if positive {
            self.run = self.run.saturating_add(1);
        } else {
            self.run = 0;
        }
        let stance = self.run >= self.config.min_samples;
        if stance {
            self.since_stance = 0;
            // Quiet enough for the unraised threshold: back to it.
            if self.last_statistic < self.last_threshold {
                self.raised = false;
            }
        } else {
            self.since_stance = self.since_stance.saturating_add(1);
            if self.config.raise_after_samples > 0
                && self.since_stance >= self.config.raise_after_samples
            {
                self.raised = true;
            }
        }
        stance
    }

    /// SHOE's or ARED's decision on statistic `t`: below `threshold` adapted to the gait, times
    /// `scale` while raised.
    fn energy_test(&mut self, t: f64, threshold: f64, scale: f64) -> bool {
        self.last_statistic = t;
        self.last_threshold = threshold * self.gait_factor();
        t < self.last_threshold * scale
    }

    /// The gait's factor on the SHOE or ARED threshold (1 with a fixed threshold).
    fn gait_factor(&self) -> f64 {
        if self.config.gait_exponent > 0.0 {
            self.gait_energy
                .max(GAIT_ENERGY_FLOOR)
                .powf(self.config.gait_exponent)
        } else {
            1.0
        }
    }

    /// Whether the SHOE threshold is raised now.
    pub fn is_raised(&self) -> bool {
        self.raised
    }

    /// The detector's test on the window ending with this sample.
    fn test(
        &mut self,
        gyro: [f64; 3],
        accel: [f64; 3],
        pressure: Option<f64>,
        gravity: f64,
        shoe_scale: f64,
    ) -> bool {
        let w = self.config.window;
        self.ring[self.head] = Entry { gyro, accel };
        self.head = (self.head + 1) % w;
        self.len = (self.len + 1).min(w);
        if self.len < w {
            return false;
        }
        let window = &self.ring[..w];
        match self.config.detector {
            StanceTest::Thresholds {
                accel_tolerance_mps2,
                gyro_max_rps,
            } => {
                let worst_accel = window
                    .iter()
                    .map(|e| (norm(&e.accel) - gravity).abs())
                    .fold(0.0, f64::max);
                let worst_gyro = window.iter().map(|e| norm(&e.gyro)).fold(0.0, f64::max);
                self.last_statistic = worst_accel;
                worst_accel < accel_tolerance_mps2 && worst_gyro < gyro_max_rps
            }
            StanceTest::Fsr { threshold } => {
                let p = pressure.unwrap_or(f64::NAN);
                self.last_statistic = p;
                // No reading (NaN) is not stance.
                p > threshold
            }
            StanceTest::Shoe {
                accel_sigma_mps2,
                gyro_sigma_rps,
                threshold,
            } => {
                let mut mean = [0.0; 3];
                for e in window {
                    for (m, a) in mean.iter_mut().zip(e.accel) {
                        *m += a / w as f64;
                    }
                }
                let m = norm(&mean).max(f64::MIN_POSITIVE);
                let up = [mean[0] / m, mean[1] / m, mean[2] / m];
                let mut t = 0.0;
                for e in window {
                    let da: f64 = (0..3).map(|k| (e.accel[k] - gravity * up[k]).powi(2)).sum();
                    let dg: f64 = e.gyro.iter().map(|x| x * x).sum();
                    t += da / (accel_sigma_mps2 * accel_sigma_mps2)
                        + dg / (gyro_sigma_rps * gyro_sigma_rps);
                }
                t /= w as f64;
                self.energy_test(t, threshold, shoe_scale)
            }
            StanceTest::Ared {
                gyro_sigma_rps,
                threshold,
            } => {
                let t = window
                    .iter()
                    .map(|e| e.gyro.iter().map(|x| x * x).sum::<f64>())
                    .sum::<f64>()
                    / (w as f64 * gyro_sigma_rps * gyro_sigma_rps);
                self.energy_test(t, threshold, shoe_scale)
            }
        }
    }
}
