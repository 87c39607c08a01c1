//! Static coarse alignment: gyro bias, roll and pitch from a static window, heading from the magnetometer.
//!
//! Roll and pitch. With `C_nb = Rz(ψ) Ry(θ) Rx(φ)` (body→NED) and a vehicle at rest, the specific force is
//! the reaction to gravity, `fⁿ = −gⁿ = [0, 0, −g]`, so
//! `fᵇ = C_nbᵀ [0, 0, −g] = −g · (third row of C_nb)ᵀ = [g sinθ, −g sinφ cosθ, −g cosφ cosθ]`.
//! Hence `θ = atan2(f_x, √(f_y² + f_z²))` (= asin(f_x/|f|)) and `φ = atan2(−f_y, −f_z)`; level gives
//! `f = [0, 0, −g]` and nose-up pitch gives `f_x > 0`. \[R3\]'s `θ = −asin(f_x/g)`, `γ = atan2(f_y, f_z)`
//! are the same relations written for the accelerometer output taken as `−f` (gravity rather than its
//! reaction). The atan2 form stays accurate at any pitch and does not depend on the exact value of g.
//!
//! Heading. The field in body axes is levelled by the roll and pitch just found,
//! `H = Ry(θ) Rx(φ) mᵇ = Rz(ψ)ᵀ mⁿ`, giving
//! `H_x = m_x cosθ + (m_y sinφ + m_z cosφ) sinθ`, `H_y = m_y cosφ − m_z sinφ`. For a field with horizontal
//! intensity B_h pointing at magnetic north, `H_x = B_h cos(ψ − D)` and `H_y = −B_h sin(ψ − D)`, so
//! `ψ = atan2(−H_y, H_x) + D` with the declination D positive east.
//!
//! Gyro bias is the mean rate over the window (\[R3\] eq. 1); it includes the Earth rate, which is what a
//! non-rotating mechanisation should subtract.

use nalgebra::{UnitQuaternion, Vector3};

use crate::attitude::{quaternion_from_euler, wrap_pi};
use rins_earth::STANDARD_GRAVITY;

/// Heading is declared unaided when the levelled horizontal field is below this fraction of the total field
/// (near a magnetic pole or with a dead magnetometer).
const MIN_HORIZONTAL_FIELD_FRACTION: f64 = 0.01;

/// Limits of a static alignment window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlignConfig {
    /// Window length in device time, s.
    pub window_s: f64,
    /// Gravity magnitude expected at the site, m/s².
    pub gravity_mps2: f64,
    /// Largest accepted `| |f̄| − g |`, m/s².
    pub specific_force_tolerance_mps2: f64,
    /// Largest accepted norm of the mean rate (the gyro bias), rad/s.
    pub max_mean_rate_rps: f64,
    /// Largest accepted standard deviation of any specific-force axis over the window, m/s².
    pub max_specific_force_std_mps2: f64,
    /// Largest accepted standard deviation of any rate axis over the window, rad/s.
    pub max_rate_std_rps: f64,
    /// Take the gyro bias from the window's mean rate. Off for a unit that is never still for
    /// long (a foot before its first step): there the mean rate over a fraction of a second is
    /// the foot's sway as much as the gyro's bias, and the filter starts from zero bias instead.
    pub gyro_bias_from_window: bool,
}

impl Default for AlignConfig {
    fn default() -> Self {
        Self {
            window_s: 1.0,
            gravity_mps2: STANDARD_GRAVITY,
            specific_force_tolerance_mps2: 0.3,
            max_mean_rate_rps: 0.1,
            max_specific_force_std_mps2: 0.3,
            max_rate_std_rps: 0.05,
            gyro_bias_from_window: true,
        }
    }
}

/// Result of a successful alignment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Alignment {
    /// Body→NED attitude.
    pub attitude: UnitQuaternion<f64>,
    /// Roll, rad.
    pub roll: f64,
    /// Pitch, rad.
    pub pitch: f64,
    /// Heading (true, with declination applied), rad, in (−π, π]; 0 when not aided.
    pub yaw: f64,
    /// Mean body rate over the window, rad/s.
    pub gyro_bias_rps: Vector3<f64>,
    /// Mean specific force over the window, m/s².
    pub mean_specific_force_mps2: Vector3<f64>,
    /// Mean magnetic field over the window, µT, when any sample arrived.
    pub mean_field_ut: Option<Vector3<f64>>,
    /// True when the heading came from the magnetometer; false means heading 0 by assumption.
    pub heading_aided: bool,
    /// IMU samples in the window.
    pub imu_samples: u32,
    /// Magnetometer samples in the window.
    pub mag_samples: u32,
}

