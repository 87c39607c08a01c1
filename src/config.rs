//! The product configuration: one TOML file with a section per process. Unknown keys are rejected,
//! and every value is range-checked with an error that names the field and the value.

use std::path::Path;

use anyhow::{Result, anyhow, bail};
use rins_acquisition::config::AcquisitionConfig;
use rins_altimeter::AltimeterConfig;
use rins_bridge::config::ZenohConfig;
use rins_fusion::FusionConfig;
use rins_gnss::config::GnssConfig;
use rins_mavlink::config::MavlinkConfig;
use rins_navigator::config::NavigatorConfig;
use rins_runtime::bounded_file;
use rins_sim::SimConfig;
use rins_watchdog::config::WatchdogConfig;
use serde::{Deserialize, Serialize};

use crate::cli::ScenarioArg;

pub mod resolved;
mod retired;

/// The IMU rates `device.imu_rate_hz` (and `--imu-rate`) accepts, Hz: from a slow block to what
/// the pipeline carries.
pub const MIN_IMU_RATE_HZ: f64 = 50.0;
/// See [`MIN_IMU_RATE_HZ`].
pub const MAX_IMU_RATE_HZ: f64 = 16_000.0;

/// The configuration used when no file is given (also shipped as `config/rins.toml`).
pub const BUILT_IN: &str = include_str!("../config/rins.toml");
/// The pedestrian profile (foot-mounted unit): navigator settings only.
pub const PEDESTRIAN: &str = include_str!("../config/pedestrian.toml");
/// The UAV profile (baro and magnetometer aiding, zero-velocity updates only while landed):
/// navigator settings only.
pub const UAV: &str = include_str!("../config/uav.toml");

/// What the sensor block's datasheet says about its converters and its output rate: the one place
/// the IMU rate is stated (fusion, the simulator and the timing of every stage follow it).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct DeviceConfig {
    /// Gyro full scale: ±this many °/s over the converter's range.
    pub gyro_full_scale_dps: f64,
    /// Accelerometer full scale: ±this many g over the converter's range.
    pub accel_full_scale_g: f64,
    /// The converter's resolution, bits (8..=16): full scale is 2^(bits−1) counts. The serial
    /// protocol carries 12-bit counts; other values are for recordings replayed without it.
    pub converter_bits: u8,
    /// The block's output rate, Hz.
    pub imu_rate_hz: f64,
}

impl Default for DeviceConfig {
    fn default() -> Self {
        Self {
            gyro_full_scale_dps: 300.0,
            accel_full_scale_g: 8.0,
            converter_bits: SERIAL_CONVERTER_BITS,
            imu_rate_hz: 1000.0,
        }
    }
}

use rins_earth::STANDARD_GRAVITY;

/// The converter resolution the serial protocol carries, bits.
pub const SERIAL_CONVERTER_BITS: u8 = 12;
/// Converter resolutions `device.converter_bits` accepts.
pub const CONVERTER_BITS: std::ops::RangeInclusive<u8> =
    rins_fusion::fdi::channel_health::CONVERTER_BITS;

impl DeviceConfig {
    /// Checks both full scales (finite, positive, within what a MEMS converter offers), the
    /// converter's bits and the IMU rate; the error names the field and its value.
    pub fn validate(&self) -> Result<(), String> {
        for (field, value, max) in [
            (
                "device.gyro_full_scale_dps",
                self.gyro_full_scale_dps,
                10_000.0,
            ),
            (
                "device.accel_full_scale_g",
                self.accel_full_scale_g,
                1_000.0,
            ),
        ] {
            if !(value.is_finite() && value > 0.0 && value <= max) {
                return Err(format!("{field} = {value}: must be > 0 and <= {max}"));
            }
        }
        if !CONVERTER_BITS.contains(&self.converter_bits) {
            return Err(format!(
                "device.converter_bits = {}: must be {}..={}",
                self.converter_bits,
                CONVERTER_BITS.start(),
                CONVERTER_BITS.end()
            ));
        }
        let hz = self.imu_rate_hz;
        if !(hz.is_finite() && (MIN_IMU_RATE_HZ..=MAX_IMU_RATE_HZ).contains(&hz)) {
            return Err(format!(
                "device.imu_rate_hz = {hz}: must be {MIN_IMU_RATE_HZ}..={MAX_IMU_RATE_HZ} Hz"
            ));
        }
        Ok(())
    }

