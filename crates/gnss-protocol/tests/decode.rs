//! The decoder on receiver output: published example sentences, a NAV-PVT frame laid out byte
//! by byte, the simulated receiver's own output, and hostile bytes.

mod common;

use common::{simulated_epoch as epoch, simulated_stream};
use ipc_types::{GnssFix, GnssFixType, GnssProtocol};
use proptest::prelude::*;
use rins_gnss_protocol::decode::GnssDecoder;
use rins_gnss_protocol::encode::{write_nmea_epoch, write_ubx_frame};

fn decode_all(bytes: &[u8]) -> (Vec<GnssFix>, GnssDecoder) {
    let mut d = GnssDecoder::new();
    let mut fixes = Vec::new();
    d.push(bytes, 42, |f| fixes.push(f));
    (fixes, d)
}

/// The GGA and RMC examples of the NMEA 0183 reference descriptions (a fix over Munich at
/// 12:35:19 UTC), as a receiver sends them, with a GSV the decoder passes by.
const REFERENCE_EPOCH: &str = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n\
$GPGSV,2,1,08,01,40,083,46,02,17,308,41,12,07,344,39,14,22,228,45*75\r\n\
$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\r\n";

/// `$body*hh\r\n`.
fn with_checksum(body: &str) -> String {
    let checksum = body.bytes().fold(0u8, |c, b| c ^ b);
    format!("${body}*{checksum:02X}\r\n")
}

#[test]
fn the_reference_sentences_make_one_fix() {
    // The first epoch is known complete when the next one starts.
    let next = with_checksum("GPGGA,123520,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,");
    let (fixes, d) = decode_all(format!("{REFERENCE_EPOCH}{next}").as_bytes());
    assert_eq!(fixes.len(), 1, "{:?}", d.stats());
    let f = &fixes[0];
    assert_eq!(f.fix_type, GnssFixType::Fix3d as u8);
    assert_eq!(f.protocol, GnssProtocol::Nmea as u8);
    assert_eq!(f.satellites, 8);
    assert!((f.latitude_rad.to_degrees() - (48.0 + 7.038 / 60.0)).abs() < 1e-9);
    assert!((f.longitude_rad.to_degrees() - (11.0 + 31.0 / 60.0)).abs() < 1e-9);
    assert!((f.altitude_m - 545.4).abs() < 1e-3);
    assert_eq!(f.receiver_time_us, (12 * 3600 + 35 * 60 + 19) * 1_000_000);
    // 22.4 kn at 84.4° true.
    let speed = 22.4 * 1852.0 / 3600.0;
    let course = 84.4f64.to_radians();
    assert_eq!(f.velocity_valid, 1);
    assert!((f.velocity_ned_mps[0] - speed * course.cos()).abs() < 1e-3);
    assert!((f.velocity_ned_mps[1] - speed * course.sin()).abs() < 1e-3);
    // No GST: the accuracy comes from the HDOP.
    assert_eq!(f.accuracy_reported, 0);
    assert!((f.horizontal_accuracy_m - 0.9 * 3.0).abs() < 1e-6);
    assert_eq!(f.header.origin_seq, 1);
    assert_eq!(f.header.origin_rx_ns, 42);
    let s = d.stats();
    assert_eq!((s.sentences, s.unsupported, s.checksum_errors), (3, 1, 0));
}

#[test]
fn a_bad_checksum_is_counted_and_the_sentence_not_used() {
    let corrupted = REFERENCE_EPOCH.replace("545.4", "745.4")
        + &with_checksum("GPRMC,123520,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W");
    let (fixes, d) = decode_all(corrupted.as_bytes());
    // The epoch's RMC is left: a two-dimensional fix, nothing of the GGA (altitude) in it; the
    // next RMC is an epoch of its own, complete as the receiver's epochs now go.
    assert_eq!(fixes.len(), 2, "{:?}", d.stats());
    for f in &fixes {
        assert_eq!(f.fix_type, GnssFixType::Fix2d as u8);
        assert!(f.altitude_m.is_nan());
    }
    assert_eq!(d.stats().checksum_errors, 1);
}

