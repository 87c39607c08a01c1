//! UBX NAV-PVT (class 0x01, id 0x07, 92-byte payload) as the u-blox receiver description lays it
//! out, little-endian, with the 8-bit Fletcher checksum over class, id, length and payload.

use ipc_types::GnssFixType;

use ipc_types::GnssFix;

use super::fix_type;

/// Milliseconds in a GPS week.
const WEEK_MS: u64 = 604_800_000;
const PAYLOAD_LEN: usize = 92;

/// Appends the epoch as one NAV-PVT frame to `out`.
pub fn write_nav_pvt(epoch: &GnssFix, out: &mut Vec<u8>) {
    let mut p = [0u8; PAYLOAD_LEN];
    let itow = ((epoch.receiver_time_us / 1_000) % WEEK_MS) as u32;
    let kind = fix_type(epoch);
    let (fix_number, flags): (u8, u8) = match kind {
        GnssFixType::NoFix => (0, 0),
        GnssFixType::DeadReckoning => (1, 0x01),
        GnssFixType::Fix2d => (2, 0x01),
        GnssFixType::Fix3d => (3, 0x01),
        GnssFixType::Differential => (3, 0x03),
        GnssFixType::RtkFloat => (3, 0x43),
        GnssFixType::RtkFixed => (3, 0x83),
    };
    let mm = |x: f64| (x * 1e3).round() as i32;
    let umm = |x: f64| (x.max(0.0) * 1e3).round().min(f64::from(u32::MAX)) as u32;
    let deg7 = |rad: f64| (rad.to_degrees() * 1e7).round() as i32;
    let [vn, ve, vd] = epoch.velocity_ned_mps;
    put(&mut p, 0, &itow.to_le_bytes());
    p[20] = fix_number;
    p[21] = flags;
    p[23] = epoch.satellites;
    if kind != GnssFixType::NoFix {
        put(&mut p, 24, &deg7(epoch.longitude_rad).to_le_bytes());
        put(&mut p, 28, &deg7(epoch.latitude_rad).to_le_bytes());
        put(&mut p, 32, &mm(epoch.altitude_m).to_le_bytes());
        put(&mut p, 36, &mm(epoch.altitude_m).to_le_bytes());
        put(&mut p, 40, &umm(epoch.horizontal_accuracy_m).to_le_bytes());
        put(&mut p, 44, &umm(epoch.vertical_accuracy_m).to_le_bytes());
        put(&mut p, 48, &mm(vn).to_le_bytes());
        put(&mut p, 52, &mm(ve).to_le_bytes());
        put(&mut p, 56, &mm(vd).to_le_bytes());
        put(&mut p, 60, &mm(vn.hypot(ve)).to_le_bytes());
        let heading = (ve.atan2(vn).to_degrees().rem_euclid(360.0) * 1e5).round() as i32;
        put(&mut p, 64, &heading.to_le_bytes());
        put(&mut p, 68, &umm(epoch.speed_accuracy_mps).to_le_bytes());
        put(
            &mut p,
            76,
            &((epoch.hdop * 150.0).round() as u16).to_le_bytes(),
        );
    }
    write_ubx_frame(0x01, 0x07, &p, out);
}

/// Appends one UBX frame of `class`, `id` and `payload` to `out`: sync, header, payload and the
/// checksum over class, id, length and payload. A payload longer than a UBX length field holds
/// (65 535 bytes) is cut there.
pub fn write_ubx_frame(class: u8, id: u8, payload: &[u8], out: &mut Vec<u8>) {
    let len = u16::try_from(payload.len()).unwrap_or(u16::MAX);
    let payload = &payload[..usize::from(len)];
    let start = out.len();
    out.extend_from_slice(&[0xB5, 0x62, class, id]);
    out.extend_from_slice(&len.to_le_bytes());
    out.extend_from_slice(payload);
    let (mut a, mut b) = (0u8, 0u8);
    for &byte in &out[start + 2..] {
        a = a.wrapping_add(byte);
        b = b.wrapping_add(a);
    }
    out.extend_from_slice(&[a, b]);
}

fn put(p: &mut [u8; PAYLOAD_LEN], at: usize, bytes: &[u8]) {
    p[at..at + bytes.len()].copy_from_slice(bytes);
}
