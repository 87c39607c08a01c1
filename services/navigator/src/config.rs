//! Navigator settings as read from the TOML configuration.

use serde::{Deserialize, Serialize};

use crate::aided_config::AidedConfig;
use crate::aiding::airspeed::AirspeedAidingConfig;
use crate::aiding::baro::BaroAidingConfig;
use crate::aiding::gnss::config::GnssAidingConfig;
use crate::aiding::mag_heading::MagAidingConfig;
use crate::aiding::tilt::TiltAidingConfig;
use crate::aiding::zupt::ZuptConfig;
use crate::alignment::AlignConfig;
use crate::checks::Table;
use crate::ekf::EkfNoise;
use crate::integrity::IntegrityConfig;
use crate::mag_calibration::MagCalibration;
use crate::mechanisation::StrapdownConfig;
use crate::stance::StanceConfig;
use crate::start::InFlightStart;
use rins_earth::normal_gravity;

pub use rins_runtime::config_error::ConfigError;

use crate::force_delay::MAX_GYRO_LAG_S;

/// Navigator settings. Degrees only here, at the edge; everything inside is radians.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NavigatorConfig {
    /// Static alignment window, s of device time.
    pub align_s: f64,
    /// Magnetic declination, degrees, positive east.
    pub declination_deg: f64,
    /// Initial latitude, degrees. Absent (with the longitude): the horizontal position is unknown
    /// until an absolute fix sets it, and the integrity says so (`position-unknown`); navigation
    /// starts at a placeholder of latitude and longitude 0 (gravity at 45°).
    pub initial_latitude_deg: Option<f64>,
    /// Initial longitude, degrees; given together with the latitude.
    pub initial_longitude_deg: Option<f64>,
    /// Initial altitude, m; replaced by the first valid baro reading when there is one.
    pub initial_altitude_m: f64,
    /// Largest accepted IMU sample interval, s; longer gaps are skipped as device-time glitches.
    pub max_dt_s: f64,
    /// Two-sample coning correction in the attitude update.
    pub coning_correction: bool,
    /// An aiding source counts as used while its last accepted update is younger than this, and
    /// as stale (the filter coasts, the nav state says so) once its last reading is older, s.
    pub aiding_timeout_s: f64,
    /// Alignment: largest accepted | |f̄| − g |, m/s².
    pub align_specific_force_tolerance_mps2: f64,
    /// Alignment: largest accepted norm of the mean rate, rad/s.
    pub align_max_rate_rps: f64,
    /// Alignment: largest accepted standard deviation of a specific-force axis, m/s².
    pub align_max_specific_force_std_mps2: f64,
    /// Alignment: largest accepted standard deviation of a rate axis, rad/s.
    pub align_max_rate_std_rps: f64,
    /// Alignment: take the gyro bias from the window's mean rate (off: start from zero bias).
    pub align_gyro_bias: bool,
    /// How long the unit's gyro channel lags its accelerometer's, s (0..=0.05): each rate sample
    /// is paired with the specific force of this long before.
    pub gyro_lag_s: f64,
    /// Error-state filter noise (`[navigator.ekf]`).
    pub ekf: EkfNoise,
    /// Zero-velocity updates (`[navigator.zupt]`).
    pub zupt: ZuptConfig,
    /// Stance detector (`[navigator.stance]`).
    pub stance: StanceConfig,
    /// Barometric height updates (`[navigator.baro]`).
    pub baro: BaroAidingConfig,
    /// Magnetometer heading updates (`[navigator.mag]`).
    pub mag: MagAidingConfig,
    /// Tilt updates from the specific force, the AHRS (`[navigator.tilt]`).
    pub tilt: TiltAidingConfig,
    /// GNSS position and velocity updates (`[navigator.gnss]`).
    pub gnss: GnssAidingConfig,
    /// Pitot airspeed updates, zero wind assumed (`[navigator.airspeed]`).
    pub airspeed: AirspeedAidingConfig,
    /// Hard- and soft-iron correction of the magnetometer (`[navigator.mag_calibration]`, as
    /// printed by `rins calibrate mag`).
    pub mag_calibration: MagCalibration,
    /// Integrity monitor and recovery policies (`[navigator.integrity]`).
    pub integrity: IntegrityConfig,
    /// An in-flight start (`[navigator.start]`): the state taken over at the first IMU sample at
    /// or after its time instead of a static alignment (absent: static alignment).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start: Option<InFlightStart>,
}

