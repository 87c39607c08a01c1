//! Garbage, bit errors and truncated frames: the decoder never panics, hands out only frames that
//! were sent, and loses nothing but the damaged frame.

mod common;

use common::{arb_chunks, arb_consecutive_frames, encode_one, flush, push_chunked, to_wire};
use proptest::collection::vec;
use proptest::prelude::*;
use rins_protocol::{Decoder, Frame, MAX_FRAME_LEN};

/// Garbage that looks like the start of frames as often as not: random bytes, sync words with
/// plausible headers, and lone sync bytes.
fn arb_garbage() -> impl Strategy<Value = Vec<u8>> {
    let piece = prop_oneof![
        vec(any::<u8>(), 0..40),
        (0u8..6, any::<u8>(), vec(any::<u8>(), 0..8)).prop_map(|(t, len, tail)| {
            let mut v = vec![0xA5, 0x5A, t, len % 96];
            v.extend(tail);
            v
        }),
        Just(vec![0xA5]),
        Just(vec![0xA5, 0x5A]),
    ];
    vec(piece, 0..6).prop_map(|pieces| pieces.concat())
}

/// Frames other than the `dropped` one, as they should come out of the decoder.
fn expected_without(frames: &[Frame], dropped: usize) -> Vec<Frame> {
    frames
        .iter()
        .enumerate()
        .filter_map(|(k, f)| (k != dropped).then_some(*f))
        .collect()
}

/// Losses the decoder must report when frame `dropped` of a consecutive stream is missing: one if
/// frames of the same type come both before it (setting the reference) and after it (revealing
/// the gap), else none.
fn expected_loss(frames: &[Frame], dropped: usize) -> u64 {
    let t = frames[dropped].payload.frame_type();
    let same = |f: &Frame| f.payload.frame_type() == t;
    u64::from(frames[..dropped].iter().any(same) && frames[dropped + 1..].iter().any(same))
}

proptest! {
    #![proptest_config(common::config(512))]

    /// Random bytes: no panic, and anything handed out is a frame that literally occurs, CRC and
    /// all, in the input (re-encoding it gives bytes found there). Every byte is accounted for
    /// (handed out, withheld as a duplicate or late frame, discarded, or buffered).
    #[test]
    fn garbage_alone_yields_only_frames_present_in_it(
        garbage in prop_oneof![vec(any::<u8>(), 0..2000), arb_garbage()],
        chunks in arb_chunks(),
    ) {
        let mut decoder = Decoder::new();
        let decoded = push_chunked(&mut decoder, &garbage, &chunks);
        let mut frame_bytes = 0;
        for d in &decoded {
            let bytes = encode_one(&to_wire(d));
            prop_assert!(garbage.windows(bytes.len()).any(|w| w == bytes.as_slice()));
            frame_bytes += bytes.len();
        }
        let stats = decoder.stats();
        prop_assert_eq!(stats.frames, decoded.len() as u64);
        prop_assert!(decoder.buffered_len() < MAX_FRAME_LEN);
        prop_assert_eq!(
            frame_bytes as u64
                + stats.withheld_bytes
                + stats.resync_bytes
                + decoder.buffered_len() as u64,
            garbage.len() as u64
        );
    }

    /// Garbage before, between and after real frames: every real frame comes out, in order, and
    /// exactly the garbage is discarded.
    #[test]
    fn frames_interleaved_with_garbage_are_all_recovered(
        frames in arb_consecutive_frames(20),
        garbage in vec(arb_garbage(), 21),
        chunks in arb_chunks(),
    ) {
        let mut stream = Vec::new();
        let mut garbage_len = 0;
        for (f, g) in frames.iter().zip(&garbage) {
            stream.extend(g);
            stream.extend(encode_one(f));
            garbage_len += g.len();
        }
        stream.extend(&garbage[frames.len()]);
        stream.extend(flush());
        garbage_len += garbage[frames.len()].len() + flush().len();

        let mut decoder = Decoder::new();
        let decoded = push_chunked(&mut decoder, &stream, &chunks);
        let got: Vec<Frame> = decoded.iter().map(to_wire).collect();
        prop_assert_eq!(got, frames);
        let stats = decoder.stats();
        prop_assert_eq!(stats.resync_bytes, garbage_len as u64);
        prop_assert_eq!(stats.lost_frames, 0);
        prop_assert_eq!(decoder.buffered_len(), 0);
    }

    /// One bit flipped anywhere in one frame: that frame alone is dropped and counted.
    #[test]
    fn a_bit_flip_drops_only_the_hit_frame(
        frames in arb_consecutive_frames(12),
        which in any::<prop::sample::Index>(),
        in_header in any::<bool>(),
        byte in any::<prop::sample::Index>(),
        bit in 0u8..8,
        chunks in arb_chunks(),
    ) {
        let hit = which.index(frames.len());
        let mut stream = Vec::new();
        let mut hit_len = 0;
        let mut hit_byte = 0;
        for (k, f) in frames.iter().enumerate() {
            let mut bytes = encode_one(f);
            if k == hit {
                // Half the flips go to the header fields, where they are hardest to survive.
                hit_byte = if in_header { 2 + byte.index(8) } else { byte.index(bytes.len()) };
                bytes[hit_byte] ^= 1 << bit;
                hit_len = bytes.len();
            }
            stream.extend(bytes);
        }
        stream.extend(flush());

        let mut decoder = Decoder::new();
        let decoded = push_chunked(&mut decoder, &stream, &chunks);
        let got: Vec<Frame> = decoded.iter().map(to_wire).collect();
        prop_assert_eq!(got, expected_without(&frames, hit));

        let stats = decoder.stats();
        // A damaged sync word hides the frame without a candidate to reject; any other flip is
        // caught by the header checks or the CRC.
        if hit_byte >= 2 {
            prop_assert!(stats.crc_errors + stats.malformed >= 1);
        }
        prop_assert_eq!(stats.resync_bytes, (hit_len + MAX_FRAME_LEN) as u64);
        prop_assert_eq!(stats.lost_frames, expected_loss(&frames, hit));
    }

    /// A frame cut short and directly followed by the next: only the cut frame is lost.
    #[test]
    fn a_truncated_frame_does_not_take_the_next_one_with_it(
        frames in arb_consecutive_frames(12),
        which in any::<prop::sample::Index>(),
        keep in any::<prop::sample::Index>(),
        chunks in arb_chunks(),
    ) {
        let cut = which.index(frames.len());
        let mut stream = Vec::new();
        let mut kept = 0;
        let mut cut_off = Vec::new();
        let mut cut_end = 0;
        for (k, f) in frames.iter().enumerate() {
            let bytes = encode_one(f);
            if k == cut {
                kept = keep.index(bytes.len()); // 0..len: strictly shorter
                stream.extend(&bytes[..kept]);
                cut_off = bytes[kept..].to_vec();
                cut_end = stream.len();
            } else {
                stream.extend(bytes);
            }
        }
        stream.extend(flush());
        // If the bytes that follow happen to begin with exactly the bytes cut off (say the frame
        // ended in A5 and lost only that byte), the stream *is* the whole frame followed by a
        // damaged next one; no decoder can tell the difference.
        prop_assume!(!stream[cut_end..].starts_with(&cut_off));

        let mut decoder = Decoder::new();
        let decoded = push_chunked(&mut decoder, &stream, &chunks);
        let got: Vec<Frame> = decoded.iter().map(to_wire).collect();
        prop_assert_eq!(got, expected_without(&frames, cut));
        let stats = decoder.stats();
        prop_assert_eq!(stats.resync_bytes, (kept + MAX_FRAME_LEN) as u64);
        prop_assert_eq!(stats.lost_frames, expected_loss(&frames, cut));
    }
}

