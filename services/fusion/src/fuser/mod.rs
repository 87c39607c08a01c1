//! The gyro and accelerometer sides together: counts → SI (with temperature compensation) →
//! fault detection and isolation → weighted least squares over the channels in service.
//!
//! Each side is a [`SensorMonitor`]: it owns the solver and parity space of its active channel
//! set, rebuilt only when a channel is excluded or readmitted (rare). Exclusions latch; see
//! [`crate::fdi::monitor`]. The stationary detector spans both sides (it needs the fused rate and
//! specific force) and feeds their stationary references.
//!
//! **Fusion method** (`[fusion] method`): `wls` outputs the monitor's per-sample least-squares
//! solution; `kalman` feeds the same channels to a [`crate::kalman::KalmanFuser`] (see [`crate::kalman`] for
//! when each is better), switched to the new channel set on every exclusion or readmission while
//! keeping its state, so a reconfiguration does not reset or glitch the estimate. Fault detection
//! always works on the raw channel values, independent of the method.
//!
//! **Rest bias** (`[fusion] rest_bias_s`): gyro channel biases from a start-up window at rest,
//! subtracted before parity and the solve; see [`crate::rest_bias`].

mod fused;
mod sensor_side;

pub use fused::Fused;

use crate::config::FusionConfig;
use crate::error::ConfigError;
use crate::fdi::stationary::StationaryDetector;
use crate::fdi::{ChannelEvents, ReadmitError, SensorMonitor};
use crate::geometry::Geometry;
use crate::kalman::FusionMethod;
use crate::rest_bias::{RestBias, RestBiasState};
use ipc_types::{RawImu, SensorType, status};
use sensor_side::{FrameContext, RedundantSensor};

/// Bit of the first accelerometer channel in the raw valid mask (bit i gyro i, bit 16 + i accel i).
pub const ACCEL_MASK_SHIFT: u32 = 16;

/// One raw frame as slices: what [`ImuFuser::fuse_sample`] needs.
#[derive(Debug, Clone, Copy, Default)]
pub struct ImuSample<'a> {
    /// Gyro counts, channel i at index i (missing channels count as invalid).
    pub gyro_counts: &'a [i16],
    /// Accelerometer counts.
    pub accel_counts: &'a [i16],
    /// Bit i gyro channel i valid, bit 16 + i accel channel i valid.
    pub valid_mask: u32,
    /// Device status bits ([`ipc_types::status`]).
    pub status: u32,
    /// Module temperatures, °C (empty: no compensation, no temperature check).
    pub temperatures_c: &'a [f32],
}

/// Combines the redundant gyro and accelerometer channels into body rate and specific force,
/// detecting, isolating and excluding faulty channels.
#[derive(Debug, Clone)]
pub struct ImuFuser {
    gyro: RedundantSensor,
    accel: RedundantSensor,
    stationary: StationaryDetector,
    rest_bias: RestBias,
}

impl ImuFuser {
    /// Builds the fuser. `gyro_lsb` (rad/s per count) and `accel_lsb` (m/s² per count) come from
    /// the ADC full scale of the sensor block.
    pub fn new(config: &FusionConfig, gyro_lsb: f64, accel_lsb: f64) -> Result<Self, ConfigError> {
        let settings = config.fdi_settings()?;
        let kalman = config.kalman_settings()?;
        let rest_window = config.rest_bias_samples()?;
        let gyro = RedundantSensor::new(config, SensorType::Gyro, gyro_lsb, settings, &kalman)?;
        let accel = RedundantSensor::new(config, SensorType::Accel, accel_lsb, settings, &kalman)?;
        // The configured spreads are the motion allowed; the fused values also spread by the
        // sensors' own noise, which grows with √rate: allow it on top.
        let mut stationary = settings.stationary;
        stationary.rate_spread = stationary
            .rate_spread
            .hypot(gyro.fused_noise_variance().sqrt());
        stationary.force_spread = stationary
            .force_spread
            .hypot(accel.fused_noise_variance().sqrt());
        let rest_bias = RestBias::new(rest_window, gyro.geometry.n(), stationary);
        Ok(Self {
            gyro,
            accel,
            stationary: StationaryDetector::new(stationary),
            rest_bias,
        })
    }

    /// Fuses one frame without device status or temperatures. `valid_mask`: bit i gyro channel
    /// i, bit 16 + i accel channel i; invalid channels and channels beyond the end of a counts
    /// slice are excluded (and stay excluded, see [`Self::readmit`]).
    pub fn fuse(&mut self, gyro_counts: &[i16], accel_counts: &[i16], valid_mask: u32) -> Fused {
        self.fuse_sample(&ImuSample {
            gyro_counts,
            accel_counts,
            valid_mask,
            ..ImuSample::default()
        })
    }