impl Default for NavigatorConfig {
    fn default() -> Self {
        let align = AlignConfig::default();
        let strapdown = StrapdownConfig::default();
        Self {
            align_s: align.window_s,
            declination_deg: 0.0,
            initial_latitude_deg: None,
            initial_longitude_deg: None,
            initial_altitude_m: 0.0,
            max_dt_s: strapdown.max_dt_s,
            coning_correction: strapdown.coning_correction,
            aiding_timeout_s: 1.0,
            align_specific_force_tolerance_mps2: align.specific_force_tolerance_mps2,
            align_max_rate_rps: align.max_mean_rate_rps,
            align_max_specific_force_std_mps2: align.max_specific_force_std_mps2,
            align_max_rate_std_rps: align.max_rate_std_rps,
            align_gyro_bias: align.gyro_bias_from_window,
            gyro_lag_s: 0.0,
            ekf: EkfNoise::default(),
            zupt: ZuptConfig::default(),
            stance: StanceConfig::default(),
            baro: BaroAidingConfig::default(),
            mag: MagAidingConfig::default(),
            tilt: TiltAidingConfig::default(),
            gnss: GnssAidingConfig::default(),
            airspeed: AirspeedAidingConfig::default(),
            mag_calibration: MagCalibration::default(),
            integrity: IntegrityConfig::default(),
            start: None,
        }
    }
}

/// The `[navigator]` table, for the range checks of its own keys.
const NAVIGATOR: Table = Table("navigator");

