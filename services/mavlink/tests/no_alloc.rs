//! The per-sample path of the MAVLink output must not touch the heap: every fused sample and
//! solution through the stream's state machine, and every message it emits framed as MAVLink 2
//! into the fixed buffer the network thread uses.

use std::io::Cursor;

use ipc_types::{FusedImu, NavMode, NavState};
use mavlink::MavHeader;
use rins_mavlink::config::MavlinkConfig;
use rins_mavlink::dialect::MavMessage;
use rins_mavlink::stream::MavlinkStream;
use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// A frame's worst size: MAVLink 2 header, the largest payload, checksum and signature.
const MAX_FRAME: usize = 280;

fn flying(k: u64) -> NavState {
    let mut nav = NavState {
        mode: NavMode::Navigating as u8,
        quaternion: [0.9, 0.1, -0.2, 0.3829708],
        velocity_ned_mps: [12.0, -3.5, 0.25],
        latitude_rad: 0.8203 + k as f64 * 1e-9,
        longitude_rad: 0.1396,
        altitude_m: 512.5,
        solution_start_seq: 4,
        ..NavState::default()
    };
    nav.header.origin_seq = k;
    nav.header.origin_rx_ns = k * 1_000_000;
    nav.header.origin_device_time_us = k * 1_000;
    nav
}

fn fused(k: u64) -> FusedImu {
    let mut f = FusedImu {
        rate_rps: [0.01, -0.02, 0.5],
        specific_force_mps2: [0.1, 0.2 * (k % 3) as f64, -9.8],
        n_gyro: 4,
        n_accel: 4,
        ..FusedImu::default()
    };
    f.header.origin_seq = k;
    f.header.origin_rx_ns = k * 1_000_000;
    f.header.origin_device_time_us = k * 1_000;
    f
}

#[test]
fn streaming_and_framing_do_not_allocate() {
    // The counter sees this thread's allocations.
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);

    let mut stream = MavlinkStream::new(&MavlinkConfig::default());
    let mut buf = [0u8; MAX_FRAME];
    let (mut messages, mut bytes) = (0u64, 0u64);
    let mut emit = |m: MavMessage| {
        let header = MavHeader {
            system_id: 1,
            component_id: 197,
            sequence: messages as u8,
        };
        let mut cursor = Cursor::new(&mut buf[..]);
        mavlink::write_v2_msg(&mut cursor, header, &m).expect("a frame fits the buffer");
        messages += 1;
        bytes += cursor.position();
    };
    // Two seconds at 1 kHz: every paced message falls due several times.
    let allocations = allocations_during(|| {
        for k in 1..=2000 {
            stream.on_fused(&fused(k), &mut emit);
            stream.on_nav(&flying(k), (0, None), &mut emit);
            stream.on_clock(k * 1_000_000, &mut emit);
        }
    });
    assert!(messages > 100, "{messages} messages emitted in 2 s");
    assert!(bytes > messages * 20, "{bytes} bytes framed");
    assert_eq!(allocations, 0, "allocations in the per-sample path");
}
