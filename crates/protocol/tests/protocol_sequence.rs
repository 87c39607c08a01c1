//! Sequence-gap counting, duplicates, late frames and jumps, and the 64-bit extension of sequence
//! numbers and device time with its re-bases; resume points.

mod common;

use common::{arb_payload, encode_one};
use proptest::collection::vec;
use proptest::prelude::*;
use rins_protocol::{
    AuxFrame, BaroFrame, DecodedFrame, Decoder, Frame, FrameType, ImuFrame, Payload, ResumeError,
    ResumePoint,
};

fn imu() -> Payload {
    Payload::Imu(ImuFrame::default())
}

fn baro() -> Payload {
    Payload::Baro(BaroFrame::default())
}

fn frame(payload: Payload, seq: u16, device_time_us: u32) -> Frame {
    Frame {
        seq,
        device_time_us,
        payload,
    }
}

/// Decodes `frames`, all received at the same instant.
fn decode_all(decoder: &mut Decoder, frames: &[Frame]) -> Vec<DecodedFrame> {
    let timed: Vec<(Frame, u64)> = frames.iter().map(|f| (*f, 0)).collect();
    decode_timed(decoder, &timed)
}

/// Decodes `frames`, each received at its CLOCK_MONOTONIC time (ns).
fn decode_timed(decoder: &mut Decoder, frames: &[(Frame, u64)]) -> Vec<DecodedFrame> {
    let mut out = Vec::new();
    for (f, rx_ns) in frames {
        decoder.push(&encode_one(f), *rx_ns, |d| out.push(d));
    }
    out
}

const WRAP32: u64 = 1 << 32;
const MS: u64 = 1_000_000;

/// A device streaming IMU frames at 1 kHz: frame k carries wire number `seq0 + k`, device time
/// `k` ms, and is received at `k` ms.
fn imu_stream(seq0: u16, from: u64, to: u64) -> Vec<(Frame, u64)> {
    (from..to)
        .map(|k| {
            let f = frame(imu(), seq0.wrapping_add(k as u16), (k * 1_000) as u32);
            (f, k * MS)
        })
        .collect()
}

/// Long enough for the decoder to know the IMU period (1 s of warm-up, three 1 s blocks).
const LEARNT: u64 = 5_000;

#[test]
fn gaps_are_counted_per_type_across_the_u16_wrap() {
    let frames = [
        frame(imu(), 65_533, 10),
        frame(baro(), 7, 11),
        frame(imu(), 65_535, 12), // 65534 lost
        frame(imu(), 0, 13),
        frame(baro(), 8, 14),
        frame(imu(), 4, 15),   // 1, 2, 3 lost
        frame(baro(), 20, 16), // 9..=19 lost: 11
    ];
    let mut decoder = Decoder::new();
    let out = decode_all(&mut decoder, &frames);
    let seqs: Vec<u64> = out.iter().map(|d| d.seq).collect();
    assert_eq!(seqs, [65_533, 7, 65_535, 65_536, 8, 65_540, 20]);
    let stats = decoder.stats();
    let (i, b) = (FrameType::Imu.index(), FrameType::Baro.index());
    assert_eq!(stats.lost_frames_by_type[i], 1 + 3);
    assert_eq!(stats.lost_frames_by_type[b], 11);
    assert_eq!(stats.lost_frames, 4 + 11);
    assert_eq!(stats.frames_by_type[i], 4);
    assert_eq!(stats.frames_by_type[b], 3);
    assert_eq!(stats.frames, 7);
}

#[test]
fn device_time_is_extended_across_the_u32_wrap_with_one_clock_for_all_types() {
    let frames = [
        frame(imu(), 0, u32::MAX - 1_000),
        // Baro sampled slightly before the IMU frame that preceded it on the wire.
        frame(baro(), 0, u32::MAX - 1_500),
        frame(imu(), 1, u32::MAX),
        frame(imu(), 2, 999), // wrapped
        frame(baro(), 1, 500),
        frame(imu(), 3, 1 << 31),  // 35.8 min later, still taken as forward
        frame(imu(), 4, u32::MAX), // and another wrap after that
        frame(imu(), 5, 3),
    ];
    let mut decoder = Decoder::new();
    let times: Vec<u64> = decode_all(&mut decoder, &frames)
        .iter()
        .map(|d| d.device_time_us)
        .collect();
    assert_eq!(
        times,
        [
            WRAP32 - 1_001,
            WRAP32 - 1_501,
            WRAP32 - 1,
            WRAP32 + 999,
            WRAP32 + 500,
            WRAP32 + (1 << 31),
            2 * WRAP32 - 1,
            2 * WRAP32 + 3,
        ]
    );
}

