//! UBX HNR-PVT (class 0x28, id 0x00: the high-rate solution of u-blox automotive receivers,
//! which blend their own inertial sensors in) as a fix, read like NAV-PVT.

use ipc_types::{GnssFix, GnssProtocol, PAYLOAD_VERSION};
use ublox::hnr_pvt::{HnrPvtFlags, HnrPvtRef};

use super::ubx_fix_type::{SolutionStatus, fix_type};

/// The fix an HNR-PVT frame reports, typed by the UBX fix-type rule (`ubx_fix_type`); not
/// checked for plausibility. HNR-PVT has no satellite count and no vertical velocity: the
/// velocity fields hold the ground speed along the heading of motion, but are not marked valid,
/// since a vertical velocity of 0 stated as measured would pull a climbing aircraft's solution
/// level.
pub fn fix_from_hnr_pvt(hnr: &HnrPvtRef<'_>) -> GnssFix {
    let flags = hnr.flags();
    let status = SolutionStatus {
        gps_fix: hnr.fix_type() as u8,
        fix_ok: flags.contains(HnrPvtFlags::GPS_FIX_OK),
        differential: flags.contains(HnrPvtFlags::DIFF_SOLN),
        carrier: 0,
    };
    let speed = hnr.ground_speed_2d();
    let (sin, cos) = hnr.heading_motion().to_radians().sin_cos();
    GnssFix {
        version: PAYLOAD_VERSION,
        fix_type: fix_type(status) as u8,
        satellites: 0,
        protocol: GnssProtocol::Ubx as u8,
        velocity_valid: 0,
        accuracy_reported: 1,
        receiver_time_us: u64::from(hnr.itow()) * 1_000,
        latitude_rad: hnr.latitude().to_radians(),
        longitude_rad: hnr.longitude().to_radians(),
        altitude_m: hnr.height_msl(),
        velocity_ned_mps: [speed * cos, speed * sin, 0.0],
        horizontal_accuracy_m: hnr.horizontal_accuracy(),
        vertical_accuracy_m: hnr.vertical_accuracy(),
        speed_accuracy_mps: hnr.speed_accuracy(),
        hdop: 0.0,
        ..GnssFix::default()
    }
}
