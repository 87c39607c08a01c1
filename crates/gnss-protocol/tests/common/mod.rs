//! What the tests share: the real receivers' captures in `captures/` (see its `SOURCES.md`).

// Each test file is its own crate and uses only some of these.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// Where the captures are.
pub fn captures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/captures")
}

/// A capture without its leading `#` comment lines: the receiver's bytes.
pub fn receiver_bytes(mut log: &[u8]) -> &[u8] {
    while log.first() == Some(&b'#') {
        match log.iter().position(|&x| x == b'\n') {
            Some(end) => log = &log[end + 1..],
            None => return &[],
        }
    }
    log
}

/// The receiver's bytes of the capture `name` (e.g. `ublox-lea-4t.log`).
pub fn capture(name: &str) -> Vec<u8> {
    let path = captures_dir().join(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    receiver_bytes(&bytes).to_vec()
}

/// Epoch `i` of the simulated receiver: 5 Hz from 12:34:56 UTC, a 3-D fix over Sydney moving by
/// 1e-6° north-west and 1 m up per epoch, with the accuracies and velocity it reports.
pub fn simulated_epoch(i: u64) -> ipc_types::GnssFix {
    ipc_types::GnssFix {
        receiver_time_us: 45_296_000_000 + i * 200_000,
        fix_type: ipc_types::GnssFixType::Fix3d as u8,
        satellites: 11,
        latitude_rad: (-33.8688 + i as f64 * 1e-6).to_radians(),
        longitude_rad: (151.2093 - i as f64 * 1e-6).to_radians(),
        altitude_m: 58.25 + i as f64,
        velocity_ned_mps: [3.0, -4.0, 0.5],
        horizontal_accuracy_m: 1.5,
        vertical_accuracy_m: 3.0,
        speed_accuracy_mps: 0.1,
        hdop: 0.8,
        ..ipc_types::GnssFix::default()
    }
}

/// The simulated receiver's first `n` epochs as it sends them: NAV-PVT frames (`ubx`) or NMEA
/// sentences.
pub fn simulated_stream(n: u64, ubx: bool) -> Vec<u8> {
    use rins_gnss_protocol::encode::{write_nav_pvt, write_nmea_epoch};
    let mut out = Vec::new();
    for i in 0..n {
        if ubx {
            write_nav_pvt(&simulated_epoch(i), &mut out);
        } else {
            write_nmea_epoch(&simulated_epoch(i), &mut out);
        }
    }
    out
}
