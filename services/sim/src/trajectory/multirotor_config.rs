//! `[sim.multirotor]`: the simulated quadrotor airframe of the `multirotor` scenario — its rotor
//! drag, the gust it meets and the vibration its rotors shake the sensor block with.

use serde::{Deserialize, Serialize};

use crate::error::{SimError, check_range};

/// The multirotor scenario's airframe and environment.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct MultirotorConfig {
    /// Rotor-drag coefficient along body x, 1/s: the accelerometers' x specific force is
    /// −μx times the body-x airspeed.
    pub drag_per_s: f64,
    /// Rotor-drag coefficient along body y, 1/s.
    pub lateral_drag_per_s: f64,
    /// Height of the hover and the pattern above the take-off point, m.
    pub altitude_agl_m: f64,
    /// Wind speed the gust adds, m/s (once per pattern, from calm).
    pub gust_mps: f64,
    /// Direction the gust blows towards, degrees clockwise from true north.
    pub gust_towards_deg: f64,
    /// Time the wind takes to change by `gust_mps` (both ways), s.
    pub gust_rise_s: f64,
    /// Blade-pass frequency in hover (blades × rotor revolutions per second), Hz; it follows the
    /// square root of the thrust, within ±20 %.
    pub blade_pass_hz: f64,
    /// Amplitude of the rotor vibration on the accelerometers, m/s² (largest body axis).
    pub vibration_accel_mps2: f64,
    /// Amplitude of the rotor vibration on the gyros, °/s (largest body axis).
    pub vibration_gyro_dps: f64,
}

impl Default for MultirotorConfig {
    fn default() -> Self {
        Self {
            // The values config/uav.toml's drag model was fitted to on real quadrotor flights.
            drag_per_s: 0.4,
            lateral_drag_per_s: 0.6,
            altitude_agl_m: 30.0,
            gust_mps: 3.0,
            gust_towards_deg: 60.0,
            gust_rise_s: 3.0,
            // Two blades at 100 rev/s.
            blade_pass_hz: 200.0,
            vibration_accel_mps2: 3.0,
            vibration_gyro_dps: 0.5,
        }
    }
}

impl MultirotorConfig {
    /// Checks every field; the error names the field (`sim.multirotor.…`) and its value.
    pub fn validate(&self) -> Result<(), SimError> {
        for (field, value) in [
            ("sim.multirotor.drag_per_s", self.drag_per_s),
            ("sim.multirotor.lateral_drag_per_s", self.lateral_drag_per_s),
        ] {
            check_range(field, value, 0.0, 2.0, "must be within 0..=2")?;
        }
        check_range(
            "sim.multirotor.altitude_agl_m",
            self.altitude_agl_m,
            5.0,
            1000.0,
            "must be within 5..=1000",
        )?;
        check_range(
            "sim.multirotor.gust_mps",
            self.gust_mps,
            0.0,
            10.0,
            "must be within 0..=10",
        )?;
        check_range(
            "sim.multirotor.gust_towards_deg",
            self.gust_towards_deg,
            -360.0,
            360.0,
            "must be within -360..=360",
        )?;
        // Faster would be a step the smooth schedules were not meant for; slower overlaps the
        // next gust.
        check_range(
            "sim.multirotor.gust_rise_s",
            self.gust_rise_s,
            0.5,
            10.0,
            "must be within 0.5..=10",
        )?;
        check_range(
            "sim.multirotor.blade_pass_hz",
            self.blade_pass_hz,
            10.0,
            2000.0,
            "must be within 10..=2000",
        )?;
        check_range(
            "sim.multirotor.vibration_accel_mps2",
            self.vibration_accel_mps2,
            0.0,
            50.0,
            "must be within 0..=50",
        )?;
        check_range(
            "sim.multirotor.vibration_gyro_dps",
            self.vibration_gyro_dps,
            0.0,
            50.0,
            "must be within 0..=50",
        )
    }
}
