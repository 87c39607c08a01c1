//! An in-flight start (`[navigator.start]`): a vehicle that is already moving cannot align on a
//! rest, so the navigator is given its state at one device time and takes it over at the first
//! IMU sample at or after that time, as it takes over the other lane's solution.
//!
//! One function builds the state from the settings ([`InFlightStart::state`]): the running
//! navigator and the in-process evaluations start from the same code.

use nalgebra::Vector3;
use rins_runtime::config_error::ConfigError;
use serde::{Deserialize, Serialize};

use crate::aided_config::AidedConfig;
use crate::attitude::quaternion_from_euler;
use crate::checks::Table;
use crate::ekf::STATES;
use crate::mechanisation::{ImuBias, NominalState};

/// Largest device time accepted, s (about 31 700 years of µs fit in a u64; this is far inside).
const MAX_TIME_S: f64 = 1e12;
/// Largest speed accepted per axis, m/s.
const MAX_SPEED_MPS: f64 = 1000.0;
/// Largest gyro bias accepted per axis, °/s.
const MAX_GYRO_BIAS_DPS: f64 = 100.0;

/// The state to take over, `[navigator.start]`. Degrees at this edge, like every setting.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InFlightStart {
    /// Device time of the state, s.
    pub time_s: f64,
    /// Roll, ZYX, FRD body → NED, degrees.
    pub roll_deg: f64,
    /// Pitch, degrees.
    pub pitch_deg: f64,
    /// Heading, degrees from north.
    pub heading_deg: f64,
    /// Velocity, north, east, down, m/s.
    pub velocity_ned_mps: [f64; 3],
    /// Altitude, m.
    pub altitude_m: f64,
    /// Gyro bias estimate, body FRD, °/s (absent: zero); its σ is `[navigator.ekf]
    /// initial_gyro_bias_sigma`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro_bias_dps: Option<[f64; 3]>,
}

/// What the navigator takes over: the nominal state at a device time, the bias estimates and the
/// error variances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartState {
    /// Device time of the state, µs.
    pub device_time_us: u64,
    /// Nominal state.
    pub state: NominalState,
    /// Bias estimates.
    pub bias: ImuBias,
    /// Error-state variances (correlations zero).
    pub variances: [f64; STATES],
}

/// The `[navigator.start]` table, for the range checks of its keys.
const START: Table = Table("navigator.start");

impl InFlightStart {
    /// Checks every value; the error names the key (`navigator.start.KEY`) and its value.
    pub fn validate(&self) -> Result<(), ConfigError> {
        START.check(
            "time_s",
            self.time_s,
            |x| (0.0..=MAX_TIME_S).contains(&x),
            "must be a device time in [0, 1e12] s",
        )?;
        START.check(
            "roll_deg",
            self.roll_deg,
            |x| x.abs() <= 180.0,
            "must be in [-180, 180] degrees",
        )?;
        START.check(
            "pitch_deg",
            self.pitch_deg,
            |x| x.abs() <= 90.0,
            "must be in [-90, 90] degrees",
        )?;
        START.check(
            "heading_deg",
            self.heading_deg,
            |x| x.abs() <= 360.0,
            "must be in [-360, 360] degrees",
        )?;
        for v in self.velocity_ned_mps {
            START.check(
                "velocity_ned_mps",
                v,
                |x| x.abs() <= MAX_SPEED_MPS,
                "every entry must be in [-1000, 1000] m/s",
            )?;
        }
        START.check(
            "altitude_m",
            self.altitude_m,
            |x| (-1000.0..=50_000.0).contains(&x),
            "must be in [-1000, 50000] m",
        )?;
        for b in self.gyro_bias_dps.into_iter().flatten() {
            START.check(
                "gyro_bias_dps",
                b,
                |x| x.abs() <= MAX_GYRO_BIAS_DPS,
                "every entry must be in [-100, 100] °/s",
            )?;
        }
        Ok(())
    }

    /// Device time of the state, µs.
    pub fn device_time_us(&self) -> u64 {
        (self.time_s * 1e6).round() as u64
    }

