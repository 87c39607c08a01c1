//! Height and vertical speed from barometer samples: a two-state constant-velocity Kalman filter.
//!
//! State x = [h, v] (height above the QNH reference, vertical speed positive up). Between samples
//! the vertical acceleration is white noise of spectral density q, so over Δt
//! `F = [[1, Δt], [0, 1]]`, `Q = q·[[Δt³/3, Δt²/2], [Δt²/2, Δt]]`. Each sample measures h through
//! the ISA formula with variance `(dh/dp·σ_p)²`. A gap longer than `max_dt_s` (or time running
//! backwards) restarts the filter from the next sample, since the state is then meaningless.

use crate::error::ConfigError;
use rins_earth::isa::{altitude_per_pascal, pressure_to_altitude};
use serde::{Deserialize, Serialize};

/// Altimeter configuration.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct AltimeterConfig {
    /// Reference pressure for height zero, Pa (default 101 325).
    pub qnh_pa: f64,
    /// White noise σ of one pressure sample, Pa (default 2).
    pub pressure_noise_pa: f64,
    /// Spectral density q of the vertical acceleration modelled as white noise, (m/s²)²/Hz
    /// (default 0.5: a few m/s² of manoeuvre over a second). Larger follows climbs faster, smaller
    /// smooths more.
    pub vertical_accel_psd: f64,
    /// σ of the vertical speed assumed when the filter (re)starts, m/s (default 5).
    pub initial_vertical_speed_sigma_mps: f64,
    /// Longest gap between samples that is still bridged by prediction, s (default 1).
    pub max_dt_s: f64,
    /// Lowest plausible pressure, Pa (default 30 000, about 9 km).
    pub min_pressure_pa: f64,
    /// Highest plausible pressure, Pa (default 110 000).
    pub max_pressure_pa: f64,
}

impl Default for AltimeterConfig {
    fn default() -> Self {
        Self {
            qnh_pa: 101_325.0,
            pressure_noise_pa: 2.0,
            vertical_accel_psd: 0.5,
            initial_vertical_speed_sigma_mps: 5.0,
            max_dt_s: 1.0,
            min_pressure_pa: 30_000.0,
            max_pressure_pa: 110_000.0,
        }
    }
}

/// Range accepted for QNH, Pa: beyond the recorded sea-level extremes (87 kPa, 108.4 kPa).
const QNH_RANGE_PA: (f64, f64) = (80_000.0, 110_000.0);

impl AltimeterConfig {
    /// Checks every field; errors name the field and its value.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let (lo, hi) = QNH_RANGE_PA;
        if !(self.qnh_pa >= lo && self.qnh_pa <= hi) {
            return Err(ConfigError::new(
                "qnh_pa",
                self.qnh_pa,
                format!("must be in {lo}..={hi}"),
            ));
        }
        positive("pressure_noise_pa", self.pressure_noise_pa)?;
        positive("vertical_accel_psd", self.vertical_accel_psd)?;
        positive(
            "initial_vertical_speed_sigma_mps",
            self.initial_vertical_speed_sigma_mps,
        )?;
        positive("max_dt_s", self.max_dt_s)?;
        positive("min_pressure_pa", self.min_pressure_pa)?;
        if !(self.max_pressure_pa.is_finite() && self.max_pressure_pa > self.min_pressure_pa) {
            return Err(ConfigError::new(
                "max_pressure_pa",
                self.max_pressure_pa,
                format!(
                    "must be finite and > min_pressure_pa ({})",
                    self.min_pressure_pa
                ),
            ));
        }
        Ok(())
    }
}

fn positive(field: &str, v: f64) -> Result<(), ConfigError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ConfigError::new(field, v, "must be finite and > 0"))
    }
}

/// Estimate after one sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AltitudeOutput {
    /// Height above the QNH reference, m.
    pub height_m: f64,
    /// Vertical speed, positive up, m/s.
    pub vertical_speed_mps: f64,
    /// Variance of `height_m`, m².
    pub height_var: f64,
    /// Variance of `vertical_speed_mps`, (m/s)².
    pub vertical_speed_var: f64,
    /// False when this sample was rejected (the other fields then repeat the last estimate, or
    /// are zero before the first accepted sample).
    pub valid: bool,
}

/// Filter state after the last accepted sample.
#[derive(Debug, Clone, Copy)]
struct Track {
    time_us: u64,
    h: f64,
    v: f64,
    /// Covariance of [h, v], symmetric.
    p: [[f64; 2]; 2],
}

