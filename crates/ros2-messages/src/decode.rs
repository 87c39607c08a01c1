//! The bytes a ROS 2 publisher puts on the wire back into a message: the inverse of
//! [`crate::encode()`], for rins's own remote tools. The input comes from the network, so anything
//! is refused with an error rather than trusted: a header other than plain CDR, a message cut
//! short, bytes left over, a string that is not UTF-8.

use byteorder::{BigEndian, LittleEndian};
use serde::de::DeserializeOwned;

/// Why bytes are not a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DecodeError {
    /// Fewer than the 4 bytes of the encapsulation header.
    NoHeader,
    /// An encapsulation other than plain CDR (big or little endian).
    Encapsulation([u8; 2]),
    /// The CDR does not hold the message: the decoder's reason.
    Body(String),
    /// The message ends before the bytes do (more than CDR's alignment padding left).
    TrailingBytes(usize),
}

impl std::fmt::Display for DecodeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NoHeader => write!(f, "shorter than the CDR encapsulation header"),
            Self::Encapsulation(e) => {
                write!(f, "encapsulation {e:02x?} is not plain CDR")
            }
            Self::Body(why) => write!(f, "not the message: {why}"),
            Self::TrailingBytes(n) => write!(f, "{n} bytes after the message"),
        }
    }
}

impl std::error::Error for DecodeError {}

/// Decodes a message of type `T` from `bytes` (encapsulation header first).
pub fn decode<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, DecodeError> {
    let (header, body) = bytes
        .split_first_chunk::<4>()
        .ok_or(DecodeError::NoHeader)?;
    let body_error = |e: cdr_encoding::Error| DecodeError::Body(e.to_string());
    let (msg, used) = match [header[0], header[1]] {
        [0x00, 0x01] => cdr_encoding::from_bytes::<T, LittleEndian>(body).map_err(body_error)?,
        [0x00, 0x00] => cdr_encoding::from_bytes::<T, BigEndian>(body).map_err(body_error)?,
        other => return Err(DecodeError::Encapsulation(other)),
    };
    // Writers may pad the message to a multiple of 4 (or 8) bytes.
    let left = body.len().saturating_sub(used);
    if left >= 8 {
        return Err(DecodeError::TrailingBytes(left));
    }
    Ok(msg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnostics::{DiagnosticArray, DiagnosticStatus, KeyValue};
    use crate::messages::{Header, Odometry, Time};

    fn odometry() -> Odometry {
        let mut o = Odometry {
            header: Header {
                stamp: Time { sec: 3, nanosec: 4 },
                frame_id: "map".into(),
            },
            child_frame_id: "base_link".into(),
            ..Odometry::default()
        };
        o.pose.pose.position.x = 1.25;
        o.twist.covariance.0[35] = 0.5;
        o
    }

    #[test]
    fn what_is_encoded_decodes_to_itself() {
        let mut bytes = Vec::new();
        crate::encode(&odometry(), &mut bytes).unwrap();
        assert_eq!(decode::<Odometry>(&bytes), Ok(odometry()));
        let array = DiagnosticArray {
            header: odometry().header,
            status: vec![DiagnosticStatus {
                level: DiagnosticStatus::WARN,
                name: "rins: fusion".into(),
                message: "running".into(),
                hardware_id: "rins".into(),
                values: vec![KeyValue {
                    key: "pid".into(),
                    value: "42".into(),
                }],
            }],
        };
        crate::encode(&array, &mut bytes).unwrap();
        assert_eq!(decode::<DiagnosticArray>(&bytes), Ok(array));
    }

    #[test]
    fn garbage_is_refused_not_trusted() {
        let mut bytes = Vec::new();
        crate::encode(&odometry(), &mut bytes).unwrap();
        assert_eq!(decode::<Odometry>(&bytes[..3]), Err(DecodeError::NoHeader));
        assert!(matches!(
            decode::<Odometry>(&bytes[..bytes.len() - 1]),
            Err(DecodeError::Body(_))
        ));
        let mut other = bytes.clone();
        other[1] = 0x07;
        assert_eq!(
            decode::<Odometry>(&other),
            Err(DecodeError::Encapsulation([0x00, 0x07]))
        );
        let mut longer = bytes.clone();
        longer.extend([0; 16]);
        assert_eq!(
            decode::<Odometry>(&longer),
            Err(DecodeError::TrailingBytes(16))
        );
        // A string length far beyond the message.
        let mut huge = bytes;
        huge[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode::<Odometry>(&huge).is_err());
    }
}