    /// Counts per full scale: 2^(bits−1).
    pub fn counts_per_full_scale(&self) -> f64 {
        f64::from(
            1u32 << (self
                .converter_bits
                .clamp(*CONVERTER_BITS.start(), *CONVERTER_BITS.end())
                - 1),
        )
    }

    /// One gyro count, rad/s: the full scale spread over the converter's counts.
    pub fn gyro_lsb_rps(&self) -> f64 {
        self.gyro_full_scale_dps.to_radians() / self.counts_per_full_scale()
    }

    /// One accelerometer count, m/s².
    pub fn accel_lsb_mps2(&self) -> f64 {
        self.accel_full_scale_g * STANDARD_GRAVITY / self.counts_per_full_scale()
    }

    /// Refuses a converter other than the serial protocol's 12 bits for a deployment that reads
    /// the serial line.
    pub fn check_serial_link(&self) -> Result<()> {
        if self.converter_bits != SERIAL_CONVERTER_BITS {
            bail!(
                "device.converter_bits = {}: the serial line carries {SERIAL_CONVERTER_BITS}-bit \
                 counts, so a deployment reading it needs converter_bits = {SERIAL_CONVERTER_BITS} \
                 (a recording of a {}-bit block is replayed without the serial link)",
                self.converter_bits,
                self.converter_bits
            );
        }
        Ok(())
    }
}

/// Which processes `rins up` runs.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct DeploymentConfig {
    /// 1: one navigator; 2: a primary and a hot standby.
    pub navigator_lanes: u8,
}

impl Default for DeploymentConfig {
    fn default() -> Self {
        Self { navigator_lanes: 2 }
    }
}

impl DeploymentConfig {
    /// Checks the number of navigator lanes (1 or 2).
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=2).contains(&self.navigator_lanes) {
            return Err(format!(
                "deployment.navigator_lanes = {}: must be 1 or 2",
                self.navigator_lanes
            ));
        }
        Ok(())
    }
}

/// The whole configuration file: one table per service plus the device and the deployment. Every
/// table has defaults, and an unknown key anywhere is refused.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct RinsConfig {
    /// `[device]`: the sensor block's converters.
    pub device: DeviceConfig,
    /// `[sim]`: the device simulator (scenario, sensor models, seed).
    pub sim: SimConfig,
    /// `[acquisition]`: the serial port and its reconnection.
    pub acquisition: AcquisitionConfig,
    /// `[fusion]`: geometry, noise, calibration, fault detection and isolation.
    pub fusion: FusionConfig,
    /// `[altimeter]`: QNH and the vertical filter.
    pub altimeter: AltimeterConfig,
    /// `[navigator]`: alignment, filter noise, aiding, integrity limits.
    pub navigator: NavigatorConfig,
    /// `[watchdog]`: restart policy, timeouts, output deadlines.
    pub watchdog: WatchdogConfig,
    /// `[deployment]`: which processes `rins up` runs.
    pub deployment: DeploymentConfig,
    /// `[mavlink]`: the MAVLink 2 output over UDP or a serial port.
    pub mavlink: MavlinkConfig,
    /// `[gnss]`: the GNSS receiver's serial line.
    pub gnss: GnssConfig,
    /// `[zenoh]`: the ROS 2 topics over Zenoh, beyond the host.
    pub zenoh: ZenohConfig,
    /// `[realtime]`: scheduling, affinity and memory locking of each service.
    pub realtime: crate::realtime_config::RealtimeConfig,
    /// `[wait]`: how the stages wait for their input.
    pub wait: crate::wait_config::WaitConfig,
    /// `[record]`: flight recordings from the start of `rins up`.
    pub record: crate::record::config::RecordConfig,
}