    /// The state to take over with the navigator's settings `config`: position from its origin
    /// (latitude, longitude), velocity σ `initial_velocity_sigma`, gyro bias σ
    /// `initial_gyro_bias_sigma`, the other variances the configured initial ones.
    pub fn state(&self, config: &AidedConfig) -> StartState {
        let [lat, lon, _] = config.origin;
        let mut state = NominalState::at_rest(lat, lon, self.altitude_m);
        state.attitude = quaternion_from_euler(
            self.roll_deg.to_radians(),
            self.pitch_deg.to_radians(),
            self.heading_deg.to_radians(),
        );
        state.velocity_ned = Vector3::from(self.velocity_ned_mps);
        let mut bias = ImuBias::default();
        if let Some(b) = self.gyro_bias_dps {
            bias.gyro_rps = Vector3::from(b.map(f64::to_radians));
        }
        StartState {
            device_time_us: self.device_time_us(),
            state,
            bias,
            variances: config.noise.initial_variances(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::attitude::{euler_from_quaternion, quaternion_from_euler};
    use crate::config::NavigatorConfig;
    use crate::ekf::{BG, VEL};

    const TOML: &str = "initial_latitude_deg = 47.0\ninitial_longitude_deg = 8.0\n\
        [ekf]\ninitial_velocity_sigma = 5.0\ninitial_gyro_bias_sigma = 0.01\n\
        [start]\ntime_s = 12.5\nroll_deg = 10.0\npitch_deg = -5.0\nheading_deg = 120.0\n\
        velocity_ned_mps = [3.0, -4.0, 0.5]\naltitude_m = 520.0\ngyro_bias_dps = [0.1, -0.2, 0.3]\n";

    fn parse(text: &str) -> NavigatorConfig {
        toml::from_str(text).expect("parses")
    }

    #[test]
    fn the_state_is_built_from_the_table() {
        let config = parse(TOML);
        config.validate().expect("valid");
        let start = config.start.expect("a start");
        let s = start.state(&config.aided_config());
        assert_eq!(s.device_time_us, 12_500_000);
        let [roll, pitch, heading] = euler_from_quaternion(&s.state.attitude);
        assert!((roll.to_degrees() - 10.0).abs() < 1e-9);
        assert!((pitch.to_degrees() + 5.0).abs() < 1e-9);
        assert!((heading.to_degrees() - 120.0).abs() < 1e-9);
        assert_eq!(s.state.velocity_ned, Vector3::new(3.0, -4.0, 0.5));
        assert_eq!(s.state.alt, 520.0);
        assert!((s.state.lat - 47f64.to_radians()).abs() < 1e-15);
        assert!((s.state.lon - 8f64.to_radians()).abs() < 1e-15);
        assert!((s.bias.gyro_rps.y - (-0.2f64).to_radians()).abs() < 1e-15);
        assert_eq!(s.variances[VEL], 25.0);
        assert!((s.variances[BG] - 1e-4).abs() < 1e-18);
    }

    #[test]
    fn absent_is_static_alignment() {
        assert_eq!(parse("").start, None);
    }

    #[test]
    fn bad_values_name_the_key() {
        for (from, to, key) in [
            (
                "roll_deg = 10.0",
                "roll_deg = 200.0",
                "navigator.start.roll_deg",
            ),
            (
                "pitch_deg = -5.0",
                "pitch_deg = nan",
                "navigator.start.pitch_deg",
            ),
            ("time_s = 12.5", "time_s = -1.0", "navigator.start.time_s"),
            (
                "velocity_ned_mps = [3.0, -4.0, 0.5]",
                "velocity_ned_mps = [3.0, inf, 0.5]",
                "navigator.start.velocity_ned_mps",
            ),
            (
                "altitude_m = 520.0",
                "altitude_m = 1e9",
                "navigator.start.altitude_m",
            ),
            (
                "gyro_bias_dps = [0.1, -0.2, 0.3]",
                "gyro_bias_dps = [0.1, -0.2, 300.0]",
                "navigator.start.gyro_bias_dps",
            ),
        ] {
            let err = parse(&TOML.replace(from, to)).validate().unwrap_err();
            assert!(err.to_string().contains(key), "{to}: {err}");
        }
    }

    #[test]
    fn a_start_needs_the_position() {
        let text = TOML.replace(
            "initial_latitude_deg = 47.0\ninitial_longitude_deg = 8.0\n",
            "",
        );
        let err = parse(&text).validate().unwrap_err().to_string();
        assert!(
            err.contains("initial_latitude_deg") && err.contains("initial_longitude_deg"),
            "{err}"
        );
    }

    #[test]
    fn the_navigator_takes_the_start_over_at_its_time() {
        let mut nav = crate::Navigator::new(parse(TOML)).expect("valid");
        let (rate, force) = ([0.0, 0.0, 0.1], [0.0, 0.0, -9.8]);
        // Before the start: nothing, not even an alignment.
        assert!(nav.on_imu(12_490_000, rate, force).is_none());
        assert!(nav.start_pending());
        // At its own instant: the configured state, not propagated.
        let at = nav.on_imu(12_500_000, rate, force).expect("navigating");
        assert!(!nav.start_pending());
        let q = quaternion_from_euler(
            10f64.to_radians(),
            (-5f64).to_radians(),
            120f64.to_radians(),
        );
        let [w, x, y, z] = at.quaternion;
        assert!((w * q.w + x * q.i + y * q.j + z * q.k).abs() > 1.0 - 1e-15);
        assert_eq!(at.velocity_ned, [3.0, -4.0, 0.5]);
        // After it: propagated by the interval from the start.
        let next = nav.on_imu(12_510_000, rate, force).expect("navigating");
        assert_ne!(next.quaternion, at.quaternion);
        assert_eq!(nav.rejected_imu_samples(), 0);
        // A restart aligns: the start is in the past.
        nav.restart_alignment();
        assert!(!nav.start_pending());
    }

    #[test]
    fn a_stream_already_past_the_start_leaves_it_behind() {
        // A lane restarted in flight: its first sample is seconds after the start.
        let mut nav = crate::Navigator::new(parse(TOML)).expect("valid");
        assert!(nav.on_imu(20_000_000, [0.0; 3], [0.0, 0.0, -9.8]).is_none());
        assert!(!nav.start_pending());
        assert_eq!(nav.mode(), ipc_types::NavMode::Aligning);
    }

    #[test]
    fn a_start_between_samples_is_propagated_from_its_time() {
        let mut a = crate::Navigator::new(parse(TOML)).expect("valid");
        let text = TOML.replace("time_s = 12.5", "time_s = 12.495");
        let mut b = crate::Navigator::new(parse(&text)).expect("valid");
        let (rate, force) = ([0.0, 0.0, 0.1], [0.0, 0.0, -9.8]);
        // The state at 12.5 s vs the same state 5 ms earlier, propagated to 12.5 s.
        let at = a.on_imu(12_500_000, rate, force).expect("navigating");
        let after = b.on_imu(12_500_000, rate, force).expect("navigating");
        assert_ne!(at.quaternion, after.quaternion);
    }

    #[test]
    fn unknown_keys_are_refused() {
        let text = TOML.replace("altitude_m", "height_m");
        assert!(toml::from_str::<NavigatorConfig>(&text).is_err());
    }
}
