//! Simulator configuration (the `[sim]` section of the product configuration).

use serde::{Deserialize, Serialize};

use crate::calibration_config::CalibrationConfig;
use crate::error::{SimError, check_positive, check_range};
use crate::sensor_model::mag::EarthField;
use crate::sensor_model::{Environment, SensorModelConfig};
use crate::slow_sensor_list::slow_sensor_list;
use crate::trajectory::multirotor_config::MultirotorConfig;
use crate::trajectory::{Scenario, TrajectoryStart};

/// Highest accepted IMU rate, Hz.
pub const MAX_IMU_RATE_HZ: f64 = 100_000.0;
/// Latitude limit: longitude rate grows as 1/cos φ near the poles.
pub const MAX_ABS_LATITUDE_DEG: f64 = 85.0;

/// Local Earth magnetic field as configured.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct EarthFieldConfig {
    /// Total intensity, µT.
    pub intensity_ut: f64,
    /// Inclination (dip), positive down, degrees.
    pub inclination_deg: f64,
    /// Declination, positive east, degrees.
    pub declination_deg: f64,
}

impl Default for EarthFieldConfig {
    fn default() -> Self {
        Self {
            intensity_ut: 50.0,
            inclination_deg: 60.0,
            declination_deg: 0.0,
        }
    }
}

impl EarthFieldConfig {
    /// The field in SI-style internal units (nT, rad).
    pub fn to_field(&self) -> EarthField {
        EarthField {
            intensity_nt: self.intensity_ut * 1e3,
            inclination_rad: self.inclination_deg.to_radians(),
            declination_rad: self.declination_deg.to_radians(),
        }
    }
}

/// Everything the simulator needs besides the sensor geometry and the seed.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// Motion to simulate.
    pub scenario: Scenario,
    /// Seed of every random draw: the same seed gives the same frames.
    pub seed: u64,
    /// IMU frame rate (the simulator's base tick), Hz: the block's, `device.imu_rate_hz`, set
    /// by the deployment (not a `[sim]` key).
    #[serde(skip)]
    pub imu_rate_hz: f64,
    /// Barometer frame rate, Hz (at most the IMU rate).
    pub baro_rate_hz: f64,
    /// Magnetometer frame rate, Hz (at most the IMU rate).
    pub mag_rate_hz: f64,
    /// Auxiliary (foot-pressure) frame rate, Hz (at most the IMU rate).
    pub aux_rate_hz: f64,
    /// Origin geodetic latitude, degrees.
    pub origin_latitude_deg: f64,
    /// Origin longitude, degrees.
    pub origin_longitude_deg: f64,
    /// Ground altitude at the origin above mean sea level, m.
    pub origin_altitude_m: f64,
    /// Initial heading, degrees clockwise from true north.
    pub initial_heading_deg: f64,
    /// UAV, walk and calibrate scenarios: time at rest, level, before moving, s (the window a
    /// navigator's static alignment needs).
    pub static_s: f64,
    /// UAV scenario: length of the whole flight, s (parking, take-off, circuits, landing); the
    /// pair of circuits repeats as many times as fit. Unset: one pair (about 615 s), then parked.
    /// The multirotor scenario repeats its pattern the same way (unset: one, about 125 s).
    pub uav_flight_s: Option<f64>,
    /// Sea-level pressure of the ISA model, Pa.
    pub qnh_pa: f64,
    /// Local Earth magnetic field.
    pub earth_field: EarthFieldConfig,
    /// Sensor error model.
    pub sensors: SensorModelConfig,
    /// Calibrate scenario: the turns and the magnetometer's hard and soft iron.
    pub calibration: CalibrationConfig,
    /// Multirotor scenario: the airframe's rotor drag, the gust and the rotor vibration
    /// (`[sim.multirotor]`).
    pub multirotor: MultirotorConfig,
    /// The simulated GNSS receiver (`[sim.gnss]`).
    pub gnss: crate::gnss_config::GnssReceiverConfig,
    /// The simulated pitot airspeed sensor (`[sim.airspeed]`; off by default).
    pub airspeed: crate::sensor_model::airspeed::AirspeedSensorConfig,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            scenario: Scenario::Uav,
            seed: 1,
            imu_rate_hz: 1000.0,
            baro_rate_hz: 50.0,
            mag_rate_hz: 100.0,
            aux_rate_hz: 100.0,
            origin_latitude_deg: 47.397_742,
            origin_longitude_deg: 8.545_594,
            origin_altitude_m: 488.0,
            initial_heading_deg: 0.0,
            static_s: 3.0,
            uav_flight_s: None,
            qnh_pa: 101_325.0,
            earth_field: EarthFieldConfig::default(),
            sensors: SensorModelConfig::default(),
            calibration: CalibrationConfig::default(),
            multirotor: MultirotorConfig::default(),
            gnss: crate::gnss_config::GnssReceiverConfig::default(),
            airspeed: Default::default(),
        }
    }
}

