//! Error models of the simulated sensor block: redundant single-axis gyros and accelerometers with a
//! 12-bit ADC, module temperatures, barometer, magnetometer and foot-pressure sensor, and the rotor
//! vibration a multirotor shakes the block with ([`vibration`]).
//!
//! Everything random comes from ChaCha8 generators seeded with one `u64`; each sensor type draws from
//! its own stream so that, for instance, changing the barometer rate leaves the IMU noise unchanged,
//! and injecting a fault into one channel leaves the noise of every other channel unchanged.
//! Samples are instantaneous values at the sample time (no anti-alias averaging).

pub mod baro;
pub mod config;
pub mod fault;
mod foot_pressure;
pub mod inertial;
pub mod mag;
mod temperature;
pub mod vibration;

/// The `pub mod` declarations of the listed slower sensors whose model has a file of its own.
macro_rules! model_modules {
    ($($name:ident $(in mod $module:ident)?: fitted $build:expr, checked $check:expr;)*) => {
        $($(pub mod $module;)?)*
    };
}

// The models of the slower sensors that have a file of their own (`airspeed`, …), declared by
// their entries in the one list of the slower sensors (`slow_sensor_list.rs`).
crate::slow_sensor_list::slow_sensor_list!(model_modules);

use ipc_types::MAX_CHANNELS;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rins_protocol::{AuxFrame, BaroFrame, ImuFrame, MagFrame};

use crate::error::SimError;
use crate::trajectory::TruthState;
use baro::BaroModel;
pub use config::SensorModelConfig;
use fault::{ChannelFault, InertialSensor};
use foot_pressure::FootPressureModel;
use inertial::{BankParams, ChannelErrors, InertialBank};
use mag::{EarthField, MagModel};
use rins_earth::STANDARD_GRAVITY;
pub use temperature::TEMPERATURE_SLOTS;
use temperature::TemperatureModel;

/// Fewest inertial channels of one kind.
pub const MIN_CHANNELS: usize = 3;
/// Shortest accepted axis vector before normalisation.
const MIN_AXIS_NORM: f64 = 1e-6;

/// Atmosphere and magnetic field the sensors are immersed in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Environment {
    /// Sea-level pressure used by the ISA model, Pa.
    pub qnh_pa: f64,
    /// Local Earth magnetic field.
    pub earth_field: EarthField,
}

/// Independent random streams, one per consumer.
#[derive(Debug, Clone)]
struct Streams {
    imu: ChaCha8Rng,
    baro: ChaCha8Rng,
    mag: ChaCha8Rng,
    aux: ChaCha8Rng,
    fault: ChaCha8Rng,
}

fn stream(seed: u64, id: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(id);
    rng
}

/// All sensor models of the block.
#[derive(Debug, Clone)]
pub struct SensorModel {
    gyro: InertialBank,
    accel: InertialBank,
    temperature: TemperatureModel,
    baro: BaroModel,
    mag: MagModel,
    foot: FootPressureModel,
    rng: Streams,
}

/// Validates and normalises one axis list (3..=16 finite, non-zero vectors).
pub fn normalize_axes(
    kind: &'static str,
    axes: &[[f64; 3]],
) -> Result<Vec<Vector3<f64>>, SimError> {
    if !(MIN_CHANNELS..=MAX_CHANNELS).contains(&axes.len()) {
        return Err(SimError::AxisCount {
            kind,
            count: axes.len(),
        });
    }
    axes.iter()
        .enumerate()
        .map(|(index, a)| {
            let v = Vector3::from(*a);
            let err = |reason| SimError::Axis {
                kind,
                index,
                axis: *a,
                reason,
            };
            if !a.iter().all(|x| x.is_finite()) {
                Err(err("components must be finite"))
            } else if v.norm() < MIN_AXIS_NORM {
                Err(err("must not be a zero vector"))
            } else {
                Ok(v.normalize())
            }
        })
        .collect()
}

