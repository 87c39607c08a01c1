//! UBX output of real u-blox receivers (the GPSD project's regression logs in `captures/`, each
//! with gpsd's own decode of the same bytes in its `.chk`), and UBX messages laid out from the
//! u-blox receiver description where no capture carries them.

mod common;

use chrono::{NaiveDate, NaiveDateTime, Timelike};
use common::{capture, simulated_epoch as epoch};
use ipc_types::{GnssFix, GnssFixType, GnssProtocol};
use proptest::prelude::*;
use rins_gnss_protocol::decode::{GnssDecoder, GnssDecoderStats, is_plausible};
use rins_gnss_protocol::encode::{write_nav_pvt, write_nmea_epoch, write_ubx_frame};

const WEEK_MS: i64 = 604_800_000;

/// Decodes `bytes` in 64-byte reads, as a serial port hands them out.
fn decode(bytes: &[u8]) -> (Vec<GnssFix>, GnssDecoderStats) {
    let mut d = GnssDecoder::new();
    let mut fixes = Vec::new();
    for read in bytes.chunks(64) {
        d.push(read, 1, |f| fixes.push(f));
    }
    (fixes, d.stats())
}

/// [`decode`], then the end of the output: the epoch in progress is handed out.
fn decode_to_end(bytes: &[u8]) -> (Vec<GnssFix>, GnssDecoderStats) {
    let mut d = GnssDecoder::new();
    let mut fixes = Vec::new();
    for read in bytes.chunks(64) {
        d.push(read, 1, |f| fixes.push(f));
    }
    d.flush(2, |f| fixes.push(f));
    (fixes, d.stats())
}

/// One fix epoch of gpsd's decode: GPS time of week (ms), mode (2 or 3), latitude and longitude
/// (degrees), altitude above mean sea level (m), and where gpsd gives them the receiver's ECEF
/// position (m) and velocity (m/s) with gpsd's geoid height (m).
#[derive(Debug, Clone, Copy)]
struct Reference {
    tow_ms: i64,
    mode: u8,
    lat: f64,
    lon: f64,
    alt_msl: f64,
    ecef: Option<([f64; 3], [f64; 3], f64)>,
}

fn number(object: &str, key: &str) -> Option<f64> {
    let at = object.find(&format!("\"{key}\":"))? + key.len() + 3;
    let rest = &object[at..];
    let end = rest.find([',', '}']).unwrap_or(rest.len());
    rest[..end].parse().ok()
}

fn text<'a>(object: &'a str, key: &str) -> Option<&'a str> {
    let at = object.find(&format!("\"{key}\":\""))? + key.len() + 4;
    let rest = &object[at..];
    Some(&rest[..rest.find('"')?])
}

/// The GPS time of week (ms) of a UTC time, `leap` seconds behind GPS time.
fn gps_tow_ms(utc: &str, leap: i64) -> i64 {
    let t = NaiveDateTime::parse_from_str(utc, "%Y-%m-%dT%H:%M:%S%.fZ").expect("time");
    let gps = t + chrono::Duration::seconds(leap);
    let epoch = NaiveDate::from_ymd_opt(1980, 1, 6).expect("date");
    let day = (gps.date() - epoch).num_days().rem_euclid(7);
    day * 86_400_000
        + i64::from(gps.num_seconds_from_midnight()) * 1_000
        + i64::from(gps.nanosecond() / 1_000_000)
}

