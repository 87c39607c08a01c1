//! Encode → stream → decode round trips under arbitrary chunking.

mod common;

use common::{arb_chunks, arb_consecutive_frames, encode_one, push_chunked, to_wire};
use proptest::prelude::*;
use rins_protocol::{Decoder, FrameType};

proptest! {
    #![proptest_config(common::config(512))]

    #[test]
    fn frames_survive_any_chunking(frames in arb_consecutive_frames(40), chunks in arb_chunks()) {
        let stream: Vec<u8> = frames.iter().flat_map(encode_one).collect();
        let mut decoder = Decoder::new();
        let decoded = push_chunked(&mut decoder, &stream, &chunks);

        prop_assert_eq!(decoded.len(), frames.len());
        let mut first_seq: [Option<u64>; FrameType::COUNT] = [None; FrameType::COUNT];
        let mut count_by_type = [0u64; FrameType::COUNT];
        let mut elapsed = 0u64;
        for (k, (d, f)) in decoded.iter().zip(&frames).enumerate() {
            prop_assert_eq!(to_wire(d), *f);
            // Sequence numbers advance by one per type: the extension counts up from the first.
            let i = f.payload.frame_type().index();
            let first = *first_seq[i].get_or_insert(u64::from(f.seq));
            prop_assert_eq!(d.seq, first + count_by_type[i]);
            count_by_type[i] += 1;
            // Device time only moves forward: the extension is the first time plus the steps.
            if k > 0 {
                elapsed += u64::from(f.device_time_us.wrapping_sub(frames[k - 1].device_time_us));
            }
            prop_assert_eq!(d.device_time_us, u64::from(frames[0].device_time_us) + elapsed);
        }

        let stats = decoder.stats();
        prop_assert_eq!(stats.frames, frames.len() as u64);
        prop_assert_eq!(stats.frames_by_type, count_by_type);
        prop_assert_eq!(
            (stats.crc_errors, stats.malformed, stats.lost_frames, stats.resync_bytes),
            (0, 0, 0, 0)
        );
        prop_assert_eq!(decoder.buffered_len(), 0);
    }

    /// Until the last byte of a frame has arrived nothing is handed out, and it is handed out as
    /// soon as it has.
    #[test]
    fn a_frame_is_delivered_exactly_when_complete(frames in arb_consecutive_frames(4)) {
        let mut decoder = Decoder::new();
        for f in &frames {
            let bytes = encode_one(f);
            let mut got = 0;
            for (k, b) in bytes.iter().enumerate() {
                decoder.push(std::slice::from_ref(b), 0, |d| {
                    assert_eq!(to_wire(&d), *f);
                    got += 1;
                });
                prop_assert_eq!(got, usize::from(k + 1 == bytes.len()));
            }
        }
    }
}
