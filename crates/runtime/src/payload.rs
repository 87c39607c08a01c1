//! What the stage loop needs to know of a payload: the payload version it was written with (checked
//! once, on receipt), and the header each stage stamps with its publish time.

use ipc_types::{
    Altitude, FaultApplied, FusedImu, FusionControl, FusionReply, GnssFix, Header, NavState,
    PAYLOAD_VERSION, RawAux, RawBaro, RawImu, RawMag, SimControl, Truth,
};

/// A payload that carries the [`PAYLOAD_VERSION`] of the build that wrote it.
pub trait Versioned {
    /// The payload version it was written with.
    fn version(&self) -> u16;

    /// Whether this build reads it as written: the same payload version.
    fn is_current(&self) -> bool {
        self.version() == PAYLOAD_VERSION
    }
}

/// A payload with the common [`Header`]: where its data came from and when each stage published it.
pub trait Stamped: Versioned {
    /// The header, for the publishing stage's stamp.
    fn header_mut(&mut self) -> &mut Header;

    /// The header.
    fn header(&self) -> &Header;
}

macro_rules! versioned {
    ($($payload:ty),* $(,)?) => {$(
        impl Versioned for $payload {
            fn version(&self) -> u16 {
                self.version
            }
        }
    )*};
}

macro_rules! stamped {
    ($($payload:ty),* $(,)?) => {$(
        versioned!($payload);
        impl Stamped for $payload {
            fn header_mut(&mut self) -> &mut Header {
                &mut self.header
            }

            fn header(&self) -> &Header {
                &self.header
            }
        }
    )*};
}

versioned!(FusionControl, FusionReply, SimControl, FaultApplied);
stamped!(
    RawImu, RawBaro, RawMag, RawAux, GnssFix, FusedImu, Altitude, NavState, Truth
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_current_version_is_read_and_another_is_not() {
        let mut nav = NavState::default();
        assert!(nav.is_current());
        nav.version = PAYLOAD_VERSION + 1;
        assert!(!nav.is_current());
        nav.header_mut().origin_seq = 7;
        assert_eq!(nav.header.origin_seq, 7);
    }
}
