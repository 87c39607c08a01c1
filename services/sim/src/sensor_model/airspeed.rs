//! Pitot-static airspeed sensor (MS4525DO class): the dynamic pressure q = ½ρV² of the true
//! airspeed — the truth velocity less the scenario's wind — with the density of the standard
//! atmosphere at the true altitude, plus a constant offset (the sensor's zero error) and white
//! noise, saturating at the sensor's range. A pitot tube reads the whole airspeed over the small
//! angles of attack and sideslip of a flight, so the model takes the magnitude.
//!
//! Off by default (`[sim.airspeed] enabled = false`): it then emits nothing and draws nothing, and
//! every other frame stays exactly as without it. Its noise comes from its own random stream.

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rins_protocol::layout::AIRSPEED_MAX_ABS_PA;
use rins_protocol::{AirspeedFrame, Payload};
use serde::{Deserialize, Serialize};

use super::baro::isa_temperature_k;
use super::temperature::to_centi_c;
use crate::error::{SimError, check_range};
use crate::sensor_model::SensorModel;
use crate::slow_sensor::{SampleAt, SlowSensor};

/// The random stream of the airspeed noise, after those of the other sensors (0..=5).
const AIRSPEED_STREAM: u64 = 6;

/// `[sim.airspeed]`: the simulated pitot sensor.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct AirspeedSensorConfig {
    /// Whether the block carries the sensor and sends its frames.
    pub enabled: bool,
    /// Frame rate, Hz (at most the IMU rate).
    pub rate_hz: f64,
    /// White noise of the differential pressure, 1σ, Pa.
    pub noise_pa: f64,
    /// Constant zero offset of the differential pressure, Pa.
    pub offset_pa: f64,
}

impl Default for AirspeedSensorConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            rate_hz: 50.0,
            noise_pa: 1.0,
            offset_pa: 0.5,
        }
    }
}

impl AirspeedSensorConfig {
    /// Checks every field against the IMU rate the frames are scheduled on; the error names the
    /// field (`sim.airspeed.…`) and its value.
    pub fn validate(&self, imu_rate_hz: f64) -> Result<(), SimError> {
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0 && self.rate_hz <= imu_rate_hz) {
            return Err(SimError::config(
                "sim.airspeed.rate_hz",
                self.rate_hz,
                "must be > 0 and <= device.imu_rate_hz",
            ));
        }
        check_range(
            "sim.airspeed.noise_pa",
            self.noise_pa,
            0.0,
            100.0,
            "must be within 0..=100",
        )?;
        check_range(
            "sim.airspeed.offset_pa",
            self.offset_pa,
            -100.0,
            100.0,
            "must be within -100..=100",
        )
    }
}

// One ISA for the whole product: the navigator's airspeed aid divides by the same density.
pub use rins_earth::isa::density_kg_m3 as isa_density;

/// The sensor: its errors, its schedule and its random stream.
#[derive(Debug, Clone)]
pub struct AirspeedModel {
    config: AirspeedSensorConfig,
    qnh_pa: f64,
    rng: ChaCha8Rng,
}

impl AirspeedModel {
    /// The model of `config` (validated by the caller), in an atmosphere with sea-level pressure
    /// `qnh_pa`, its noise drawn from `seed`'s airspeed stream.
    pub fn new(config: AirspeedSensorConfig, qnh_pa: f64, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(AIRSPEED_STREAM);
        Self {
            config,
            qnh_pa,
            rng,
        }
    }

    /// Frame rate, Hz.
    pub fn rate_hz(&self) -> f64 {
        self.config.rate_hz
    }

    /// The noiseless reading for air-relative velocity `air_n` (NED, m/s) at `altitude_m`: the
    /// dynamic pressure plus the offset, Pa.
    pub fn expected_pa(&self, air_n: &Vector3<f64>, altitude_m: f64) -> f64 {
        0.5 * isa_density(altitude_m, self.qnh_pa) * air_n.norm_squared() + self.config.offset_pa
    }