/// Why a window cannot give an alignment; the caller restarts the window.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum AlignError {
    /// The window is not over yet: too short in device time or too few IMU samples.
    #[error("alignment window incomplete: {elapsed_s} s of {required_s} s, {samples} IMU samples")]
    Incomplete {
        /// Device time the window has covered, s.
        elapsed_s: f64,
        /// Window length required, s.
        required_s: f64,
        /// IMU samples in the window so far.
        samples: u32,
    },
    /// The mean specific force is not gravity: the vehicle accelerates (or an accelerometer is
    /// wrong).
    #[error(
        "vehicle not static: mean specific force {magnitude_mps2} m/s² differs from gravity {gravity_mps2} m/s² by more than {tolerance_mps2} m/s²"
    )]
    SpecificForceMagnitude {
        /// Norm of the mean specific force over the window, m/s².
        magnitude_mps2: f64,
        /// Gravity expected at the site, m/s².
        gravity_mps2: f64,
        /// Largest accepted difference, m/s².
        tolerance_mps2: f64,
    },
    /// The mean rate is too large for a vehicle at rest (or a gyro bias beyond what alignment
    /// accepts).
    #[error("vehicle rotating: mean rate {rate_rps} rad/s above {limit_rps} rad/s")]
    RateTooHigh {
        /// Norm of the mean rate over the window, rad/s.
        rate_rps: f64,
        /// Largest accepted norm, rad/s.
        limit_rps: f64,
    },
    /// The specific force varies too much over the window: the vehicle is not at rest.
    #[error(
        "vehicle not static: specific force standard deviation {std_mps2} m/s² above {limit_mps2} m/s²"
    )]
    SpecificForceUnsteady {
        /// Largest standard deviation of a specific-force axis, m/s².
        std_mps2: f64,
        /// Largest accepted, m/s².
        limit_mps2: f64,
    },
    /// The rate varies too much over the window: the vehicle is not at rest.
    #[error("vehicle not static: rate standard deviation {std_rps} rad/s above {limit_rps} rad/s")]
    RateUnsteady {
        /// Largest standard deviation of a rate axis, rad/s.
        std_rps: f64,
        /// Largest accepted, rad/s.
        limit_rps: f64,
    },
}

/// Running mean and variance per axis (Welford), numerically safe over long windows.
#[derive(Debug, Clone, Copy, PartialEq)]
struct AxisStats {
    count: u32,
    mean: Vector3<f64>,
    sum_sq_dev: Vector3<f64>,
}

impl AxisStats {
    const EMPTY: Self = Self {
        count: 0,
        mean: Vector3::new(0.0, 0.0, 0.0),
        sum_sq_dev: Vector3::new(0.0, 0.0, 0.0),
    };

    fn push(&mut self, x: Vector3<f64>) {
        self.count += 1;
        let delta = x - self.mean;
        self.mean += delta / f64::from(self.count);
        self.sum_sq_dev += delta.component_mul(&(x - self.mean));
    }

    /// Largest per-axis sample standard deviation.
    fn max_std(&self) -> f64 {
        if self.count < 2 {
            return 0.0;
        }
        (self.sum_sq_dev.max() / f64::from(self.count - 1)).sqrt()
    }
}

/// Accumulates a static window of fused IMU and magnetometer samples.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticAligner {
    config: AlignConfig,
    window_us: u64,
    start_us: Option<u64>,
    last_us: u64,
    rate: AxisStats,
    force: AxisStats,
    field_sum: Vector3<f64>,
    mag_count: u32,
}

impl StaticAligner {
    /// An empty window. A non-finite or negative `window_s` is treated as zero (the window then completes
    /// on the second sample); validate the configuration before.
    pub fn new(config: AlignConfig) -> Self {
        let window_us = if config.window_s.is_finite() && config.window_s > 0.0 {
            (config.window_s * 1e6).round() as u64
        } else {
            0
        };
        Self {
            config,
            window_us,
            start_us: None,
            last_us: 0,
            rate: AxisStats::EMPTY,
            force: AxisStats::EMPTY,
            field_sum: Vector3::zeros(),
            mag_count: 0,
        }
    }

    /// The limits in use.
    pub fn config(&self) -> &AlignConfig {
        &self.config
    }

    /// Empties the window.
    pub fn reset(&mut self) {
        *self = Self::new(self.config);
    }

