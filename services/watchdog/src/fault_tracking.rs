//! Detection and isolation of injected faults, measured in device time from the simulator's
//! fault events and fusion's per-channel states; and false alarms: channels leaving Ok, or
//! fusion reporting a fault it cannot isolate, on a sensor type with no injected fault active.
//! Faults of the simulated GNSS receiver are detected from the navigation solution: a jump or a
//! drift when it rejects the receiver, an outage or a freeze when it reports GNSS aiding stale;
//! a receiver rejected with no GNSS fault active is a false alarm.

use ipc_types::{
    ChannelState, FaultApplied, FaultOutcome, FaultReason, FusedImu, MAX_CHANNELS, SensorType,
    SimControl, SimFault, aiding, fused_flags,
};
use serde::Serialize;

/// One injected fault as the summary reports it; times are device seconds since the simulator
/// started, `None` (JSON null) when it did not happen.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FaultRecord {
    /// `gyro2`, `accel0`, ...
    pub channel: String,
    /// Fault kind: `dead`, `stuck`, `bias`, `ramp`, `noise`, `saturate`, `intermittent`.
    pub kind: &'static str,
    /// The fault's parameter (SI units, or the noise factor), if it takes one.
    pub param: Option<f64>,
    /// When the fault was injected, s since the start of the run.
    pub injected_at_s: f64,
    /// First fused output at or after injection with the channel Suspect or Excluded, or the
    /// type's detected-not-isolated flag set.
    pub detected_at_s: Option<f64>,
    /// First fused output at or after injection with the channel Excluded.
    pub isolated_at_s: Option<f64>,
    /// [`FaultReason`] name given for the exclusion (`unknown` for a number this build cannot
    /// read).
    pub reason: Option<&'static str>,
    /// When the fault was cleared or replaced by another fault on the same channel.
    pub cleared_at_s: Option<f64>,
    /// GNSS faults: the solution's horizontal error against the truth at the last navigation
    /// sample of the fault (the end of an outage, the coast's drift), m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coast_horiz_err_m: Option<f64>,
    /// GNSS faults: the horizontal position σ the navigator reported at that sample (the larger
    /// of north and east), m — the drift as the solution reports it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coast_horiz_sigma_m: Option<f64>,
    /// GNSS faults: the largest step of the horizontal solution from one sample to the next
    /// while the fault was active that the truth's motion does not explain, m: what reached
    /// the solution of a jump or a drift.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub horiz_step_m_max: Option<f64>,
    /// The sensor type; `None` for the GNSS receiver.
    #[serde(skip)]
    sensor: Option<SensorType>,
    #[serde(skip)]
    index: usize,
}

impl FaultRecord {
    fn active_at(&self, t_s: f64) -> bool {
        self.injected_at_s <= t_s && self.cleared_at_s.is_none_or(|c| t_s < c)
    }
}

/// What was last seen of one channel, and since when.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ChannelTrack {
    state: ChannelState,
    /// Name of the [`FaultReason`] fusion gave.
    reason: &'static str,
    /// Start of the current stretch away from Ok (Suspect or Excluded).
    not_ok_since_s: Option<f64>,
    /// Start of the current exclusion.
    excluded_since_s: Option<f64>,
}

impl Default for ChannelTrack {
    fn default() -> Self {
        Self {
            state: ChannelState::Ok,
            reason: FaultReason::None.name(),
            not_ok_since_s: None,
            excluded_since_s: None,
        }
    }
}

/// A false alarm: when, and on which sensor type.
#[derive(Debug, Clone, Copy, PartialEq)]
struct FalseAlarm {
    /// `None` for the GNSS receiver.
    sensor: Option<SensorType>,
    t_s: f64,
}

const TYPES: [SensorType; 2] = [SensorType::Gyro, SensorType::Accel];

fn type_index(sensor: SensorType) -> usize {
    sensor as usize
}

fn detected_not_isolated_flag(sensor: SensorType) -> u32 {
    match sensor {
        SensorType::Gyro => fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED,
        SensorType::Accel => fused_flags::ACCEL_FAULT_DETECTED_NOT_ISOLATED,
    }
}

