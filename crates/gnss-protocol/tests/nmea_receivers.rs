//! NMEA epoch assembly on what real receivers send: the GPSD project's regression logs in
//! `tests/captures` (see its SOURCES.md), each checked against gpsd's own decode of the same
//! bytes (the `.chk` file) where gpsd reports the epoch, and against the sentences themselves.

mod common;

use std::path::PathBuf;

use common::capture;
use ipc_types::{GnssFix, GnssFixType};
use rins_gnss_protocol::decode::{GnssDecoder, GnssDecoderStats};

/// The lines of a capture that are sentences, as text.
fn sentences(name: &str) -> Vec<String> {
    String::from_utf8_lossy(&capture(name))
        .lines()
        .filter(|l| l.starts_with('$'))
        .map(|l| l.trim_end().to_string())
        .collect()
}

/// Nanoseconds per byte at 9600 baud (10 bits a byte).
const NS_PER_BYTE: u64 = 1_041_667;

/// Every fix of `bytes` read 64 bytes at a time at the line rate, with a flush at the end when
/// `flush`, and the decoder's counters.
fn decode(bytes: &[u8], flush: bool) -> (Vec<GnssFix>, GnssDecoderStats) {
    let mut d = GnssDecoder::new();
    let mut fixes = Vec::new();
    let mut rx_ns = 0;
    for read in bytes.chunks(64) {
        rx_ns += read.len() as u64 * NS_PER_BYTE;
        d.push(read, rx_ns, |f| fixes.push(f));
    }
    if flush {
        d.flush(rx_ns, |f| fixes.push(f));
    }
    (fixes, d.stats())
}

/// An epoch gpsd reports with a position: time of day (ms), mode, latitude and longitude (°).
#[derive(Debug, Clone, Copy)]
struct Reference {
    ms_of_day: u64,
    mode: u8,
    lat_deg: f64,
    lon_deg: f64,
}

/// gpsd's epochs of a capture: the first TPV of each time with mode 2 or 3 and a position.
fn reference(name: &str) -> Vec<Reference> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/captures")
        .join(format!("{name}.chk"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut out: Vec<Reference> = Vec::new();
    for line in text.lines().filter(|l| l.contains("\"class\":\"TPV\"")) {
        let number = |key: &str| {
            let at = line.find(&format!("\"{key}\":"))? + key.len() + 3;
            let end = line[at..].find([',', '}']).map_or(line.len(), |n| at + n);
            line[at..end].parse::<f64>().ok()
        };
        let time = line
            .find("\"time\":\"")
            .map(|at| &line[at + 8..])
            .and_then(|t| t.split_once('T'))
            .and_then(|(_, t)| t.split_once('Z'))
            .map(|(t, _)| t);
        let (Some(time), Some(mode), Some(lat_deg), Some(lon_deg)) =
            (time, number("mode"), number("lat"), number("lon"))
        else {
            continue;
        };
        let hms: Vec<f64> = time.split(':').filter_map(|x| x.parse().ok()).collect();
        let ms_of_day = ((hms[0] * 3600.0 + hms[1] * 60.0 + hms[2]) * 1000.0).round() as u64;
        if mode >= 2.0 && !out.iter().any(|r| r.ms_of_day == ms_of_day) {
            out.push(Reference {
                ms_of_day,
                mode: mode as u8,
                lat_deg,
                lon_deg,
            });
        }
    }
    out
}

fn ms_of_day(fix: &GnssFix) -> u64 {
    (fix.receiver_time_us + 500) / 1000 % 86_400_000
}

fn has_position(fix: &GnssFix) -> bool {
    GnssFixType::from_u8(fix.fix_type)
        .is_some_and(|t| !matches!(t, GnssFixType::NoFix | GnssFixType::DeadReckoning))
}

/// Horizontal distance between a fix and a reference epoch, m (small-angle, spherical Earth).
fn horizontal_m(fix: &GnssFix, r: &Reference) -> f64 {
    let m_per_rad = 6_371_000.0;
    let north = (fix.latitude_rad - r.lat_deg.to_radians()) * m_per_rad;
    let east = (fix.longitude_rad - r.lon_deg.to_radians()) * m_per_rad * fix.latitude_rad.cos();
    north.hypot(east)
}

/// For each reference epoch, the published fix of its time with a position, if any.
fn matched<'a>(reference: &[Reference], fixes: &'a [GnssFix]) -> Vec<Option<&'a GnssFix>> {
    reference
        .iter()
        .map(|r| {
            fixes
                .iter()
                .find(|f| has_position(f) && ms_of_day(f) == r.ms_of_day)
        })
        .collect()
}

