//! UBX NAV-PVT (the u-blox receiver's position, velocity and time solution) as a fix.

use ipc_types::{GnssFix, GnssProtocol, PAYLOAD_VERSION};
use ublox::nav_pvt::common::NavPvtFlags;
use ublox::nav_pvt::proto23::NavPvtRef;

use super::ubx_fix_type::{SolutionStatus, fix_type};

/// The fix a NAV-PVT frame reports, typed by the UBX fix-type rule (`ubx_fix_type`: what the
/// receiver says, never better); not checked for plausibility (see [`super::is_plausible`]). The
/// receiver time is iTOW, in µs.
pub fn fix_from_nav_pvt(pvt: &NavPvtRef<'_>) -> GnssFix {
    let flags = pvt.flags();
    let carrier = if flags.contains(NavPvtFlags::CARR_SOLN_FIXED) {
        2
    } else {
        u8::from(flags.contains(NavPvtFlags::CARR_SOLN_FLOAT))
    };
    let status = SolutionStatus {
        gps_fix: pvt.fix_type() as u8,
        fix_ok: flags.contains(NavPvtFlags::GPS_FIX_OK),
        differential: flags.contains(NavPvtFlags::DIFF_SOLN),
        carrier,
    };
    GnssFix {
        version: PAYLOAD_VERSION,
        fix_type: fix_type(status) as u8,
        satellites: pvt.num_satellites(),
        protocol: GnssProtocol::Ubx as u8,
        velocity_valid: 1,
        accuracy_reported: 1,
        receiver_time_us: u64::from(pvt.itow()) * 1_000,
        latitude_rad: pvt.latitude().to_radians(),
        longitude_rad: pvt.longitude().to_radians(),
        altitude_m: pvt.height_msl(),
        velocity_ned_mps: [pvt.vel_north(), pvt.vel_east(), pvt.vel_down()],
        horizontal_accuracy_m: pvt.horizontal_accuracy(),
        vertical_accuracy_m: pvt.vertical_accuracy(),
        speed_accuracy_mps: pvt.speed_accuracy(),
        hdop: 0.0,
        ..GnssFix::default()
    }
}