#[test]
fn reset_continues_the_numbering_and_counts_the_frames_sent_meanwhile() {
    let mut decoder = Decoder::new();
    let before = decode_all(
        &mut decoder,
        &[frame(imu(), 100, 50), frame(imu(), 102, 60)],
    );
    assert_eq!(before[1].seq, 102);
    assert_eq!(decoder.stats().lost_frames, 1);
    decoder.reset();
    // Unplugged for 1000 frames: the numbers go on and the frames sent meanwhile are lost.
    let after = decode_all(
        &mut decoder,
        &[frame(imu(), 1103, 1060), frame(imu(), 1104, 1061)],
    );
    assert_eq!((after[0].seq, after[0].device_time_us), (1103, 1060));
    assert_eq!(after[1].seq, 1104);
    assert_eq!(decoder.stats().lost_frames, 1 + 1000);
    // The device restarted its counter: 1104 → 0 is 1104 behind, too far for a late frame, so a
    // sequence jump: the numbers still run forward, nothing more counted lost.
    decoder.reset();
    let again = decode_all(&mut decoder, &[frame(imu(), 0, 5), frame(imu(), 1, 6)]);
    assert_eq!(again[0].seq, 1105);
    assert_eq!(again[1].seq, 1106);
    let stats = decoder.stats();
    assert_eq!(
        (stats.frames, stats.seq_jumps, stats.lost_frames),
        (6, 1, 1001)
    );
}

#[test]
fn a_resumed_decoder_continues_a_previous_run() {
    let mut first = Decoder::new();
    decode_all(&mut first, &[frame(imu(), 65535, 50), frame(imu(), 0, 60)]);
    let point = first.resume_point();
    assert_eq!(point.seq[FrameType::Imu.index()], Some(65536));
    assert_eq!(point.time_us, Some(60));
    let mut second = Decoder::new();
    second.resume_from(&point).unwrap();
    // Saved again before the first frame arrives, the point is unchanged.
    assert_eq!(second.resume_point(), point);
    // Ten frames went by while no process read the port.
    let out = decode_all(&mut second, &[frame(imu(), 11, 160)]);
    assert_eq!((out[0].seq, out[0].device_time_us), (65547, 160));
    assert_eq!(second.stats().lost_frames, 0);
}

/// After a sequence jump and a re-based clock the extended values' low bits are no longer the wire
/// values: the point carries the wire values too, so a restart still continues
/// the numbering forward instead of ignoring the point (and running backwards downstream).
#[test]
fn a_decoder_resumed_after_a_jump_and_a_re_based_clock_continues_forward() {
    let mut first = Decoder::new();
    // A device counter restarted (1104 → 0: a jump, once 1 confirms it) and a clock that stepped
    // back 10 s (a re-base).
    decode_all(
        &mut first,
        &[
            frame(imu(), 1103, 20_000_000),
            frame(imu(), 1104, 20_001_000),
        ],
    );
    decode_all(
        &mut first,
        &[frame(imu(), 0, 10_001_000), frame(imu(), 1, 10_002_000)],
    );
    let stats = first.stats();
    assert_eq!((stats.seq_jumps, stats.time_rebases), (1, 1));
    let point = first.resume_point();
    let (seq, time) = (
        point.seq[FrameType::Imu.index()].unwrap(),
        point.time_us.unwrap(),
    );
    assert_eq!(point.seq_wire[FrameType::Imu.index()], Some(1));
    assert_eq!(point.time_wire, Some(10_002_000));
    assert_ne!(
        seq as u16, 1,
        "the low bits are not the wire number any more"
    );
    let mut second = Decoder::new();
    second.resume_from(&point).unwrap();
    // Five frames and 5 ms later.
    let out = decode_all(&mut second, &[frame(imu(), 6, 10_007_000)]);
    assert_eq!((out[0].seq, out[0].device_time_us), (seq + 5, time + 5_000));
    assert_eq!(second.stats().resume_rejected, 0);
}

