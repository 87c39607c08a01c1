//! One sensor type of the fuser: counts → SI (with temperature compensation and the rest bias) →
//! its fault monitor → the monitor's least-squares solution or, with the Kalman method, the filter
//! over the monitor's active channels.

use crate::calibration::{Calibration, MAX_TEMPERATURE_C, MIN_TEMPERATURE_C};
use crate::config::FusionConfig;
use crate::error::ConfigError;
use crate::fdi::channel_health::stuck_run_needed;
use crate::fdi::{
    ChannelEvents, FdiSettings, MonitorInput, SensorEstimate, SensorMonitor, SensorStatus,
};
use crate::geometry::{Geometry, MAX_CHANNELS, channel_mask};
use crate::kalman::{FusionMethod, KalmanConfig, KalmanFuser};
use crate::rest_bias::RestBias;
use ipc_types::SensorType;

/// What both sides of one frame share.
#[derive(Debug, Clone, Copy)]
pub(super) struct FrameContext<'a> {
    /// Module temperatures, °C.
    pub temperatures_c: &'a [f32],
    /// The device reports an error.
    pub device_error: bool,
    /// The vehicle is judged stationary now.
    pub stationary: bool,
}

/// One sensor type: geometry, calibration, its fault monitor and, with the Kalman method, the
/// filter over the monitor's active channels.
#[derive(Debug, Clone)]
pub(super) struct RedundantSensor {
    /// Sensitive axes of the channels.
    pub geometry: Geometry,
    /// Counts → SI per channel.
    calibration: Calibration,
    /// Fault detection, isolation and the least-squares solution.
    pub monitor: SensorMonitor,
    /// Channel noise σ² including quantisation (first N entries).
    variances: [f64; MAX_CHANNELS],
    /// The filter of the Kalman method (`None` with WLS).
    pub kalman: Option<KalmanFuser>,
}

impl RedundantSensor {
    /// The side of `sensor` from the configuration; `lsb` is its converter step in SI units.
    pub fn new(
        config: &FusionConfig,
        sensor: SensorType,
        lsb: f64,
        mut settings: FdiSettings,
        kalman: &KalmanConfig,
    ) -> Result<Self, ConfigError> {
        let lsb_field = match sensor {
            SensorType::Gyro => "gyro_lsb",
            SensorType::Accel => "accel_lsb",
        };
        if !(lsb.is_finite() && lsb > 0.0) {
            return Err(ConfigError::new(lsb_field, lsb, "must be finite and > 0"));
        }
        let (geometry, mut variances, calibration) = config.side_parts(sensor)?;
        let n = geometry.n();
        let calibration = Calibration::new(calibration, n, lsb)
            .map_err(|e| e.within(sensor.name()).within("calibration"))?;
        // A healthy channel repeats its count in runs whose length depends on its noise in
        // counts (long at low rates, where the white noise is below one count): the stuck run
        // must be long enough for the quietest channel.
        let quietest = (0..n)
            .map(|i| {
                let step = (calibration.apply(i, 1) - calibration.apply(i, 0)).abs();
                variances[i].sqrt() / step
            })
            .fold(f64::INFINITY, f64::min);
        let channel_samples_per_hour = n as f64 * config.block.imu_rate_hz * 3600.0;
        settings.health.stuck_samples = settings
            .health
            .stuck_samples
            .max(stuck_run_needed(quietest, channel_samples_per_hour));
        // The converter adds its quantisation noise, (step)²/12 with the step in SI units, to the
        // sensor's own: significant at 1–2 lsb of noise, where it raises the variance by 2–6 %.
        for (i, v) in variances.iter_mut().enumerate().take(n) {
            let step = calibration.apply(i, 1) - calibration.apply(i, 0);
            *v += step * step / 12.0;
        }
        let [rail_lo, rail_hi] = settings.health.rails;
        let rail_values =
            std::array::from_fn(|i| [calibration.apply(i, rail_lo), calibration.apply(i, rail_hi)]);
        let monitor = SensorMonitor::new(sensor, geometry, variances, rail_values, settings);
        // The full geometry passed the conditioning check, so this only fails on a logic error.
        if monitor.solver().is_none() {
            return Err(ConfigError::new(
                format!("geometry.{}", sensor.name()),
                format!("{n} axes"),
                "no least-squares solution for the full channel set",
            ));
        }
        let kalman = match config.method {
            FusionMethod::Wls => None,
            FusionMethod::Kalman => {
                let (q, field) = match sensor {
                    SensorType::Gyro => (kalman.process_noise.gyro, "process_noise.gyro"),
                    SensorType::Accel => (kalman.process_noise.accel, "process_noise.accel"),
                };
                let kf = KalmanFuser::new(
                    &geometry,
                    geometry.full_mask(),
                    &variances[..n],
                    config.sample_period_s(),
                    q,
                )
                .map_err(|e| ConfigError::new(format!("kalman.{field}"), q, e.to_string()))?;
                Some(kf)
            }
        };
        Ok(Self {
            geometry,
            calibration,
            monitor,
            variances,
            kalman,
        })
    }

