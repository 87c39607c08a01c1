//! The product configuration: one TOML file with a section per process. Unknown keys are rejected,
//! and every value is range-checked with an error that names the field and the value.

use std::path::Path;

use anyhow::{Result, anyhow, bail};
use rins_acquisition::config::AcquisitionConfig;
use rins_altimeter::AltimeterConfig;
use rins_fusion::FusionConfig;
use rins_gnss::config::GnssConfig;
use rins_mavlink::config::MavlinkConfig;
use rins_navigator::config::NavigatorConfig;
use rins_runtime::bounded_file;
use rins_sim::SimConfig;
use rins_watchdog::config::WatchdogConfig;
use serde::{Deserialize, Serialize};

use crate::cli::ScenarioArg;

/// The IMU rates `--imu-rate` accepts, Hz: from a slow block to what the pipeline carries.
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

/// What the sensor block's datasheet says about its converters.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct DeviceConfig {
    /// Gyro full scale: ±this many °/s over the 12-bit range.
    pub gyro_full_scale_dps: f64,
    /// Accelerometer full scale: ±this many g over the 12-bit range.
    pub accel_full_scale_g: f64,
}

impl Default for DeviceConfig {
    fn default() -> Self {
        Self {
            gyro_full_scale_dps: 300.0,
            accel_full_scale_g: 8.0,
        }
    }
}

use rins_earth::STANDARD_GRAVITY;
use rins_protocol::layout::COUNTS_PER_FULL_SCALE;

impl DeviceConfig {
    /// Checks both full scales (finite, positive, within what a MEMS converter offers); the error
    /// names the field and its value.
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
        Ok(())
    }

    /// One gyro count, rad/s: the full scale spread over the converter's counts.
    pub fn gyro_lsb_rps(&self) -> f64 {
        self.gyro_full_scale_dps.to_radians() / COUNTS_PER_FULL_SCALE
    }

    /// One accelerometer count, m/s².
    pub fn accel_lsb_mps2(&self) -> f64 {
        self.accel_full_scale_g * STANDARD_GRAVITY / COUNTS_PER_FULL_SCALE
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
    /// `[mavlink]`: the MAVLink 2 output over UDP.
    pub mavlink: MavlinkConfig,
    /// `[gnss]`: the GNSS receiver's serial line.
    pub gnss: GnssConfig,
    /// `[realtime]`: scheduling, affinity and memory locking of each service.
    pub realtime: crate::realtime_config::RealtimeConfig,
    /// `[wait]`: how the stages wait for their input.
    pub wait: crate::wait_config::WaitConfig,
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
        let mut cfg: RinsConfig =
            toml::from_str(text).map_err(|e| anyhow!("{origin}: {}", e.to_string().trim_end()))?;
        cfg.validate().map_err(|e| anyhow!("{origin}: {e}"))?;
        // The simulated block has the configured device's converters.
        cfg.sim.sensors.gyro_full_scale_dps = cfg.device.gyro_full_scale_dps;
        cfg.sim.sensors.accel_full_scale_g = cfg.device.accel_full_scale_g;
        Ok(cfg)
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
        self.realtime.validate()?;
        self.wait.validate()?;
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
        }
    }

    /// The block's IMU sample rate, `hz`, everywhere the configuration states it: the
    /// simulator's rate, fusion's nominal rate and its Kalman filter's period. The other
    /// simulated sensors keep their rates (capped at the IMU's).
    pub fn set_imu_rate(&mut self, hz: f64) -> Result<()> {
        if !(hz.is_finite() && (MIN_IMU_RATE_HZ..=MAX_IMU_RATE_HZ).contains(&hz)) {
            bail!("--imu-rate {hz}: must be {MIN_IMU_RATE_HZ}..={MAX_IMU_RATE_HZ} Hz");
        }
        self.sim.imu_rate_hz = hz;
        self.sim.baro_rate_hz = self.sim.baro_rate_hz.min(hz);
        self.sim.mag_rate_hz = self.sim.mag_rate_hz.min(hz);
        self.sim.aux_rate_hz = self.sim.aux_rate_hz.min(hz);
        self.fusion.sample_rate_hz = hz;
        self.fusion.kalman.sample_period_s = 1.0 / hz;
        self.validate().map_err(|e| anyhow!("--imu-rate {hz}: {e}"))
    }

    /// Sets the simulator scenario from the command line's choice.
    pub fn set_scenario(&mut self, scenario: ScenarioArg) {
        self.sim.scenario = match scenario {
            ScenarioArg::Static => rins_sim::Scenario::Static,
            ScenarioArg::Uav => rins_sim::Scenario::Uav,
            ScenarioArg::Walk => rins_sim::Scenario::Walk,
            ScenarioArg::Calibrate => rins_sim::Scenario::Calibrate,
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
        let err = RinsConfig::parse("[device]\ngyro_full_scale_dps = -5\n", "t").unwrap_err();
        assert!(
            format!("{err}").contains("device.gyro_full_scale_dps = -5"),
            "{err}"
        );
        let err = RinsConfig::parse(
            "[fusion.geometry.gyro]\nkind = \"pyramid\"\nn = 4\nalpha_deg = 95\nbeta0_deg = 45\n",
            "t",
        )
        .unwrap_err();
        assert!(
            format!("{err}").contains("fusion.geometry.gyro.alpha_deg = 95"),
            "{err}"
        );
        let err = RinsConfig::parse("[deployment]\nnavigator_lanes = 3\n", "t").unwrap_err();
        assert!(
            format!("{err}").contains("deployment.navigator_lanes = 3: must be 1 or 2"),
            "{err}"
        );
    }

    #[test]
    fn wrong_types_are_reported_with_the_key() {
        let err = RinsConfig::parse("[acquisition]\nbaud = \"fast\"\n", "t").unwrap_err();
        assert!(format!("{err}").contains("baud"), "{err}");
    }
}
