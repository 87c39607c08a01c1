//! The navigator: static alignment, then the error-state EKF with baro height, magnetometer heading
//! and zero-velocity aiding (see [`crate::inertial_core`]), wrapped for the process and its payload.
//!
//! Sequence. IMU samples fill the alignment window; when it spans `align_s` of device time the window is
//! checked and either gives the initial attitude and gyro bias or is discarded and restarted (the reason
//! is kept in [`Navigator::last_align_error`]). The sample that completes a good window is the reference
//! epoch of the navigation solution and the first one with an output; each later sample propagates by the
//! device-time difference to the previous one. A difference that is not positive or exceeds `max_dt_s`
//! is a device-time glitch: the sample is not integrated and the epoch jumps to it.
//!
//! Integrity. Every solution carries the integrity monitor's verdict (see [`crate::integrity`]); a
//! solution judged invalid is published with mode [`NavMode::Invalid`] and without aiding bits, so
//! that no view reports it as navigating. Fused samples without a usable solution reach the
//! navigator too ([`Navigator::on_unusable_imu`]): the state stands still and the monitor counts
//! the outage.
//!
//! Initial state: position from the configuration, altitude from the first valid baro reading if one
//! arrived (else the configured altitude, and the first valid reading after alignment then sets it),
//! velocity zero, heading from the magnetometer when it reported during the window.

use ipc_types::{Integrity, NAV_STATES, NavMode, NavState, aiding, integrity_reason};

use crate::aiding::baro::BaroReading;
use crate::aiding::gnss::measurement::{GnssMeasurement, GnssOutcome};
use crate::aiding::mag::MagReading;
use crate::aiding::outcome::AidingOutcome;
use crate::aiding::readings::{Reading, ReadingSink};
use crate::alignment::{AlignError, Alignment};
use crate::attitude::quaternion_to_array;
use crate::config::{ConfigError, NavigatorConfig};
use crate::ekf::{AidingCounts, AidingSource, ErrorStateEkf};
use crate::inertial_core::AidedNavigator;
use crate::mechanisation::{NominalState, StepOutcome};
use crate::start::InFlightStart;
use crate::takeover::{TakeOverError, peer_solution};
use crate::unisolated_fault::FusionFault;

/// One navigation solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavOutput {
    /// Device time of the solution, µs.
    pub device_time_us: u64,
    /// Body (FRD) → NED attitude, Hamilton, `[w, x, y, z]`.
    pub quaternion: [f64; 4],
    /// Velocity NED, m/s.
    pub velocity_ned: [f64; 3],
    /// Latitude, rad.
    pub lat: f64,
    /// Longitude, rad.
    pub lon: f64,
    /// Altitude, m.
    pub alt: f64,
    /// Aligning or navigating.
    pub mode: NavMode,
    /// Sources with an accepted update within the aiding timeout, bits of [`aiding`]; MAG also
    /// while the heading is the magnetometer's from alignment and no heading update was tried;
    /// BARO_STALE / MAG_STALE while a configured source has been silent for the timeout.
    pub aiding: u32,
    /// Diagonal of the error-state covariance (δθ rad², δv (m/s)², δp m², δb_g, δb_a).
    pub covariance_diag: [f64; NAV_STATES],
    /// Accepted and gated-out updates per [`AidingSource`] since alignment.
    pub counts: [AidingCounts; AidingSource::COUNT],
    /// Estimated gyro bias (rad/s) and accelerometer bias (m/s²), body FRD.
    pub gyro_bias_rps: [f64; 3],
    /// Estimated accelerometer bias, body FRD, m/s².
    pub accel_bias_mps2: [f64; 3],
    /// Whether the solution can be used, and why not (bits of [`ipc_types::integrity_reason`]).
    pub integrity: Integrity,
    /// Reasons for the integrity verdict, bits of [`ipc_types::integrity_reason`].
    pub integrity_reasons: u32,
    /// Resets of the filter from each aiding source so far, per [`AidingSource`].
    pub resets: [u64; AidingSource::COUNT],
}

