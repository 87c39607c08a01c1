//! The navigator's output: the navigation solution, its mode, its integrity and why, and which
//! aiding sources vouch for it.

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

use crate::{Header, PAYLOAD_VERSION};

wire_enum! {
    /// Navigator mode, [`NavState::mode`].
    #[derive(Default)]
    pub enum NavMode: u8 {
        /// Collecting the static alignment window.
        #[default]
        Aligning = 0 => "aligning",
        /// Aligned and navigating.
        Navigating = 1 => "navigating",
        /// Navigating on inertial only: an aiding source expected by the profile is missing.
        Coasting = 2 => "coasting",
        /// Aligned, but the solution's integrity is [`Integrity::Invalid`]: it must not be used.
        Invalid = 3 => "invalid",
    }
}

impl NavMode {
    /// A solution a consumer may use: aligned and not invalid.
    pub fn is_usable(self) -> bool {
        matches!(self, NavMode::Navigating | NavMode::Coasting)
    }
}

wire_enum! {
    /// How far the navigation solution can be trusted, [`NavState::integrity`]: the navigator's
    /// own judgement from its filter's consistency and its input (see [`integrity_reason`]).
    /// Ordered from best to worst.
    #[derive(PartialOrd, Ord, Default)]
    pub enum Integrity: u8 {
        /// Consistent: use it.
        #[default]
        Ok = 0 => "ok",
        /// Usable with care: an aiding source is inconsistent or silent, an uncertainty is beyond
        /// its limit, or the solution is recovering from an invalid episode.
        Degraded = 1 => "degraded",
        /// Not usable: the solution is not being propagated, or nothing that aids it agrees with
        /// it.
        Invalid = 2 => "invalid",
    }
}

/// Why the integrity is not [`Integrity::Ok`], bits of [`NavState::integrity_reasons`].
pub mod integrity_reason {
    /// Fused IMU samples arrive without a usable solution (too few channels of a type, the block
    /// saturated, frames rejected): the state is not propagated. Invalid beyond the outage limit.
    pub const IMU_UNUSABLE: u32 = 1 << 0;
    /// The device time does not advance from sample to sample (or jumps): nothing is integrated.
    pub const TIME_NOT_ADVANCING: u32 = 1 << 1;
    /// Every configured aiding source disagrees with the solution persistently.
    pub const ALL_AIDING_REJECTED: u32 = 1 << 2;
    /// Baro heights persistently rejected, or their normalised innovations too large.
    pub const BARO_INCONSISTENT: u32 = 1 << 3;
    /// Magnetometer headings persistently rejected, or their normalised innovations too large.
    pub const MAG_INCONSISTENT: u32 = 1 << 4;
    /// Zero-velocity (or stance heading) updates persistently rejected or inconsistent.
    pub const ZUPT_INCONSISTENT: u32 = 1 << 5;
    /// An error standard deviation (tilt, heading, vertical, horizontal) beyond its limit.
    pub const COVARIANCE: u32 = 1 << 6;
    /// Back from an invalid episode or a reset: held degraded until the aiding confirms it.
    pub const RECOVERING: u32 = 1 << 7;
    /// The filter state is not finite.
    pub const NON_FINITE: u32 = 1 << 8;
    /// A configured aiding source is silent: the filter coasts on the inertial solution.
    pub const AIDING_STALE: u32 = 1 << 9;
    /// The GNSS receiver disagrees with the inertial solution (a jump, or a drift the inertial
    /// solution does not follow): it is rejected until it is consistent again.
    pub const GNSS_INCONSISTENT: u32 = 1 << 10;
    /// Fusion detects a fault among the redundant IMU channels that it cannot yet pin on one
    /// channel: the solution still includes the channel that disagrees. Held after the fault is
    /// isolated while the attitude error it may have left is beyond the limit.
    pub const SENSOR_FAULT_UNISOLATED: u32 = 1 << 11;
    /// No initial position was configured and no absolute fix has set one yet: the horizontal
    /// position is unknown (latitude and longitude are placeholders).
    pub const POSITION_UNKNOWN: u32 = 1 << 12;
    /// Airspeeds persistently rejected, or their normalised innovations too large (in wind, the
    /// zero-wind airspeed aid disagrees with the velocity over the ground).
    pub const AIRSPEED_INCONSISTENT: u32 = 1 << 13;

    /// Every reason with its name, in bit order.
    pub const NAMES: [(u32, &str); 14] = [
        (IMU_UNUSABLE, "imu-unusable"),
        (TIME_NOT_ADVANCING, "time-not-advancing"),
        (ALL_AIDING_REJECTED, "all-aiding-rejected"),
        (BARO_INCONSISTENT, "baro-inconsistent"),
        (MAG_INCONSISTENT, "mag-inconsistent"),
        (ZUPT_INCONSISTENT, "zupt-inconsistent"),
        (COVARIANCE, "covariance"),
        (RECOVERING, "recovering"),
        (NON_FINITE, "non-finite"),
        (AIDING_STALE, "aiding-stale"),
        (GNSS_INCONSISTENT, "gnss-inconsistent"),
        (SENSOR_FAULT_UNISOLATED, "sensor-fault-unisolated"),
        (POSITION_UNKNOWN, "position-unknown"),
        (AIRSPEED_INCONSISTENT, "airspeed-inconsistent"),
    ];

