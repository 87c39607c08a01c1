//! One receiver fix as the GNSS aiding takes it, and what became of it.

use ipc_types::{GnssFix, GnssFixType};

/// One receiver fix, placed on the device time base.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssMeasurement {
    /// Device time of the instant the receiver measured, µs.
    pub t_us: u64,
    /// The receiver's own time of the fix, µs: a fix whose time does not advance is a repeat.
    pub receiver_time_us: u64,
    /// The receiver has a three-dimensional fix from the satellites.
    pub fix_3d: bool,
    /// Antenna latitude, longitude (rad) and altitude (m).
    pub position: [f64; 3],
    /// Antenna velocity NED, m/s, when reported.
    pub velocity_ned: Option<[f64; 3]>,
    /// Reported horizontal σ per axis, m.
    pub sigma_h_m: f64,
    /// Reported vertical σ, m.
    pub sigma_v_m: f64,
    /// Reported velocity σ per axis, m/s.
    pub sigma_vel_mps: f64,
}

impl GnssMeasurement {
    /// The measurement of `fix`, whose receiver measured at device time `t_us`.
    pub fn from_fix(fix: &GnssFix, t_us: u64) -> Self {
        let fix_3d = GnssFixType::from_u8(fix.fix_type).is_some_and(GnssFixType::is_3d);
        Self {
            t_us,
            receiver_time_us: fix.receiver_time_us,
            fix_3d,
            position: [fix.latitude_rad, fix.longitude_rad, fix.altitude_m],
            velocity_ned: (fix.velocity_valid != 0).then_some(fix.velocity_ned_mps),
            sigma_h_m: fix.horizontal_accuracy_m,
            sigma_v_m: fix.vertical_accuracy_m,
            sigma_vel_mps: fix.speed_accuracy_mps,
        }
    }

    pub(crate) fn is_finite(&self) -> bool {
        self.position.iter().all(|x| x.is_finite())
            && self
                .velocity_ned
                .is_none_or(|v| v.iter().all(|x| x.is_finite()))
    }
}

/// What became of one fix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GnssOutcome {
    /// Position (and velocity) applied; `d2` is the position innovation's squared Mahalanobis
    /// distance.
    Applied {
        /// Squared Mahalanobis distance of the position innovation.
        d2: f64,
    },
    /// The receiver came back after a rejection; this fix was applied.
    Readmitted,
    /// Outside the gate, alone so far: skipped.
    Outlier,
    /// The receiver is judged inconsistent: skipped.
    Rejected,
    /// No three-dimensional fix, or values that are not numbers: nothing to apply.
    NoFix,
    /// The receiver's time did not advance (a frozen receiver repeating itself): skipped.
    Repeated,
    /// Measured before the oldest remembered state: skipped.
    TooOld,
    /// GNSS aiding is off, or the filter is not navigating yet.
    NotUsed,
}