/// Every reference epoch of `name` published, within `tolerance_m` of gpsd's position.
fn assert_all_matched(name: &str, fixes: &[GnssFix], tolerance_m: f64) {
    let reference = reference(name);
    assert!(!reference.is_empty(), "{name}: no reference");
    for (r, fix) in reference.iter().zip(matched(&reference, fixes)) {
        let fix = fix.unwrap_or_else(|| panic!("{name}: {r:?} not published"));
        let d = horizontal_m(fix, r);
        assert!(d <= tolerance_m, "{name}: {d} m from {r:?}: {fix:?}");
    }
}

/// `$body*hh\r\n`.
fn with_checksum(body: &str) -> String {
    let checksum = body.bytes().fold(0u8, |c, b| c ^ b);
    format!("${body}*{checksum:02X}\r\n")
}

#[test]
fn a_receiver_sending_only_rmc_gives_two_dimensional_fixes() {
    // Digital Yacht AIT250: RMC and GBS, no GGA.
    let (fixes, stats) = decode(&capture("ait250.log"), true);
    assert_all_matched("ait250.log", &fixes, 1e-3);
    let rmc = sentences("ait250.log")
        .iter()
        .filter(|s| s.starts_with("$GPRMC") && s.split(',').nth(2) == Some("A"))
        .count();
    assert_eq!(fixes.iter().filter(|f| has_position(f)).count(), rmc);
    for f in fixes.iter().filter(|f| has_position(f)) {
        assert_eq!(f.fix_type, GnssFixType::Fix2d as u8, "{f:?}");
        assert!(f.altitude_m.is_nan() && f.vertical_accuracy_m.is_nan());
        // No HDOP: the accuracy of a poor geometry, 10 × 3 m.
        assert_eq!((f.accuracy_reported, f.horizontal_accuracy_m), (0, 30.0));
    }
    assert_eq!((stats.malformed, stats.unparsable), (0, 0), "{stats:?}");
    assert_eq!(stats.nmea.gbs, 33, "{stats:?}");

    // Telit HE910 after the 2019 week rollover: a garbled date, which the fix does not use.
    let (fixes, _) = decode(&capture("april6_2019.log"), true);
    assert_all_matched("april6_2019.log", &fixes, 1e-3);
    assert_eq!(fixes.iter().filter(|f| has_position(f)).count(), 2);
}

#[test]
fn gns_sentences_give_the_fix_with_their_best_mode() {
    // A BeiDou receiver: GNGGA, GNGNS (mode ANNA: GPS and BeiDou autonomous) and GNRMC.
    let with_gga = capture("beidou-bd.log");
    let (fixes, stats) = decode(&with_gga, true);
    assert_all_matched("beidou-bd.log", &fixes, 1e-3);
    assert_eq!(stats.malformed, 0, "{stats:?}");
    // The same without its GGA: the GNS alone gives the three-dimensional fixes.
    let without_gga: Vec<u8> = String::from_utf8_lossy(&with_gga)
        .lines()
        .filter(|l| !l.contains("GGA,"))
        .flat_map(|l| format!("{l}\n").into_bytes())
        .collect();
    let (gns_only, _) = decode(&without_gga, true);
    assert_all_matched("beidou-bd.log", &gns_only, 1e-3);
    let reference = reference("beidou-bd.log");
    for (r, f) in reference.iter().zip(matched(&reference, &gns_only)) {
        let f = f.unwrap();
        assert_eq!((r.mode, f.fix_type), (3, GnssFixType::Fix3d as u8), "{f:?}");
        assert!(f.altitude_m.is_finite() && f.satellites == 7, "{f:?}");
    }
    // GNS of a receiver with no fix (mode NNNN) is no fix, not malformed.
    let (_, stats) = decode(&without_gga, true);
    assert_eq!((stats.malformed, stats.unparsable), (0, 0), "{stats:?}");
}

