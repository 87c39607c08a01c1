//! The events a crew reads as STATUSTEXT, found by comparing each input with the one before: a
//! channel changing state in the fused samples, the consumers' lane changing, a service's restart
//! count growing in the watchdog's report.

use ipc_types::{
    ChannelState, FaultReason, FusedImu, HealthReport, MAX_SUPERVISED, SensorType, ServiceKind,
};

use rins_navigator::lanes::Switch;

use crate::dialect::STATUSTEXT_DATA;
use crate::status_text::{channel_event, lane_switch, service_restarted};

/// What was seen last, to tell what changed.
#[derive(Debug, Clone, Default)]
pub struct EventWatch {
    /// Channel states of the last fused sample, gyro then accelerometer.
    channels: Option<([u8; ipc_types::MAX_CHANNELS], [u8; ipc_types::MAX_CHANNELS])>,
    /// Lane switches seen so far.
    switches: u64,
    /// Restarts per service kind in the last report.
    restarts: Option<[u32; MAX_SUPERVISED]>,
}

impl EventWatch {
    /// The channel events of fused sample `f` (none for the first sample: what is already so at
    /// start is the state, not an event).
    pub fn on_fused(&mut self, f: &FusedImu, mut emit: impl FnMut(STATUSTEXT_DATA)) {
        let now = (f.gyro_state, f.accel_state);
        if let Some((gyro, accel)) = self.channels {
            let kinds = [
                (
                    SensorType::Gyro,
                    &gyro,
                    &f.gyro_state,
                    &f.gyro_reason,
                    f.n_gyro,
                ),
                (
                    SensorType::Accel,
                    &accel,
                    &f.accel_state,
                    &f.accel_reason,
                    f.n_accel,
                ),
            ];
            for (sensor, before, after, reasons, n) in kinds {
                for ch in 0..usize::from(n).min(before.len()) {
                    if before[ch] == after[ch] {
                        continue;
                    }
                    let Some(state) = ChannelState::from_u8(after[ch]) else {
                        continue;
                    };
                    let reason = FaultReason::from_u8(reasons[ch]).unwrap_or(FaultReason::None);
                    emit(channel_event(sensor, ch as u8, state, reason));
                }
            }
        }
        self.channels = Some(now);
    }

    /// A lane switch, with its cause, when the selector's count of switches grew; `last` is its
    /// latest switch.
    pub fn on_switches(
        &mut self,
        (switches, last): (u64, Option<Switch>),
        mut emit: impl FnMut(STATUSTEXT_DATA),
    ) {
        if switches > self.switches
            && let Some(s) = last
        {
            emit(lane_switch(&s));
        }
        self.switches = switches;
    }

    /// A restart event for each service whose restart count grew since the last report.
    pub fn on_health(&mut self, report: &HealthReport, mut emit: impl FnMut(STATUSTEXT_DATA)) {
        let mut now = [0u32; MAX_SUPERVISED];
        let count = usize::from(report.count).min(MAX_SUPERVISED);
        for s in &report.services[..count] {
            if let Some(slot) = now.get_mut(usize::from(s.service)) {
                *slot = s.restarts;
            }
        }
        if let Some(before) = self.restarts {
            for (kind, (b, a)) in before.iter().zip(&now).enumerate() {
                if a > b
                    && let Some(k) = u8::try_from(kind).ok().and_then(ServiceKind::from_u8)
                {
                    emit(service_restarted(k.name()));
                }
            }
        }
        self.restarts = Some(now);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::ServiceHealth;
    use rins_navigator::lanes::{Distrust, SwitchReason};

    fn texts(run: impl FnOnce(&mut dyn FnMut(STATUSTEXT_DATA))) -> Vec<String> {
        let mut out = Vec::new();
        run(&mut |m: STATUSTEXT_DATA| {
            let bytes: [u8; 50] = m.text.into();
            let end = bytes.iter().position(|b| *b == 0).unwrap_or(50);
            out.push(String::from_utf8_lossy(&bytes[..end]).into_owned());
        });
        out
    }

    #[test]
    fn channel_changes_are_events_the_start_state_is_not() {
        let mut w = EventWatch::default();
        let mut f = FusedImu {
            n_gyro: 4,
            n_accel: 4,
            ..FusedImu::default()
        };
        f.gyro_state[2] = ChannelState::Excluded as u8;
        assert!(texts(|e| w.on_fused(&f, e)).is_empty());
        f.gyro_state[1] = ChannelState::Excluded as u8;
        f.gyro_reason[1] = FaultReason::Missing as u8;
        f.gyro_state[2] = ChannelState::Ok as u8;
        assert_eq!(
            texts(|e| w.on_fused(&f, e)),
            ["rins gyro1 excluded: missing", "rins gyro2 in service"]
        );
        assert!(texts(|e| w.on_fused(&f, e)).is_empty());
    }

    #[test]
    fn switches_and_restarts() {
        let mut w = EventWatch::default();
        assert!(texts(|e| w.on_switches((0, None), e)).is_empty());
        let switch = Switch {
            from: 0,
            to: 1,
            reason: SwitchReason::Untrusted(Distrust::Invalid),
            at_seq: 7,
        };
        assert_eq!(
            texts(|e| w.on_switches((1, Some(switch)), e)),
            ["rins lane 0->1: lane 0 invalid"]
        );
        // Once per switch, not per sample.
        assert!(texts(|e| w.on_switches((1, Some(switch)), e)).is_empty());
        let mut report = HealthReport {
            count: 2,
            ..HealthReport::default()
        };
        report.services[0] = ServiceHealth {
            service: ServiceKind::Fusion as u8,
            ..ServiceHealth::default()
        };
        report.services[1] = ServiceHealth {
            service: ServiceKind::Navigator as u8,
            ..ServiceHealth::default()
        };
        assert!(texts(|e| w.on_health(&report, e)).is_empty());
        report.services[1].restarts = 1;
        assert_eq!(
            texts(|e| w.on_health(&report, e)),
            ["rins navigator restarted"]
        );
        assert!(texts(|e| w.on_health(&report, e)).is_empty());
    }
}