impl NavOutput {
    /// Copies the solution into an IPC payload; leaves its header untouched.
    pub fn write_nav_state(&self, out: &mut NavState) {
        out.mode = self.mode as u8;
        out.aiding = self.aiding;
        out.quaternion = self.quaternion;
        out.velocity_ned_mps = self.velocity_ned;
        out.latitude_rad = self.lat;
        out.longitude_rad = self.lon;
        out.altitude_m = self.alt;
        out.covariance_diag = self.covariance_diag;
        out.gyro_bias_rps = self.gyro_bias_rps;
        out.accel_bias_mps2 = self.accel_bias_mps2;
        out.integrity = self.integrity as u8;
        out.integrity_reasons = self.integrity_reasons;
        // One slot per source, in `AidingSource` index order (checked at compile time below);
        // a count past the `u32` range saturates.
        out.aiding_accepted = self.counts.map(|c| saturate_u32(c.accepted));
        out.aiding_rejected = self.counts.map(|c| saturate_u32(c.rejected));
    }

    /// True when `source`'s bit is set in [`NavOutput::aiding`].
    pub fn aided_by(&self, bit: u32) -> bool {
        self.aiding & bit != 0
    }
}

// The payload's per-source counts have one slot for each `AidingSource`, so that none is left
// out of `NavState`: a new source needs a new payload layout.
const _: () = assert!(ipc_types::AIDING_SOURCES == AidingSource::COUNT);

/// `n`, or `u32::MAX` when it does not fit.
fn saturate_u32(n: u64) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// The navigator of the process. Allocation-free per sample once aligned.
#[derive(Debug, Clone)]
pub struct Navigator {
    config: NavigatorConfig,
    core: AidedNavigator,
    aiding_timeout_us: u64,
    /// Device time of the navigation state (of the last IMU sample while aligning), µs.
    state_time_us: u64,
    rejected_imu_samples: u64,
    /// The integrity of the last sample, evaluated once per sample.
    integrity: (Integrity, u32),
    /// The in-flight start not yet taken over (`[navigator.start]`).
    pending_start: Option<InFlightStart>,
}

impl Navigator {
    /// A navigator waiting for its alignment window. Fails when the configuration is out of range.
    pub fn new(config: NavigatorConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(Self {
            core: AidedNavigator::new(config.aided_config()),
            aiding_timeout_us: (config.aiding_timeout_s * 1e6).round() as u64,
            state_time_us: 0,
            rejected_imu_samples: 0,
            integrity: (Integrity::Invalid, 0),
            pending_start: config.start,
            config,
        })
    }

    /// Navigates from now on from the other lane's solution in `peer` (see [`crate::takeover`]);
    /// the next IMU sample propagates from the peer's device time.
    pub fn take_over(&mut self, peer: &NavState) -> Result<(), TakeOverError> {
        let sol = peer_solution(peer)?;
        self.pending_start = None;
        self.core.take_over(
            sol.device_time_us,
            sol.state,
            sol.bias,
            &sol.covariance_diag,
        );
        self.state_time_us = sol.device_time_us;
        self.core
            .set_position_known(peer.integrity_reasons & integrity_reason::POSITION_UNKNOWN == 0);
        self.integrity = self.core.evaluate_integrity();
        Ok(())
    }

    /// Drops the solution and starts a new alignment window (a configured in-flight start is
    /// in the past by now: never taken again).
    pub fn restart_alignment(&mut self) {
        let config = self.config.clone();
        if let Ok(mut fresh) = Self::new(config) {
            fresh.pending_start = None;
            *self = fresh;
        }
    }

    /// With an in-flight start pending: takes its state over when the IMU stream reaches its time
    /// (`device_time_us` at or after it). Returns whether the sample is to be left out: it comes
    /// before the start, or is the start's own instant (the state is already there). A stream
    /// that is already more than `max_dt_s` past the start (a lane restarted in flight) has left
    /// the start behind: it is dropped, and the lane aligns or takes the other lane's solution
    /// over as without one.
    fn start_in_flight(&mut self, device_time_us: u64) -> bool {
        let Some(start) = self.pending_start else {
            return false;
        };
        let start_us = start.device_time_us();
        if device_time_us < start_us {
            self.state_time_us = device_time_us;
            return true;
        }
        let max_dt_us = (self.config.max_dt_s * 1e6).round() as u64;
        if device_time_us - start_us > max_dt_us {
            self.pending_start = None;
            return false;
        }
        let s = start.state(self.core.config());
        self.core
            .take_over(s.device_time_us, s.state, s.bias, &s.variances);
        self.core
            .set_position_known(self.config.initial_latitude_deg.is_some());
        self.state_time_us = s.device_time_us;
        self.pending_start = None;
        device_time_us == start_us
    }

    /// Whether an in-flight start waits for the IMU stream to reach its time: the lane then
    /// takes its own start, not the other lane's solution.
    pub fn start_pending(&self) -> bool {
        self.pending_start.is_some()
    }

    /// The configuration in use.
    pub fn config(&self) -> &NavigatorConfig {
        &self.config
    }

