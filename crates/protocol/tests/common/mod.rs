//! Frame generators and stream helpers shared by the protocol tests.
#![allow(dead_code)]

use proptest::collection::vec;
use proptest::prelude::*;
use rins_protocol::{
    AirspeedFrame, AuxFrame, BaroFrame, DecodedFrame, Decoder, Frame, FrameType, ImuFrame,
    MAX_FRAME_LEN, MagFrame, Payload, encode,
};

/// Proptest settings for these tests: `cases` unless `PROPTEST_CASES` is set (for long soak
/// runs). Failures are not persisted: the shrunk input is printed.
pub fn config(cases: u32) -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(cases);
    ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// The frame used as the worked example in `docs/protocol.md`.
pub fn example_imu_frame() -> Frame {
    let mut imu = ImuFrame {
        n_gyro: 4,
        n_accel: 4,
        n_temperature: 2,
        status: 0x0002,
        valid_mask: 0x000F_000F,
        ..ImuFrame::default()
    };
    imu.gyro_counts[..4].copy_from_slice(&[100, -100, 2047, -2048]);
    imu.accel_counts[..4].copy_from_slice(&[0, 1, -1, 512]);
    imu.temperature_centi_c[..2].copy_from_slice(&[2512, -500]);
    Frame {
        seq: 0x1234,
        device_time_us: 123_456,
        payload: Payload::Imu(imu),
    }
}

/// IMU payloads with valid channel counts; array entries past the counts are zero, as the decoder
/// produces them.
pub fn arb_imu() -> impl Strategy<Value = ImuFrame> {
    (
        0..=16u8,
        0..=16u8,
        0..=4u8,
        any::<u16>(),
        any::<u32>(),
        vec(-2048i16..=2047, 16),
        vec(-2048i16..=2047, 16),
        vec(any::<i16>(), 4),
    )
        .prop_map(|(ng, na, nt, status, valid_mask, g, a, t)| {
            let mut imu = ImuFrame {
                n_gyro: ng,
                n_accel: na,
                n_temperature: nt,
                status,
                valid_mask,
                ..ImuFrame::default()
            };
            let (ng, na, nt) = (usize::from(ng), usize::from(na), usize::from(nt));
            imu.gyro_counts[..ng].copy_from_slice(&g[..ng]);
            imu.accel_counts[..na].copy_from_slice(&a[..na]);
            imu.temperature_centi_c[..nt].copy_from_slice(&t[..nt]);
            imu
        })
}

/// Any payload. Pressures are never NaN so that frames compare equal with `==`.
pub fn arb_payload() -> impl Strategy<Value = Payload> {
    use proptest::num::f32 as f;
    prop_oneof![
        3 => arb_imu().prop_map(Payload::Imu),
        1 => (f::NORMAL | f::SUBNORMAL | f::ZERO | f::INFINITE, any::<i16>()).prop_map(
            |(pressure_pa, temperature_centi_c)| Payload::Baro(BaroFrame {
                pressure_pa,
                temperature_centi_c,
            })
        ),
        1 => any::<[i32; 3]>().prop_map(|field_nt| Payload::Mag(MagFrame { field_nt })),
        1 => any::<u16>().prop_map(|foot_pressure| Payload::Aux(AuxFrame { foot_pressure })),
        1 => (-7000.0f32..=7000.0, -5000i16..=15000).prop_map(
            |(diff_pressure_pa, temperature_centi_c)| Payload::Airspeed(AirspeedFrame {
                diff_pressure_pa,
                temperature_centi_c,
            })
        ),
    ]
}

/// A stream of frames whose sequence numbers advance by one per frame type and whose device time
/// advances monotonically, both starting anywhere (so wraps are exercised).
pub fn arb_consecutive_frames(max_len: usize) -> impl Strategy<Value = Vec<Frame>> {
    (
        any::<[u16; FrameType::COUNT]>(),
        any::<u32>(),
        vec((arb_payload(), 0u32..5_000), 1..max_len),
    )
        .prop_map(|(mut seqs, mut time, items)| {
            items
                .into_iter()
                .map(|(payload, dt)| {
                    let i = payload.frame_type().index();
                    let frame = Frame {
                        seq: seqs[i],
                        device_time_us: time,
                        payload,
                    };
                    seqs[i] = seqs[i].wrapping_add(1);
                    time = time.wrapping_add(dt);
                    frame
                })
                .collect()
        })
}

/// Chunk sizes for splitting a stream; 0 means an empty push.
pub fn arb_chunks() -> impl Strategy<Value = Vec<usize>> {
    vec(0usize..=2 * MAX_FRAME_LEN, 1..16)
}

pub fn encode_one(frame: &Frame) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let n = encode(frame, &mut buf).expect("test frames are valid");
    buf[..n].to_vec()
}

/// Pushes `bytes` in chunks of the given sizes (cycled), all received at the same instant, and
/// returns the frames handed out.
pub fn push_chunked(decoder: &mut Decoder, bytes: &[u8], chunks: &[usize]) -> Vec<DecodedFrame> {
    let mut out = Vec::new();
    let mut rest = bytes;
    let mut sizes = chunks.iter().cycle();
    while !rest.is_empty() {
        let n = sizes.next().copied().unwrap_or(rest.len()).min(rest.len());
        let (head, tail) = rest.split_at(n);
        decoder.push(head, 0, |f| out.push(f));
        // An empty push must be harmless; then move on by one byte.
        rest = if n == 0 {
            let (one, tail) = rest.split_at(1);
            decoder.push(one, 0, |f| out.push(f));
            tail
        } else {
            tail
        };
    }
    out
}

/// The wire form of a decoded frame: sequence and time truncated back to 16 and 32 bits.
pub fn to_wire(d: &DecodedFrame) -> Frame {
    Frame {
        seq: d.seq as u16,
        device_time_us: d.device_time_us as u32,
        payload: d.payload,
    }
}

/// Zeros to append after a stream so that any candidate started by a spurious sync word has been
/// resolved: a real frame is delivered once `MAX_FRAME_LEN` bytes from its start have arrived.
pub fn flush() -> Vec<u8> {
    vec![0u8; MAX_FRAME_LEN]
}