impl RinsConfig {
    /// A GNSS receiver is fitted: the gnss service runs, the navigator takes its fixes, and a
    /// simulated deployment simulates it.
    pub fn enable_gnss(&mut self) {
        self.gnss.enabled = true;
        self.navigator.gnss.enabled = true;
        self.sim.gnss.enabled = true;
    }

    /// Parses and validates a configuration text; errors start with `origin` (the file's path or
    /// the built-in profile's name) and name the offending field and value.
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let syntax = |e: toml::de::Error| anyhow!("{origin}: {}", e.to_string().trim_end());
        let table: toml::Table = toml::from_str(text).map_err(syntax)?;
        if let Some(message) = retired::retired_keys(&table) {
            bail!("{origin}: {message}");
        }
        let mut cfg: RinsConfig = toml::from_str(text).map_err(syntax)?;
        cfg.device
            .validate()
            .map_err(|e| anyhow!("{origin}: {e}"))?;
        cfg.apply_device();
        cfg.validate().map_err(|e| anyhow!("{origin}: {e}"))?;
        Ok(cfg)
    }

    /// Hands `[device]` to every table that depends on the block: fusion's rate and converter,
    /// the simulator's rate (its slower sensors capped at it) and converters.
    fn apply_device(&mut self) {
        let hz = self.device.imu_rate_hz;
        self.fusion.block = rins_fusion::config::ImuBlock {
            imu_rate_hz: hz,
            converter_bits: self.device.converter_bits,
        };
        self.sim.imu_rate_hz = hz;
        self.sim.baro_rate_hz = self.sim.baro_rate_hz.min(hz);
        self.sim.mag_rate_hz = self.sim.mag_rate_hz.min(hz);
        self.sim.aux_rate_hz = self.sim.aux_rate_hz.min(hz);
        // The simulated block has the configured device's converters.
        self.sim.sensors.gyro_full_scale_dps = self.device.gyro_full_scale_dps;
        self.sim.sensors.accel_full_scale_g = self.device.accel_full_scale_g;
    }

    /// Checks every table; the error names the first bad field with its table and its value.
    pub fn validate(&self) -> Result<(), String> {
        self.device.validate()?;
        self.sim.validate().map_err(|e| e.to_string())?;
        self.acquisition.validate()?;
        self.gnss.validate()?;
        self.fusion
            .validate()
            .map_err(|e| e.within("fusion").to_string())?;
        self.altimeter
            .validate()
            .map_err(|e| e.within("altimeter").to_string())?;
        self.navigator.validate().map_err(|e| e.to_string())?;
        self.watchdog.validate()?;
        self.deployment.validate()?;
        self.mavlink.validate()?;
        self.zenoh.validate()?;
        self.realtime.validate()?;
        self.wait.validate()?;
        self.record.validate()?;
        Ok(())
    }

    /// The gyro and accelerometer geometries of the configured sensor block.
    pub fn geometries(&self) -> Result<(rins_fusion::Geometry, rins_fusion::Geometry)> {
        let build = |cfg: &rins_fusion::GeometryConfig, field: &str| {
            cfg.build().map_err(|e| anyhow!("{}", e.within(field)))
        };
        Ok((
            build(&self.fusion.geometry.gyro, "fusion.geometry.gyro")?,
            build(&self.fusion.geometry.accel, "fusion.geometry.accel")?,
        ))
    }

    /// The simulator scenario's name as the command line spells it.
    pub fn scenario_name(&self) -> &'static str {
        match self.sim.scenario {
            rins_sim::Scenario::Static => "static",
            rins_sim::Scenario::Uav => "uav",
            rins_sim::Scenario::Walk => "walk",
            rins_sim::Scenario::Calibrate => "calibrate",
            rins_sim::Scenario::Multirotor => "multirotor",
        }
    }

    /// Sets the block's IMU sample rate, `device.imu_rate_hz`, and hands it on (fusion's noise,
    /// windows and Kalman period, the simulator's tick). The other simulated sensors keep their
    /// rates (capped at the IMU's).
    pub fn set_imu_rate(&mut self, hz: f64) -> Result<()> {
        if !(hz.is_finite() && (MIN_IMU_RATE_HZ..=MAX_IMU_RATE_HZ).contains(&hz)) {
            bail!("--imu-rate {hz}: must be {MIN_IMU_RATE_HZ}..={MAX_IMU_RATE_HZ} Hz");
        }
        self.device.imu_rate_hz = hz;
        self.apply_device();
        self.validate().map_err(|e| anyhow!("--imu-rate {hz}: {e}"))
    }

    /// Sets the simulator scenario from the command line's choice.
    pub fn set_scenario(&mut self, scenario: ScenarioArg) {
        self.sim.scenario = match scenario {
            ScenarioArg::Static => rins_sim::Scenario::Static,
            ScenarioArg::Uav => rins_sim::Scenario::Uav,
            ScenarioArg::Walk => rins_sim::Scenario::Walk,
            ScenarioArg::Calibrate => rins_sim::Scenario::Calibrate,
            ScenarioArg::Multirotor => rins_sim::Scenario::Multirotor,
        };
    }
}