/// Turns a stream of barometer samples into height and vertical speed. Allocation-free.
#[derive(Debug, Clone)]
pub struct AltitudeEstimator {
    config: AltimeterConfig,
    track: Option<Track>,
    rejected: u64,
    resets: u64,
}

impl AltitudeEstimator {
    /// Builds the estimator after validating `config`.
    pub fn new(config: AltimeterConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(Self {
            config,
            track: None,
            rejected: 0,
            resets: 0,
        })
    }

    /// Processes one sample taken at `device_time_us` (device clock) with static pressure
    /// `pressure_pa`. Non-finite or implausible pressure is rejected and counted.
    ///
    /// The barometer's temperature is not an input: the ISA model assumes the standard lapse
    /// rate, and the die temperature says little about the outside air.
    pub fn update(&mut self, device_time_us: u64, pressure_pa: f64) -> AltitudeOutput {
        let cfg = &self.config;
        if !(pressure_pa.is_finite()
            && pressure_pa >= cfg.min_pressure_pa
            && pressure_pa <= cfg.max_pressure_pa)
        {
            self.rejected += 1;
            return self.output(false);
        }
        let z = pressure_to_altitude(pressure_pa, cfg.qnh_pa);
        let r = (altitude_per_pascal(pressure_pa, cfg.qnh_pa) * cfg.pressure_noise_pa).powi(2);

        let track = match self.track {
            Some(t) if device_time_us >= t.time_us => {
                let dt = (device_time_us - t.time_us) as f64 * 1e-6;
                if dt <= cfg.max_dt_s {
                    Some(predict(t, dt, cfg.vertical_accel_psd))
                } else {
                    None
                }
            }
            _ => None,
        };
        let track = match track {
            Some(t) => correct(t, z, r),
            None => {
                if self.track.is_some() {
                    self.resets += 1;
                }
                let sv = cfg.initial_vertical_speed_sigma_mps;
                Track {
                    time_us: device_time_us,
                    h: z,
                    v: 0.0,
                    p: [[r, 0.0], [0.0, sv * sv]],
                }
            }
        };
        self.track = Some(Track {
            time_us: device_time_us,
            ..track
        });
        self.output(true)
    }

    /// Forgets the state; the next accepted sample restarts the filter.
    pub fn reset(&mut self) {
        self.track = None;
    }

    /// Samples rejected so far (non-finite or implausible pressure).
    pub fn rejected_count(&self) -> u64 {
        self.rejected
    }

    /// Restarts caused by a gap longer than `max_dt_s` or time running backwards.
    pub fn reset_count(&self) -> u64 {
        self.resets
    }

    /// The configuration in use.
    pub fn config(&self) -> &AltimeterConfig {
        &self.config
    }

    fn output(&self, valid: bool) -> AltitudeOutput {
        match self.track {
            Some(t) => AltitudeOutput {
                height_m: t.h,
                vertical_speed_mps: t.v,
                height_var: t.p[0][0],
                vertical_speed_var: t.p[1][1],
                valid,
            },
            None => AltitudeOutput::default(),
        }
    }
}

/// x ← F x, P ← F P Fᵀ + Q.
fn predict(t: Track, dt: f64, q: f64) -> Track {
    let [[p00, p01], [_, p11]] = t.p;
    let dt2 = dt * dt;
    let n00 = p00 + 2.0 * dt * p01 + dt2 * p11 + q * dt2 * dt / 3.0;
    let n01 = p01 + dt * p11 + q * dt2 / 2.0;
    let n11 = p11 + q * dt;
    Track {
        time_us: t.time_us,
        h: t.h + dt * t.v,
        v: t.v,
        p: [[n00, n01], [n01, n11]],
    }
}

/// Scalar measurement of h with variance r.
fn correct(t: Track, z: f64, r: f64) -> Track {
    let [[p00, p01], [_, p11]] = t.p;
    let s = p00 + r;
    let (k0, k1) = (p00 / s, p01 / s);
    let innovation = z - t.h;
    // P ← (I − K H) P, written out for the symmetric 2×2 case.
    let n00 = (1.0 - k0) * p00;
    let n01 = (1.0 - k0) * p01;
    let n11 = p11 - k1 * p01;
    Track {
        time_us: t.time_us,
        h: t.h + k0 * innovation,
        v: t.v + k1 * innovation,
        p: [[n00, n01], [n01, n11]],
    }
}