fn is_not_ok(state: ChannelState) -> bool {
    matches!(state, ChannelState::Suspect | ChannelState::Excluded)
}

/// Follows injected faults through fusion's output.
///
/// Fault events normally arrive before any fused output derived from the faulty sample (the
/// simulator announces a fault before sending the frame). Should one arrive late, the detection
/// and isolation seen meanwhile are credited to it and the false alarms raised meanwhile on its
/// sensor type are withdrawn.
#[derive(Debug, Clone, Default)]
pub struct FaultTracker {
    records: Vec<FaultRecord>,
    channels: [[ChannelTrack; MAX_CHANNELS]; 2],
    /// Start of the current detected-not-isolated stretch, per sensor type.
    unisolated_since_s: [Option<f64>; 2],
    false_alarms: Vec<FalseAlarm>,
    /// The last navigation sample had the GNSS receiver rejected.
    gnss_rejected: bool,
    /// North/east error of the last navigation sample, m.
    last_err_ne_m: Option<[f64; 2]>,
}

impl FaultTracker {
    /// A tracker with no fault injected yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Every fault injected so far, in order of injection.
    pub fn records(&self) -> &[FaultRecord] {
        &self.records
    }

    /// False alarms counted so far.
    pub fn false_alarms(&self) -> u64 {
        self.false_alarms.len() as u64
    }

    fn fault_active(&self, sensor: Option<SensorType>, t_s: f64) -> bool {
        self.records
            .iter()
            .any(|r| r.sensor == sensor && r.active_at(t_s))
    }

    /// Takes a simulator fault event. Rejected commands are ignored; `clear` ends the channel's
    /// fault; any other fault replaces the channel's fault and starts a new record.
    pub fn on_fault_applied(&mut self, event: &FaultApplied) {
        if FaultOutcome::from_u8(event.outcome) != Some(FaultOutcome::Applied) {
            return;
        }
        if event.sensor == SimControl::GNSS_RECEIVER {
            self.on_gnss_fault(event);
            return;
        }
        let (Some(sensor), Some(fault)) = (
            SensorType::from_u8(event.sensor),
            SimFault::from_u8(event.fault),
        ) else {
            return;
        };
        let index = usize::from(event.channel);
        if index >= MAX_CHANNELS {
            return;
        }
        let t_s = event.device_time_us as f64 / 1e6;
        for r in self
            .records
            .iter_mut()
            .filter(|r| r.sensor == Some(sensor) && r.index == index && r.cleared_at_s.is_none())
        {
            r.cleared_at_s = Some(t_s);
        }
        if fault == SimFault::Clear {
            return;
        }
        let has_param = matches!(
            fault,
            SimFault::BiasStep | SimFault::Ramp | SimFault::Noise | SimFault::Intermittent
        );
        let mut record = FaultRecord {
            channel: format!("{}{index}", sensor.name()),
            kind: fault.name(),
            param: has_param.then_some(event.param),
            injected_at_s: t_s,
            detected_at_s: None,
            isolated_at_s: None,
            reason: None,
            cleared_at_s: None,
            coast_horiz_err_m: None,
            coast_horiz_sigma_m: None,
            horiz_step_m_max: None,
            sensor: Some(sensor),
            index,
        };
        // Late event: credit what fusion already showed after the injection time.
        let track = &self.channels[type_index(sensor)][index];
        let since_injection = |since: Option<f64>| since.filter(|&s| s >= t_s);
        let detected = [
            since_injection(track.not_ok_since_s),
            since_injection(self.unisolated_since_s[type_index(sensor)]),
        ];
        record.detected_at_s = detected.into_iter().flatten().reduce(f64::min);
        if let Some(s) = since_injection(track.excluded_since_s) {
            record.isolated_at_s = Some(s);
            record.reason = Some(track.reason);
        }
        self.false_alarms
            .retain(|a| !(a.sensor == Some(sensor) && a.t_s >= t_s));
        self.records.push(record);
    }