    /// Aligning, navigating, or (aligned but the integrity says so) invalid.
    pub fn mode(&self) -> NavMode {
        match (self.core.is_navigating(), self.integrity.0) {
            (false, _) => NavMode::Aligning,
            (true, Integrity::Invalid) => NavMode::Invalid,
            (true, _) => NavMode::Navigating,
        }
    }

    /// The integrity of the last solution and its reasons.
    pub fn integrity(&self) -> (Integrity, u32) {
        self.integrity
    }

    /// Resets of the filter from each aiding source so far, per [`AidingSource`].
    pub fn resets(&self) -> [u64; AidingSource::COUNT] {
        self.core.resets()
    }

    /// The alignment the solution started from.
    pub fn alignment(&self) -> Option<&Alignment> {
        self.core.alignment()
    }

    /// Why the last alignment window was discarded, until an alignment succeeds.
    pub fn last_align_error(&self) -> Option<&AlignError> {
        if self.core.is_navigating() {
            None
        } else {
            self.core.last_align_error()
        }
    }

    /// The filter (nominal state, biases, covariance, counts), once aligned.
    pub fn ekf(&self) -> Option<&ErrorStateEkf> {
        self.core.ekf()
    }

    /// IMU samples not integrated because of a device-time glitch or non-finite values.
    pub fn rejected_imu_samples(&self) -> u64 {
        self.rejected_imu_samples
    }

    /// One fused IMU sample: body rate (rad/s) and specific force (m/s²), FRD, at device time (µs).
    /// `None` while aligning; a solution from the sample that completes the alignment on.
    pub fn on_imu(
        &mut self,
        device_time_us: u64,
        rate_rps: [f64; 3],
        specific_force: [f64; 3],
    ) -> Option<NavOutput> {
        if self.start_in_flight(device_time_us) {
            self.integrity = self.core.evaluate_integrity();
            return self.core.is_navigating().then(|| self.output());
        }
        let step = self
            .core
            .on_imu(device_time_us, rate_rps, specific_force, None);
        match step.propagated {
            Some(StepOutcome::Applied) | None => self.state_time_us = device_time_us,
            Some(StepOutcome::InvalidDt) => {
                self.state_time_us = device_time_us;
                self.rejected_imu_samples += 1;
            }
            Some(StepOutcome::NonFiniteInput) => self.rejected_imu_samples += 1,
        }
        self.integrity = self.core.evaluate_integrity();
        self.core.is_navigating().then(|| self.output())
    }

    /// Fusion's fault report of the fused sample about to be fed: its flags and rate variance
    /// (see [`crate::unisolated_fault`]).
    pub fn on_fusion_status(&mut self, flags: u32, rate_var: [f64; 3]) {
        self.core
            .on_fusion_fault(FusionFault::from_fused(flags, rate_var));
    }

    /// A fused IMU sample at device time `device_time_us` without a usable solution: nothing is
    /// integrated; once aligned, the solution is published as it stands with the integrity that
    /// says so. While aligning the window is not disturbed (`None`).
    pub fn on_unusable_imu(&mut self, device_time_us: u64) -> Option<NavOutput> {
        if self.start_in_flight(device_time_us) {
            self.integrity = self.core.evaluate_integrity();
            return self.core.is_navigating().then(|| self.output());
        }
        self.core.on_unusable_imu(device_time_us);
        self.integrity = self.core.evaluate_integrity();
        self.core.is_navigating().then(|| self.output())
    }

    /// One magnetometer sample, µT, body FRD: the alignment heading, then heading updates.
    pub fn on_mag(&mut self, device_time_us: u64, field_ut: [f64; 3]) -> AidingOutcome {
        self.on_reading(Reading::Mag(MagReading {
            t_us: device_time_us,
            field_ut,
        }))
    }

    /// One barometric height (m, positive up) with its variance (m²) at device time (µs);
    /// ignored unless `valid`.
    pub fn on_baro(
        &mut self,
        device_time_us: u64,
        height_m: f64,
        variance_m2: f64,
        valid: bool,
    ) -> AidingOutcome {
        self.on_reading(Reading::Baro(BaroReading {
            t_us: device_time_us,
            height_m,
            variance_m2,
            valid,
        }))
    }

    /// One aiding reading of a topic of its own, applied now (see [`crate::aiding::readings`]).
    pub fn on_reading(&mut self, r: Reading) -> AidingOutcome {
        self.core.on_reading(r)
    }