    /// Fills `out` for the truth velocity `velocity_n` in the wind `wind_n` (both NED, m/s) at
    /// `altitude_m`.
    pub fn sample(
        &mut self,
        velocity_n: &Vector3<f64>,
        wind_n: &Vector3<f64>,
        altitude_m: f64,
        out: &mut AirspeedFrame,
    ) {
        let noise = self.config.noise_pa * self.rng.sample::<f64, _>(StandardNormal);
        let full_scale = f64::from(AIRSPEED_MAX_ABS_PA);
        let reading = self.expected_pa(&(velocity_n - wind_n), altitude_m) + noise;
        out.diff_pressure_pa = reading.clamp(-full_scale, full_scale) as f32;
        out.temperature_centi_c = to_centi_c(isa_temperature_k(altitude_m) - 273.15);
    }
}

impl SlowSensor for AirspeedModel {
    fn rate_hz(&self) -> f64 {
        self.config.rate_hz
    }

    fn sample(&mut self, at: &SampleAt<'_>, _: &mut SensorModel) -> Payload {
        let mut frame = AirspeedFrame::default();
        let wind_n = at.trajectory.wind_n(at.t_s);
        AirspeedModel::sample(
            self,
            &at.truth.velocity_n,
            &wind_n,
            at.truth.altitude_m,
            &mut frame,
        );
        Payload::Airspeed(frame)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(noise_pa: f64, offset_pa: f64) -> AirspeedModel {
        let config = AirspeedSensorConfig {
            enabled: true,
            noise_pa,
            offset_pa,
            ..AirspeedSensorConfig::default()
        };
        AirspeedModel::new(config, 101_325.0, 1)
    }

    #[test]
    fn sea_level_density_is_the_standard_one() {
        assert!((isa_density(0.0, 101_325.0) - 1.225).abs() < 1e-3);
        // Thinner aloft: about 0.909 kg/m³ at 3 km.
        assert!((isa_density(3000.0, 101_325.0) - 0.909).abs() < 2e-3);
    }

    #[test]
    fn the_reading_is_the_dynamic_pressure_of_the_air_relative_velocity_plus_the_offset() {
        let mut m = model(0.0, 2.0);
        let mut out = AirspeedFrame::default();
        // 25 m/s north into a 5 m/s head wind from the north: 30 m/s through the air.
        m.sample(
            &Vector3::new(25.0, 0.0, 0.0),
            &Vector3::new(-5.0, 0.0, 0.0),
            0.0,
            &mut out,
        );
        let q = 0.5 * isa_density(0.0, 101_325.0) * 900.0;
        assert!((f64::from(out.diff_pressure_pa) - (q + 2.0)).abs() < 1e-3);
        assert_eq!(out.temperature_centi_c, 1500);
    }

    #[test]
    fn the_noise_has_its_configured_spread_and_the_reading_saturates() {
        let mut m = model(3.0, 0.0);
        let mut out = AirspeedFrame::default();
        let n = 4000;
        let sum_sq: f64 = (0..n)
            .map(|_| {
                m.sample(&Vector3::zeros(), &Vector3::zeros(), 0.0, &mut out);
                f64::from(out.diff_pressure_pa).powi(2)
            })
            .sum();
        let sigma = (sum_sq / f64::from(n)).sqrt();
        // The sample σ of 4000 draws is within 5 % of the true one at well over 3σ.
        assert!((sigma - 3.0).abs() < 0.15, "σ = {sigma}");
        m.sample(
            &Vector3::new(300.0, 0.0, 0.0),
            &Vector3::zeros(),
            0.0,
            &mut out,
        );
        assert_eq!(out.diff_pressure_pa, AIRSPEED_MAX_ABS_PA);
    }

    #[test]
    fn bad_values_are_named() {
        let bad = AirspeedSensorConfig {
            noise_pa: -1.0,
            ..AirspeedSensorConfig::default()
        };
        let e = bad.validate(1000.0).unwrap_err().to_string();
        assert!(e.contains("sim.airspeed.noise_pa = -1"), "{e}");
        let fast = AirspeedSensorConfig {
            rate_hz: 2000.0,
            ..AirspeedSensorConfig::default()
        };
        let e = fast.validate(1000.0).unwrap_err().to_string();
        assert!(e.contains("sim.airspeed.rate_hz = 2000"), "{e}");
    }
}