/// A NAV-PVT frame laid out field by field from the u-blox interface description.
fn reference_nav_pvt() -> Vec<u8> {
    let mut p = [0u8; 92];
    let mut put = |at: usize, bytes: &[u8]| p[at..at + bytes.len()].copy_from_slice(bytes);
    put(0, &123_456_000u32.to_le_bytes()); // iTOW ms
    put(20, &[3, 0x01, 0, 14]); // fixType 3D, gnssFixOK, flags2, numSV
    put(24, &115_166_667i32.to_le_bytes()); // lon 11.5166667°
    put(28, &481_173_000i32.to_le_bytes()); // lat 48.1173°
    put(32, &592_300i32.to_le_bytes()); // height above ellipsoid, mm
    put(36, &545_400i32.to_le_bytes()); // hMSL, mm
    put(40, &1_200u32.to_le_bytes()); // hAcc, mm
    put(44, &2_500u32.to_le_bytes()); // vAcc, mm
    put(48, &1_100i32.to_le_bytes()); // velN mm/s
    put(52, &(-2_200i32).to_le_bytes()); // velE
    put(56, &300i32.to_le_bytes()); // velD
    put(68, &150u32.to_le_bytes()); // sAcc mm/s
    ubx_frame(0x01, 0x07, &p)
}

#[test]
fn a_nav_pvt_frame_makes_one_fix_with_the_receivers_accuracies() {
    let (fixes, d) = decode_all(&reference_nav_pvt());
    assert_eq!(fixes.len(), 1, "{:?}", d.stats());
    let f = &fixes[0];
    assert_eq!(f.protocol, GnssProtocol::Ubx as u8);
    assert_eq!(f.fix_type, GnssFixType::Fix3d as u8);
    assert_eq!(f.satellites, 14);
    assert_eq!(f.receiver_time_us, 123_456_000_000);
    assert!((f.latitude_rad.to_degrees() - 48.1173).abs() < 1e-7);
    assert!((f.longitude_rad.to_degrees() - 11.5166667).abs() < 1e-7);
    assert!((f.altitude_m - 545.4).abs() < 1e-6);
    assert_eq!(f.velocity_ned_mps, [1.1, -2.2, 0.3]);
    assert_eq!(f.accuracy_reported, 1);
    assert!((f.horizontal_accuracy_m - 1.2).abs() < 1e-9);
    assert!((f.vertical_accuracy_m - 2.5).abs() < 1e-9);
    assert!((f.speed_accuracy_mps - 0.15).abs() < 1e-9);
}

/// A UBX frame of `payload` with its checksum.
fn ubx_frame(class: u8, id: u8, payload: &[u8]) -> Vec<u8> {
    let mut frame = Vec::new();
    write_ubx_frame(class, id, payload, &mut frame);
    frame
}

#[test]
fn a_protocol_14_nav_pvt_of_84_bytes_makes_the_same_fix_as_the_92_byte_form() {
    // u-blox 7 firmware ends NAV-PVT after pDOP and its reserved bytes; later ones add headVeh,
    // magDec and magAcc, which the fix does not use.
    let long = reference_nav_pvt();
    let mut payload = long[6..6 + 92].to_vec();
    payload[84..].copy_from_slice(&[0x10, 0x27, 0, 0, 0x2C, 0x01, 0x64, 0]);
    let (from_long, _) = decode_all(&ubx_frame(0x01, 0x07, &payload));
    let (from_short, d) = decode_all(&ubx_frame(0x01, 0x07, &payload[..84]));
    assert_eq!(from_short.len(), 1, "{:?}", d.stats());
    assert_eq!(from_short, from_long);
    assert_eq!(from_short[0].fix_type, GnssFixType::Fix3d as u8);
    let s = d.stats();
    assert_eq!(
        (s.ubx_frames, s.malformed, s.framing.wrong_length),
        (1, 0, 0)
    );
}