#[test]
fn a_combined_solution_is_preferred_to_one_system_and_counts_its_satellites() {
    // GPGGA (6 GPS satellites) and GNGNS (7, GPS and BeiDou) of one epoch.
    let (fixes, _) = decode(&capture("beidou-gb.log"), true);
    assert_all_matched("beidou-gb.log", &fixes, 1e-3);
    let with_fix: Vec<_> = fixes.iter().filter(|f| has_position(f)).collect();
    assert!(!with_fix.is_empty());
    assert!(with_fix.iter().all(|f| f.satellites == 7), "{with_fix:?}");
}

#[test]
fn the_talkers_of_one_epoch_make_one_fix_with_their_satellites_summed() {
    // SiRFstarV: GPGGA (GPS satellites), GLGGA (GLONASS satellites) and GNRMC each second.
    let name = "sirfstarv-nmea.log";
    let (fixes, _) = decode(&capture(name), true);
    assert_all_matched(name, &fixes, 1e-3);
    let mut expected: Vec<(u64, u32)> = Vec::new();
    for s in sentences(name)
        .iter()
        .filter(|s| s[3..].starts_with("GGA,"))
    {
        let f: Vec<&str> = s.split(',').collect();
        let t: f64 = f[1].parse().unwrap();
        let hms = (t / 10_000.0).trunc() * 3600.0 + (t / 100.0 % 100.0).trunc() * 60.0 + t % 100.0;
        let ms = (hms * 1000.0).round() as u64;
        let n: u32 = f[7].parse().unwrap();
        match expected.iter_mut().find(|(m, _)| *m == ms) {
            Some((_, sum)) => *sum += n,
            None => expected.push((ms, n)),
        }
    }
    assert_eq!(fixes.len(), expected.len());
    for (f, (ms, sum)) in fixes.iter().zip(&expected) {
        assert_eq!(
            (ms_of_day(f), u32::from(f.satellites)),
            (*ms, *sum),
            "{f:?}"
        );
    }
}

#[test]
fn a_gga_without_altitude_is_a_two_dimensional_fix() {
    // Septentrio PolaRx2 with three satellites: GGA, GLL, GNS and RMC without altitude.
    let (fixes, stats) = decode(&capture("polarx2.log"), true);
    assert_all_matched("polarx2.log", &fixes, 1e-3);
    assert!(!fixes.is_empty());
    for f in &fixes {
        assert_eq!(f.fix_type, GnssFixType::Fix2d as u8, "{f:?}");
        // Its GST's σ (hundreds of metres with three satellites); no altitude, no vertical σ.
        assert_eq!(f.accuracy_reported, 1);
        assert!(
            f.horizontal_accuracy_m > 100.0 && f.vertical_accuracy_m.is_nan(),
            "{f:?}"
        );
    }
    assert_eq!(stats.malformed, 0, "{stats:?}");
    // Saab R4: GGA with differential quality and nothing after the quality field.
    let (fixes, stats) = decode(&capture("saab-r4.log"), true);
    assert_all_matched("saab-r4.log", &fixes, 1e-3);
    assert!(fixes.iter().all(|f| f.fix_type == GnssFixType::Fix2d as u8));
    assert_eq!(stats.malformed, 0, "{stats:?}");
}