impl SensorModel {
    /// Builds the models; draws every channel's errors from `seed`. `config` is validated here.
    pub fn new(
        config: &SensorModelConfig,
        environment: &Environment,
        gyro_axes: &[[f64; 3]],
        accel_axes: &[[f64; 3]],
        imu_rate_hz: f64,
        seed: u64,
    ) -> Result<Self, SimError> {
        config.validate()?;
        let gyro_axes = normalize_axes("gyro", gyro_axes)?;
        let accel_axes = normalize_axes("accel", accel_axes)?;
        crate::error::check_positive(
            "sim.imu_rate_hz",
            imu_rate_hz,
            1e6,
            "must be > 0 and <= 1000000",
        )?;

        let mut construction = stream(seed, 0);
        let period = 1.0 / imu_rate_hz;
        let sqrt_rate = imu_rate_hz.sqrt();
        let temperature_sensors = usize::from(config.temperature_sensors);
        let misalignment = config.axis_misalignment_sigma_mrad * 1e-3;
        let gyro = InertialBank::new(
            &gyro_axes,
            &BankParams {
                lsb: config.gyro_lsb_rps(),
                white_sigma: config.gyro_noise_density_dps_rthz.to_radians() * sqrt_rate,
                turn_on_sigma: config.gyro_turn_on_bias_sigma_dps.to_radians(),
                gm_sigma: config.gyro_bias_instability_sigma_dps.to_radians(),
                gm_tau_s: config.gyro_bias_instability_tau_s,
                scale_sigma: config.gyro_scale_error_sigma,
                temp_coeff_sigma: config.gyro_bias_temp_coeff_sigma_dps_per_c.to_radians(),
                misalignment_sigma_rad: misalignment,
                sample_period_s: period,
                temperature_sensors,
            },
            &mut construction,
        );
        let mg = 1e-3 * STANDARD_GRAVITY;
        let accel = InertialBank::new(
            &accel_axes,
            &BankParams {
                lsb: config.accel_lsb_mps2(),
                white_sigma: config.accel_noise_density_ug_rthz
                    * 1e-6
                    * STANDARD_GRAVITY
                    * sqrt_rate,
                turn_on_sigma: config.accel_turn_on_bias_sigma_mg * mg,
                gm_sigma: config.accel_bias_instability_sigma_mg * mg,
                gm_tau_s: config.accel_bias_instability_tau_s,
                scale_sigma: config.accel_scale_error_sigma,
                temp_coeff_sigma: config.accel_bias_temp_coeff_sigma_mg_per_c * mg,
                misalignment_sigma_rad: misalignment,
                sample_period_s: period,
                temperature_sensors,
            },
            &mut construction,
        );
        let temperature = TemperatureModel::new(
            temperature_sensors,
            config.temperature_c,
            config.temperature_spread_c,
            config.temperature_warmup_c,
            config.temperature_warmup_tau_s,
            &mut construction,
        );
        let ut = 1e3; // nT per µT
        Ok(Self {
            gyro,
            accel,
            temperature,
            baro: BaroModel {
                qnh_pa: environment.qnh_pa,
                noise_pa: config.baro_noise_pa,
            },
            mag: MagModel {
                field_ned_nt: environment.earth_field.ned_nt(),
                soft_iron: Matrix3::from_fn(|r, c| config.mag_soft_iron[r][c]),
                hard_iron_nt: Vector3::from(config.mag_hard_iron_ut) * ut,
                noise_nt: config.mag_noise_ut * ut,
            },
            foot: FootPressureModel {
                noise_counts: config.foot_pressure_noise_counts,
            },
            rng: Streams {
                imu: stream(seed, 1),
                baro: stream(seed, 2),
                mag: stream(seed, 3),
                aux: stream(seed, 4),
                fault: stream(seed, 5),
            },
        })
    }