    /// Adds one fused IMU sample (rad/s, m/s², FRD). Non-finite samples are ignored (returns false);
    /// device time going backwards restarts the window at this sample.
    pub fn push_imu(
        &mut self,
        device_time_us: u64,
        rate_rps: [f64; 3],
        specific_force: [f64; 3],
    ) -> bool {
        if !rate_rps
            .iter()
            .chain(specific_force.iter())
            .all(|x| x.is_finite())
        {
            return false;
        }
        match self.start_us {
            None => self.start_us = Some(device_time_us),
            Some(_) if device_time_us < self.last_us => {
                self.reset();
                self.start_us = Some(device_time_us);
            }
            Some(_) => {}
        }
        self.last_us = device_time_us;
        self.rate.push(Vector3::from(rate_rps));
        self.force.push(Vector3::from(specific_force));
        true
    }

    /// Adds one magnetometer sample (µT, body FRD). Samples older than the window start or not finite are
    /// ignored (returns false).
    pub fn push_mag(&mut self, device_time_us: u64, field_ut: [f64; 3]) -> bool {
        if !field_ut.iter().all(|x| x.is_finite()) {
            return false;
        }
        if self.start_us.is_some_and(|start| device_time_us < start) {
            return false;
        }
        self.field_sum += Vector3::from(field_ut);
        self.mag_count += 1;
        true
    }

    /// Device time covered by the IMU samples so far, s.
    pub fn elapsed_s(&self) -> f64 {
        self.start_us
            .map_or(0.0, |start| (self.last_us - start) as f64 * 1e-6)
    }

    /// True once the IMU samples span the window (and there are at least two).
    pub fn is_complete(&self) -> bool {
        self.rate.count >= 2
            && self
                .start_us
                .is_some_and(|start| self.last_us - start >= self.window_us)
    }

    /// Alignment from the window, with the declination (rad, positive east) added to the magnetic heading.
    pub fn finish(&self, declination_rad: f64) -> Result<Alignment, AlignError> {
        let c = &self.config;
        if !self.is_complete() {
            return Err(AlignError::Incomplete {
                elapsed_s: self.elapsed_s(),
                required_s: self.window_us as f64 * 1e-6,
                samples: self.rate.count,
            });
        }
        let force_std = self.force.max_std();
        if force_std > c.max_specific_force_std_mps2 {
            return Err(AlignError::SpecificForceUnsteady {
                std_mps2: force_std,
                limit_mps2: c.max_specific_force_std_mps2,
            });
        }
        let rate_std = self.rate.max_std();
        if rate_std > c.max_rate_std_rps {
            return Err(AlignError::RateUnsteady {
                std_rps: rate_std,
                limit_rps: c.max_rate_std_rps,
            });
        }
        let f = self.force.mean;
        let magnitude = f.norm();
        if (magnitude - c.gravity_mps2).abs() > c.specific_force_tolerance_mps2 {
            return Err(AlignError::SpecificForceMagnitude {
                magnitude_mps2: magnitude,
                gravity_mps2: c.gravity_mps2,
                tolerance_mps2: c.specific_force_tolerance_mps2,
            });
        }
        let bias = self.rate.mean;
        if bias.norm() > c.max_mean_rate_rps {
            return Err(AlignError::RateTooHigh {
                rate_rps: bias.norm(),
                limit_rps: c.max_mean_rate_rps,
            });
        }

        let roll = (-f.y).atan2(-f.z);
        let pitch = f.x.atan2(f.y.hypot(f.z));
        let mean_field = (self.mag_count > 0).then(|| self.field_sum / f64::from(self.mag_count));
        let heading = mean_field.and_then(|m| magnetic_heading(&m, roll, pitch));
        let yaw = heading.map_or(0.0, |psi| wrap_pi(psi + declination_rad));
        Ok(Alignment {
            attitude: quaternion_from_euler(roll, pitch, yaw),
            roll,
            pitch,
            yaw,
            gyro_bias_rps: if c.gyro_bias_from_window {
                bias
            } else {
                Vector3::zeros()
            },
            mean_specific_force_mps2: f,
            mean_field_ut: mean_field,
            heading_aided: heading.is_some(),
            imu_samples: self.rate.count,
            mag_samples: self.mag_count,
        })
    }
}

/// Magnetic heading `atan2(−H_y, H_x)` of the tilt-compensated field (\[R3\] eq. 9), rad, or `None` when
/// the horizontal field is too weak to define it.
pub fn magnetic_heading(field_body: &Vector3<f64>, roll: f64, pitch: f64) -> Option<f64> {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (mx, my, mz) = (field_body.x, field_body.y, field_body.z);
    let hx = mx * cp + (my * sr + mz * cr) * sp;
    let hy = my * cr - mz * sr;
    let horizontal = hx.hypot(hy);
    // Samples are finite (checked on entry), so this also catches an all-zero field.
    if horizontal <= MIN_HORIZONTAL_FIELD_FRACTION * field_body.norm() {
        return None;
    }
    Some((-hy).atan2(hx))
}
