//! What the runtime needs to know of a payload: the payload version it was written with (checked
//! once, on receipt, by every topic subscriber), and the header each stage stamps with its publish
//! time.

use ipc_types::{Header, PAYLOAD_VERSION};

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

/// A sample as received, told apart by its payload version.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Received<T> {
    /// Written with this build's payload version.
    Current(T),
    /// Written with another payload version: already counted as rejected.
    OtherVersion(T),
}

impl<T> Received<T> {
    /// The sample, whatever its version.
    pub fn payload(&self) -> &T {
        match self {
            Received::Current(s) | Received::OtherVersion(s) => s,
        }
    }
}

/// One warning per consumer the first time it has refused samples of another payload version
/// (a process of another build on the deployment); the count itself goes with the consumer's
/// counters. Called where the consumer reports its counters, not per sample.
#[derive(Debug, Default)]
pub struct OtherVersionWarning {
    warned: bool,
}

impl OtherVersionWarning {
    /// Nothing warned yet.
    pub const fn new() -> Self {
        Self { warned: false }
    }

    /// Warns once, when `rejected` (the consumer's total of samples of another payload version)
    /// is first above zero.
    pub fn check(&mut self, consumer: &str, rejected: u64) {
        if rejected > 0 && !self.warned {
            self.warned = true;
            tracing::warn!(
                consumer,
                rejected,
                expected_version = PAYLOAD_VERSION,
                "samples of another payload version dropped (a process of another build on the \
                 deployment?); further ones are counted, not logged"
            );
        }
    }
}

/// Makes every payload of the topic table [`Versioned`], and those with the common header
/// [`Stamped`].
macro_rules! payload_traits {
    ($($payload:ident $kind:ident;)+) => {$(
        payload_traits!(@$kind $payload);
    )+};
    (@stamped $payload:ident) => {
        stamped!(ipc_types::$payload);
    };
    (@unstamped $payload:ident) => {
        versioned!(ipc_types::$payload);
    };
}

ipc_types::for_each_topic!(payloads => payload_traits);

#[cfg(test)]
mod tests {
    use ipc_types::NavState;

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

    #[test]
    fn the_other_version_warning_waits_for_a_refusal_and_comes_once() {
        let mut warning = OtherVersionWarning::new();
        warning.check("test", 0);
        assert!(!warning.warned);
        warning.check("test", 2);
        assert!(warning.warned);
        warning.check("test", 3);
        assert!(warning.warned);
    }
}