#[test]
fn a_sync_word_in_garbage_does_not_swallow_the_frame_after_it() {
    let frame = common::example_imu_frame();
    let bytes = encode_one(&frame);
    // A fake IMU header announcing the longest payload, right before a real frame.
    let mut stream = vec![0xA5, 0x5A, 0x01, 81, 0, 0];
    stream.extend(&bytes);
    let mut decoder = Decoder::new();
    let mut got = Vec::new();
    decoder.push(&stream, 0, |d| got.push(to_wire(&d)));
    // The fake candidate needs 95 bytes; only 49 are there, so the real frame waits...
    assert!(got.is_empty());
    // ...until enough bytes arrive to reject the candidate: MAX_FRAME_LEN from the fake start.
    decoder.push(&[0u8; MAX_FRAME_LEN - 49], 0, |d| got.push(to_wire(&d)));
    assert_eq!(got, vec![frame]);
    let stats = decoder.stats();
    assert_eq!(stats.crc_errors, 1);
    assert_eq!(stats.resync_bytes, 6 + (MAX_FRAME_LEN - 49) as u64);
}

#[test]
fn reset_drops_buffered_bytes_but_keeps_counters() {
    let frame = common::example_imu_frame();
    let bytes = encode_one(&frame);
    let mut decoder = Decoder::new();
    let mut got = Vec::new();
    decoder.push(&[1, 2, 3], 0, |d| got.push(d));
    decoder.push(&bytes[..20], 0, |d| got.push(d));
    assert_eq!(decoder.buffered_len(), 20);
    decoder.reset();
    assert_eq!(decoder.buffered_len(), 0);
    assert_eq!(decoder.stats().resync_bytes, 23);
    // The tail of the interrupted frame is garbage now; the next whole frame decodes.
    decoder.push(&bytes[20..], 0, |d| got.push(d));
    decoder.push(&bytes, 0, |d| got.push(d));
    assert_eq!(got.len(), 1);
    assert_eq!(to_wire(&got[0]), frame);
    assert_eq!(decoder.stats().resync_bytes, 23 + 23);
}