/// The pedestrian profile, built in or from `path`.
pub fn load_pedestrian(path: Option<&Path>) -> Result<RinsConfig> {
    load_profile(PEDESTRIAN, "built-in pedestrian profile", path)
}

/// The UAV profile, built in or from `path`.
pub fn load_uav(path: Option<&Path>) -> Result<RinsConfig> {
    load_profile(UAV, "built-in uav profile", path)
}

fn load_profile(built_in: &str, origin: &str, path: Option<&Path>) -> Result<RinsConfig> {
    match path {
        None => RinsConfig::parse(built_in, origin),
        Some(path) => load(Some(path)),
    }
}

/// Reads `path` (a regular file of at most [`bounded_file::DEFAULT_LIMIT`] bytes: a FIFO or a device
/// is refused at once), or the built-in configuration when none is given.
pub fn load(path: Option<&Path>) -> Result<RinsConfig> {
    match path {
        None => RinsConfig::parse(BUILT_IN, "built-in configuration"),
        Some(path) => {
            let text =
                bounded_file::read_text(path, "configuration file", bounded_file::DEFAULT_LIMIT)?;
            RinsConfig::parse(&text, &path.display().to_string())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Asserts that the configuration `text` (from file `file`) is refused with an error that
    /// says `what`.
    #[track_caller]
    fn assert_refused(text: &str, file: &str, what: &str) {
        let err = RinsConfig::parse(text, file).unwrap_err();
        assert!(format!("{err}").contains(what), "{err}");
    }

    #[test]
    fn built_in_pedestrian_profile_is_valid() {
        let cfg = load_pedestrian(None).unwrap();
        assert!(cfg.navigator.zupt.enabled);
    }

    #[test]
    fn built_in_uav_profile_is_valid() {
        let cfg = load_uav(None).unwrap();
        assert!(!cfg.navigator.zupt.enabled);
    }

    #[test]
    fn built_in_configuration_is_valid() {
        let cfg = load(None).unwrap();
        assert_eq!(cfg, RinsConfig::parse(BUILT_IN, "x").unwrap());
    }

    /// The endurance profile is a copy of the built-in file: only its simulated sensors and
    /// scenario may differ, and its slow errors must be worse than the typical block's.
    #[test]
    fn endurance_profile_is_the_built_in_one_with_worse_slow_sensor_errors() {
        let text = include_str!("../config/endurance.toml");
        let endurance = RinsConfig::parse(text, "config/endurance.toml").unwrap();
        let built_in = load(None).unwrap();
        let typical = &built_in.sim.sensors;
        let worst = &endurance.sim.sensors;
        assert!(worst.gyro_bias_instability_sigma_dps > typical.gyro_bias_instability_sigma_dps);
        assert!(worst.accel_bias_instability_sigma_mg > typical.accel_bias_instability_sigma_mg);
        assert!(
            worst.gyro_bias_temp_coeff_sigma_dps_per_c
                > typical.gyro_bias_temp_coeff_sigma_dps_per_c
        );
        assert!(worst.temperature_warmup_c > typical.temperature_warmup_c);
        assert_eq!(endurance.sim.scenario, rins_sim::Scenario::Uav);
        let mut same = endurance.clone();
        same.sim = built_in.sim.clone();
        assert_eq!(same, built_in);
    }

    #[test]
    fn unknown_keys_are_rejected_by_name() {
        let err = RinsConfig::parse("[fusion]\nspeed = 3\n", "test.toml").unwrap_err();
        let msg = format!("{err:#}");
        assert!(msg.contains("test.toml") && msg.contains("speed"), "{msg}");
    }

    #[test]
    fn bad_values_name_field_and_value() {
        assert_refused(
            "[device]\ngyro_full_scale_dps = -5\n",
            "t",
            "device.gyro_full_scale_dps = -5",
        );
        assert_refused(
            "[fusion.geometry.gyro]\nkind = \"pyramid\"\nn = 4\nalpha_deg = 95\nbeta0_deg = 45\n",
            "t",
            "fusion.geometry.gyro.alpha_deg = 95",
        );
        assert_refused(
            "[deployment]\nnavigator_lanes = 3\n",
            "t",
            "deployment.navigator_lanes = 3: must be 1 or 2",
        );
    }

    #[test]
    fn the_converter_bits_set_the_lsb_and_the_serial_link_needs_12() {
        let cfg = RinsConfig::parse("[device]\nconverter_bits = 16\n", "t").unwrap();
        let lsb = cfg.device.gyro_lsb_rps();
        assert!((lsb - 300f64.to_radians() / 32768.0).abs() < 1e-18, "{lsb}");
        assert_eq!(cfg.fusion.block.converter_bits, 16);
        let err = cfg.device.check_serial_link().unwrap_err().to_string();
        assert!(
            err.contains("device.converter_bits = 16") && err.contains("12-bit"),
            "{err}"
        );
        let twelve = load(None).unwrap();
        twelve.device.check_serial_link().unwrap();
        assert!((twelve.device.accel_lsb_mps2() - 8.0 * STANDARD_GRAVITY / 2048.0).abs() < 1e-15);
        assert_refused(
            "[device]\nconverter_bits = 17\n",
            "t",
            "device.converter_bits = 17: must be 8..=16",
        );
    }

    #[test]
    fn the_imu_rate_is_one_key_handed_to_every_table() {
        let cfg = RinsConfig::parse("[device]\nimu_rate_hz = 250\n", "t").unwrap();
        assert_eq!(cfg.fusion.block.imu_rate_hz, 250.0);
        assert_eq!(cfg.sim.imu_rate_hz, 250.0);
        let mut cfg = load(None).unwrap();
        cfg.set_imu_rate(4000.0).unwrap();
        assert_eq!(
            (
                cfg.device.imu_rate_hz,
                cfg.fusion.block.imu_rate_hz,
                cfg.sim.imu_rate_hz
            ),
            (4000.0, 4000.0, 4000.0)
        );
        assert_refused(
            "[fusion]\nsample_rate_hz = 500\n",
            "f.toml",
            "f.toml: fusion.sample_rate_hz is no longer read: the IMU rate is one key, device.imu_rate_hz",
        );
        assert_refused(
            "[device]\nimu_rate_hz = 20000\n",
            "t",
            "device.imu_rate_hz = 20000",
        );
    }

    #[test]
    fn wrong_types_are_reported_with_the_key() {
        assert_refused("[acquisition]\nbaud = \"fast\"\n", "t", "baud");
    }
}