/// gpsd's fix epochs of a capture: the first TPV report of each time with mode 2 or 3 and a
/// position.
fn reference(name: &str) -> Vec<Reference> {
    let chk = String::from_utf8(capture(&format!("{name}.chk"))).expect("utf-8");
    let tpvs: Vec<&str> = chk
        .split("{\"class\":\"TPV\"")
        .skip(1)
        .map(|s| &s[..s.find('}').unwrap_or(s.len())])
        .collect();
    let leap = tpvs
        .iter()
        .filter_map(|o| number(o, "leapseconds"))
        .fold(0.0, f64::max) as i64;
    let mut out: Vec<Reference> = Vec::new();
    for o in tpvs {
        let (Some(time), Some(mode), Some(lat), Some(lon)) = (
            text(o, "time"),
            number(o, "mode"),
            number(o, "lat"),
            number(o, "lon"),
        ) else {
            continue;
        };
        let tow_ms = gps_tow_ms(time, leap);
        if mode < 2.0 || out.iter().any(|r| r.tow_ms == tow_ms) {
            continue;
        }
        let key = |k: &str| number(o, k);
        let ecef = match [
            "ecefx", "ecefy", "ecefz", "ecefvx", "ecefvy", "ecefvz", "geoidSep",
        ]
        .map(key)
        {
            [
                Some(x),
                Some(y),
                Some(z),
                Some(vx),
                Some(vy),
                Some(vz),
                Some(n),
            ] => Some(([x, y, z], [vx, vy, vz], n)),
            _ => None,
        };
        out.push(Reference {
            tow_ms,
            mode: mode as u8,
            lat,
            lon,
            alt_msl: number(o, "altMSL").unwrap_or(f64::NAN),
            ecef,
        });
    }
    out
}

fn fix_type(f: &GnssFix) -> GnssFixType {
    GnssFixType::from_u8(f.fix_type).expect("fix type")
}

fn positioned(fixes: &[GnssFix]) -> Vec<GnssFix> {
    fixes
        .iter()
        .filter(|f| !matches!(fix_type(f), GnssFixType::NoFix))
        .copied()
        .collect()
}

/// The ECEF point (m) of a WGS84 latitude and longitude (radians) and ellipsoidal height (m).
fn ecef_from_geodetic(lat: f64, lon: f64, h: f64) -> [f64; 3] {
    let (a, f) = (6_378_137.0, 1.0 / 298.257_223_563);
    let e2 = f * (2.0 - f);
    let n = a / (1.0 - e2 * lat.sin().powi(2)).sqrt();
    [
        (n + h) * lat.cos() * lon.cos(),
        (n + h) * lat.cos() * lon.sin(),
        (n * (1.0 - e2) + h) * lat.sin(),
    ]
}

