//! The MAVLink stream as a pure state machine: the latest fused sample, solution and health report
//! go in, the messages due go out, each paced by its own rate. The service around it only moves
//! samples in and messages out.

use ipc_types::{FusedImu, HealthReport, NavState};

use crate::attitude::attitude_quaternion;
use crate::autopilot::Autopilot;
use crate::config::MavlinkConfig;
use crate::dialect::MavMessage;
use crate::events::EventWatch;
use crate::heartbeat::{Profile, heartbeat};
use crate::highres_imu::highres_imu;
use crate::local_frame::LocalOrigin;
use crate::odometry::{ResetCounter, odometry};
use crate::origin::{OriginAnnouncer, OriginChange, OriginTracker};
use crate::position::{global_position_int, local_position_ned};
use crate::rate_gate::RateGate;
use crate::sys_status::{present, sys_status};
use crate::vibration::VibrationMeter;

/// Each stream's pacing.
#[derive(Debug, Clone)]
struct Gates {
    heartbeat: RateGate,
    attitude: RateGate,
    global_position: RateGate,
    local_position: RateGate,
    odometry: RateGate,
    highres_imu: RateGate,
    sys_status: RateGate,
    vibration: RateGate,
}

/// The stream's state between samples.
#[derive(Debug, Clone)]
pub struct MavlinkStream {
    profile: Profile,
    gates: Gates,
    /// The local frame's origin: the first shown solution's position, moved to the first known
    /// one.
    origin: OriginTracker,
    /// The autopilot ODOMETRY is shaped for.
    autopilot: Autopilot,
    /// The global origin's announcement, to an autopilot that takes it.
    announcer: Option<OriginAnnouncer>,
    resets: ResetCounter,
    vibration: VibrationMeter,
    events: EventWatch,
    fused: Option<FusedImu>,
    nav: Option<NavState>,
    /// Every aiding bit a solution has shown: which aiding sensors SYS_STATUS reports present.
    aiding_seen: u32,
    /// `[mavlink] odometry_quality_sigma_m`: the horizontal σ of ODOMETRY quality 50.
    quality_sigma_m: f64,
    /// The pipeline's CPU load, ‰, for SYS_STATUS (0: not measured).
    load_permille: u16,
}

impl MavlinkStream {
    /// The stream of `config` (its profile and rates; the caller has validated it).
    pub fn new(config: &MavlinkConfig) -> Self {
        let r = &config.rates;
        Self {
            profile: config.profile().unwrap_or(Profile::Onboard),
            gates: Gates {
                heartbeat: RateGate::new(r.heartbeat_hz),
                attitude: RateGate::new(r.attitude_quaternion_hz),
                global_position: RateGate::new(r.global_position_int_hz),
                local_position: RateGate::new(r.local_position_ned_hz),
                odometry: RateGate::new(r.odometry_hz),
                highres_imu: RateGate::new(r.highres_imu_hz),
                sys_status: RateGate::new(r.sys_status_hz),
                vibration: RateGate::new(r.vibration_hz),
            },
            origin: OriginTracker::default(),
            autopilot: config.autopilot().unwrap_or(Autopilot::Generic),
            announcer: config
                .autopilot()
                .ok()
                .and_then(Autopilot::origin_form)
                .map(|form| OriginAnnouncer::new(config.system_id, form)),
            resets: ResetCounter::default(),
            vibration: VibrationMeter::default(),
            events: EventWatch::default(),
            fused: None,
            nav: None,
            aiding_seen: 0,
            quality_sigma_m: config.odometry_quality_sigma_m,
            load_permille: 0,
        }
    }

    /// The local frame's origin, once a usable solution set it.
    pub fn origin(&self) -> Option<&LocalOrigin> {
        self.origin.origin()
    }

    /// A fused IMU sample: HIGHRES_IMU and VIBRATION when due, channel events.
    pub fn on_fused(&mut self, f: &FusedImu, emit: &mut impl FnMut(MavMessage)) {
        let t_ns = f.header.origin_rx_ns;
        self.vibration.add(f);
        self.events.on_fused(f, |m| emit(MavMessage::STATUSTEXT(m)));
        if self.gates.highres_imu.due(t_ns) {
            emit(MavMessage::HIGHRES_IMU(highres_imu(f)));
        }
        if self.gates.vibration.due(t_ns) {
            emit(MavMessage::VIBRATION(self.vibration.take(t_ns / 1_000)));
        }
        self.fused = Some(*f);
    }