    /// Fuses one raw IPC frame (counts sliced to the configured channel counts).
    pub fn fuse_raw(&mut self, raw: &RawImu) -> Fused {
        let n_temperature = usize::from(raw.n_temperature).min(raw.temperature_c.len());
        self.fuse_sample(&ImuSample {
            gyro_counts: &raw.gyro_counts[..self.gyro.geometry.n()],
            accel_counts: &raw.accel_counts[..self.accel.geometry.n()],
            valid_mask: raw.valid_mask,
            status: raw.status,
            temperatures_c: &raw.temperature_c[..n_temperature],
        })
    }

    /// Fuses one frame. Allocates only when a channel is excluded (reconfiguration).
    pub fn fuse_sample(&mut self, sample: &ImuSample) -> Fused {
        let device_error = sample.status & status::DEVICE_ERROR != 0;
        let stationary = self.stationary.is_stationary();
        let mut events = ChannelEvents::EMPTY;
        let frame = FrameContext {
            temperatures_c: sample.temperatures_c,
            device_error,
            stationary,
        };
        let (g, gyro_status) = self.gyro.fuse(
            sample.gyro_counts,
            sample.valid_mask,
            &frame,
            Some(&mut self.rest_bias),
            &mut events,
        );
        let (a, accel_status) = self.accel.fuse(
            sample.accel_counts,
            sample.valid_mask >> ACCEL_MASK_SHIFT,
            &frame,
            None,
            &mut events,
        );
        if let Some(verdict) = self.stationary.push(&g.x, &a.x, g.ok && a.ok) {
            self.gyro.monitor.end_block(verdict);
            self.accel.monitor.end_block(verdict);
        }
        if let Some(bias) = self.rest_bias.end_sample(&g.x, &a.x, g.ok && a.ok) {
            self.gyro.monitor.subtract_channel_biases(bias);
            // The filter's state holds the biased rate: start it afresh on the corrected values.
            if let Some(kf) = self.gyro.kalman.as_mut() {
                kf.reset();
            }
        }
        Fused {
            rate: g.x,
            specific_force: a.x,
            rate_var: g.var,
            specific_force_var: a.var,
            gyro_ok: g.ok,
            accel_ok: a.ok,
            gyro_mask: g.mask,
            accel_mask: a.mask,
            gyro_status,
            accel_status,
            events,
            stationary,
            rest_bias_pending: self.rest_bias.state() == RestBiasState::Collecting,
        }
    }

    /// Re-admits an excluded channel — by explicit command only; exclusions otherwise latch (see
    /// [`crate::fdi::monitor`]). It rejoins the solution after passing its probation
    /// ([`crate::fdi::probation`]). `Ok(false)` when the channel was not excluded.
    pub fn readmit(&mut self, sensor: SensorType, channel: usize) -> Result<bool, ReadmitError> {
        self.monitor_mut(sensor).readmit(channel)
    }

    /// The fault-detection state of one sensor type.
    pub fn monitor(&self, sensor: SensorType) -> &SensorMonitor {
        match sensor {
            SensorType::Gyro => &self.gyro.monitor,
            SensorType::Accel => &self.accel.monitor,
        }
    }

    fn monitor_mut(&mut self, sensor: SensorType) -> &mut SensorMonitor {
        match sensor {
            SensorType::Gyro => &mut self.gyro.monitor,
            SensorType::Accel => &mut self.accel.monitor,
        }
    }

    /// The start-up window at rest was found and its per-channel gyro biases are being subtracted.
    pub fn rest_bias_estimated(&self) -> bool {
        self.rest_bias.state() == RestBiasState::Estimated
    }

    /// Where the start-up gyro bias estimate stands (collecting, estimated, not at rest, disabled).
    pub fn rest_bias_state(&self) -> RestBiasState {
        self.rest_bias.state()
    }

    /// The per-channel gyro biases subtracted, rad/s (N entries; zeros unless estimated).
    pub fn gyro_rest_bias(&self) -> &[f64] {
        self.rest_bias.bias()
    }

    /// How the channels are fused.
    pub fn method(&self) -> FusionMethod {
        if self.gyro.kalman.is_some() {
            FusionMethod::Kalman
        } else {
            FusionMethod::Wls
        }
    }

    /// Gyro axes.
    pub fn gyro_geometry(&self) -> &Geometry {
        &self.gyro.geometry
    }

    /// Accelerometer axes.
    pub fn accel_geometry(&self) -> &Geometry {
        &self.accel.geometry
    }
}
