//! STATUSTEXT: the events a crew must read — a channel excluded or back in service, a navigation
//! lane switch, a service restarted — as one line of at most 50 characters with its severity.

use ipc_types::{ChannelState, FaultReason, SensorType};
use rins_navigator::lanes::{Switch, SwitchReason};

use crate::dialect::{MavSeverity, STATUSTEXT_DATA};

/// Longest text one STATUSTEXT carries.
pub const MAX_TEXT: usize = 50;

/// A STATUSTEXT of `severity` with `text` (ASCII; cut at [`MAX_TEXT`] bytes).
pub fn status_text(severity: MavSeverity, text: &str) -> STATUSTEXT_DATA {
    STATUSTEXT_DATA {
        severity,
        text: text.into(),
        // One chunk: no id needed to reassemble it.
        id: 0,
        chunk_seq: 0,
    }
}

/// A channel's change of state: an exclusion is a warning, a suspect a notice, a return an info.
pub fn channel_event(
    sensor: SensorType,
    channel: u8,
    state: ChannelState,
    reason: FaultReason,
) -> STATUSTEXT_DATA {
    let name = format!("rins {}{channel}", sensor.name());
    match state {
        ChannelState::Excluded => status_text(
            MavSeverity::MAV_SEVERITY_WARNING,
            &format!("{name} excluded: {}", reason.name()),
        ),
        ChannelState::Suspect => status_text(
            MavSeverity::MAV_SEVERITY_NOTICE,
            &format!("{name} suspect: {}", reason.name()),
        ),
        ChannelState::Ok => status_text(
            MavSeverity::MAV_SEVERITY_INFO,
            &format!("{name} in service"),
        ),
        ChannelState::Absent => {
            status_text(MavSeverity::MAV_SEVERITY_INFO, &format!("{name} absent"))
        }
    }
}

/// The consumers now follow navigation lane `s.to`, and why they left `s.from`:
/// `rins lane 0->1: lane 0 silent 12 ms, 15 behind`.
pub fn lane_switch(s: &Switch) -> STATUSTEXT_DATA {
    let (from, to) = (s.from, s.to);
    let ms = |ns: u64| ns.saturating_add(500_000) / 1_000_000;
    let why = match s.reason {
        SwitchReason::Silent { silent_ns, ahead } => {
            format!("lane {from} silent {} ms, {ahead} behind", ms(silent_ns))
        }
        SwitchReason::Behind { ahead } => format!("lane {from} {ahead} behind, no times"),
        SwitchReason::RingFull { silent_ns, ahead } => {
            format!("{ahead} pending, lane {from} silent {} ms", ms(silent_ns))
        }
        SwitchReason::Untrusted(d) => format!("lane {from} {}", d.name()),
    };
    status_text(
        MavSeverity::MAV_SEVERITY_WARNING,
        &format!("rins lane {from}->{to}: {why}"),
    )
}

/// The watchdog restarted `service`.
pub fn service_restarted(service: &str) -> STATUSTEXT_DATA {
    status_text(
        MavSeverity::MAV_SEVERITY_WARNING,
        &format!("rins {service} restarted"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(m: &STATUSTEXT_DATA) -> String {
        let bytes: [u8; MAX_TEXT] = m.text.into();
        let end = bytes.iter().position(|b| *b == 0).unwrap_or(MAX_TEXT);
        String::from_utf8_lossy(&bytes[..end]).into_owned()
    }

    #[test]
    fn channel_events_name_the_channel_and_why() {
        let m = channel_event(
            SensorType::Gyro,
            2,
            ChannelState::Excluded,
            FaultReason::Missing,
        );
        assert_eq!(m.severity, MavSeverity::MAV_SEVERITY_WARNING);
        assert_eq!(text(&m), "rins gyro2 excluded: missing");
        let m = channel_event(SensorType::Accel, 0, ChannelState::Ok, FaultReason::None);
        assert_eq!(
            (m.severity, text(&m).as_str()),
            (MavSeverity::MAV_SEVERITY_INFO, "rins accel0 in service")
        );
        assert_eq!(
            text(&service_restarted("navigator-standby")),
            "rins navigator-standby restarted"
        );
    }

    #[test]
    fn a_lane_switch_says_why() {
        use rins_navigator::lanes::Distrust;
        let switch = |reason| Switch {
            from: 0,
            to: 1,
            reason,
            at_seq: 1001,
        };
        let cases = [
            (
                SwitchReason::Silent {
                    silent_ns: 12_400_000,
                    ahead: 15,
                },
                "rins lane 0->1: lane 0 silent 12 ms, 15 behind",
            ),
            (
                SwitchReason::Behind { ahead: 8 },
                "rins lane 0->1: lane 0 8 behind, no times",
            ),
            (
                SwitchReason::RingFull {
                    silent_ns: 8_600_000,
                    ahead: 512,
                },
                "rins lane 0->1: 512 pending, lane 0 silent 9 ms",
            ),
            (
                SwitchReason::Untrusted(Distrust::Aligning),
                "rins lane 0->1: lane 0 aligning",
            ),
            (
                SwitchReason::Untrusted(Distrust::Young { run: 3 }),
                "rins lane 0->1: lane 0 too young",
            ),
        ];
        for (reason, want) in cases {
            let m = lane_switch(&switch(reason));
            assert_eq!(m.severity, MavSeverity::MAV_SEVERITY_WARNING);
            assert_eq!(text(&m), want);
        }
        // A silence of a day is cut at the message size.
        let long = lane_switch(&switch(SwitchReason::Silent {
            silent_ns: 99_999_000_000_000,
            ahead: 512,
        }));
        assert_eq!(
            text(&long),
            "rins lane 0->1: lane 0 silent 99999000 ms, 512 beh"
        );
    }

    #[test]
    fn long_texts_are_cut_to_the_message_size() {
        let long = "x".repeat(80);
        assert_eq!(
            text(&status_text(MavSeverity::MAV_SEVERITY_INFO, &long)).len(),
            MAX_TEXT
        );
        // The longest event text fits whole.
        let m = channel_event(
            SensorType::Accel,
            15,
            ChannelState::Excluded,
            FaultReason::StationaryReference,
        );
        assert_eq!(text(&m), "rins accel15 excluded: stationary-reference");
    }
}
