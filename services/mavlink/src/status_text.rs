//! STATUSTEXT: the events a crew must read — a channel excluded or back in service, a navigation
//! lane switch, a service restarted — as one line of at most 50 characters with its severity.

use ipc_types::{ChannelState, FaultReason, SensorType};

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

/// The consumers now follow navigation lane `lane`.
pub fn lane_switch(lane: u8) -> STATUSTEXT_DATA {
    status_text(
        MavSeverity::MAV_SEVERITY_WARNING,
        &format!("rins navigation switched to lane {lane}"),
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
        assert_eq!(text(&lane_switch(1)), "rins navigation switched to lane 1");
        assert_eq!(
            text(&service_restarted("navigator-standby")),
            "rins navigator-standby restarted"
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
