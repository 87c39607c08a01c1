//! A feed whose sequence numbers start anywhere in the 16-bit range (a device does not start at
//! 0 after a power cycle), at 1 kHz with receive times in 4 ms reads: one frame swapped with its
//! neighbour is late, not lost; a real gap of k frames is k lost; passing the wrap loses nothing.

mod common;

use common::encode_one;
use proptest::prelude::*;
use rins_protocol::{Decoder, DecoderStats, Frame, ImuFrame, Payload};

const MS: u64 = 1_000_000;
const READ_MS: u64 = 4;

/// The k-th frame from `start`: its wire number and device time follow k.
fn frame(start: u16, k: u64) -> Frame {
    Frame {
        // Truncation intended: the wire number wraps.
        seq: start.wrapping_add(k as u16),
        device_time_us: (k * 1_000) as u32,
        payload: Payload::Imu(ImuFrame::default()),
    }
}

/// Feeds the frames numbered `ks` (k-th made at k ms, read with its 4 ms read).
fn feed(start: u16, ks: &[u64]) -> DecoderStats {
    let mut d = Decoder::new();
    for &k in ks {
        d.push(
            &encode_one(&frame(start, k)),
            k / READ_MS * READ_MS * MS,
            |_| {},
        );
    }
    d.stats()
}

const N: u64 = 3_000;

proptest! {
    #![proptest_config(common::config(64))]

    #[test]
    fn one_swapped_frame_is_late_and_nothing_is_lost(start in any::<u16>(), at in 0..N - 1) {
        let mut ks: Vec<u64> = (0..N).collect();
        ks.swap(at as usize, at as usize + 1);
        let s = feed(start, &ks);
        prop_assert_eq!((s.lost_frames, s.late, s.duplicates, s.seq_jumps), (0, 1, 0, 0));
        prop_assert_eq!(s.frames, N - 1);
    }

    #[test]
    fn a_gap_of_k_frames_is_k_lost(start in any::<u16>(), at in 1..N - 200, k in 1..200u64) {
        let ks: Vec<u64> = (0..N).filter(|i| !(at..at + k).contains(i)).collect();
        let s = feed(start, &ks);
        prop_assert_eq!((s.lost_frames, s.late, s.seq_jumps), (k, 0, 0));
    }
}

#[test]
fn passing_the_counter_wrap_loses_nothing() {
    // 65 535 → 0 halfway through, and once more 65 536 frames later.
    let ks: Vec<u64> = (0..70_000).collect();
    let s = feed(65_535 - 1_500, &ks);
    assert_eq!((s.lost_frames, s.late, s.seq_jumps), (0, 0, 0));
    assert_eq!(s.frames, 70_000);
}

/// The frames `0..n` in order, but frame `k` arrives right after frame `k + by` instead.
fn one_moved_back(n: u64, k: u64, by: u64) -> Vec<u64> {
    let mut ks: Vec<u64> = (0..n).filter(|&i| i != k).collect();
    let at = ks.iter().position(|&i| i == k + by).expect("in range") + 1;
    ks.insert(at, k);
    ks
}

#[test]
fn one_frame_far_out_of_place_is_late_and_loses_nothing() {
    // 1 792 places late: beyond the window of numbers whose reception is remembered, but a
    // single frame, which the next frames contradict — not a counter that restarted there.
    // Early in the feed, before the frame period is learnt ...
    let s = feed(40_000, &one_moved_back(3_000, 150, 1_792));
    assert_eq!((s.lost_frames, s.seq_jumps, s.late), (0, 0, 1), "{s:?}");
    assert_eq!(s.frames, 2_999);
    // ... and once it is.
    let s = feed(12_345, &one_moved_back(12_000, 6_000, 1_792));
    assert_eq!((s.lost_frames, s.seq_jumps, s.late), (0, 0, 1), "{s:?}");
}

#[test]
fn a_counter_that_restarts_far_behind_is_still_a_jump() {
    // The device restarts its counter at 100 after frame 3 000 (number 3 099): the new numbers
    // run on from there, and are delivered (all but the first, which only the second confirms).
    let mut d = Decoder::new();
    let mut delivered = Vec::new();
    for k in 0..6_000u64 {
        let wire = if k < 3_000 {
            100 + k
        } else {
            100 + (k - 3_000)
        };
        let f = Frame {
            seq: wire as u16,
            device_time_us: (k * 1_000) as u32,
            payload: Payload::Imu(ImuFrame::default()),
        };
        d.push(&encode_one(&f), k / READ_MS * READ_MS * MS, |f| {
            delivered.push(f.seq)
        });
    }
    let s = d.stats();
    assert_eq!((s.lost_frames, s.seq_jumps), (0, 1), "{s:?}");
    assert_eq!(s.frames, 5_999, "{s:?}");
    assert!(delivered.windows(2).all(|w| w[0] < w[1]));
}