#[test]
fn a_repeated_sequence_number_is_a_duplicate_and_loses_nothing() {
    let aux = Payload::Aux(AuxFrame { foot_pressure: 1 });
    let mut decoder = Decoder::new();
    let out = decode_all(
        &mut decoder,
        &[frame(aux, 9, 0), frame(aux, 9, 1), frame(aux, 10, 2)],
    );
    let seqs: Vec<u64> = out.iter().map(|d| d.seq).collect();
    assert_eq!(seqs, [9, 10]);
    let stats = decoder.stats();
    assert_eq!((stats.duplicates, stats.lost_frames, stats.late), (1, 0, 0));
}

#[test]
fn one_reordered_frame_is_late_not_lost() {
    let mut decoder = Decoder::new();
    let mut stream = imu_stream(65_530, 0, 20);
    stream.swap(10, 11); // k + 1 arrives before k
    let out = decode_timed(&mut decoder, &stream);
    let stats = decoder.stats();
    assert_eq!((stats.lost_frames, stats.late, stats.duplicates), (0, 1, 0));
    assert_eq!(stats.frames, 19);
    // Delivered in increasing order, without the late one, across the u16 wrap.
    let seqs: Vec<u64> = out.iter().map(|d| d.seq).collect();
    let expected: Vec<u64> = (0..20).filter(|&k| k != 10).map(|k| 65_530 + k).collect();
    assert_eq!(seqs, expected);
}

#[test]
fn a_jump_of_30000_then_back_1_and_100_loses_nothing() {
    let mut decoder = Decoder::new();
    let mut stream = imu_stream(100, 0, LEARNT);
    let after = |k: u64, wire: u16| (frame(imu(), wire, (k * 1_000) as u32), k * MS);
    let jumped = 100 + LEARNT as u16 + 30_000;
    stream.push(after(LEARNT, jumped));
    stream.push(after(LEARNT + 1, jumped - 1));
    stream.push(after(LEARNT + 2, jumped - 100));
    stream.push(after(LEARNT + 3, jumped + 1));
    let out = decode_timed(&mut decoder, &stream);
    let stats = decoder.stats();
    assert_eq!(stats.seq_jumps, 1);
    assert_eq!(stats.lost_frames, 0);
    // Behind the newest, not received: late (they were never counted lost).
    assert_eq!((stats.late, stats.duplicates), (2, 0));
    let seqs: Vec<u64> = out.iter().map(|d| d.seq).collect();
    assert!(
        seqs.windows(2).all(|w| w[1] == w[0] + 1),
        "{:?}",
        &seqs[seqs.len() - 3..]
    );
    assert_eq!(seqs.last(), Some(&(100 + LEARNT + 1)));
}

#[test]
fn device_time_jumps_are_re_based_on_the_receive_clock() {
    let mut decoder = Decoder::new();
    let mut stream = imu_stream(0, 0, 2_000);
    // +600 s on the device clock, then +2^31 + 1 µs (a step of 2^31 − 1 µs backwards on the
    // wire), each 1 ms after the previous frame on the receive clock; baro frames ride along.
    let mut offset = 600_000_000u32;
    for k in 2_000..4_000u64 {
        if k == 3_000 {
            offset = offset.wrapping_add((1 << 31) + 1);
        }
        let t = ((k * 1_000) as u32).wrapping_add(offset);
        stream.push((frame(imu(), k as u16, t), k * MS));
        if k % 20 == 0 {
            stream.push((frame(baro(), (k / 20) as u16, t), k * MS));
        }
    }
    let out = decode_timed(&mut decoder, &stream);
    assert_eq!(decoder.stats().time_rebases, 2);
    // Every step of the extended time equals the receive-clock step: 1 ms, or 0 for the baro
    // frame of the same instant.
    let times: Vec<u64> = out.iter().map(|d| d.device_time_us).collect();
    assert_eq!(times[0], 0);
    for (w, d) in times.windows(2).zip(&out[1..]) {
        let expected = if matches!(d.payload, Payload::Baro(_)) {
            0
        } else {
            1_000
        };
        assert_eq!(w[1] - w[0], expected, "{w:?}");
    }
    assert_eq!(times.last(), Some(&3_999_000));
}

