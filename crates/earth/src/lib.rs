//! The Earth models every part of rins shares: attitude angles ([`attitude`]), the WGS84 ellipsoid ([`wgs84`]), gravity
//! ([`gravity`]: the standard value and normal gravity) the standard atmosphere ([`isa`]) and a local
//! tangent-plane NED frame ([`local_frame`]).
//! Pure functions and constants.

pub mod attitude;
pub mod gravity;
pub mod isa;
pub mod local_frame;
pub mod wgs84;

pub use attitude::euler_deg;
pub use gravity::{STANDARD_GRAVITY, normal_gravity};
pub use local_frame::LocalOrigin;
pub use wgs84::{meridian_radius, prime_vertical_radius};