    /// A fault of the simulated GNSS receiver: `clear` ends the active one, any other replaces it.
    fn on_gnss_fault(&mut self, event: &FaultApplied) {
        let Some(fault) = SimFault::from_u8(event.fault) else {
            return;
        };
        let t_s = event.device_time_us as f64 / 1e6;
        for r in self
            .records
            .iter_mut()
            .filter(|r| r.sensor.is_none() && r.cleared_at_s.is_none_or(|c| c > t_s))
        {
            r.cleared_at_s = Some(t_s);
        }
        if fault == SimFault::Clear {
            return;
        }
        self.records.push(FaultRecord {
            channel: "gnss".to_string(),
            kind: fault.name(),
            param: Some(event.param),
            injected_at_s: t_s,
            detected_at_s: None,
            isolated_at_s: None,
            reason: None,
            // An outage or freeze of a given length ends by itself.
            cleared_at_s: matches!(fault, SimFault::GnssOutage | SimFault::GnssFreeze)
                .then_some(event.param)
                .filter(|&d| d > 0.0)
                .map(|d| t_s + d),
            coast_horiz_err_m: None,
            coast_horiz_sigma_m: None,
            horiz_step_m_max: None,
            sensor: None,
            index: 0,
        });
        self.false_alarms
            .retain(|a| !(a.sensor.is_none() && a.t_s >= t_s));
    }

    /// Takes one navigation sample after alignment at device time `t_s`: its aiding bits, its
    /// north/east error against the truth (when known) and its horizontal σ. Detects GNSS faults
    /// and counts a receiver rejected with none active as a false alarm.
    pub fn on_nav(&mut self, t_s: f64, aiding_bits: u32, err_ne_m: Option<[f64; 2]>, sigma_m: f64) {
        let horiz_err_m = err_ne_m.map(|[n, e]| n.hypot(e));
        let step = match (err_ne_m, self.last_err_ne_m) {
            (Some([n, e]), Some([n0, e0])) => Some((n - n0).hypot(e - e0)),
            _ => None,
        };
        self.last_err_ne_m = err_ne_m;
        let rejected = aiding_bits & aiding::GNSS_REJECTED != 0;
        let stale = aiding_bits & aiding::GNSS_STALE != 0;
        if rejected && !self.gnss_rejected && !self.fault_active(None, t_s) {
            self.false_alarms.push(FalseAlarm { sensor: None, t_s });
        }
        self.gnss_rejected = rejected;
        for r in self
            .records
            .iter_mut()
            .filter(|r| r.sensor.is_none() && r.active_at(t_s))
        {
            let seen = match SimFault::from_name(r.kind) {
                Some(SimFault::GnssJump | SimFault::GnssDrift) => rejected,
                _ => stale || rejected,
            };
            if r.detected_at_s.is_none() && seen {
                r.detected_at_s = Some(t_s);
            }
            if horiz_err_m.is_some() {
                r.coast_horiz_err_m = horiz_err_m;
                r.coast_horiz_sigma_m = Some(sigma_m);
            }
            if let Some(step) = step {
                r.horiz_step_m_max = Some(r.horiz_step_m_max.map_or(step, |m| m.max(step)));
            }
        }
    }

