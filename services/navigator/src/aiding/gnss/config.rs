//! Settings of the GNSS aiding (`[navigator.gnss]`): the receiver's antenna and latency, the
//! measurement noise floors, and the consistency monitor's thresholds.

use ipc_types::integrity_reason as why;
use serde::{Deserialize, Serialize};

use crate::aiding::source::stream_aiding_sensor;
use crate::checks::positive;

/// Settings of the GNSS position and velocity updates (`[navigator.gnss]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GnssAidingConfig {
    /// Apply GNSS position (and velocity) updates.
    pub enabled: bool,
    /// Antenna position relative to the IMU, body FRD, m.
    pub lever_arm_m: [f64; 3],
    /// The receiver's output latency: from the instant it measured to the fix's last byte on
    /// the serial line, s. The measurement is compared with the state of that instant.
    pub delay_s: f64,
    /// Use the receiver's velocity as well as its position.
    pub use_velocity: bool,
    /// Smallest horizontal σ used per axis, m, whatever accuracy the receiver reports.
    pub sigma_horizontal_floor_m: f64,
    /// Smallest vertical σ used, m.
    pub sigma_vertical_floor_m: f64,
    /// Smallest velocity σ used per axis, m/s.
    pub sigma_velocity_floor_mps: f64,
    /// Innovation gate of the position and of the velocity update (Mahalanobis distance, 3 dof).
    pub gate: f64,
    /// Consecutive fixes outside the gate that make the receiver inconsistent (a jump): one is an
    /// outlier, this many in a row are the receiver.
    pub reject_after_fixes: u32,
    /// Allowance of the drift test, in σ of the normalised horizontal innovation: a cumulative
    /// sum of each axis's normalised innovation less this grows only under a persistent bias.
    pub drift_slack: f64,
    /// The cumulative sum at which the receiver is declared drifting away from the inertial
    /// solution, in σ. The default and `drift_slack`'s are what leave-one-flight-out on the
    /// real quadrotor flights chooses (`rins eval quadrotor --mode gnss`): a smaller allowance
    /// or threshold raises alarms on clean fixes there.
    pub drift_threshold: f64,
    /// Threshold of the displacement test ([`crate::aiding::gnss::displacement`]), σ (2 dof): the
    /// receiver's displacement over 10 s against the inertial velocity. Under white fix noise
    /// of the reported accuracy, 6 σ is passed once in some 10⁸ fixes; a 0.5 m/s drift passes it
    /// within about ten seconds.
    pub displacement_threshold: f64,
    /// A rejected receiver comes back once its fixes have passed the gate for this long, s.
    pub readmit_after_s: f64,
}

impl Default for GnssAidingConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            lever_arm_m: [0.0; 3],
            delay_s: 0.08,
            use_velocity: true,
            sigma_horizontal_floor_m: 0.3,
            sigma_vertical_floor_m: 0.5,
            sigma_velocity_floor_mps: 0.05,
            gate: 5.0,
            reject_after_fixes: 3,
            drift_slack: 2.0,
            drift_threshold: 25.0,
            displacement_threshold: 6.0,
            readmit_after_s: 3.0,
        }
    }
}

impl GnssAidingConfig {
    /// `(field, value)` of the first out-of-range parameter.
    pub fn check(&self) -> Result<(), (&'static str, f64)> {
        for (k, x) in self.lever_arm_m.iter().enumerate() {
            if !x.is_finite() || x.abs() > 100.0 {
                return Err((
                    ["lever_arm_m[0]", "lever_arm_m[1]", "lever_arm_m[2]"][k],
                    *x,
                ));
            }
        }
        if !(self.delay_s.is_finite() && (0.0..=0.5).contains(&self.delay_s)) {
            return Err(("delay_s", self.delay_s));
        }
        positive("sigma_horizontal_floor_m", self.sigma_horizontal_floor_m)?;
        positive("sigma_vertical_floor_m", self.sigma_vertical_floor_m)?;
        positive("sigma_velocity_floor_mps", self.sigma_velocity_floor_mps)?;
        positive("gate", self.gate)?;
        positive("reject_after_fixes", f64::from(self.reject_after_fixes))?;
        positive("drift_slack", self.drift_slack)?;
        positive("drift_threshold", self.drift_threshold)?;
        positive("displacement_threshold", self.displacement_threshold)?;
        positive("readmit_after_s", self.readmit_after_s)
    }
}

stream_aiding_sensor!(
    GnssAidingConfig => Gnss,
    inconsistent: why::GNSS_INCONSISTENT,
    section: "navigator.gnss",
    range: "out of range (delay_s in [0, 0.5], |lever_arm_m| <= 100, others finite and > 0)",
);
