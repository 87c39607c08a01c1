//! A message as the bytes a ROS 2 subscriber reads: the CDR encapsulation header (plain CDR,
//! little endian), then the message, each primitive aligned to its size counted from the byte after
//! the header.

use byteorder::LittleEndian;
use serde::Serialize;

/// The CDR encapsulation header of a little-endian plain-CDR message.
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Replaces `out` with the message `msg` (the buffer's capacity is kept, so a reused buffer does
/// not allocate once it is large enough).
pub fn encode<T: Serialize>(msg: &T, out: &mut Vec<u8>) -> Result<(), cdr_encoding::Error> {
    out.clear();
    out.extend_from_slice(&CDR_LE_HEADER);
    // The serializer counts alignment from its own start: the byte after the header.
    cdr_encoding::to_writer::<T, LittleEndian, _>(&mut *out, msg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::{Header, NavSatFix, NavSatStatus, Time};

    #[test]
    fn a_navsatfix_is_laid_out_as_cdr_says() {
        let fix = NavSatFix {
            header: Header {
                stamp: Time { sec: 7, nanosec: 9 },
                frame_id: "gps".into(),
            },
            status: NavSatStatus {
                status: 0,
                service: 1,
            },
            latitude: 1.5,
            ..NavSatFix::default()
        };
        let mut out = Vec::new();
        encode(&fix, &mut out).unwrap();
        let mut expected = CDR_LE_HEADER.to_vec();
        expected.extend(7i32.to_le_bytes());
        expected.extend(9u32.to_le_bytes());
        expected.extend(4u32.to_le_bytes()); // "gps" and its terminator
        expected.extend(b"gps\0");
        expected.push(0); // status (int8) at 16
        expected.push(0); // padding to 2
        expected.extend(1u16.to_le_bytes()); // service at 18
        expected.extend([0; 4]); // padding to 8: latitude at 24
        expected.extend(1.5f64.to_le_bytes());
        expected.extend(0f64.to_le_bytes()); // longitude
        expected.extend(0f64.to_le_bytes()); // altitude
        for _ in 0..9 {
            expected.extend(0f64.to_le_bytes());
        }
        expected.push(0); // covariance type
        assert_eq!(out, expected);
    }
}