    /// A solution of the merged stream; `switches` is the lane selector's count of lane changes
    /// and its latest ([`rins_navigator::lanes::NavSubscriber::switches`]).
    pub fn on_nav(
        &mut self,
        nav: &NavState,
        switches: (u64, Option<rins_navigator::lanes::Switch>),
        emit: &mut impl FnMut(MavMessage),
    ) {
        let t_ns = nav.header.origin_rx_ns;
        self.events
            .on_switches(switches, |m| emit(MavMessage::STATUSTEXT(m)));
        let switches = switches.0;
        let shown = nav.is_shown();
        if self.origin.observe(nav, shown) == OriginChange::Moved {
            self.resets.bump();
        }
        if let (Some(announcer), Some(origin)) = (&mut self.announcer, self.origin.known())
            && let Some(m) = announcer.due(origin, nav)
        {
            emit(m);
        }
        let reset_counter = self.resets.observe(nav, switches);
        // The body rate: the fused rate less the filter's bias estimate.
        let (rate, rate_var) = match &self.fused {
            Some(f) => (
                [0, 1, 2].map(|i| f.rate_rps[i] - nav.gyro_bias_rps[i]),
                f.rate_var,
            ),
            None => ([f64::NAN; 3], [f64::NAN; 3]),
        };
        if shown && self.gates.attitude.due(t_ns) {
            emit(MavMessage::ATTITUDE_QUATERNION(attitude_quaternion(
                nav, rate,
            )));
        }
        if let (true, Some(origin)) = (shown, self.origin.origin()) {
            if self.gates.global_position.due(t_ns) {
                emit(MavMessage::GLOBAL_POSITION_INT(global_position_int(
                    nav, origin,
                )));
            }
            if self.gates.local_position.due(t_ns) {
                emit(MavMessage::LOCAL_POSITION_NED(local_position_ned(
                    nav, origin,
                )));
            }
        }
        // Odometry goes out whatever the solution's state (unless the autopilot must not see it
        // then): its quality (−1) is how a receiver learns it must not use it.
        if self.gates.odometry.due(t_ns) {
            let m = match self.origin.origin() {
                Some(origin) => odometry(
                    nav,
                    origin,
                    rate,
                    rate_var,
                    reset_counter,
                    self.quality_sigma_m,
                ),
                None => odometry(
                    nav,
                    &LocalOrigin::new(0.0, 0.0, 0.0),
                    rate,
                    rate_var,
                    reset_counter,
                    self.quality_sigma_m,
                ),
            };
            if let Some(m) = self.autopilot.shape(m, shown) {
                emit(MavMessage::ODOMETRY(m));
            }
        }
        self.nav = Some(*nav);
        self.aiding_seen |= nav.aiding;
    }

    /// The watchdog's report: restarts become events.
    pub fn on_health(&mut self, report: &HealthReport, emit: &mut impl FnMut(MavMessage)) {
        self.events
            .on_health(report, |m| emit(MavMessage::STATUSTEXT(m)));
    }

    /// The load SYS_STATUS reports from now on: the pipeline's CPU, ‰ (see
    /// [`crate::pipeline_cpu`]; 0: not measured).
    pub fn set_load_permille(&mut self, permille: u16) {
        self.load_permille = permille;
    }

    /// HEARTBEAT and SYS_STATUS when due at `now_ns` (CLOCK_MONOTONIC): they say the stream is
    /// alive, so they go on when no sample arrives.
    pub fn on_clock(&mut self, now_ns: u64, emit: &mut impl FnMut(MavMessage)) {
        if self.gates.heartbeat.due(now_ns) {
            emit(MavMessage::HEARTBEAT(heartbeat(
                self.profile,
                self.nav.as_ref(),
            )));
        }
        if self.gates.sys_status.due(now_ns) {
            emit(MavMessage::SYS_STATUS(sys_status(
                self.fused.as_ref(),
                self.nav.as_ref(),
                present(self.aiding_seen),
                self.load_permille,
            )));
        }
    }
}

#[cfg(test)]
mod tests {
    use ipc_types::{Integrity, NavMode, aiding};

    use super::*;
    use crate::dialect::{MavSysStatusSensor, MavSysStatusSensorExtended};

    fn navigating(t_ns: u64, aiding: u32, sigma_h_m: f64) -> NavState {
        let mut nav = NavState {
            mode: NavMode::Navigating as u8,
            aiding,
            quaternion: [1.0, 0.0, 0.0, 0.0],
            ..NavState::default()
        };
        nav.header.origin_rx_ns = t_ns;
        nav.covariance_diag[6] = sigma_h_m * sigma_h_m;
        nav
    }

