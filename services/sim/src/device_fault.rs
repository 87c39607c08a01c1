//! Faults of the whole device rather than of one channel: the serial line unplugged for a while,
//! as a pulled cable or a USB adapter that drops off the bus and comes back.

use std::fmt;

use crate::fault_parse_error::FaultParseError;

/// Longest accepted disconnect, s: longer is a dead device, not a fault to recover from.
pub const MAX_DISCONNECT_S: f64 = 3600.0;

/// What a disconnect's duration must be, for messages.
pub const DURATION_RANGE: &str = "must be a number of seconds > 0 and <= 3600";

/// The device's serial line goes away for `duration_s` seconds of device time, then comes back
/// as a new port under the same path. Frames the device produces meanwhile are lost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disconnect {
    /// Length of the outage in device time, s; in (0, 3600] ([`MAX_DISCONNECT_S`]).
    pub duration_s: f64,
}

impl Disconnect {
    /// Checks the duration; the error says what it must be.
    pub fn new(duration_s: f64) -> Result<Self, &'static str> {
        if duration_s.is_finite() && duration_s > 0.0 && duration_s <= MAX_DISCONNECT_S {
            Ok(Self { duration_s })
        } else {
            Err(DURATION_RANGE)
        }
    }

    /// Parses the duration as typed; errors name `field` (e.g. `disconnect --duration`) and the
    /// text.
    pub fn parse(field: &str, text: &str) -> Result<Self, FaultParseError> {
        let value: f64 = text
            .trim()
            .parse()
            .map_err(|_| FaultParseError::new(format!("{field} {text:?}"), DURATION_RANGE))?;
        Self::new(value)
            .map_err(|reason| FaultParseError::new(format!("{field} = {value}"), reason))
    }

    /// The outage in ticks of `imu_rate_hz`, at least one: the line is down for whole samples.
    pub fn ticks(&self, imu_rate_hz: f64) -> u64 {
        // Finite and at most an hour after validation: the product fits easily.
        (self.duration_s * imu_rate_hz).round().max(1.0) as u64
    }
}

impl fmt::Display for Disconnect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "disconnect {} s", self.duration_s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_are_checked_and_errors_name_field_and_value() {
        assert_eq!(Disconnect::new(2.0).unwrap().duration_s, 2.0);
        assert!(Disconnect::new(3600.0).is_ok());
        for bad in [0.0, -1.0, 3600.5, f64::NAN, f64::INFINITY] {
            assert_eq!(Disconnect::new(bad), Err(DURATION_RANGE), "{bad}");
        }
        let d = Disconnect::parse("disconnect --duration", " 1.5 ").unwrap();
        assert_eq!(d.duration_s, 1.5);
        assert_eq!(d.to_string(), "disconnect 1.5 s");
        let e = Disconnect::parse("disconnect --duration", "soon").unwrap_err();
        assert_eq!(e.token, "disconnect --duration \"soon\"");
        assert!(e.reason.contains("> 0"), "{e}");
        let e = Disconnect::parse("disconnect --duration", "-2").unwrap_err();
        assert_eq!(e.token, "disconnect --duration = -2");
        let e = Disconnect::parse("disconnect --duration", "7200").unwrap_err();
        assert!(
            e.to_string().contains("= 7200") && e.reason.contains("3600"),
            "{e}"
        );
    }

    #[test]
    fn the_outage_lasts_whole_ticks() {
        let d = |s: f64| Disconnect::new(s).unwrap();
        assert_eq!(d(1.0).ticks(1000.0), 1000);
        assert_eq!(d(0.0004).ticks(1000.0), 1);
        assert_eq!(d(0.25).ticks(400.0), 100);
    }
}