    /// Samples every gyro and accelerometer channel and the module temperatures for `truth`.
    pub fn imu(&mut self, truth: &TruthState, out: &mut ImuFrame) {
        let delta_c = self.temperature.delta_c(truth.time_s);
        let (vibration_rate_b, vibration_force_b) = vibration::body_vibration(&truth.rotor);
        let g = self.gyro.sample(
            &(truth.angular_rate_b + vibration_rate_b),
            truth.time_s,
            &delta_c,
            &mut self.rng.imu,
            &mut self.rng.fault,
            &mut out.gyro_counts,
        );
        let a = self.accel.sample(
            &(truth.specific_force_b + vibration_force_b),
            truth.time_s,
            &delta_c,
            &mut self.rng.imu,
            &mut self.rng.fault,
            &mut out.accel_counts,
        );
        self.temperature
            .centi_c(&delta_c, &mut out.temperature_centi_c);
        // Channel counts are at most 16, so they fit the u8 fields.
        out.n_gyro = self.gyro.count() as u8;
        out.n_accel = self.accel.count() as u8;
        out.n_temperature = self.temperature.count() as u8;
        out.valid_mask = u32::from(g.valid) | (u32::from(a.valid) << 16);
        // The frame's status word is 16 bits; the device status bits all live in the low half.
        out.status = if g.saturated || a.saturated {
            ipc_types::status::SATURATION as u16
        } else {
            0
        };
    }

    /// Samples the barometer at the true altitude.
    pub fn baro(&mut self, altitude_m: f64, out: &mut BaroFrame) {
        self.baro.sample(altitude_m, &mut self.rng.baro, out);
    }

    /// Samples the magnetometer at the true attitude.
    pub fn mag(&mut self, attitude: &UnitQuaternion<f64>, out: &mut MagFrame) {
        self.mag.sample(attitude, &mut self.rng.mag, out);
    }

    /// Samples the foot-pressure sensor under the true load `foot_load` (fraction of full scale).
    pub fn foot_pressure(&mut self, foot_load: f64, out: &mut AuxFrame) {
        self.foot.sample(foot_load, &mut self.rng.aux, out);
    }

    fn bank(&self, sensor: InertialSensor) -> &InertialBank {
        match sensor {
            InertialSensor::Gyro => &self.gyro,
            InertialSensor::Accel => &self.accel,
        }
    }

    /// Number of channels of one kind.
    pub fn channel_count(&self, sensor: InertialSensor) -> usize {
        self.bank(sensor).count()
    }

    /// The true errors of one channel (SI units of the channel), `None` if it does not exist.
    pub fn channel_errors(&self, sensor: InertialSensor, channel: usize) -> Option<&ChannelErrors> {
        self.bank(sensor).errors(channel)
    }

    /// Total additive bias of a channel at time `t_s` (turn-on + Gauss–Markov + temperature term).
    pub fn channel_bias(&self, sensor: InertialSensor, channel: usize, t_s: f64) -> Option<f64> {
        let e = self.channel_errors(sensor, channel)?;
        Some(e.bias_at(self.temperature.delta_c(t_s)[e.temperature_sensor]))
    }

    /// Module temperatures above the nominal temperature at `t_s`, °C.
    pub fn temperature_delta_c(&self, t_s: f64) -> [f64; TEMPERATURE_SLOTS] {
        self.temperature.delta_c(t_s)
    }

    /// The fault in effect on a channel, if any.
    pub fn fault(&self, sensor: InertialSensor, channel: usize) -> Option<ChannelFault> {
        self.bank(sensor).fault(channel)
    }

    /// Injects (`Some`) or clears (`None`) a fault on a channel from time `now_s`.
    pub fn set_fault(
        &mut self,
        sensor: InertialSensor,
        channel: usize,
        fault: Option<ChannelFault>,
        now_s: f64,
    ) -> Result<(), SimError> {
        if let Some(f) = &fault {
            f.validate()?;
        }
        let bank = match sensor {
            InertialSensor::Gyro => &mut self.gyro,
            InertialSensor::Accel => &mut self.accel,
        };
        if channel >= bank.count() {
            return Err(SimError::NoSuchChannel {
                kind: sensor.name(),
                channel,
                count: bank.count(),
            });
        }
        bank.set_fault(channel, fault, now_s);
        Ok(())
    }
}
