//! The only contract shared between rins processes: fixed-size `#[repr(C)]` payloads that travel
//! zero-copy over iceoryx2 shared memory, the common header that makes latency measurable end to end,
//! and the service names.
//!
//! Every payload starts with a `version` field; a consumer rejects a payload whose version differs
//! from [`PAYLOAD_VERSION`] instead of misreading it. Enums travel as their `u8` discriminant and
//! are read back with `from_u8`, which answers `None` for a value it does not know: the reader
//! decides what an unknown value means in its place.
//!
//! Units are SI (angles in radians, rates in rad/s, specific force in m/s²); the navigation frame
//! is NED, the body frame FRD; times are CLOCK_MONOTONIC nanoseconds or device microseconds, as
//! each field says.

#[macro_use]
mod wire_enum;

mod altitude;
mod control;
mod fused;
mod gnss;
mod gnss_link;
mod header;
mod health;
mod nav;
mod raw;
mod truth;

pub mod names;
mod topic_table;

// Every public item of the payload modules is part of the contract: a payload added to one of
// them (or a new module listed here) is reachable as `ipc_types::Name` with no further line.
pub use altitude::*;
pub use control::*;
pub use fused::*;
pub use gnss::*;
pub use gnss_link::*;
pub use header::*;
pub use health::*;
pub use nav::*;
pub use raw::*;
pub use truth::*;

/// Version of every payload layout in this crate. Bump it on any layout change.
pub const PAYLOAD_VERSION: u16 = 10;

/// Up to this many single-axis channels per sensor type (gyro, accelerometer).
pub const MAX_CHANNELS: usize = 16;

/// The names of the bits of `bits` that `names` lists, in the list's order; bits it does not list
/// are left out (a flag word's `NAMES`: [`fused_flags::NAMES`], [`aiding::SOURCE_NAMES`],
/// [`integrity_reason::NAMES`]).
pub fn bit_names(bits: u32, names: &[(u32, &'static str)]) -> Vec<&'static str> {
    names
        .iter()
        .filter(|(bit, _)| bits & bit != 0)
        .map(|(_, name)| *name)
        .collect()
}