/// The NED velocity `v` at `lat`, `lon` (radians) in ECEF axes.
fn ecef_from_ned(v: [f64; 3], lat: f64, lon: f64) -> [f64; 3] {
    let (sl, cl) = lat.sin_cos();
    let (so, co) = lon.sin_cos();
    let [n, e, d] = v;
    [
        -sl * co * n - so * e - cl * co * d,
        -sl * so * n + co * e - cl * so * d,
        cl * n - sl * d,
    ]
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Horizontal distance, m, between two nearby places (degrees).
fn horizontal_m(lat1: f64, lon1: f64, lat2: f64, lon2: f64) -> f64 {
    let r = 6_371_000.0;
    let dn = (lat2 - lat1).to_radians() * r;
    let de = (lon2 - lon1).to_radians() * r * lat1.to_radians().cos();
    dn.hypot(de)
}

/// Every fix epoch gpsd reports is published once, at gpsd's time and place. With `by_ecef`,
/// for receivers whose solution is NAV-SOL alone (ECEF in cm and cm/s), the fix is 2-D without a
/// height (mean sea level needs a geoid model), and, taken back to ECEF at the receiver's own
/// height, is within 1 cm and 1 cm/s of it: gpsd's latitude and longitude for these
/// receivers repeat the first epoch's. Otherwise (NAV-PVT)
/// the fix is within 1 cm horizontally (gpsd prints 1e-9°, 0.1 mm) and 2 cm vertically of
/// gpsd's latitude, longitude and altitude; so is a NAV-SOL receiver's first fix where gpsd
/// gives no ECEF.
fn assert_matches_gpsd(
    name: &str,
    expect_epochs: usize,
    by_ecef: bool,
) -> (Vec<GnssFix>, GnssDecoderStats) {
    let refs = reference(name);
    assert_eq!(refs.len(), expect_epochs, "{name}: gpsd's epochs");
    let (fixes, stats) = decode_to_end(&capture(name));
    let got = positioned(&fixes);
    assert_eq!(got.len(), refs.len(), "{name}: {stats:?}");
    for (k, (f, r)) in got.iter().zip(&refs).enumerate() {
        assert_eq!(f.protocol, GnssProtocol::Ubx as u8);
        // gpsd's first reports may use a leap-second count it has not yet had from the
        // receiver: the times agree within a millisecond, give or take whole seconds.
        let tow_ms = (f.receiver_time_us / 1_000) as i64;
        let apart = (tow_ms - r.tow_ms).rem_euclid(WEEK_MS);
        let apart = apart.min(WEEK_MS - apart);
        assert!(
            apart <= 5_000 && (apart % 1_000 <= 1 || apart % 1_000 >= 999),
            "{name}: receiver time {tow_ms} ms vs gpsd {} ms",
            r.tow_ms
        );
        let expected_type = match (r.mode, by_ecef) {
            (2, _) | (_, true) => matches!(fix_type(f), GnssFixType::Fix2d),
            _ => fix_type(f).is_3d(),
        };
        assert!(expected_type, "{name}: {f:?} vs mode {}", r.mode);
        let (lat, lon) = (f.latitude_rad, f.longitude_rad);
        if let Some((position, velocity, _)) = r.ecef.filter(|_| by_ecef) {
            // The fix has no height: put it at the receiver's own, along the ellipsoid normal.
            let base = ecef_from_geodetic(lat, lon, 0.0);
            let up = [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()];
            let h: f64 = (0..3).map(|i| (position[i] - base[i]) * up[i]).sum();
            let ours = ecef_from_geodetic(lat, lon, h);
            let d = distance(ours, position);
            assert!(
                d < 0.01,
                "{name} at {tow_ms}: {d} m from the receiver's ECEF"
            );
            assert_eq!(f.velocity_valid, 1);
            let ours = ecef_from_ned(f.velocity_ned_mps, lat, lon);
            let d = distance(ours, velocity);
            assert!(d < 0.01, "{name} at {tow_ms}: {d} m/s from the receiver's");
        } else {
            // Without gpsd's ECEF, a NAV-SOL receiver's fixes after the first can only be held
            // to their own accuracy (3σ) around the position gpsd repeats.
            let tolerance = match by_ecef && k > 0 {
                true => 3.0 * f.horizontal_accuracy_m,
                false => 0.01,
            };
            let d = horizontal_m(lat.to_degrees(), lon.to_degrees(), r.lat, r.lon);
            assert!(d < tolerance, "{name} at {tow_ms}: {d} m from gpsd");
            assert!(
                by_ecef || (f.altitude_m - r.alt_msl).abs() < tolerance.max(0.02),
                "{name} at {tow_ms}: altitude {} vs {}",
                f.altitude_m,
                r.alt_msl
            );
        }
        assert_eq!(f.accuracy_reported, 1);
        assert!(is_plausible(f));
    }
    (fixes, stats)
}

#[test]
fn nav_sol_receivers_publish_every_epoch_gpsd_reports() {
    // Timing and older receivers report their solution as NAV-SOL (ECEF), with NAV-DOP,
    // NAV-TIMEGPS and others, and no NAV-PVT. The AEK-4T's capture ends within its last epoch,
    // which the end of the output hands out.
    for (name, epochs) in [
        ("ublox-lea-4t.log", 2),
        ("ublox-aek-4t.log", 4),
        ("ublox-neo-m8t.log", 39),
        ("ublox-8-time.log", 89),
    ] {
        let (fixes, stats) = assert_matches_gpsd(name, epochs, true);
        assert_eq!(fixes.len(), epochs, "{name}: {stats:?}");
        assert_eq!(stats.malformed, 0, "{name}: {stats:?}");
    }
}

#[test]
fn nav_pvt_receivers_keep_publishing_every_epoch() {
    for (name, epochs) in [("ublox-neo-m8n.log", 24), ("ublox-zed-f9p-hp.log", 29)] {
        let (fixes, stats) = assert_matches_gpsd(name, epochs, false);
        assert_eq!(fixes.len(), epochs, "{name}: {stats:?}");
    }
}

#[test]
fn an_ecef_fix_carries_the_receivers_accuracy_and_no_height() {
    // NAV-SOL's pAcc is a 3-D estimate: it bounds the horizontal σ. Its height is above the
    // ellipsoid, and mean sea level is not known without a geoid model: 2-D, no height.
    let (fixes, _) = decode(&capture("ublox-lea-4t.log"));
    let f = &fixes[0];
    assert_eq!(f.receiver_time_us, 333_358_001_000);
    assert_eq!(f.satellites, 8);
    assert!((f.horizontal_accuracy_m - 5.52).abs() < 1e-9, "{f:?}");
    assert_eq!(fix_type(f), GnssFixType::Fix2d);
    assert!(
        f.altitude_m.is_nan() && f.vertical_accuracy_m.is_nan(),
        "{f:?}"
    );
    assert!((f.speed_accuracy_mps - 0.18).abs() < 1e-9);
    // NAV-DOP's horizontal DOP.
    assert!(f.hdop > 0.0 && f.hdop < 99.0, "{f:?}");
}

/// Byte offsets at which each NAV-SOL frame starts (`B5 62 01 06`, 52-byte payload).
fn nav_sol_offsets(bytes: &[u8]) -> Vec<usize> {
    bytes
        .windows(6)
        .enumerate()
        .filter(|(_, w)| *w == [0xB5, 0x62, 0x01, 0x06, 52, 0])
        .map(|(i, _)| i)
        .collect()
}

#[test]
fn an_epoch_is_published_once_all_its_messages_are_in_not_with_the_next_one() {
    // The first epoch shows what the receiver sends; from the second on, each fix comes out with
    // the last message of its epoch, before the next epoch's NAV-SOL.
    for name in ["ublox-neo-m8t.log", "ublox-8-time.log"] {
        let bytes = capture(name);
        let starts = nav_sol_offsets(&bytes);
        let mut d = GnssDecoder::new();
        let mut out_at = Vec::new();
        for (i, b) in bytes.iter().enumerate() {
            d.push(std::slice::from_ref(b), 1, |_| out_at.push(i));
        }
        assert_eq!(out_at.len(), starts.len(), "{name}: {:?}", d.stats());
        for (k, &at) in out_at.iter().enumerate().skip(1) {
            if let Some(&next) = starts.get(k + 1) {
                assert!(
                    at < next,
                    "{name}: epoch {k} out at byte {at}, next epoch at {next}"
                );
            }
        }
    }
}

#[test]
fn time_only_solutions_are_not_positions() {
    // Timing receivers in time mode (gpsFix 5) report the surveyed-in position they hold, not a
    // measurement; gpsd shows it as a 3-D fix, rins publishes each epoch without a fix.
    for (name, epochs) in [("ublox-neo-m8t-s.log", 29), ("ublox-zed-f9t-rtcm3.log", 26)] {
        let (fixes, stats) = decode(&capture(name));
        assert_eq!(fixes.len(), epochs, "{name}: {stats:?}");
        assert!(positioned(&fixes).is_empty(), "{name}");
        assert_eq!(stats.epochs_without_fix, epochs as u64);
    }
}

/// A UBX frame around `payload`, with its checksum.
fn frame(class: u8, id: u8, payload: &[u8]) -> Vec<u8> {
    let mut f = Vec::new();
    write_ubx_frame(class, id, payload, &mut f);
    f
}

/// The payload of the first UBX frame of `class`/`id` in `bytes`.
fn first_payload(bytes: &[u8], class: u8, id: u8) -> Vec<u8> {
    let at = bytes
        .windows(4)
        .position(|w| w == [0xB5, 0x62, class, id])
        .expect("frame");
    let len = usize::from(u16::from_le_bytes([bytes[at + 4], bytes[at + 5]]));
    bytes[at + 6..at + 6 + len].to_vec()
}

#[test]
fn nav_pvt_outside_the_receivers_masks_is_published_as_what_it_is() {
    // NEO-M8N's first NAV-PVT: 3-D, gnssFixOK and diffSoln, hAcc 1.132 m, vAcc 1.602 m.
    let pvt = first_payload(&capture("ublox-neo-m8n.log"), 0x01, 0x07);
    let with = |fix_type: u8, flags: u8| {
        let mut p = pvt.clone();
        p[20] = fix_type;
        p[21] = flags;
        let (fixes, stats) = decode(&frame(0x01, 0x07, &p));
        assert_eq!(fixes.len(), 1, "{stats:?}");
        fixes[0]
    };
    let f = with(3, 0x03);
    assert_eq!(fix_type(&f), GnssFixType::Differential);
    // Without gnssFixOK: a 3-D fix with the receiver's own accuracy, never differential.
    let f = with(3, 0x02);
    assert_eq!(fix_type(&f), GnssFixType::Fix3d);
    assert_eq!(f.accuracy_reported, 1);
    assert!((f.horizontal_accuracy_m - 1.132).abs() < 1e-9);
    assert!((f.vertical_accuracy_m - 1.602).abs() < 1e-9);
    assert!((f.latitude_rad.to_degrees() - -34.9062263).abs() < 1e-9);
    assert_eq!(fix_type(&with(2, 0x00)), GnssFixType::Fix2d);
    assert_eq!(fix_type(&with(4, 0x00)), GnssFixType::Fix3d);
    assert_eq!(fix_type(&with(1, 0x01)), GnssFixType::DeadReckoning);
    assert_eq!(fix_type(&with(5, 0x01)), GnssFixType::NoFix);
    assert_eq!(fix_type(&with(0, 0x01)), GnssFixType::NoFix);
}

fn put(p: &mut [u8], at: usize, bytes: &[u8]) {
    p[at..at + bytes.len()].copy_from_slice(bytes);
}

/// NAV-SOL (52 bytes) with the LEA-4T's first solution (ECEF cm), at `itow`.
fn nav_sol(itow: u32, gps_fix: u8, flags: u8) -> Vec<u8> {
    let mut p = [0u8; 52];
    put(&mut p, 0, &itow.to_le_bytes());
    p[10] = gps_fix;
    p[11] = flags;
    put(&mut p, 12, &(-151_029_952i32).to_le_bytes());
    put(&mut p, 16, &(-348_349_794i32).to_le_bytes());
    put(&mut p, 20, &510_853_323i32.to_le_bytes());
    put(&mut p, 24, &552u32.to_le_bytes()); // pAcc cm
    put(&mut p, 28, &100i32.to_le_bytes()); // ecefVX cm/s
    put(&mut p, 40, &18u32.to_le_bytes()); // sAcc cm/s
    put(&mut p, 44, &250u16.to_le_bytes()); // pDOP
    p[47] = 8;
    frame(0x01, 0x06, &p)
}

/// NAV-POSLLH (28 bytes): longitude, latitude (1e-7°), heights and accuracies (mm).
fn nav_posllh(itow: u32) -> Vec<u8> {
    let mut p = [0u8; 28];
    put(&mut p, 0, &itow.to_le_bytes());
    put(&mut p, 4, &(-1_134_395_450i32).to_le_bytes());
    put(&mut p, 8, &535_632_560i32.to_le_bytes());
    put(&mut p, 12, &635_459i32.to_le_bytes());
    put(&mut p, 16, &654_400i32.to_le_bytes());
    put(&mut p, 20, &2_100u32.to_le_bytes());
    put(&mut p, 24, &3_400u32.to_le_bytes());
    frame(0x01, 0x02, &p)
}

/// NAV-VELNED (36 bytes): velocity (cm/s), speed accuracy (cm/s).
fn nav_velned(itow: u32) -> Vec<u8> {
    let mut p = [0u8; 36];
    put(&mut p, 0, &itow.to_le_bytes());
    put(&mut p, 4, &150i32.to_le_bytes());
    put(&mut p, 8, &(-250i32).to_le_bytes());
    put(&mut p, 12, &35i32.to_le_bytes());
    put(&mut p, 28, &12u32.to_le_bytes());
    frame(0x01, 0x12, &p)
}

/// NAV-DOP (18 bytes) with an HDOP of 1.25.
fn nav_dop(itow: u32) -> Vec<u8> {
    let mut p = [0u8; 18];
    put(&mut p, 0, &itow.to_le_bytes());
    put(&mut p, 12, &125u16.to_le_bytes());
    frame(0x01, 0x04, &p)
}

fn nav_eoe(itow: u32) -> Vec<u8> {
    frame(0x01, 0x61, &itow.to_le_bytes())
}

#[test]
fn nav_sol_with_posllh_velned_and_dop_make_one_fix_per_itow() {
    let mut stream = Vec::new();
    let mut ends = Vec::new();
    for k in 0..3u32 {
        let itow = 100_000 + 250 * k;
        stream.extend(nav_sol(itow, 3, 0x0D));
        stream.extend(nav_posllh(itow));
        stream.extend(nav_velned(itow));
        stream.extend(nav_dop(itow));
        ends.push(stream.len());
    }
    let mut d = GnssDecoder::new();
    let mut fixes = Vec::new();
    let mut fed = 0;
    let mut out_at = Vec::new();
    for read in stream.chunks(20) {
        d.push(read, 1, |f| fixes.push(f));
        fed += read.len();
        out_at.resize(fixes.len(), fed);
    }
    assert_eq!(fixes.len(), 3, "{:?}", d.stats());
    assert_eq!(d.stats().ubx_frames, 12);
    // The first epoch closes when the second's NAV-SOL (60 bytes) is in; the others come out
    // with the read that holds their last message.
    assert!(out_at[0] < ends[0] + 60 + 20, "{out_at:?} {ends:?}");
    assert!(
        out_at[1] < ends[1] + 20 && out_at[2] == ends[2],
        "{out_at:?} {ends:?}"
    );
    for (k, f) in fixes.iter().enumerate() {
        assert_eq!(f.receiver_time_us, (100_000 + 250 * k as u64) * 1_000);
        assert_eq!(fix_type(f), GnssFixType::Fix3d);
        assert_eq!(f.satellites, 8);
        // Position and accuracies from NAV-POSLLH.
        assert!((f.latitude_rad.to_degrees() - 53.563256).abs() < 1e-9);
        assert!((f.longitude_rad.to_degrees() - -113.439545).abs() < 1e-9);
        assert!((f.altitude_m - 654.4).abs() < 1e-9);
        assert!((f.horizontal_accuracy_m - 2.1).abs() < 1e-9);
        assert!((f.vertical_accuracy_m - 3.4).abs() < 1e-9);
        // Velocity from NAV-VELNED.
        assert_eq!(f.velocity_valid, 1);
        for (got, want) in f.velocity_ned_mps.iter().zip([1.5, -2.5, 0.35]) {
            assert!((got - want).abs() < 1e-9, "{f:?}");
        }
        assert!((f.speed_accuracy_mps - 0.12).abs() < 1e-9);
        assert!((f.hdop - 1.25).abs() < 1e-6);
    }
}

#[test]
fn nav_sol_alone_reads_its_ecef_velocity_as_ned() {
    // 1 m/s along ECEF x at 53.56° N 113.44° W.
    let mut stream = nav_sol(5_000, 3, 0x0D);
    stream.extend(nav_eoe(5_000));
    let (fixes, stats) = decode(&stream);
    assert_eq!(fixes.len(), 1, "{stats:?}");
    let (lat, lon) = (
        53.563256267f64.to_radians(),
        (-113.439544853f64).to_radians(),
    );
    let want = [-lat.sin() * lon.cos(), -lon.sin(), -lat.cos() * lon.cos()];
    for (got, want) in fixes[0].velocity_ned_mps.iter().zip(want) {
        assert!((got - want).abs() < 1e-9, "{:?}", fixes[0]);
    }
}

#[test]
fn nav_eoe_ends_the_epoch_at_once() {
    // The receiver's end-of-epoch message publishes even the first epoch without waiting.
    let mut stream = nav_sol(7_000, 3, 0x0D);
    stream.extend(nav_dop(7_000));
    let (fixes, _) = decode(&stream);
    assert!(fixes.is_empty());
    stream.extend(nav_eoe(7_000));
    let (fixes, stats) = decode(&stream);
    assert_eq!(fixes.len(), 1, "{stats:?}");
    assert_eq!(stats.ubx_frames, 3);
}

#[test]
fn nav_sol_without_gnss_fix_ok_is_a_fix_with_its_own_accuracy() {
    let mut stream = nav_sol(9_000, 3, 0x0C);
    stream.extend(nav_eoe(9_000));
    stream.extend(nav_sol(10_000, 3, 0x0E)); // diffSoln but not gnssFixOK
    stream.extend(nav_eoe(10_000));
    stream.extend(nav_sol(11_000, 5, 0x0F)); // time only
    stream.extend(nav_eoe(11_000));
    let (fixes, stats) = decode(&stream);
    assert_eq!(fixes.len(), 3, "{stats:?}");
    // 3-D solutions, published 2-D without a height (NAV-SOL alone, see above).
    assert_eq!(fix_type(&fixes[0]), GnssFixType::Fix2d);
    assert_eq!(fix_type(&fixes[1]), GnssFixType::Fix2d);
    assert_eq!(fix_type(&fixes[2]), GnssFixType::NoFix);
    assert!((fixes[1].horizontal_accuracy_m - 5.52).abs() < 1e-9);
}

/// HNR-PVT (72 bytes): 3-D, gnssFixOK, ground speed 10 m/s at 30° true.
fn hnr_pvt(itow: u32) -> Vec<u8> {
    let mut p = [0u8; 72];
    put(&mut p, 0, &itow.to_le_bytes());
    p[16] = 4; // GNSS + dead reckoning
    p[17] = 0x01;
    put(&mut p, 20, &115_166_667i32.to_le_bytes());
    put(&mut p, 24, &481_173_000i32.to_le_bytes());
    put(&mut p, 28, &592_300i32.to_le_bytes());
    put(&mut p, 32, &545_400i32.to_le_bytes());
    put(&mut p, 36, &10_000i32.to_le_bytes()); // gSpeed mm/s
    put(&mut p, 40, &10_050i32.to_le_bytes()); // speed mm/s
    put(&mut p, 44, &3_000_000i32.to_le_bytes()); // headMot 1e-5°
    put(&mut p, 52, &1_500u32.to_le_bytes());
    put(&mut p, 56, &2_500u32.to_le_bytes());
    put(&mut p, 60, &300u32.to_le_bytes());
    frame(0x28, 0x00, &p)
}

#[test]
fn hnr_pvt_is_read_like_nav_pvt() {
    let mut stream = hnr_pvt(20_000);
    stream.extend(hnr_pvt(20_100));
    let (fixes, stats) = decode(&stream);
    assert_eq!(fixes.len(), 2, "{stats:?}");
    let f = &fixes[0];
    assert_eq!(f.protocol, GnssProtocol::Ubx as u8);
    assert_eq!(fix_type(f), GnssFixType::Fix3d);
    assert_eq!(f.receiver_time_us, 20_000_000);
    assert!((f.latitude_rad.to_degrees() - 48.1173).abs() < 1e-9);
    assert!((f.longitude_rad.to_degrees() - 11.5166667).abs() < 1e-9);
    assert!((f.altitude_m - 545.4).abs() < 1e-9);
    assert!((f.horizontal_accuracy_m - 1.5).abs() < 1e-9);
    assert!((f.vertical_accuracy_m - 2.5).abs() < 1e-9);
    assert!((f.speed_accuracy_mps - 0.3).abs() < 1e-9);
    // The ground velocity is there, but without a vertical one it is not offered as measured.
    let c = 30f64.to_radians();
    assert_eq!(f.velocity_valid, 0);
    assert!((f.velocity_ned_mps[0] - 10.0 * c.cos()).abs() < 1e-9);
    assert!((f.velocity_ned_mps[1] - 10.0 * c.sin()).abs() < 1e-9);
}

#[test]
fn a_frame_of_an_epoch_already_past_is_late_not_a_second_fix() {
    // HNR-PVT at 10 Hz runs ahead of NAV-PVT: a NAV-PVT for 20.0 s arriving after the HNR-PVT
    // for 20.1 s is not published again, out of order.
    let mut stream = hnr_pvt(20_000);
    stream.extend(hnr_pvt(20_100));
    let mut pvt = first_payload(&capture("ublox-neo-m8n.log"), 0x01, 0x07);
    pvt[..4].copy_from_slice(&20_000u32.to_le_bytes());
    stream.extend(frame(0x01, 0x07, &pvt));
    stream.extend(hnr_pvt(20_200));
    let (fixes, stats) = decode(&stream);
    let times: Vec<u64> = fixes.iter().map(|f| f.receiver_time_us / 1_000).collect();
    assert_eq!(times, [20_000, 20_100, 20_200], "{stats:?}");
    assert_eq!(stats.ubx_late, 1);
}

#[test]
fn a_time_of_week_going_back_far_or_wrapping_starts_a_new_epoch() {
    // The week rolls over; a receiver restarting reports an earlier time: both are new epochs.
    let mut stream = hnr_pvt(604_799_900);
    stream.extend(hnr_pvt(0));
    stream.extend(hnr_pvt(100));
    stream.extend(hnr_pvt(50));
    stream.extend(hnr_pvt(5_000));
    stream.extend(hnr_pvt(2_000));
    let (fixes, stats) = decode(&stream);
    let times: Vec<u64> = fixes.iter().map(|f| f.receiver_time_us / 1_000).collect();
    assert_eq!(times, [604_799_900, 0, 100, 5_000, 2_000], "{stats:?}");
    assert_eq!(stats.ubx_late, 1);
}

#[test]
fn a_receiver_sending_ubx_and_nmea_has_one_fix_per_epoch() {
    const N: u64 = 10;
    for nmea_first in [true, false] {
        let mut stream = Vec::new();
        for i in 0..N {
            let (mut nmea, mut ubx) = (Vec::new(), Vec::new());
            write_nmea_epoch(&epoch(i), &mut nmea);
            write_nav_pvt(&epoch(i), &mut ubx);
            if nmea_first {
                stream.extend(nmea);
                stream.extend(ubx);
            } else {
                stream.extend(ubx);
                stream.extend(nmea);
            }
        }
        let (fixes, stats) = decode(&stream);
        let ubx = fixes
            .iter()
            .filter(|f| f.protocol == GnssProtocol::Ubx as u8);
        assert_eq!(ubx.count() as u64, N, "{stats:?}");
        // Only an NMEA epoch complete before the receiver's first UBX frame comes out too.
        assert!(
            fixes.len() as u64 <= N + 1,
            "nmea first {nmea_first}: {stats:?}"
        );
        let nmea = fixes.len() as u64 - N;
        // The NMEA epochs not published are counted; their sentences are used.
        assert!(stats.nmea_epochs_superseded + nmea >= N - 1, "{stats:?}");
        assert!(stats.sentences >= 2 * N, "{stats:?}");
    }
}

#[test]
fn nmea_is_published_again_when_ubx_stops() {
    let mut stream = Vec::new();
    for i in 0..5 {
        write_nav_pvt(&epoch(i), &mut stream);
        write_nmea_epoch(&epoch(i), &mut stream);
    }
    for i in 5..10 {
        write_nmea_epoch(&epoch(i), &mut stream);
    }
    let (fixes, stats) = decode(&stream);
    let nmea: Vec<u64> = fixes
        .iter()
        .filter(|f| f.protocol == GnssProtocol::Nmea as u8)
        .map(|f| (f.receiver_time_us - 45_296_000_000) / 200_000)
        .collect();
    // None while UBX comes; two epochs after the last UBX one are set aside, then NMEA is
    // published again.
    assert!(nmea.iter().all(|&i| i >= 6), "{nmea:?} {stats:?}");
    assert!(nmea.len() >= 3 && nmea.contains(&7), "{nmea:?} {stats:?}");
}

proptest! {
    #[test]
    fn corrupted_receiver_output_never_yields_an_implausible_fix(
        flips in prop::collection::vec((0usize..40_000, any::<u8>()), 0..60),
    ) {
        let mut bytes = capture("ublox-neo-m8t.log");
        bytes.extend(capture("ublox-8-time.log"));
        let n = bytes.len();
        for (at, x) in flips {
            bytes[at % n] ^= x;
        }
        let (fixes, _) = decode(&bytes);
        for f in fixes {
            prop_assert!(is_plausible(&f), "{f:?}");
        }
    }

    #[test]
    fn any_payload_of_the_messages_read_is_survived(
        kind in 0usize..7,
        payload in prop::collection::vec(any::<u8>(), 92),
        itow in any::<u32>(),
    ) {
        let (class, id, len) = [
            (0x01, 0x07, 92),
            (0x01, 0x06, 52),
            (0x01, 0x02, 28),
            (0x01, 0x12, 36),
            (0x01, 0x04, 18),
            (0x01, 0x61, 4),
            (0x28, 0x00, 72),
        ][kind];
        let mut p = payload[..len].to_vec();
        p[..4].copy_from_slice(&itow.to_le_bytes());
        let mut stream = frame(class, id, &p);
        stream.extend(nav_eoe(itow));
        let (fixes, stats) = decode(&stream);
        for f in fixes {
            prop_assert!(is_plausible(&f), "{f:?}");
        }
        prop_assert_eq!(stats.unparsable, 0);
    }
}
