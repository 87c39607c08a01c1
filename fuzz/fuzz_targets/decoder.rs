//! Feeds arbitrary bytes to the streaming frame decoder in arbitrary-sized chunks.
//!
//! Input layout: byte 0 = k (taken mod 8), bytes 1..=k = chunk sizes (cycled; 0 = an empty push
//! followed by a one-byte push), the rest = the byte stream. k = 0 pushes the stream at once.
//!
//! Beyond "never panics", it checks that every frame handed out occurs literally in the stream
//! (but for the time of a frame stamped before the first one, which the decoder clamps at zero)
//! and that every byte is accounted for (in a frame, discarded, or still buffered).

#![no_main]

use libfuzzer_sys::fuzz_target;
use rins_acquisition::protocol::layout::{CRC_LEN, TIME_OFFSET};
use rins_acquisition::protocol::{DecodedFrame, Decoder, Frame, MAX_FRAME_LEN, encode};

fuzz_target!(|data: &[u8]| {
    let Some((&k, rest)) = data.split_first() else {
        return;
    };
    let (sizes, stream) = rest.split_at(usize::from(k % 8).min(rest.len()));

    let mut decoder = Decoder::new();
    let mut frames = 0u64;
    let mut frame_bytes = 0u64;
    let mut on_frame = |d: DecodedFrame| {
        let wire = Frame {
            seq: d.seq as u16,
            device_time_us: d.device_time_us as u32,
            payload: d.payload,
        };
        let mut buf = [0u8; MAX_FRAME_LEN];
        let n = encode(&wire, &mut buf).expect("a decoded frame re-encodes");
        // A frame stamped before the first frame of the stream (and before the device clock's
        // first wrap) has its extended time clamped at zero, as the time extender documents: its
        // re-encoding differs in the time field and so in the CRC, and only the rest must match.
        let clamped = d.device_time_us == 0;
        let matches = |w: &[u8]| {
            if clamped {
                w[..TIME_OFFSET] == buf[..TIME_OFFSET]
                    && w[TIME_OFFSET + 4..n - CRC_LEN] == buf[TIME_OFFSET + 4..n - CRC_LEN]
            } else {
                w == &buf[..n]
            }
        };
        assert!(
            stream.windows(n).any(matches),
            "decoded frame not present in the input"
        );
        frames += 1;
        frame_bytes += n as u64;
    };

    let mut rest = stream;
    let mut size = sizes.iter().cycle();
    while !rest.is_empty() {
        let n = size
            .next()
            .map_or(rest.len(), |&s| usize::from(s))
            .min(rest.len());
        let (head, tail) = rest.split_at(n);
        decoder.push(head, &mut on_frame);
        rest = tail;
        if n == 0 {
            let (one, tail) = rest.split_at(1);
            decoder.push(one, &mut on_frame);
            rest = tail;
        }
    }

    let stats = decoder.stats();
    assert_eq!(stats.frames, frames);
    assert!(decoder.buffered_len() < MAX_FRAME_LEN);
    assert_eq!(
        frame_bytes + stats.resync_bytes + decoder.buffered_len() as u64,
        stream.len() as u64
    );
});
