//! The solution older and timing u-blox receivers report in several messages of one epoch
//! instead of NAV-PVT: NAV-SOL (status, ECEF position and velocity, satellites), NAV-POSLLH
//! (geodetic position, mean-sea-level height, horizontal and vertical accuracy), NAV-VELNED
//! (NED velocity) and NAV-DOP (dilution of precision).
//!
//! NAV-SOL alone makes a fix: its ECEF position is turned geodetic and its one 3-D accuracy
//! estimate (pAcc) serves as the horizontal σ (which it bounds). Its height is above the
//! ellipsoid, not mean sea level: without NAV-POSLLH the epoch's fix is published horizontal only
//! (see `ubx_epoch.rs`). NAV-POSLLH and NAV-VELNED, when the receiver sends them, replace the
//! position and velocity with the receiver's own.

use ipc_types::{GnssFix, GnssFixType, GnssProtocol, PAYLOAD_VERSION};
use ublox::nav_dop::NavDopRef;
use ublox::nav_pos_llh::NavPosLlhRef;
use ublox::nav_sol::{NavSolFlags, NavSolRef};
use ublox::nav_vel_ned::NavVelNedRef;

use super::ecef::{geodetic_from_ecef, ned_from_ecef_velocity};
use super::sanity::is_plausible;
use super::ubx_fix_type::{SolutionStatus, fix_type};

/// The fix a NAV-SOL frame reports, typed by [`super::ubx_fix_type`]'s rule; not checked for
/// plausibility. The receiver time is iTOW, in µs, as for NAV-PVT.
pub fn fix_from_nav_sol(sol: &NavSolRef<'_>) -> GnssFix {
    let flags = sol.flags();
    let status = SolutionStatus {
        gps_fix: sol.fix_type() as u8,
        fix_ok: flags.contains(NavSolFlags::GPS_FIX_OK),
        differential: flags.contains(NavSolFlags::DIFF_SOLN),
        carrier: 0,
    };
    let [lat, lon, ellipsoid_height] =
        geodetic_from_ecef([sol.ecef_x(), sol.ecef_y(), sol.ecef_z()]);
    let velocity = ned_from_ecef_velocity([sol.ecef_vx(), sol.ecef_vy(), sol.ecef_vz()], lat, lon);
    let p_acc = sol.position_accuracy_estimate();
    GnssFix {
        version: PAYLOAD_VERSION,
        fix_type: fix_type(status) as u8,
        satellites: sol.num_sv(),
        protocol: GnssProtocol::Ubx as u8,
        velocity_valid: 1,
        accuracy_reported: 1,
        receiver_time_us: u64::from(sol.itow()) * 1_000,
        latitude_rad: lat,
        longitude_rad: lon,
        // Above the ellipsoid: replaced by NAV-POSLLH's, or dropped (see `ubx_epoch.rs`).
        altitude_m: ellipsoid_height,
        velocity_ned_mps: velocity,
        horizontal_accuracy_m: p_acc,
        vertical_accuracy_m: p_acc,
        speed_accuracy_mps: sol.speed_accuracy_estimate(),
        hdop: 0.0,
        ..GnssFix::default()
    }
}

/// NAV-POSLLH's position: latitude, longitude (radians), height above mean sea level (m) and
/// the receiver's horizontal and vertical accuracy (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PosLlh {
    latitude_rad: f64,
    longitude_rad: f64,
    altitude_m: f64,
    horizontal_accuracy_m: f64,
    vertical_accuracy_m: f64,
}

impl PosLlh {
    /// The position of `llh`, or `None` when its values are out of range.
    pub fn read(llh: &NavPosLlhRef<'_>) -> Option<Self> {
        let p = Self {
            latitude_rad: llh.lat_degrees().to_radians(),
            longitude_rad: llh.lon_degrees().to_radians(),
            altitude_m: llh.height_msl(),
            horizontal_accuracy_m: llh.h_ack(),
            vertical_accuracy_m: llh.v_acc(),
        };
        let mut check = GnssFix {
            fix_type: GnssFixType::Fix3d as u8,
            ..GnssFix::default()
        };
        p.apply(&mut check);
        is_plausible(&check).then_some(p)
    }

    /// Puts this position into `fix`.
    pub fn apply(&self, fix: &mut GnssFix) {
        fix.latitude_rad = self.latitude_rad;
        fix.longitude_rad = self.longitude_rad;
        fix.altitude_m = self.altitude_m;
        fix.horizontal_accuracy_m = self.horizontal_accuracy_m;
        fix.vertical_accuracy_m = self.vertical_accuracy_m;
        fix.accuracy_reported = 1;
    }
}

/// NAV-VELNED's velocity: north, east, down (m/s) and the receiver's speed accuracy (m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelNed {
    ned_mps: [f64; 3],
    speed_accuracy_mps: f64,
}

impl VelNed {
    /// The velocity of `vel`, or `None` when its values are out of range.
    pub fn read(vel: &NavVelNedRef<'_>) -> Option<Self> {
        let v = Self {
            ned_mps: [vel.vel_north(), vel.vel_east(), vel.vel_down()],
            speed_accuracy_mps: vel.speed_accuracy_estimate(),
        };
        let mut check = GnssFix {
            fix_type: GnssFixType::Fix3d as u8,
            ..GnssFix::default()
        };
        v.apply(&mut check);
        is_plausible(&check).then_some(v)
    }

    /// Puts this velocity into `fix`.
    pub fn apply(&self, fix: &mut GnssFix) {
        fix.velocity_ned_mps = self.ned_mps;
        fix.speed_accuracy_mps = self.speed_accuracy_mps;
        fix.velocity_valid = 1;
    }
}

/// NAV-DOP's horizontal dilution of precision (0.01 resolution, never out of range).
pub fn hdop(dop: &NavDopRef<'_>) -> f64 {
    f64::from(dop.horizontal_dop())
}
