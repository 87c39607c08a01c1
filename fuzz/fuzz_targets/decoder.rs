//! Feeds arbitrary bytes to the streaming frame decoder in arbitrary-sized chunks.
//!
//! Input layout: byte 0 = k (taken mod 8), bytes 1..=k = chunk sizes (cycled; 0 = an empty push
//! followed by a one-byte push), the rest = the byte stream. k = 0 pushes the stream at once.
//!
//! Push n is received at n × 100 ms on the receive clock, so that the decoder's warm-up, learnt
//! periods and discontinuity checks are reached by short inputs.
//!
//! Beyond "never panics", it checks that every frame handed out occurs literally in the stream —
//! or, once the decoder has counted a re-base (a sequence jump or a device-time discontinuity),
//! with only its sequence number and time differing — and that every byte is accounted for (in a
//! frame handed out, withheld as a duplicate or late frame, discarded, or still buffered).

#![no_main]

use libfuzzer_sys::fuzz_target;
use rins_protocol::layout::{CRC_LEN, SEQ_OFFSET, TIME_OFFSET};
use rins_protocol::{DecodedFrame, Decoder, Frame, MAX_FRAME_LEN, encode};

fuzz_target!(|data: &[u8]| {
    let Some((&k, rest)) = data.split_first() else {
        return;
    };
    let (sizes, stream) = rest.split_at(usize::from(k % 8).min(rest.len()));

    let mut decoder = Decoder::new();
    let mut frames = 0u64;
    let mut frame_bytes = 0u64;
    let mut rebased = 0u64;
    let mut on_frame = |d: DecodedFrame| {
        let wire = Frame {
            seq: d.seq as u16,
            device_time_us: d.device_time_us as u32,
            payload: d.payload,
        };
        let mut buf = [0u8; MAX_FRAME_LEN];
        let n = encode(&wire, &mut buf).expect("a decoded frame re-encodes");
        let literal = |w: &[u8]| w == &buf[..n];
        // A re-based frame keeps everything but its sequence number and time (and so its CRC).
        let rebased_only = |w: &[u8]| {
            w[..SEQ_OFFSET] == buf[..SEQ_OFFSET]
                && w[TIME_OFFSET + 4..n - CRC_LEN] == buf[TIME_OFFSET + 4..n - CRC_LEN]
        };
        if !stream.windows(n).any(literal) {
            assert!(
                stream.windows(n).any(rebased_only),
                "decoded frame not present in the input"
            );
            rebased += 1;
        }
        frames += 1;
        frame_bytes += n as u64;
    };

    let mut rest = stream;
    let mut size = sizes.iter().cycle();
    let mut pushes = 0u64;
    let mut push = |decoder: &mut Decoder, bytes: &[u8], on_frame: &mut dyn FnMut(DecodedFrame)| {
        decoder.push(bytes, pushes * 100_000_000, on_frame);
        pushes += 1;
    };
    while !rest.is_empty() {
        let n = size
            .next()
            .map_or(rest.len(), |&s| usize::from(s))
            .min(rest.len());
        let (head, tail) = rest.split_at(n);
        push(&mut decoder, head, &mut on_frame);
        rest = tail;
        if n == 0 {
            let (one, tail) = rest.split_at(1);
            push(&mut decoder, one, &mut on_frame);
            rest = tail;
        }
    }

    let stats = decoder.stats();
    assert_eq!(stats.frames, frames);
    assert!(
        rebased == 0 || stats.seq_jumps + stats.time_rebases > 0,
        "a frame changed without a counted re-base"
    );
    assert!(decoder.buffered_len() < MAX_FRAME_LEN);
    assert_eq!(
        frame_bytes + stats.withheld_bytes + stats.resync_bytes + decoder.buffered_len() as u64,
        stream.len() as u64
    );
});
