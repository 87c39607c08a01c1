//! NMEA 0183 sentences of one epoch: GGA, RMC, GST, VTG (talker GP), each `$…*hh\r\n`.

use std::io::Write;

use ipc_types::GnssFixType;

use ipc_types::GnssFix;

use super::fix_type;

/// Microseconds in a day.
const DAY_US: u64 = 86_400_000_000;
/// Knots per m/s.
const KNOTS_PER_MPS: f64 = 3600.0 / 1852.0;
/// The simulated receiver's date in RMC (ddmmyy): the sentences carry one, the fix needs none.
const DATE: &str = "011226";

/// Appends the epoch's GGA, RMC, GST and VTG sentences to `out`.
pub fn write_nmea_epoch(epoch: &GnssFix, out: &mut Vec<u8>) {
    let t = epoch.receiver_time_us % DAY_US;
    let (h, m) = (t / 3_600_000_000, (t / 60_000_000) % 60);
    let s = (t % 60_000_000) / 10_000;
    let has_fix = fix_type(epoch) != GnssFixType::NoFix;
    let quality = match fix_type(epoch) {
        GnssFixType::NoFix | GnssFixType::Fix2d => 0,
        GnssFixType::Fix3d => 1,
        GnssFixType::Differential => 2,
        GnssFixType::RtkFixed => 4,
        GnssFixType::RtkFloat => 5,
        GnssFixType::DeadReckoning => 6,
    };
    let (lat, ns) = angle(epoch.latitude_rad.to_degrees(), 2, ['N', 'S']);
    let (lon, ew) = angle(epoch.longitude_rad.to_degrees(), 3, ['E', 'W']);
    let [vn, ve, _] = epoch.velocity_ned_mps;
    let speed_kn = vn.hypot(ve) * KNOTS_PER_MPS;
    let course = ve.atan2(vn).to_degrees().rem_euclid(360.0);
    let time = Hms(h, m, s);
    if has_fix {
        sentence(
            out,
            format_args!(
                "GPGGA,{time},{lat},{ns},{lon},{ew},{quality},{:02},{:.1},{:.3},M,0.0,M,,",
                epoch.satellites, epoch.hdop, epoch.altitude_m
            ),
        );
        sentence(
            out,
            format_args!(
                "GPRMC,{time},A,{lat},{ns},{lon},{ew},{speed_kn:.3},{course:.2},{DATE},,,A"
            ),
        );
        let (sh, sv) = (epoch.horizontal_accuracy_m, epoch.vertical_accuracy_m);
        sentence(
            out,
            format_args!("GPGST,{time},{sh:.3},{sh:.3},{sh:.3},0.0,{sh:.3},{sh:.3},{sv:.3}"),
        );
        sentence(
            out,
            format_args!(
                "GPVTG,{course:.2},T,,M,{speed_kn:.3},N,{:.3},K,A",
                speed_kn * 1.852
            ),
        );
    } else {
        sentence(out, format_args!("GPGGA,{time},,,,,0,00,99.9,,M,,M,,"));
        sentence(out, format_args!("GPRMC,{time},V,,,,,,,{DATE},,,N"));
        sentence(out, format_args!("GPGST,{time},,,,,,,"));
        sentence(out, format_args!("GPVTG,,T,,M,,N,,K,N"));
    }
}

/// `hhmmss.ss` from hours, minutes and hundredths of a second.
struct Hms(u64, u64, u64);

impl std::fmt::Display for Hms {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let hundredths = self.2;
        write!(
            f,
            "{:02}{:02}{:02}.{:02}",
            self.0,
            self.1,
            hundredths / 100,
            hundredths % 100
        )
    }
}

/// `(d)ddmm.mmmmmm` and the hemisphere letter of `degrees`, with `width` degree digits.
fn angle(degrees: f64, width: usize, hemispheres: [char; 2]) -> (Angle, char) {
    let hemisphere = if degrees < 0.0 {
        hemispheres[1]
    } else {
        hemispheres[0]
    };
    // Micro-minutes (about 2 mm), rounded once so that 59.9999996' carries into the degree.
    let total = (degrees.abs() * 60e6).round() as u64;
    (
        Angle {
            degrees: total / 60_000_000,
            micro_minutes: total % 60_000_000,
            width,
        },
        hemisphere,
    )
}

struct Angle {
    degrees: u64,
    micro_minutes: u64,
    width: usize,
}

impl std::fmt::Display for Angle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:0w$}{:02}.{:06}",
            self.degrees,
            self.micro_minutes / 1_000_000,
            self.micro_minutes % 1_000_000,
            w = self.width
        )
    }
}

/// Appends `$body*hh\r\n`, `hh` the XOR of the body's bytes.
fn sentence(out: &mut Vec<u8>, body: std::fmt::Arguments<'_>) {
    out.push(b'$');
    let start = out.len();
    // Writing into a Vec cannot fail.
    let _ = out.write_fmt(body);
    let checksum = out[start..].iter().fold(0u8, |c, b| c ^ b);
    let _ = write!(out, "*{checksum:02X}\r\n");
}
