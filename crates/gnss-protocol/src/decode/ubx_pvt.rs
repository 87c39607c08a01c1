//! UBX NAV-PVT (the u-blox receiver's position, velocity and time solution) as a fix.

use ipc_types::{GnssFix, GnssFixType, GnssProtocol, PAYLOAD_VERSION};
use ublox::nav_pvt::common::NavPvtFlags;
use ublox::nav_pvt::proto23::NavPvtRef;

/// The fix a NAV-PVT frame reports; not checked for plausibility (see [`super::is_plausible`]).
pub fn fix_from_nav_pvt(pvt: &NavPvtRef<'_>) -> GnssFix {
    let flags = pvt.flags();
    let fix_ok = flags.contains(NavPvtFlags::GPS_FIX_OK);
    let fix_type = match (fix_ok, pvt.fix_type()) {
        (false, _) => GnssFixType::NoFix,
        (true, ublox::GnssFixType::Fix3D | ublox::GnssFixType::GPSPlusDeadReckoning) => {
            if flags.contains(NavPvtFlags::CARR_SOLN_FIXED) {
                GnssFixType::RtkFixed
            } else if flags.contains(NavPvtFlags::CARR_SOLN_FLOAT) {
                GnssFixType::RtkFloat
            } else if flags.contains(NavPvtFlags::DIFF_SOLN) {
                GnssFixType::Differential
            } else {
                GnssFixType::Fix3d
            }
        }
        (true, ublox::GnssFixType::Fix2D) => GnssFixType::Fix2d,
        (true, ublox::GnssFixType::DeadReckoningOnly) => GnssFixType::DeadReckoning,
        (true, _) => GnssFixType::NoFix,
    };
    GnssFix {
        version: PAYLOAD_VERSION,
        fix_type: fix_type as u8,
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