    /// One GNSS receiver fix, measured at device time `t_us` (see [`AidedNavigator::on_gnss`]).
    pub fn on_gnss(&mut self, fix: &ipc_types::GnssFix, t_us: u64) -> GnssOutcome {
        self.core.on_gnss(&GnssMeasurement::from_fix(fix, t_us))
    }

    /// The GNSS receiver's consistency monitor.
    pub fn gnss_monitor(&self) -> &crate::aiding::gnss::monitor::GnssMonitor {
        self.core.gnss_monitor()
    }

    /// The current solution (a level, at-rest placeholder at the configured position while aligning).
    pub fn output(&self) -> NavOutput {
        let placeholder;
        let (state, ekf) = match self.core.ekf() {
            Some(ekf) => (ekf.state(), Some(ekf)),
            None => {
                let [lat, lon, alt] = self.core.config().origin;
                placeholder = NominalState::at_rest(lat, lon, alt);
                (&placeholder, None)
            }
        };
        let mut aiding_bits = 0;
        let (integrity, integrity_reasons) = self.integrity;
        let mut counts = [AidingCounts::default(); AidingSource::COUNT];
        let mut covariance_diag = [0.0; NAV_STATES];
        let (mut gyro_bias_rps, mut accel_bias_mps2) = ([0.0; 3], [0.0; 3]);
        if let Some(ekf) = ekf {
            let b = ekf.bias();
            (gyro_bias_rps, accel_bias_mps2) = (b.gyro_rps.into(), b.accel_mps2.into());
            for source in AidingSource::ALL {
                let recent = self.core.last_accepted_us(source).is_some_and(|t| {
                    self.state_time_us <= t.saturating_add(self.aiding_timeout_us)
                });
                if recent {
                    aiding_bits |= source.bit();
                }
                counts[source as usize] = ekf.counts(source);
            }
            // Until the first heading update the heading is the magnetometer's from alignment.
            let no_heading_update = [AidingSource::Mag, AidingSource::Hupt]
                .iter()
                .all(|s| counts[*s as usize] == AidingCounts::default());
            let heading_from_alignment =
                self.core.alignment().is_some_and(|a| a.heading_aided) && no_heading_update;
            if heading_from_alignment {
                aiding_bits |= aiding::MAG;
            }
            for (source, bit) in [
                (AidingSource::Baro, aiding::BARO_STALE),
                (AidingSource::Mag, aiding::MAG_STALE),
                (AidingSource::Gnss, aiding::GNSS_STALE),
            ] {
                if self.core.is_stale(source) {
                    aiding_bits |= bit;
                }
            }
            let p = ekf.covariance();
            for (k, d) in covariance_diag.iter_mut().enumerate() {
                *d = p[(k, k)];
            }
            // An invalid solution is aided by nothing: whatever was accepted before no longer
            // vouches for it.
            if self.core.gnss_monitor().rejected().is_some() {
                aiding_bits |= aiding::GNSS_REJECTED;
            }
            if integrity == Integrity::Invalid {
                aiding_bits &= aiding::BARO_STALE
                    | aiding::MAG_STALE
                    | aiding::GNSS_STALE
                    | aiding::GNSS_REJECTED;
            }
        }
        NavOutput {
            device_time_us: self.state_time_us,
            quaternion: quaternion_to_array(&state.attitude),
            velocity_ned: state.velocity_ned.into(),
            lat: state.lat,
            lon: state.lon,
            alt: state.alt,
            mode: self.mode(),
            aiding: aiding_bits,
            covariance_diag,
            counts,
            gyro_bias_rps,
            accel_bias_mps2,
            integrity,
            integrity_reasons,
            resets: self.core.resets(),
        }
    }
}

impl ReadingSink for Navigator {
    fn take(&mut self, r: Reading) {
        let _ = self.on_reading(r);
    }
}

/// Whether a fused IMU sample (its `FusedImu::flags`) may drive the navigator: both solutions valid
/// (enough channels, not saturated, the frame not rejected), and fusion no longer measuring
/// per-channel gyro biases — the rate before that correction carries
/// the biases the alignment window would otherwise average into its own estimate.
pub fn fused_sample_usable(flags: u32) -> bool {
    use ipc_types::fused_flags;
    flags
        & (fused_flags::GYRO_INSUFFICIENT
            | fused_flags::ACCEL_INSUFFICIENT
            | fused_flags::GYRO_REST_BIAS_PENDING
            | fused_flags::GYRO_SATURATED
            | fused_flags::ACCEL_SATURATED
            | fused_flags::INPUT_REJECTED)
        == 0
}