#[test]
fn gsa_mode_2_makes_a_two_dimensional_fix_with_the_receivers_altitude() {
    // Garmin GPS 25LP and Foretrex 201: GGA quality 1 or 2 with an altitude, then GSA mode 2, in
    // every epoch with a fix. gpsd reports most of those epochs 3-D from the GGA's altitude; they
    // are matched all the same.
    // The Foretrex sends 4 GSA before its first timed sentence: no epoch to place them in.
    let captures = [
        ("garmin25lp.log", 10, 746.1, 0),
        ("foretrex-201.log", 7, -9.1, 4),
    ];
    for (name, epochs, altitude, gsa_unused) in captures {
        let (fixes, stats) = decode(&capture(name), true);
        assert_all_matched(name, &fixes, 1e-3);
        let counted = (stats.malformed, stats.nmea.gsa);
        assert_eq!(counted, (0, gsa_unused), "{name}: {stats:?}");
        let positioned: Vec<_> = fixes.iter().filter(|f| has_position(f)).collect();
        assert_eq!(positioned.len(), epochs, "{name}");
        for f in positioned {
            assert_eq!(f.fix_type, GnssFixType::Fix2d as u8, "{name}: {f:?}");
            assert!(
                f.altitude_m == altitude && f.vertical_accuracy_m.is_nan(),
                "{f:?}"
            );
        }
    }
}

#[test]
fn simulation_and_dead_reckoning_are_never_a_satellite_fix() {
    // Garmin GPSmap 76S in simulator mode: GGA quality 8, RMC status V mode S. gpsd reports
    // these as 3-D fixes; they are not measurements.
    for name in ["GPSmap-76S.log", "garmin-geko201.log"] {
        let (fixes, stats) = decode(&capture(name), true);
        assert!(!fixes.is_empty(), "{name}");
        assert!(
            fixes.iter().all(|f| f.fix_type == GnssFixType::NoFix as u8),
            "{name}"
        );
        assert_eq!(stats.epochs_without_fix, stats.epochs, "{name}");
    }
    // Garmin Mobile 10: one GGA of quality 6 (dead reckoning) among satellite fixes.
    let (fixes, _) = decode(&capture("garmin-10x.log"), true);
    let dr = fixes
        .iter()
        .find(|f| ms_of_day(f) == (16 * 3600 + 50 * 60 + 10) * 1000)
        .expect("the epoch of 16:50:10");
    assert_eq!(dr.fix_type, GnssFixType::DeadReckoning as u8, "{dr:?}");
    assert_eq!(dr.velocity_valid, 0);
    // Manual input (quality 7) is not a fix either.
    let manual = with_checksum("GPGGA,123519,4807.038,N,01131.000,E,7,08,0.9,545.4,M,46.9,M,,");
    let (fixes, _) = decode(manual.as_bytes(), true);
    assert_eq!(fixes.len(), 1);
    assert_eq!(fixes[0].fix_type, GnssFixType::NoFix as u8);
}

#[test]
fn valid_sentences_not_used_are_counted_by_kind_and_are_not_malformed() {
    // SkyTraq: PSTI (proprietary), GSV of GPS and BeiDou, ZDA, with GGA, GLL, GST, RMC, VTG and
    // GSA (its fix mode is used; every one of them follows a timed sentence of its epoch).
    let name = "skytraq-dgps.log";
    let (fixes, stats) = decode(&capture(name), true);
    assert_all_matched(name, &fixes, 1e-3);
    let lines = sentences(name);
    let count = |f: &dyn Fn(&str) -> bool| lines.iter().filter(|s| f(s)).count() as u64;
    let n = stats.nmea;
    assert_eq!(n.proprietary, count(&|s| s.starts_with("$P")), "{stats:?}");
    assert_eq!(n.gsv, count(&|s| s[3..].starts_with("GSV")), "{stats:?}");
    assert_eq!(n.gsa, 0, "{stats:?}");
    assert_eq!(n.zda, count(&|s| s[3..].starts_with("ZDA")), "{stats:?}");
    assert_eq!(
        stats.unsupported,
        n.proprietary + n.gsv + n.zda,
        "{stats:?}"
    );
    let used = ["GGA", "GLL", "GST", "RMC", "VTG", "GSA"];
    let used = count(&|s| used.iter().any(|u| s[3..].starts_with(u)));
    assert_eq!(stats.sentences, used, "{stats:?}");
    assert_eq!(
        (stats.malformed, stats.unparsable, stats.checksum_errors),
        (0, 0, 0),
        "{stats:?}"
    );
    // GST gives the accuracy.
    assert!(fixes.iter().all(|f| f.accuracy_reported == 1), "{fixes:?}");
}