#[test]
fn a_resume_point_out_of_bounds_is_rejected_whole() {
    let mut decoder = Decoder::new();
    let point = ResumePoint {
        seq: [Some(1 << 48), Some(5), None, None, None],
        time_us: Some(10),
        ..ResumePoint::default()
    };
    assert_eq!(
        decoder.resume_from(&point),
        Err(ResumeError::SeqOutOfBounds {
            frame_type: FrameType::Imu,
            value: 1 << 48
        })
    );
    let point = ResumePoint {
        seq: [Some(7), None, None, None, None],
        time_us: Some(u64::MAX),
        ..ResumePoint::default()
    };
    assert!(decoder.resume_from(&point).is_err());
    assert_eq!(decoder.stats().resume_rejected, 2);
    // Nothing of either point applies: numbering from the wire values.
    let out = decode_all(&mut decoder, &[frame(imu(), 3, 40), frame(baro(), 6, 41)]);
    assert_eq!((out[0].seq, out[0].device_time_us), (3, 40));
    assert_eq!(out[1].seq, 6);
}

#[test]
fn a_resume_point_far_from_the_first_frame_is_ignored_part_by_part() {
    let mut decoder = Decoder::new();
    let point = ResumePoint {
        // IMU 65 546 (wire 10): a first IMU frame at wire 5 is behind it, 2^16 − 5 steps ahead.
        // Baro 1 000: wire 1 003 is 3 ahead, continued.
        seq: [Some(65_546), Some(1_000), None, None, None],
        // A planted time 2^40 µs; the device's first frame is 11 min past it on the wire.
        time_us: Some(1 << 40),
        ..ResumePoint::default()
    };
    decoder.resume_from(&point).unwrap();
    let eleven_min = 11 * 60 * 1_000_000;
    let out = decode_all(
        &mut decoder,
        &[
            frame(imu(), 5, eleven_min),
            frame(baro(), 1_003, eleven_min + 1),
        ],
    );
    assert_eq!(out[0].seq, 5);
    assert_eq!(out[1].seq, 1_003);
    assert_eq!(out[0].device_time_us, u64::from(eleven_min));
    assert_eq!(out[1].device_time_us, u64::from(eleven_min) + 1);
    // The IMU part and the time were ignored; the baro part continued.
    assert_eq!(decoder.stats().resume_rejected, 2);
    assert_eq!(decoder.stats().lost_frames, 0);
}

proptest! {
    #![proptest_config(common::config(256))]

    /// Arbitrary per-type forward steps, small or up to the largest (2^15 − 1), with no receive
    /// clock to judge them by: the decoder's loss count is the sum of (step − 1) and the extended
    /// numbers advance by the steps.
    #[test]
    fn lost_frames_equal_the_sum_of_gaps(
        start in any::<[u16; FrameType::COUNT]>(),
        items in vec((arb_payload(), prop_oneof![3 => 1u16..=3, 1 => 1u16..=32_767]), 1..60),
    ) {
        let mut wire = start;
        let mut extended: [Option<u64>; FrameType::COUNT] = [None; FrameType::COUNT];
        let mut expected_lost = 0u64;
        let mut decoder = Decoder::new();
        for (payload, step) in items {
            let i = payload.frame_type().index();
            let expected_seq = match extended[i] {
                None => u64::from(wire[i]),
                Some(prev) => {
                    wire[i] = wire[i].wrapping_add(step);
                    expected_lost += u64::from(step) - 1;
                    prev + u64::from(step)
                }
            };
            extended[i] = Some(expected_seq);
            let out = decode_all(&mut decoder, &[frame(payload, wire[i], 0)]);
            prop_assert_eq!(out.len(), 1);
            prop_assert_eq!(out[0].seq, expected_seq);
        }
        prop_assert_eq!(decoder.stats().lost_frames, expected_lost);
    }
}
