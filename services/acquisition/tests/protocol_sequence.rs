//! Sequence-gap counting and 64-bit extension of sequence numbers and device time.

mod common;

use common::{arb_payload, encode_one};
use proptest::collection::vec;
use proptest::prelude::*;
use rins_acquisition::protocol::{
    AuxFrame, BaroFrame, DecodedFrame, Decoder, Frame, FrameType, ImuFrame, Payload,
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

fn decode_all(decoder: &mut Decoder, frames: &[Frame]) -> Vec<DecodedFrame> {
    let mut out = Vec::new();
    for f in frames {
        decoder.push(&encode_one(f), |d| out.push(d));
    }
    out
}

const WRAP32: u64 = 1 << 32;

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
    // The device restarted its counter: the numbers still run forward (65536 = 1104 + (0 − 1104
    // mod 2^16)); the loss counted across that is meaningless, as documented.
    decoder.reset();
    let again = decode_all(&mut decoder, &[frame(imu(), 0, 5)]);
    assert_eq!(again[0].seq, 65536);
    assert_eq!(decoder.stats().frames, 5);
}

#[test]
fn a_resumed_decoder_continues_a_previous_run() {
    let mut first = Decoder::new();
    decode_all(&mut first, &[frame(imu(), 65535, 50), frame(imu(), 0, 60)]);
    let point = first.resume_point();
    assert_eq!(point.seq[FrameType::Imu.index()], Some(65536));
    assert_eq!(point.time_us, Some(60));
    let mut second = Decoder::new();
    second.resume_from(&point);
    // Ten frames went by while no process read the port.
    let out = decode_all(&mut second, &[frame(imu(), 11, 160)]);
    assert_eq!((out[0].seq, out[0].device_time_us), (65547, 160));
    assert_eq!(second.stats().lost_frames, 0);
}

#[test]
fn a_repeated_sequence_number_loses_nothing() {
    let aux = Payload::Aux(AuxFrame { foot_pressure: 1 });
    let mut decoder = Decoder::new();
    let out = decode_all(
        &mut decoder,
        &[frame(aux, 9, 0), frame(aux, 9, 1), frame(aux, 10, 2)],
    );
    let seqs: Vec<u64> = out.iter().map(|d| d.seq).collect();
    assert_eq!(seqs, [9, 9, 10]);
    assert_eq!(decoder.stats().lost_frames, 0);
}

proptest! {
    #![proptest_config(common::config(256))]

    /// Arbitrary per-type steps, small or up to a full wrap: the decoder's loss count is the sum
    /// of (step − 1) and the extended numbers advance by the steps.
    #[test]
    fn lost_frames_equal_the_sum_of_gaps(
        start in any::<[u16; 4]>(),
        items in vec((arb_payload(), prop_oneof![3 => 1u16..=3, 1 => 1u16..=u16::MAX]), 1..60),
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