    #[test]
    fn odometry_quality_follows_the_configured_sigma_and_sys_status_what_was_configured() {
        let config = MavlinkConfig {
            odometry_quality_sigma_m: 20.0,
            ..MavlinkConfig::default()
        };
        let mut stream = MavlinkStream::new(&config);
        let mut sent = Vec::new();
        // σ_h = 20 m = σ₀: quality 50 (with the built-in 10 m it would be 20).
        let nav = navigating(1_000_000_000, aiding::BARO | aiding::MAG, 20.0);
        stream.on_nav(&nav, (0, None), &mut |m| sent.push(m));
        // The barometer then goes quiet: still present, no longer healthy.
        let quiet = navigating(1_100_000_000, aiding::BARO_STALE | aiding::MAG, 20.0);
        stream.on_nav(&quiet, (0, None), &mut |m| sent.push(m));
        stream.on_clock(2_000_000_000, &mut |m| sent.push(m));
        let quality: Vec<i8> = sent
            .iter()
            .filter_map(|m| match m {
                MavMessage::ODOMETRY(o) => Some(o.quality),
                _ => None,
            })
            .collect();
        assert_eq!(quality.first(), Some(&50));
        let Some(MavMessage::SYS_STATUS(s)) =
            sent.iter().find(|m| matches!(m, MavMessage::SYS_STATUS(_)))
        else {
            panic!("no SYS_STATUS in {sent:?}");
        };
        let baro = MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE;
        let mag = MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_MAG;
        let present = s.onboard_control_sensors_present;
        assert!(present.contains(baro | mag), "{present:?}");
        assert!(!present.contains(MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_GPS));
        let health = s.onboard_control_sensors_health;
        assert!(health.contains(mag) && !health.contains(baro), "{health:?}");
        assert_eq!(
            s.onboard_control_sensors_present_extended,
            MavSysStatusSensorExtended::empty()
        );
        // Not measured until the service sets it.
        assert_eq!(s.load, 0);
        stream.set_load_permille(137);
        let mut later = Vec::new();
        stream.on_clock(3_000_000_000, &mut |m| later.push(m));
        assert!(
            later
                .iter()
                .any(|m| matches!(m, MavMessage::SYS_STATUS(s) if s.load == 137)),
            "{later:?}"
        );
    }

    #[test]
    fn an_autopilot_gets_its_frames_and_the_origin_and_a_moved_origin_is_a_reset() {
        use crate::dialect::MavFrame;
        use ipc_types::integrity_reason;
        let config = MavlinkConfig {
            autopilot: "ardupilot".into(),
            system_id: 9,
            ..MavlinkConfig::default()
        };
        let mut stream = MavlinkStream::new(&config);
        let mut sent = Vec::new();
        // Aligning: ArduPilot gets no ODOMETRY, and there is no origin yet.
        let aligning = NavState {
            mode: NavMode::Aligning as u8,
            ..navigating(1_000_000_000, 0, 1.0)
        };
        stream.on_nav(&aligning, (0, None), &mut |m| sent.push(m));
        assert!(sent.is_empty(), "{sent:?}");
        // Navigating with a placeholder position: the frame starts, nothing is announced.
        let mut placeholder = navigating(2_000_000_000, 0, 1.0);
        placeholder.integrity = Integrity::Degraded as u8;
        placeholder.integrity_reasons = integrity_reason::POSITION_UNKNOWN;
        stream.on_nav(&placeholder, (0, None), &mut |m| sent.push(m));
        let odometry = |sent: &[MavMessage]| -> Vec<(MavFrame, u8)> {
            sent.iter()
                .filter_map(|m| match m {
                    MavMessage::ODOMETRY(o) => Some((o.frame_id, o.reset_counter)),
                    _ => None,
                })
                .collect()
        };
        assert_eq!(odometry(&sent), [(MavFrame::MAV_FRAME_LOCAL_FRD, 0)]);
        assert!(!sent.iter().any(|m| matches!(m, MavMessage::COMMAND_INT(_))));
        // The position becomes known: the origin moves there (a reset) and is announced to
        // system 9's autopilot.
        sent.clear();
        let mut known = navigating(3_000_000_000, 0, 1.0);
        (known.latitude_rad, known.longitude_rad) = (0.8, 0.15);
        stream.on_nav(&known, (0, None), &mut |m| sent.push(m));
        assert_eq!(odometry(&sent), [(MavFrame::MAV_FRAME_LOCAL_FRD, 1)]);
        let Some(MavMessage::COMMAND_INT(c)) = sent
            .iter()
            .find(|m| matches!(m, MavMessage::COMMAND_INT(_)))
        else {
            panic!("no origin command in {sent:?}");
        };
        assert_eq!((c.target_system, c.x), (9, 458_366_236));
        let origin = stream.origin().expect("an origin");
        assert_eq!((origin.latitude_rad, origin.longitude_rad), (0.8, 0.15));
    }
}