impl NavigatorConfig {
    /// Checks every numeric field; the error names the first offending field and its value.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let positive = |x: f64| x > 0.0;
        NAVIGATOR.check(
            "align_s",
            self.align_s,
            |x| x > 0.0 && x <= 600.0,
            "must be in (0, 600] s",
        )?;
        NAVIGATOR.check(
            "declination_deg",
            self.declination_deg,
            |x| x.abs() <= 180.0,
            "must be in [-180, 180] degrees",
        )?;
        match (self.initial_latitude_deg, self.initial_longitude_deg) {
            (Some(lat), Some(lon)) => {
                NAVIGATOR.check(
                    "initial_latitude_deg",
                    lat,
                    |x| x.abs() <= 89.9,
                    "must be in [-89.9, 89.9] degrees (longitude is undefined at the poles)",
                )?;
                NAVIGATOR.check(
                    "initial_longitude_deg",
                    lon,
                    |x| x.abs() <= 180.0,
                    "must be in [-180, 180] degrees",
                )?;
            }
            (None, None) => {}
            (Some(lat), None) => {
                return Err(ConfigError::new(
                    "initial_latitude_deg",
                    lat,
                    "is given without initial_longitude_deg: give both, or neither",
                )
                .within("navigator"));
            }
            (None, Some(lon)) => {
                return Err(ConfigError::new(
                    "initial_longitude_deg",
                    lon,
                    "is given without initial_latitude_deg: give both, or neither",
                )
                .within("navigator"));
            }
        }
        NAVIGATOR.check(
            "initial_altitude_m",
            self.initial_altitude_m,
            |x| (-1000.0..=50_000.0).contains(&x),
            "must be in [-1000, 50000] m",
        )?;
        NAVIGATOR.check(
            "max_dt_s",
            self.max_dt_s,
            |x| x > 0.0 && x <= 10.0,
            "must be in (0, 10] s",
        )?;
        NAVIGATOR.check(
            "gyro_lag_s",
            self.gyro_lag_s,
            |x| (0.0..=MAX_GYRO_LAG_S).contains(&x),
            "must be in [0, 0.05] s",
        )?;
        NAVIGATOR.check(
            "aiding_timeout_s",
            self.aiding_timeout_s,
            positive,
            "must be finite and > 0 s",
        )?;
        NAVIGATOR.check(
            "align_specific_force_tolerance_mps2",
            self.align_specific_force_tolerance_mps2,
            positive,
            "must be finite and > 0 m/s²",
        )?;
        NAVIGATOR.check(
            "align_max_rate_rps",
            self.align_max_rate_rps,
            positive,
            "must be finite and > 0 rad/s",
        )?;
        NAVIGATOR.check(
            "align_max_specific_force_std_mps2",
            self.align_max_specific_force_std_mps2,
            positive,
            "must be finite and > 0 m/s²",
        )?;
        NAVIGATOR.check(
            "align_max_rate_std_rps",
            self.align_max_rate_std_rps,
            positive,
            "must be finite and > 0 rad/s",
        )?;
        if let Err((field, value)) = self.ekf.check() {
            return Err(
                ConfigError::new(field, value, "must be finite and > 0").within("navigator.ekf")
            );
        }
        if let Err((field, value)) = self.stance.check() {
            return Err(ConfigError::new(
                field,
                value,
                "out of range (window 1..=64, others finite and > 0)",
            )
            .within("navigator.stance"));
        }
        for sensor in self.aided_config().sensors() {
            sensor.validate()?;
        }
        if let Err((field, value)) = self.integrity.check() {
            return Err(ConfigError::new(
                field,
                value,
                "out of range (nis_window 1..=64, time_stall_samples >= 1, limits >= 0, others finite and > 0)",
            )
            .within("navigator.integrity"));
        }
        if let Some(start) = &self.start {
            start.validate()?;
            if self.initial_latitude_deg.is_none() {
                return Err(ConfigError::new(
                    "start",
                    "a state",
                    "needs the position: give initial_latitude_deg and initial_longitude_deg",
                )
                .within("navigator"));
            }
        }
        let calibration = &self.mag_calibration;
        let entries = calibration
            .hard_iron_ut
            .iter()
            .chain(calibration.soft_iron_correction.iter().flatten());
        if let Some(bad) = entries.copied().find(|x| !x.is_finite()) {
            return Err(
                ConfigError::new("mag_calibration", bad, "every entry must be finite")
                    .within("navigator"),
            );
        }
        Ok(())
    }

    /// Settings of the aided inertial core.
    pub fn aided_config(&self) -> AidedConfig {
        AidedConfig {
            align: self.align_config(),
            strapdown: self.strapdown_config(),
            noise: self.ekf,
            zupt: self.zupt,
            stance: self.stance,
            baro: self.baro,
            mag: self.mag,
            tilt: self.tilt,
            gnss: self.gnss,
            airspeed: self.airspeed,
            mag_calibration: self.mag_calibration,
            stale_after_s: self.aiding_timeout_s,
            declination_rad: self.declination_deg.to_radians(),
            origin: [
                self.initial_latitude_deg.unwrap_or(0.0).to_radians(),
                self.initial_longitude_deg.unwrap_or(0.0).to_radians(),
                self.initial_altitude_m,
            ],
            origin_known: self.initial_latitude_deg.is_some(),
            integrity: self.integrity,
            gyro_lag_s: self.gyro_lag_s,
        }
    }

    /// Alignment limits, with the gravity expected at the initial position.
    pub fn align_config(&self) -> AlignConfig {
        AlignConfig {
            window_s: self.align_s,
            // Unknown latitude: gravity at 45°, within 0.03 m/s² of any latitude's, well inside
            // the alignment's tolerance.
            gravity_mps2: normal_gravity(
                self.initial_latitude_deg.unwrap_or(45.0).to_radians(),
                self.initial_altitude_m,
            ),
            specific_force_tolerance_mps2: self.align_specific_force_tolerance_mps2,
            max_mean_rate_rps: self.align_max_rate_rps,
            max_specific_force_std_mps2: self.align_max_specific_force_std_mps2,
            max_rate_std_rps: self.align_max_rate_std_rps,
            gyro_bias_from_window: self.align_gyro_bias,
        }
    }

    /// Strapdown settings.
    pub fn strapdown_config(&self) -> StrapdownConfig {
        StrapdownConfig {
            max_dt_s: self.max_dt_s,
            coning_correction: self.coning_correction,
        }
    }
}