#[test]
fn a_nav_pvt_with_a_corrupted_byte_is_a_checksum_error() {
    let mut frame = reference_nav_pvt();
    frame[40] ^= 0x10;
    let (fixes, d) = decode_all(&frame);
    assert!(fixes.is_empty());
    assert_eq!(d.stats().checksum_errors, 1);
}

#[test]
fn an_implausible_value_under_a_valid_checksum_is_malformed() {
    let good = reference_nav_pvt();
    let mut payload = good[6..good.len() - 2].to_vec();
    payload[28..32].copy_from_slice(&1_900_000_000i32.to_le_bytes()); // lat 190°
    let (fixes, d) = decode_all(&ubx_frame(0x01, 0x07, &payload));
    assert!(fixes.is_empty());
    assert_eq!(d.stats().malformed, 1);
}

#[test]
fn the_simulated_receivers_epochs_read_back_within_their_resolution() {
    for ubx in [false, true] {
        let (fixes, d) = decode_all(&simulated_stream(6, ubx));
        assert_eq!(fixes.len(), 6, "{:?}", d.stats());
        for (i, f) in fixes.iter().enumerate() {
            let e = epoch(i as u64);
            assert_eq!(f.protocol, if ubx { 1 } else { 0 });
            // 1e-7° (UBX) or 1e-6 minute (NMEA): about a centimetre.
            let m_per_rad = 6.37e6;
            assert!(
                (f.latitude_rad - e.latitude_rad).abs() * m_per_rad < 0.012,
                "{f:?}"
            );
            assert!(
                (f.longitude_rad - e.longitude_rad).abs() * m_per_rad < 0.012,
                "{f:?}"
            );
            assert!((f.altitude_m - e.altitude_m).abs() < 1e-3);
            assert!((f.horizontal_accuracy_m - 1.5).abs() < 1e-3);
            assert!((f.vertical_accuracy_m - 3.0).abs() < 1e-3);
            assert_eq!(
                f.receiver_time_us % 86_400_000_000 / 10_000,
                e.receiver_time_us / 10_000 % 8_640_000
            );
            // NMEA carries no vertical speed.
            let vd = if ubx { 0.5 } else { 0.0 };
            let expected = [3.0, -4.0, vd];
            for (got, want) in f.velocity_ned_mps.iter().zip(expected) {
                assert!((got - want).abs() < 2e-3, "{f:?}");
            }
        }
    }
}

#[test]
fn an_epoch_without_a_fix_is_published_as_such() {
    let mut out = Vec::new();
    write_nmea_epoch(
        &GnssFix {
            fix_type: GnssFixType::NoFix as u8,
            ..epoch(0)
        },
        &mut out,
    );
    write_nmea_epoch(&epoch(1), &mut out);
    write_nmea_epoch(&epoch(2), &mut out);
    let (fixes, d) = decode_all(&out);
    assert_eq!(fixes.len(), 3, "{:?}", d.stats());
    assert_eq!(fixes[0].fix_type, GnssFixType::NoFix as u8);
    assert_eq!(fixes[1].fix_type, GnssFixType::Fix3d as u8);
    assert_eq!(d.stats().epochs_without_fix, 1);
}

proptest! {
    #[test]
    fn the_same_epochs_whatever_the_chunking(cuts in prop::collection::vec(1usize..200, 1..40)) {
        let mut stream = simulated_stream(8, false);
        stream.extend(simulated_stream(8, true));
        let (whole, _) = decode_all(&stream);
        let mut d = GnssDecoder::new();
        let mut pieces = Vec::new();
        let mut at = 0;
        for cut in cuts.iter().cycle() {
            if at >= stream.len() {
                break;
            }
            let end = (at + cut).min(stream.len());
            d.push(&stream[at..end], 42, |f| pieces.push(f));
            at = end;
        }
        prop_assert_eq!(whole, pieces);
    }

    #[test]
    fn any_bytes_are_survived(noise in prop::collection::vec(any::<u8>(), 0..2000)) {
        let mut d = GnssDecoder::new();
        let mut n = 0;
        d.push(&noise, 1, |_| n += 1);
        // After garbage, a good epoch still comes through.
        let mut after = 0;
        d.push(b"\r\n", 2, |_| {});
        // A corrupted UBX header at the end of the garbage may take the first frame or two with
        // it, and no more: it is refused as soon as a whole frame follows it.
        d.push(&simulated_stream(30, true), 3, |_| after += 1);
        prop_assert!(after >= 28, "{:?}", d.stats());
    }
}