#[test]
fn a_doubled_dollar_is_read_as_one() {
    let bytes = capture("skytraq-dgps.log");
    let doubled: Vec<u8> = bytes
        .iter()
        .flat_map(|&b| if b == b'$' { vec![b'$', b'$'] } else { vec![b] })
        .collect();
    let (once, _) = decode(&bytes, true);
    let (twice, stats) = decode(&doubled, true);
    assert_eq!(once.len(), twice.len(), "{stats:?}");
    for (a, b) in once.iter().zip(&twice) {
        assert_eq!(
            (
                a.receiver_time_us,
                a.latitude_rad,
                a.longitude_rad,
                a.altitude_m
            ),
            (
                b.receiver_time_us,
                b.latitude_rad,
                b.longitude_rad,
                b.altitude_m
            )
        );
    }
    assert_eq!(
        (stats.malformed, stats.checksum_errors),
        (0, 0),
        "{stats:?}"
    );
}

#[test]
fn the_last_epoch_is_published_by_a_flush_or_when_the_receiver_goes_quiet() {
    // A capture of one epoch: GGA, RMC, GSA, GSV, ZDA.
    let bytes = capture("tcp-test.log");
    let (fixes, _) = decode(&bytes, false);
    assert!(fixes.is_empty(), "{fixes:?}");
    let (fixes, _) = decode(&bytes, true);
    assert_eq!(fixes.len(), 1);
    let f = &fixes[0];
    assert_eq!(f.fix_type, GnssFixType::Fix3d as u8);
    // GGA's position (5 decimals of a minute), not RMC's (4).
    assert!((f.latitude_rad.to_degrees() - (20.0 + 37.72792 / 60.0)).abs() < 1e-9);
    assert!((f.altitude_m + 30.4).abs() < 1e-9);
    // Stamped with the receive time of its last sentence, not of the flush.
    let last_sentence_end = bytes.windows(6).rposition(|w| w == b"GPRMC,").unwrap();
    assert!(f.header.origin_rx_ns < bytes.len() as u64 * NS_PER_BYTE);
    assert!(f.header.origin_rx_ns >= last_sentence_end as u64 * NS_PER_BYTE);

    // A flush twice, or after the epoch is out, hands out nothing more.
    let mut d = GnssDecoder::new();
    let mut n = 0;
    d.push(&bytes, 5, |_| n += 1);
    d.flush(6, |_| n += 1);
    d.flush(7, |_| n += 1);
    assert_eq!(n, 1);

    // Without a flush: the receiver has sent nothing for a second.
    let mut d = GnssDecoder::new();
    let mut out = Vec::new();
    d.push(&bytes, 1_000, |f| out.push(f));
    d.close_quiet(1_000 + 999_999_999, |f| out.push(f));
    assert!(out.is_empty());
    d.push(&[], 1_000 + 1_000_000_000, |f| out.push(f));
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].header.origin_rx_ns, 1_000);
}