    /// The largest per-axis variance of the least-squares estimate from the channel noise alone
    /// (full channel set), SI²: what the stationary detector's spreads must allow beyond motion.
    pub fn fused_noise_variance(&self) -> f64 {
        let n = self.geometry.n();
        let worst = self.variances[..n].iter().copied().fold(0.0, f64::max);
        let factor = self
            .geometry
            .variance_factors()
            .into_iter()
            .fold(0.0, f64::max);
        worst * factor
    }

    /// One side of one frame. `rest_bias`: the start-up bias estimate of this side, if any
    /// (collects the calibrated values, later subtracts the biases before parity and the solve).
    pub fn fuse(
        &mut self,
        counts: &[i16],
        valid: u32,
        frame: &FrameContext,
        rest_bias: Option<&mut RestBias>,
        events: &mut ChannelEvents,
    ) -> (SensorEstimate, SensorStatus) {
        let FrameContext {
            temperatures_c,
            device_error,
            stationary,
        } = *frame;
        let n = self.geometry.n();
        let valid = valid & channel_mask(n.min(counts.len()));
        let mut z = [f64::NAN; MAX_CHANNELS];
        let mut temperature_suspect = 0;
        if temperatures_c.is_empty() {
            self.calibration.apply_all(counts, &mut z);
        } else {
            self.calibration
                .apply_all_with_temperature(counts, temperatures_c, &mut z);
            for i in 0..n {
                let reading = temperatures_c.get(self.calibration.temperature_sensor(i));
                if reading.is_some_and(|&t| {
                    !(f64::from(t).is_finite()
                        && (MIN_TEMPERATURE_C..=MAX_TEMPERATURE_C).contains(&f64::from(t)))
                }) {
                    temperature_suspect |= 1 << i;
                }
            }
        }
        if let Some(rest_bias) = rest_bias {
            rest_bias.apply(&mut z, valid);
        }
        let input = MonitorInput {
            counts,
            z: &z,
            valid,
            device_error,
            temperature_suspect,
        };
        let (estimate, status) = self.monitor.step(&input, stationary, events);
        let estimate = match self.kalman.as_mut() {
            Some(kf) => {
                let z = self.monitor.corrected(&z);
                Self::filter(kf, &self.geometry, &self.variances, estimate, &z)
            }
            None => estimate,
        };
        (estimate, status)
    }

    /// The Kalman estimate over the channels the monitor solved with, following its channel set.
    fn filter(
        kf: &mut KalmanFuser,
        geometry: &Geometry,
        variances: &[f64; MAX_CHANNELS],
        wls: SensorEstimate,
        z: &[f64; MAX_CHANNELS],
    ) -> SensorEstimate {
        let not_ok = SensorEstimate {
            mask: wls.mask,
            ..SensorEstimate::default()
        };
        if !wls.ok {
            kf.reset();
            return not_ok;
        }
        if kf.mask() != wls.mask
            && kf
                .set_channels(geometry, wls.mask, &variances[..geometry.n()])
                .is_err()
        {
            kf.reset();
            return not_ok;
        }
        let (x, var) = kf.update(z);
        SensorEstimate {
            x,
            var,
            ok: true,
            mask: wls.mask,
        }
    }
}