/// Feeds `stream` in 32-byte reads, as a serial port hands them out; returns the fixes and, for
/// each, how many whole NAV-PVT frames (100 bytes each after a `skip`-byte prefix) had arrived
/// beyond it when it came out: 0 when every fix is published with its own frame.
fn decode_in_reads(stream: &[u8], skip: usize) -> (Vec<GnssFix>, u64, GnssDecoder) {
    let mut d = GnssDecoder::new();
    let mut fixes = Vec::new();
    let (mut fed, mut worst_lag) = (0usize, 0u64);
    for read in stream.chunks(32) {
        d.push(read, 1, |f| fixes.push(f));
        fed += read.len();
        let complete = (fed.saturating_sub(skip) / 100) as u64;
        worst_lag = worst_lag.max(complete.saturating_sub(fixes.len() as u64));
    }
    (fixes, worst_lag, d)
}

#[test]
fn an_oversized_ubx_length_is_malformed_and_the_frames_after_it_are_found() {
    const N: u64 = 12;
    let mut stream = vec![0xB5, 0x62, 0x01, 0x07, 0xFF, 0xFF];
    stream.extend(simulated_stream(N, true));
    assert_eq!(simulated_stream(1, true).len(), 100);
    let (fixes, d) = decode_all(&stream);
    assert_eq!(fixes.len() as u64, N, "{:?}", d.stats());
    assert_eq!(d.stats().malformed, 1, "{:?}", d.stats());
    assert_eq!(d.stats().ubx_frames, N);
    let (fixes, lag, d) = decode_in_reads(&stream, 6);
    assert_eq!((fixes.len() as u64, lag), (N, 0), "{:?}", d.stats());
    assert_eq!(d.stats().malformed, 1, "{:?}", d.stats());
}

#[test]
fn a_nav_pvt_header_declaring_another_length_holds_nothing_up() {
    // 512 bytes would be within what a UBX frame may declare, but not for NAV-PVT: the fixes
    // behind it come out with their frames, not five epochs later.
    const N: u64 = 12;
    let mut stream = vec![0xB5, 0x62, 0x01, 0x07, 0x00, 0x02];
    stream.extend(simulated_stream(N, true));
    let (fixes, lag, d) = decode_in_reads(&stream, 6);
    assert_eq!((fixes.len() as u64, lag), (N, 0), "{:?}", d.stats());
    assert_eq!(d.stats().malformed, 1, "{:?}", d.stats());
}

#[test]
fn a_corrupted_length_within_the_bound_is_refused_once_a_whole_frame_follows() {
    // RXM class, 4 807 bytes declared: as long as a real message may be, but what follows at once
    // is a whole NAV-PVT frame with a good checksum, which no real frame holds. Waiting for the
    // 4 807 bytes would hold up 48 fixes (10 s at 5 Hz).
    const N: u64 = 60;
    let mut stream = vec![0xB5, 0x62, 0x02, 0x22, 0xC7, 0x12];
    stream.extend(simulated_stream(N, true));
    let (fixes, lag, d) = decode_in_reads(&stream, 6);
    assert_eq!(fixes.len() as u64, N, "{:?}", d.stats());
    assert!(lag <= 1, "fixes held up by {lag} frames: {:?}", d.stats());
    assert_eq!(d.stats().malformed, 1, "{:?}", d.stats());
}