    /// The names of the bits set in `reasons`, comma-separated (empty for none).
    pub fn describe(reasons: u32) -> String {
        crate::bit_names(reasons, &NAMES).join(",")
    }
}

/// Bits of [`NavState::aiding`]: a source's bit is set while one of its updates was accepted
/// within the aiding timeout (never while the solution is invalid); the `_STALE` bits say that a
/// configured source went quiet.
pub mod aiding {
    /// The aiding sources, one line per source: `Variant = index, BIT => "name";` makes the
    /// [`AidingSourceId`] `Variant` of index `index` (its slot in the per-source counts of
    /// [`NavState`](crate::NavState)), its bit `BIT = 1 << index` and its name in
    /// [`SOURCE_NAMES`]. A new source goes last, with a new payload layout.
    macro_rules! aiding_sources {
        ($($(#[$doc:meta])* $variant:ident = $index:literal, $bit:ident => $name:literal;)+) => {
            $($(#[$doc])* pub const $bit: u32 = 1 << $index;)+

            /// An aiding source of the navigator: the bucket its updates are counted in.
            #[derive(Debug, Clone, Copy, PartialEq, Eq)]
            #[repr(u8)]
            pub enum AidingSourceId {
                $($(#[$doc])* $variant = $index,)+
            }

            impl AidingSourceId {
                /// Number of sources, the length of per-source arrays.
                pub const COUNT: usize = [$($index),+].len();
                /// Every source, in index order.
                pub const ALL: [Self; Self::COUNT] = [$(Self::$variant),+];

                /// Lower-case name for logs and reports.
                pub const fn name(self) -> &'static str {
                    match self {
                        $(Self::$variant => $name,)+
                    }
                }

                /// Its bit in [`NavState::aiding`](crate::NavState).
                pub const fn bit(self) -> u32 {
                    1 << self as u32
                }
            }

            /// Every source with its name, in bit order.
            pub const SOURCE_NAMES: [(u32, &str); AidingSourceId::COUNT] = [$(($bit, $name)),+];
        };
    }

    aiding_sources! {
        /// Barometric height updates.
        Baro = 0, BARO => "baro";
        /// Magnetometer heading updates (also while the heading is still the one the magnetometer
        /// gave at alignment).
        Mag = 1, MAG => "mag";
        /// Zero-velocity updates.
        Zupt = 2, ZUPT => "zupt";
        /// Heading updates during stance (a foot-mounted unit).
        Hupt = 3, HUPT => "hupt";
        /// The tilt is being re-levelled from gravity (after the IMU stopped propagating the
        /// attitude).
        Gravity = 4, GRAVITY => "gravity";
        /// GNSS position and velocity updates.
        Gnss = 5, GNSS => "gnss";
        /// Pitot airspeed updates.
        Airspeed = 6, AIRSPEED => "airspeed";
    }

    // Each source is where its list line puts it, with its bit, and no source bit is a stale or
    // rejected one.
    const _: () = {
        let mut k = 0;
        while k < AidingSourceId::COUNT {
            assert!(AidingSourceId::ALL[k] as usize == k);
            assert!(AidingSourceId::ALL[k].bit() == SOURCE_NAMES[k].0);
            k += 1;
        }
        let mut source_bits = 0;
        let mut k = 0;
        while k < SOURCE_NAMES.len() {
            source_bits |= SOURCE_NAMES[k].0;
            k += 1;
        }
        assert!(source_bits & (BARO_STALE | MAG_STALE | GNSS_STALE | GNSS_REJECTED) == 0);
    };

    /// Baro aiding is configured but no reading arrived within the aiding timeout: the altitude
    /// coasts on the inertial solution.
    pub const BARO_STALE: u32 = 1 << 8;
    /// Magnetometer aiding is configured but no reading arrived within the aiding timeout: the
    /// heading coasts on the gyros.
    pub const MAG_STALE: u32 = 1 << 9;
    /// GNSS aiding is configured but no usable fix arrived within the aiding timeout (an outage):
    /// the horizontal position coasts on the inertial solution, its covariance growing.
    pub const GNSS_STALE: u32 = 1 << 10;
    /// The GNSS receiver's fixes are rejected as inconsistent with the inertial solution (a jump
    /// or a drift): the position coasts on the inertial solution until they agree again.
    pub const GNSS_REJECTED: u32 = 1 << 11;

    /// Every stale-source bit with the source's name.
    pub const STALE_NAMES: [(u32, &str); 3] = [
        (BARO_STALE, "baro"),
        (MAG_STALE, "mag"),
        (GNSS_STALE, "gnss"),
    ];

    /// Every rejected-source bit with the source's name.
    pub const REJECTED_NAMES: [(u32, &str); 1] = [(GNSS_REJECTED, "gnss")];

    /// Every table of bit names with the suffix its names take in a readable list (`gnss-stale`,
    /// `gnss-rejected`): together they name each bit of [`NavState::aiding`](crate::NavState).
    pub const NAME_GROUPS: [(&[(u32, &str)], &str); 3] = [
        (&SOURCE_NAMES, ""),
        (&STALE_NAMES, "-stale"),
        (&REJECTED_NAMES, "-rejected"),
    ];
}

/// Aiding sources counted in [`NavState::aiding_accepted`] / [`NavState::aiding_rejected`], in
/// the index order of [`aiding::AidingSourceId`]: baro, mag, zupt, hupt, gravity, gnss, airspeed
/// (a new source goes last).
pub const AIDING_SOURCES: usize = aiding::AidingSourceId::COUNT;

/// Length of [`NavState::covariance_diag`]: attitude error, velocity, position, gyro bias, accel bias.
pub const NAV_STATES: usize = 15;

/// Navigation solution, published by each navigator lane, one per fused IMU sample (lane 0 on
/// [`crate::names::NAV_STATE`], lane 1 on the standby topic, see [`crate::names::NAV_LANES`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::NavState")]
pub struct NavState {
    /// Layout version, [`PAYLOAD_VERSION`].
    pub version: u16,
    /// [`NavMode`] as u8.
    pub mode: u8,
    /// Navigator lane that computed this solution (0 = primary, 1 = hot standby).
    pub lane: u8,
    /// Aiding sources used in this solution, bits of [`aiding`].
    pub aiding: u32,
    /// The fused IMU sample's header, with the navigator's publish time stamped.
    pub header: Header,
    /// Attitude quaternion body (FRD) → NED, Hamilton, scalar first.
    pub quaternion: [f64; 4],
    /// Velocity NED, m/s.
    pub velocity_ned_mps: [f64; 3],
    /// Latitude, radians (WGS84).
    pub latitude_rad: f64,
    /// Longitude, radians (WGS84).
    pub longitude_rad: f64,
    /// Altitude above mean sea level, metres.
    pub altitude_m: f64,
    /// Diagonal of the error-state covariance, in this order: attitude error (3, rad²), velocity
    /// (3, (m/s)²), position NED (3, m²), gyro bias (3, (rad/s)²), accelerometer bias (3,
    /// (m/s²)²). Zero while aligning.
    pub covariance_diag: [f64; NAV_STATES],
    /// Updates accepted per aiding source since alignment (baro, mag, zupt, hupt, gravity, gnss,
    /// airspeed).
    pub aiding_accepted: [u32; AIDING_SOURCES],
    /// Updates rejected by the innovation gate per aiding source since alignment.
    pub aiding_rejected: [u32; AIDING_SOURCES],
    /// `header.origin_seq` of the first sample of this solution (alignment completed or state taken
    /// over from the other lane); 0 while aligning. A lane selector trusts a solution only once it
    /// has run for a while, so that a lane that just reset is not chosen.
    pub solution_start_seq: u64,
    /// Estimated gyro bias (body, rad/s): with the attitude, velocity, position, accelerometer
    /// bias and covariance it is the whole filter state, so that a restarted lane can take over
    /// its peer's solution in flight.
    pub gyro_bias_rps: [f64; 3],
    /// Estimated accelerometer bias (body, m/s²), part of the filter state like
    /// [`NavState::gyro_bias_rps`].
    pub accel_bias_mps2: [f64; 3],
    /// [`Integrity`] as u8.
    pub integrity: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 3],
    /// Why the integrity is not ok, bits of [`integrity_reason`].
    pub integrity_reasons: u32,
}

impl Default for NavState {
    fn default() -> Self {
        Self {
            version: PAYLOAD_VERSION,
            mode: NavMode::Aligning as u8,
            lane: 0,
            aiding: 0,
            header: Header::default(),
            quaternion: [1.0, 0.0, 0.0, 0.0],
            velocity_ned_mps: [0.0; 3],
            latitude_rad: 0.0,
            longitude_rad: 0.0,
            altitude_m: 0.0,
            covariance_diag: [0.0; NAV_STATES],
            aiding_accepted: [0; AIDING_SOURCES],
            aiding_rejected: [0; AIDING_SOURCES],
            solution_start_seq: 0,
            gyro_bias_rps: [0.0; 3],
            accel_bias_mps2: [0.0; 3],
            integrity: Integrity::Ok as u8,
            _pad: [0; 3],
            integrity_reasons: 0,
        }
    }
}

impl NavState {
    /// Whether a consumer may show this sample as a solution: its mode usable and its integrity
    /// not invalid. Everything rins hands to another system (MAVLink, ROS 2) asks this one
    /// question, so no output claims a solution another withholds.
    pub fn is_shown(&self) -> bool {
        NavMode::from_u8(self.mode).is_some_and(NavMode::is_usable)
            && Integrity::from_u8(self.integrity).is_some_and(|i| i != Integrity::Invalid)
    }
}