    /// Takes one fused output; allocation-free except when a false alarm is recorded.
    pub fn on_fused(&mut self, fused: &FusedImu) {
        let t_s = fused.header.origin_device_time_us as f64 / 1e6;
        for sensor in TYPES {
            let ti = type_index(sensor);
            let (n, states, reasons) = match sensor {
                SensorType::Gyro => (fused.n_gyro, &fused.gyro_state, &fused.gyro_reason),
                SensorType::Accel => (fused.n_accel, &fused.accel_state, &fused.accel_reason),
            };
            let n = usize::from(n).min(MAX_CHANNELS);
            let fault_active = self.fault_active(Some(sensor), t_s);

            let unisolated = fused.flags & detected_not_isolated_flag(sensor) != 0;
            match (unisolated, self.unisolated_since_s[ti]) {
                (true, None) => {
                    self.unisolated_since_s[ti] = Some(t_s);
                    if !fault_active {
                        self.false_alarms.push(FalseAlarm {
                            sensor: Some(sensor),
                            t_s,
                        });
                    }
                }
                (false, Some(_)) => self.unisolated_since_s[ti] = None,
                _ => {}
            }

            for i in 0..n {
                // A state this build cannot read is not Ok: it counts as a channel in doubt
                // (Suspect), so that an unreadable output is never taken for a healthy channel.
                let state = ChannelState::from_u8(states[i]).unwrap_or(ChannelState::Suspect);
                let reason = FaultReason::from_u8(reasons[i]).map_or("unknown", FaultReason::name);
                let track = &mut self.channels[ti][i];
                if state == ChannelState::Absent {
                    *track = ChannelTrack::default();
                    continue;
                }
                let was_not_ok = is_not_ok(track.state);
                if is_not_ok(state) && !was_not_ok {
                    track.not_ok_since_s = Some(t_s);
                    if !fault_active {
                        self.false_alarms.push(FalseAlarm {
                            sensor: Some(sensor),
                            t_s,
                        });
                    }
                } else if !is_not_ok(state) {
                    track.not_ok_since_s = None;
                }
                if state == ChannelState::Excluded {
                    if track.state != ChannelState::Excluded {
                        track.excluded_since_s = Some(t_s);
                    }
                } else {
                    track.excluded_since_s = None;
                }
                track.state = state;
                track.reason = reason;
            }

            for r in self
                .records
                .iter_mut()
                .filter(|r| r.sensor == Some(sensor) && r.active_at(t_s))
            {
                let state = self.channels[ti][r.index].state;
                if r.detected_at_s.is_none() && (is_not_ok(state) || unisolated) {
                    r.detected_at_s = Some(t_s);
                }
                if r.isolated_at_s.is_none() && state == ChannelState::Excluded {
                    r.isolated_at_s = Some(t_s);
                    r.reason = Some(self.channels[ti][r.index].reason);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use ipc_types::{Header, PAYLOAD_VERSION};

    use super::*;

    const N: u8 = 4;

    fn event(sensor: SensorType, channel: u8, fault: SimFault, t_us: u64) -> FaultApplied {
        FaultApplied {
            version: PAYLOAD_VERSION,
            sensor: sensor as u8,
            channel,
            fault: fault as u8,
            outcome: FaultOutcome::Applied as u8,
            _pad: [0; 2],
            device_time_us: t_us,
            param: 0.5,
        }
    }

    /// A fused output at `t_us` with every fitted channel Ok.
    fn fused(t_us: u64) -> FusedImu {
        let mut f = FusedImu {
            n_gyro: N,
            n_accel: N,
            header: Header {
                origin_device_time_us: t_us,
                ..Header::default()
            },
            ..FusedImu::default()
        };
        for i in 0..usize::from(N) {
            f.gyro_state[i] = ChannelState::Ok as u8;
            f.accel_state[i] = ChannelState::Ok as u8;
        }
        f
    }

    fn with_gyro(mut f: FusedImu, i: usize, state: ChannelState, reason: FaultReason) -> FusedImu {
        f.gyro_state[i] = state as u8;
        f.gyro_reason[i] = reason as u8;
        f
    }

    /// 1 kHz outputs from `from_us` to `to_us` (exclusive), shaped by `f`.
    fn run(
        tracker: &mut FaultTracker,
        from_us: u64,
        to_us: u64,
        f: impl Fn(u64, FusedImu) -> FusedImu,
    ) {
        for t in (from_us..to_us).step_by(1000) {
            tracker.on_fused(&f(t, fused(t)));
        }
    }

    #[test]
    fn detection_and_isolation_times_are_the_first_outputs_showing_them() {
        let mut tr = FaultTracker::new();
        run(&mut tr, 0, 2_500_000, |_, f| f);
        tr.on_fault_applied(&event(SensorType::Gyro, 1, SimFault::Dead, 2_500_000));
        // Suspect from 2.503 s, excluded (missing) from 2.510 s.
        run(&mut tr, 2_500_000, 4_000_000, |t, f| {
            if t >= 2_510_000 {
                with_gyro(f, 1, ChannelState::Excluded, FaultReason::Missing)
            } else if t >= 2_503_000 {
                with_gyro(f, 1, ChannelState::Suspect, FaultReason::Missing)
            } else {
                f
            }
        });
        let r = &tr.records()[0];
        assert_eq!(r.channel, "gyro1");
        assert_eq!(r.kind, "dead");
        assert_eq!(r.param, None);
        assert_eq!(r.injected_at_s, 2.5);
        assert_eq!(r.detected_at_s, Some(2.503));
        assert_eq!(r.isolated_at_s, Some(2.51));
        assert_eq!(r.reason, Some("missing"));
        assert_eq!(r.cleared_at_s, None);
        assert_eq!(tr.false_alarms(), 0);
    }

    #[test]
    fn undetected_fault_stays_null_and_json_says_so() {
        let mut tr = FaultTracker::new();
        tr.on_fault_applied(&FaultApplied {
            param: 0.01,
            ..event(SensorType::Accel, 2, SimFault::Ramp, 1_000_000)
        });
        run(&mut tr, 0, 3_000_000, |_, f| f);
        let r = &tr.records()[0];
        assert_eq!(
            (r.detected_at_s, r.isolated_at_s, r.reason),
            (None, None, None)
        );
        assert_eq!(r.param, Some(0.01));
        let json = serde_json::to_value(r).unwrap();
        assert_eq!(json["channel"], "accel2");
        assert_eq!(json["kind"], "ramp");
        assert!(json["detected_at_s"].is_null() && json["isolated_at_s"].is_null());
        assert!(json["reason"].is_null());
        assert!(json.get("sensor").is_none());
    }

    #[test]
    fn detected_not_isolated_flag_counts_as_detection_of_that_type_only() {
        let mut tr = FaultTracker::new();
        tr.on_fault_applied(&event(SensorType::Gyro, 0, SimFault::BiasStep, 1_000_000));
        tr.on_fault_applied(&event(SensorType::Accel, 0, SimFault::BiasStep, 1_000_000));
        run(&mut tr, 1_000_000, 2_000_000, |t, mut f| {
            if t >= 1_020_000 {
                f.flags |= fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED;
            }
            f
        });
        assert_eq!(tr.records()[0].detected_at_s, Some(1.02));
        assert_eq!(tr.records()[0].isolated_at_s, None);
        assert_eq!(tr.records()[1].detected_at_s, None);
        assert_eq!(tr.false_alarms(), 0);
    }

    #[test]
    fn false_alarms_are_events_on_types_without_an_active_fault() {
        let mut tr = FaultTracker::new();
        // gyro2 goes Suspect then Excluded (one event), back to Ok, then Suspect again (second).
        run(&mut tr, 0, 1_000_000, |t, f| match t {
            100_000..200_000 => with_gyro(f, 2, ChannelState::Suspect, FaultReason::Parity),
            200_000..300_000 => with_gyro(f, 2, ChannelState::Excluded, FaultReason::Parity),
            500_000..600_000 => with_gyro(f, 2, ChannelState::Suspect, FaultReason::Noisy),
            _ => f,
        });
        assert_eq!(tr.false_alarms(), 2);
        // A detected-not-isolated stretch on the accelerometers: one more.
        run(&mut tr, 1_000_000, 1_100_000, |_, mut f| {
            f.flags |= fused_flags::ACCEL_FAULT_DETECTED_NOT_ISOLATED;
            f
        });
        assert_eq!(tr.false_alarms(), 3);
        // With a gyro fault active, other gyro channels leaving Ok are not false alarms, but an
        // accelerometer leaving Ok is.
        tr.on_fault_applied(&event(SensorType::Gyro, 0, SimFault::Stuck, 2_000_000));
        run(&mut tr, 2_000_000, 2_100_000, |t, mut f| {
            f = with_gyro(f, 3, ChannelState::Excluded, FaultReason::Parity);
            if t >= 2_050_000 {
                f.accel_state[1] = ChannelState::Suspect as u8;
            }
            f
        });
        assert_eq!(tr.false_alarms(), 4);
        // Absent (unfitted) channels never raise alarms.
        let mut f = fused(3_000_000);
        f.n_gyro = 6;
        tr.on_fused(&f);
        assert_eq!(tr.false_alarms(), 4);
    }

    #[test]
    fn a_state_or_reason_that_cannot_be_read_is_not_taken_for_ok() {
        let mut tr = FaultTracker::new();
        // An unknown state byte with no fault active: a channel in doubt, so a false alarm.
        run(&mut tr, 0, 100_000, |t, mut f| {
            if t >= 50_000 {
                f.gyro_state[0] = u8::MAX;
            }
            f
        });
        assert_eq!(tr.false_alarms(), 1);
        // An exclusion with an unknown reason is an isolation, named as unknown.
        tr.on_fault_applied(&event(SensorType::Accel, 1, SimFault::Stuck, 1_000_000));
        run(&mut tr, 1_000_000, 1_100_000, |t, mut f| {
            if t >= 1_030_000 {
                f.accel_state[1] = ChannelState::Excluded as u8;
                f.accel_reason[1] = u8::MAX;
            }
            f
        });
        let r = &tr.records()[0];
        assert_eq!(r.detected_at_s, Some(1.03));
        assert_eq!(r.isolated_at_s, Some(1.03));
        assert_eq!(r.reason, Some("unknown"));
    }

    #[test]
    fn clearing_ends_the_fault_and_later_alarms_count() {
        let mut tr = FaultTracker::new();
        tr.on_fault_applied(&event(SensorType::Gyro, 1, SimFault::Dead, 1_000_000));
        run(&mut tr, 1_000_000, 1_100_000, |_, f| {
            with_gyro(f, 1, ChannelState::Excluded, FaultReason::Missing)
        });
        tr.on_fault_applied(&event(SensorType::Gyro, 1, SimFault::Clear, 1_100_000));
        // Exclusion latches: staying excluded after the clear is no new event.
        run(&mut tr, 1_100_000, 1_200_000, |_, f| {
            with_gyro(f, 1, ChannelState::Excluded, FaultReason::Missing)
        });
        assert_eq!(tr.false_alarms(), 0);
        // Re-admitted, then excluded again with no fault: a false alarm.
        run(&mut tr, 1_200_000, 1_300_000, |_, f| f);
        run(&mut tr, 1_300_000, 1_400_000, |_, f| {
            with_gyro(f, 1, ChannelState::Excluded, FaultReason::Parity)
        });
        assert_eq!(tr.false_alarms(), 1);
        assert_eq!(tr.records().len(), 1);
        assert_eq!(tr.records()[0].cleared_at_s, Some(1.1));
        assert_eq!(tr.records()[0].isolated_at_s, Some(1.0));
    }

    #[test]
    fn replacing_a_fault_starts_a_new_record() {
        let mut tr = FaultTracker::new();
        tr.on_fault_applied(&event(SensorType::Accel, 3, SimFault::Stuck, 1_000_000));
        tr.on_fault_applied(&event(SensorType::Accel, 3, SimFault::Dead, 2_000_000));
        let r = tr.records();
        assert_eq!(r.len(), 2);
        assert_eq!(r[0].cleared_at_s, Some(2.0));
        assert_eq!((r[1].kind, r[1].cleared_at_s), ("dead", None));
    }

    #[test]
    fn late_fault_event_is_credited_and_its_false_alarms_withdrawn() {
        let mut tr = FaultTracker::new();
        // Fusion's reaction to the faulty sample is seen before the fault event.
        run(&mut tr, 0, 1_000_000, |_, f| f);
        run(&mut tr, 1_000_000, 1_005_000, |t, f| {
            if t >= 1_002_000 {
                with_gyro(f, 1, ChannelState::Excluded, FaultReason::Missing)
            } else {
                with_gyro(f, 1, ChannelState::Suspect, FaultReason::Missing)
            }
        });
        assert_eq!(tr.false_alarms(), 1);
        tr.on_fault_applied(&event(SensorType::Gyro, 1, SimFault::Dead, 1_000_000));
        assert_eq!(tr.false_alarms(), 0);
        let r = &tr.records()[0];
        assert_eq!(r.detected_at_s, Some(1.0));
        assert_eq!(r.isolated_at_s, Some(1.002));
        assert_eq!(r.reason, Some("missing"));
    }

    #[test]
    fn rejected_commands_are_not_faults() {
        let mut tr = FaultTracker::new();
        tr.on_fault_applied(&FaultApplied {
            outcome: FaultOutcome::NoSuchChannel as u8,
            ..event(SensorType::Gyro, 9, SimFault::Dead, 1_000_000)
        });
        tr.on_fault_applied(&FaultApplied {
            sensor: 9,
            ..event(SensorType::Gyro, 1, SimFault::Dead, 1_000_000)
        });
        assert!(tr.records().is_empty());
    }

    fn gnss_event(fault: SimFault, param: f64, t_us: u64) -> FaultApplied {
        FaultApplied {
            sensor: SimControl::GNSS_RECEIVER,
            channel: 0,
            param,
            ..event(SensorType::Gyro, 0, fault, t_us)
        }
    }

    #[test]
    fn a_gnss_jump_is_detected_when_the_solution_rejects_the_receiver() {
        let mut tr = FaultTracker::new();
        tr.on_nav(29.0, aiding::GNSS, Some([0.5, 0.0]), 0.4);
        tr.on_fault_applied(&gnss_event(SimFault::GnssJump, 50.0, 30_000_000));
        tr.on_nav(30.2, aiding::GNSS, Some([0.5, 0.0]), 0.4);
        tr.on_nav(30.6, aiding::GNSS_REJECTED, Some([0.6, 0.0]), 0.5);
        tr.on_fault_applied(&gnss_event(SimFault::Clear, 0.0, 40_000_000));
        tr.on_nav(45.0, aiding::GNSS, Some([0.5, 0.0]), 0.4);
        let r = &tr.records()[0];
        assert_eq!((r.channel.as_str(), r.kind), ("gnss", "gnss-jump"));
        // Steps within the fault: 0.5 → 0.5 → 0.6 m north: 0.1 m at most.
        assert!((r.horiz_step_m_max.unwrap() - 0.1).abs() < 1e-9, "{r:?}");
        assert_eq!(
            (r.param, r.detected_at_s, r.cleared_at_s),
            (Some(50.0), Some(30.6), Some(40.0))
        );
        assert_eq!(tr.false_alarms(), 0);
    }

    #[test]
    fn a_gnss_outage_reports_the_drift_at_its_end_and_a_rejection_without_fault_is_a_false_alarm() {
        let mut tr = FaultTracker::new();
        tr.on_fault_applied(&gnss_event(SimFault::GnssOutage, 60.0, 10_000_000));
        tr.on_nav(10.5, aiding::GNSS, Some([0.5, 0.0]), 0.4);
        tr.on_nav(11.5, aiding::GNSS_STALE, Some([0.9, 0.0]), 0.8);
        tr.on_nav(69.9, aiding::GNSS_STALE, Some([7.5, 0.0]), 9.0);
        // The 60 s outage ends by itself at 70 s.
        tr.on_nav(70.1, aiding::GNSS, Some([3.0, 0.0]), 1.0);
        let r = &tr.records()[0];
        assert_eq!(r.detected_at_s, Some(11.5));
        assert_eq!(
            (r.coast_horiz_err_m, r.coast_horiz_sigma_m),
            (Some(7.5), Some(9.0))
        );
        tr.on_nav(80.0, aiding::GNSS_REJECTED, Some([3.0, 0.0]), 1.0);
        tr.on_nav(80.2, aiding::GNSS_REJECTED, Some([3.0, 0.0]), 1.0);
        assert_eq!(tr.false_alarms(), 1);
    }
}