#[test]
fn an_epoch_closed_by_the_next_carries_the_receive_time_of_its_own_last_sentence() {
    let first = with_checksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,")
        + &with_checksum("GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W");
    let next = with_checksum("GPGGA,123520,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,");
    let mut d = GnssDecoder::new();
    let mut out = Vec::new();
    d.push(first.as_bytes(), 100, |f| out.push(f));
    d.push(next.as_bytes(), 900_000_000, |f| out.push(f));
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].header.origin_rx_ns, 100);
}

#[test]
fn one_instant_printed_with_different_roundings_is_one_epoch() {
    // Magellan 315: GLL at 12:08:24.758, GGA and RMC at 12:08:24.76.
    for name in ["magellan315.log", "eXplorist210.log"] {
        let (fixes, _) = decode(&capture(name), true);
        assert_all_matched(name, &fixes, 1e-3);
        let reference = reference(name);
        assert_eq!(fixes.len(), reference.len(), "{name}: {fixes:?}");
    }
}

#[test]
fn a_sentence_without_checksum_is_not_used_and_is_counted() {
    // HP 58534A: no checksums at all. Nothing on the line can be told from noise.
    let (fixes, stats) = decode(&capture("hp58534a.log"), true);
    assert!(fixes.is_empty());
    assert!(stats.nmea.without_checksum > 0, "{stats:?}");
    assert_eq!(
        stats.checksum_errors, stats.nmea.without_checksum,
        "{stats:?}"
    );
}

#[test]
fn velocity_comes_from_vtg_when_the_receiver_sends_no_rmc() {
    // Hemisphere GNSS: GGA, VTG and HDT at 2 Hz, no RMC; each VTG follows its epoch's GGA.
    let name = "hemi.log";
    let (fixes, _) = decode(&capture(name), true);
    assert_all_matched(name, &fixes, 1e-3);
    let lines = sentences(name);
    let mut checked = 0;
    for f in fixes.iter().filter(|f| has_position(f)) {
        let (t, cs) = (ms_of_day(f) / 1000, ms_of_day(f) % 1000 / 10);
        let hhmmss = format!("{:02}{:02}{:02}.{cs:02}", t / 3600, t / 60 % 60, t % 60);
        let gga = lines
            .iter()
            .position(|l| l.starts_with(&format!("$GPGGA,{hhmmss}")))
            .unwrap();
        let vtg = lines[gga..]
            .iter()
            .find(|l| l.starts_with("$GPVTG"))
            .unwrap();
        let knots: f64 = vtg.split(',').nth(5).unwrap().parse().unwrap();
        let [n, e, _] = f.velocity_ned_mps;
        assert_eq!(f.velocity_valid, 1, "{f:?}");
        assert!(
            (n.hypot(e) - knots * 1852.0 / 3600.0).abs() < 1e-9,
            "{vtg}: {f:?}"
        );
        checked += 1;
    }
    assert!(checked >= 6);
}

proptest::proptest! {
    /// Sentences with good checksums and arbitrary fields of the kinds the decoder reads: no
    /// panic, and every one is accounted for.
    #[test]
    fn any_fields_under_a_good_checksum_are_survived(
        kinds in proptest::collection::vec(0usize..8, 1..40),
        fields in proptest::collection::vec("[0-9.,NSEWAVDMPRFT+-]{0,60}", 40),
    ) {
        let addresses = ["GPGGA", "GNGNS", "GPRMC", "GLGLL", "GPGST", "GPVTG", "BDGSV", "PGRME"];
        let mut d = GnssDecoder::new();
        let mut stream = String::new();
        for (k, f) in kinds.iter().zip(&fields) {
            stream += &with_checksum(&format!("{},{f}", addresses[*k]));
        }
        let mut n = 0u64;
        d.push(stream.as_bytes(), 1, |_| n += 1);
        d.flush(2, |_| n += 1);
        let s = d.stats();
        proptest::prop_assert_eq!(s.epochs, n);
        proptest::prop_assert_eq!(
            s.sentences + s.malformed + s.unsupported,
            kinds.len() as u64,
            "{:?}", s
        );
    }
}
