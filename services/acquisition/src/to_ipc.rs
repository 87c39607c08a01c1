//! The origin header a decoded frame's IPC payload is stamped with. The payload itself is the
//! frame type's ([`rins_protocol::SensorFrame::to_ipc`]).

use ipc_types::Header;

use rins_protocol::DecodedFrame;

/// The header of a decoded frame: its device sequence and time, and when it was received (`rx_ns`).
pub fn origin_header(frame: &DecodedFrame, rx_ns: u64) -> Header {
    Header {
        origin_seq: frame.seq,
        origin_device_time_us: frame.device_time_us,
        origin_rx_ns: rx_ns,
        ..Header::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rins_protocol::{MagFrame, Payload, SensorFrame};

    #[test]
    fn header_carries_the_extended_origin() {
        let frame = DecodedFrame {
            seq: 70_000,
            device_time_us: 5_000_000_000,
            payload: Payload::Mag(MagFrame {
                field_nt: [25_000, -1_500, 43_301],
            }),
        };
        let h = origin_header(&frame, 42);
        assert_eq!(
            (h.origin_seq, h.origin_device_time_us, h.origin_rx_ns),
            (70_000, 5_000_000_000, 42)
        );
        let Payload::Mag(m) = frame.payload else {
            unreachable!()
        };
        let raw = m.to_ipc(h);
        assert_eq!(raw.field_ut, [25.0, -1.5, 43.301]);
        assert_eq!(raw.header, h);
    }
}
