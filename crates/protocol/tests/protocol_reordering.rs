//! The counting invariant under reordering, duplication and dropping: of S distinct frames the
//! device sent, every one is delivered, late or lost (delivered + late + lost = S), every extra copy
//! is a duplicate, and the delivered numbers strictly increase per frame type — with receive times
//! as a serial line gives them (in bursts of a read, late frames late), so that the decoder learns
//! the periods and must not mistake any of it for a sequence jump or a clock discontinuity.

mod common;

use common::encode_one;
use proptest::collection::vec;
use proptest::prelude::*;
use rins_protocol::{
    AirspeedFrame, AuxFrame, BaroFrame, Decoder, Frame, FrameType, ImuFrame, MagFrame, Payload,
};

const MS: u64 = 1_000_000;
/// Largest delay of a frame or of a copy, in frame periods: well within the 1024-number window.
const MAX_DELAY: u64 = 256;
/// Frames a read returns at once (receive times are those of the read).
const BURST_MS: u64 = 4;

fn payload(type_index: usize) -> Payload {
    match FrameType::ALL[type_index] {
        FrameType::Imu => Payload::Imu(ImuFrame::default()),
        FrameType::Baro => Payload::Baro(BaroFrame::default()),
        FrameType::Mag => Payload::Mag(MagFrame::default()),
        FrameType::Aux => Payload::Aux(AuxFrame::default()),
        FrameType::Airspeed => Payload::Airspeed(AirspeedFrame::default()),
    }
}

/// What happens to the k-th frame the device sends (made at k ms): its type, whether it is
/// dropped, its delay and the delay of an extra copy, in ms.
#[derive(Debug, Clone, Copy)]
struct Fate {
    type_index: usize,
    dropped: bool,
    delay: u64,
    copy: Option<u64>,
}

fn arb_fate() -> impl Strategy<Value = Fate> {
    (
        prop_oneof![6 => Just(0usize), 1 => Just(1), 1 => Just(2), 1 => Just(3)],
        prop::bool::weighted(0.05),
        prop_oneof![9 => Just(0u64), 1 => 1..MAX_DELAY],
        prop::option::weighted(0.05, 0..MAX_DELAY),
    )
        .prop_map(|(type_index, dropped, delay, copy)| Fate {
            type_index,
            dropped,
            delay,
            copy,
        })
}

proptest! {
    #![proptest_config(common::config(128))]

    #[test]
    fn delivered_late_and_lost_add_up_and_copies_are_duplicates(
        start in any::<[u16; FrameType::COUNT]>(),
        mut fates in vec(arb_fate(), 2..6_000),
    ) {
        // The first frame of each type arrives first of its type and the last one arrives: the
        // numbers outside those are not the stream's.
        for t in 0..FrameType::COUNT {
            if let Some(first) = fates.iter().position(|f| f.type_index == t) {
                fates[first].dropped = false;
                fates[first].delay = 0;
            }
            if let Some(last) = fates.iter().rposition(|f| f.type_index == t) {
                fates[last].dropped = false;
            }
        }
        // Number the frames per type; each arrives at (made + delay), copies after their own delay.
        let mut next = start;
        let mut arrivals: Vec<(u64, Frame)> = Vec::new();
        let mut copies = 0u64;
        for (k, fate) in fates.iter().enumerate() {
            let k = k as u64;
            let frame = Frame {
                seq: next[fate.type_index],
                device_time_us: (k * 1_000) as u32,
                payload: payload(fate.type_index),
            };
            next[fate.type_index] = next[fate.type_index].wrapping_add(1);
            if !fate.dropped {
                arrivals.push((k + fate.delay, frame));
            }
            if let Some(d) = fate.copy {
                arrivals.push((k + d, frame));
                // A copy of a dropped frame is the only one to arrive.
                copies += u64::from(!fate.dropped);
            }
        }
        // Stable: a frame and its copy arriving together keep the order they were sent in.
        arrivals.sort_by_key(|(at, _)| *at);

        let mut decoder = Decoder::new();
        let mut delivered: Vec<(usize, u64)> = Vec::new();
        for (at, frame) in &arrivals {
            let rx_ns = at / BURST_MS * BURST_MS * MS;
            decoder.push(&encode_one(frame), rx_ns, |d| {
                delivered.push((d.payload.frame_type().index(), d.seq));
            });
        }

        let stats = decoder.stats();
        let sent = fates.len() as u64;
        prop_assert_eq!(stats.frames + stats.late + stats.lost_frames, sent);
        prop_assert_eq!(stats.duplicates, copies);
        prop_assert_eq!((stats.seq_jumps, stats.time_rebases), (0, 0));
        prop_assert_eq!(stats.frames, delivered.len() as u64);
        for (t, first_wire) in start.iter().enumerate() {
            let seqs: Vec<u64> = delivered.iter().filter(|d| d.0 == t).map(|d| d.1).collect();
            prop_assert!(seqs.windows(2).all(|w| w[0] < w[1]), "type {} not increasing", t);
            // The extension is exact: the last delivered is the first plus the frames in between.
            let sent_of_type = fates.iter().filter(|f| f.type_index == t).count() as u64;
            if let (Some(first), Some(last)) = (seqs.first(), seqs.last()) {
                prop_assert_eq!(*first, u64::from(*first_wire));
                prop_assert_eq!(last - first + 1, sent_of_type);
            }
        }
    }
}
