//! Reading a serial line whose device may be missing at start-up or vanish later: opening the
//! port ([`port`]), the backoff between attempts ([`backoff`]), whether the device is there
//! ([`presence`]), the line's settings ([`line_config`]), the wait between attempts ([`wait`]),
//! and the one reconnecting read loop every serial reader runs ([`reconnecting`]).

pub mod backoff;
pub mod line_config;
pub mod port;
pub mod presence;
pub mod reconnecting;
pub mod wait;