/// `check_slow_sensors`: the settings checks of the listed slower sensors (their CHECK; their
/// BUILD is read by `slow_sensors.rs`), in list order.
macro_rules! slow_sensor_checks {
    ($($name:ident $(in mod $module:ident)?: fitted $build:expr, checked $check:expr;)*) => {
        fn check_slow_sensors(config: &SimConfig) -> Result<(), SimError> {
            $(check(config, $check)?;)*
            Ok(())
        }
    };
}

slow_sensor_list!(slow_sensor_checks);

/// Runs one entry's CHECK (a function, so that its closure's argument type is known).
fn check(
    config: &SimConfig,
    check: impl FnOnce(&SimConfig) -> Result<(), SimError>,
) -> Result<(), SimError> {
    check(config)
}

/// Checks a slower sensor's frame rate, Hz: positive and at most the IMU rate the frames are
/// scheduled on.
fn check_rate(field: &'static str, rate_hz: f64, config: &SimConfig) -> Result<(), SimError> {
    check_positive(
        field,
        rate_hz,
        config.imu_rate_hz,
        "must be > 0 and <= device.imu_rate_hz",
    )
}

impl SimConfig {
    /// Checks every field; the error names the field (`sim.…`) and its value.
    pub fn validate(&self) -> Result<(), SimError> {
        check_positive(
            "device.imu_rate_hz",
            self.imu_rate_hz,
            MAX_IMU_RATE_HZ,
            "must be > 0 and <= 100000",
        )?;
        // The slower sensors' own checks (their rates against the IMU's first of all).
        check_slow_sensors(self)?;
        check_range(
            "sim.origin_latitude_deg",
            self.origin_latitude_deg,
            -MAX_ABS_LATITUDE_DEG,
            MAX_ABS_LATITUDE_DEG,
            "must be within -85..=85",
        )?;
        check_range(
            "sim.origin_longitude_deg",
            self.origin_longitude_deg,
            -180.0,
            180.0,
            "must be within -180..=180",
        )?;
        // The ISA troposphere ends at 11 km; leave room for the climb.
        check_range(
            "sim.origin_altitude_m",
            self.origin_altitude_m,
            -500.0,
            8000.0,
            "must be within -500..=8000",
        )?;
        check_range(
            "sim.initial_heading_deg",
            self.initial_heading_deg,
            -360.0,
            360.0,
            "must be within -360..=360",
        )?;
        check_range(
            "sim.static_s",
            self.static_s,
            0.0,
            86_400.0,
            "must be within 0..=86400",
        )?;
        if let Some(flight_s) = self.uav_flight_s {
            check_range(
                "sim.uav_flight_s",
                flight_s,
                0.0,
                86_400.0,
                "must be within 0..=86400",
            )?;
        }
        check_range(
            "sim.qnh_pa",
            self.qnh_pa,
            50_000.0,
            120_000.0,
            "must be within 50000..=120000",
        )?;
        check_positive(
            "sim.earth_field.intensity_ut",
            self.earth_field.intensity_ut,
            1000.0,
            "must be > 0 and <= 1000",
        )?;
        check_range(
            "sim.earth_field.inclination_deg",
            self.earth_field.inclination_deg,
            -90.0,
            90.0,
            "must be within -90..=90",
        )?;
        check_range(
            "sim.earth_field.declination_deg",
            self.earth_field.declination_deg,
            -180.0,
            180.0,
            "must be within -180..=180",
        )?;
        self.calibration.validate()?;
        self.multirotor.validate()?;
        self.gnss
            .validate(self.imu_rate_hz)
            .map_err(SimError::GnssReceiver)?;
        self.sensors.validate()
    }

    /// The sensor error model the simulator runs: `sensors`, with the calibrate scenario's
    /// magnetometer distortion in that scenario.
    pub fn sensor_model(&self) -> SensorModelConfig {
        match self.scenario {
            Scenario::Calibrate => self.calibration.distort(&self.sensors),
            _ => self.sensors.clone(),
        }
    }

    /// Gyro ADC resolution: rad/s per count (same scale the fusion side must use).
    pub fn gyro_lsb_rps(&self) -> f64 {
        self.sensors.gyro_lsb_rps()
    }

    /// Accelerometer ADC resolution: m/s² per count.
    pub fn accel_lsb_mps2(&self) -> f64 {
        self.sensors.accel_lsb_mps2()
    }

    /// Start point and heading of the trajectory, in radians.
    pub fn trajectory_start(&self) -> TrajectoryStart {
        TrajectoryStart {
            latitude_rad: self.origin_latitude_deg.to_radians(),
            longitude_rad: self.origin_longitude_deg.to_radians(),
            altitude_m: self.origin_altitude_m,
            heading_rad: self.initial_heading_deg.to_radians(),
            static_s: self.static_s,
            uav_flight_s: self.uav_flight_s,
            calibration_sweep_s: self.calibration.sweep_s,
            multirotor: self.multirotor,
        }
    }

    /// Atmosphere and magnetic field.
    pub fn environment(&self) -> Environment {
        Environment {
            qnh_pa: self.qnh_pa,
            earth_field: self.earth_field.to_field(),
        }
    }
}
