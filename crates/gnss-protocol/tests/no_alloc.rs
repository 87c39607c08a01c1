//! Decoding the receiver's bytes must not touch the heap, read in the small pieces a serial port
//! hands out, every epoch published: the simulated receiver's NMEA and NAV-PVT, real receivers'
//! NMEA epochs (GGA, GNS, RMC, GLL, GST and VTG of several talkers, proprietary and other unused
//! sentences, sentences without checksum; flushed and closed on silence) and UBX epochs (NAV-SOL
//! with NAV-DOP and others, NAV-PVT with NAV-EOE).

mod common;

use common::{capture, simulated_epoch as epoch};
use rins_gnss_protocol::decode::GnssDecoder;
use rins_gnss_protocol::encode::{write_nav_pvt, write_nmea_epoch};
use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

#[test]
fn decoding_nmea_and_ubx_does_not_allocate() {
    // The counter sees this thread's allocations.
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);

    for ubx in [false, true] {
        let mut stream = Vec::new();
        for i in 0..50 {
            match ubx {
                true => write_nav_pvt(&epoch(i), &mut stream),
                false => write_nmea_epoch(&epoch(i), &mut stream),
            }
        }
        let mut decoder = GnssDecoder::new();
        // One epoch first: whatever the decoder sets up once is not per epoch.
        let first = stream.len() / 50;
        decoder.push(&stream[..first], 1, |_| {});
        let mut fixes = 0;
        let allocations = allocations_during(|| {
            for (k, piece) in stream[first..].chunks(61).enumerate() {
                decoder.push(piece, k as u64, |_| fixes += 1);
            }
        });
        // NMEA knows an epoch complete when the next begins: the last one stays pending.
        assert!(
            fixes >= 48,
            "ubx {ubx}: {fixes} fixes, {:?}",
            decoder.stats()
        );
        assert_eq!(allocations, 0, "ubx {ubx}: allocations while decoding");
    }
}

#[test]
fn assembling_nmea_epochs_does_not_allocate() {
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);
    for (name, at_least) in [
        ("sirfstarv-nmea.log", 59),
        ("beidou-bd.log", 10),
        ("skytraq-dgps.log", 96),
        ("ait250.log", 34),
        ("hemi.log", 21),
        ("hp58534a.log", 0),
        ("GPSmap-76S.log", 12),
    ] {
        let stream = capture(name);
        let mut decoder = GnssDecoder::new();
        let mut fixes = 0;
        let allocations = allocations_during(|| {
            for (k, piece) in stream.chunks(61).enumerate() {
                decoder.push(piece, k as u64 * 61_000_000, |_| fixes += 1);
            }
            decoder.close_quiet(u64::MAX, |_| fixes += 1);
            decoder.flush(u64::MAX, |_| fixes += 1);
        });
        assert!(
            fixes >= at_least,
            "{name}: {fixes} fixes, {:?}",
            decoder.stats()
        );
        assert_eq!(allocations, 0, "{name}: allocations while decoding");
    }
}

#[test]
fn assembling_ubx_epochs_does_not_allocate() {
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);
    for (name, at_least) in [
        ("ublox-neo-m8t.log", 38),
        ("ublox-8-time.log", 88),
        ("ublox-zed-f9p-hp.log", 28),
    ] {
        let stream = capture(name);
        let mut decoder = GnssDecoder::new();
        // The first epoch: whatever the decoder sets up once is not per epoch.
        let first = stream.len() / 20;
        decoder.push(&stream[..first], 1, |_| {});
        let mut fixes = 0;
        let allocations = allocations_during(|| {
            for (k, piece) in stream[first..].chunks(61).enumerate() {
                decoder.push(piece, k as u64, |_| fixes += 1);
            }
            decoder.flush(u64::MAX, |_| fixes += 1);
        });
        assert!(
            fixes >= at_least * 19 / 20,
            "{name}: {fixes} fixes, {:?}",
            decoder.stats()
        );
        assert_eq!(allocations, 0, "{name}: allocations while decoding");
    }
}
