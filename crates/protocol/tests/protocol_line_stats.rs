//! The decoder's account of the line: bytes read, valid frames, bytes discarded, and why the last
//! undecodable bytes were refused — what acquisition reports when no frame gets through.

mod common;

use common::{encode_one, example_imu_frame};
use rins_protocol::layout::TYPE_OFFSET;
use rins_protocol::{DecodeError, Decoder, Frame, link_error};

/// Bytes with no 0xA5 in them: not even the start of a sync word.
fn garbage(n: usize) -> Vec<u8> {
    (0..n).map(|i| (i * 13 % 0xA0) as u8).collect()
}

fn frame(seq: u16) -> Vec<u8> {
    encode_one(&Frame {
        seq,
        device_time_us: u32::from(seq) * 1000,
        ..example_imu_frame()
    })
}

fn push(d: &mut Decoder, bytes: &[u8]) -> usize {
    let mut n = 0;
    d.push(bytes, 0, |_| n += 1);
    n
}

#[test]
fn garbage_is_counted_read_and_discarded_as_no_sync() {
    let mut d = Decoder::new();
    assert_eq!(d.stats().last_error, None);
    assert_eq!(push(&mut d, &garbage(1000)), 0);
    let s = d.stats();
    assert_eq!((s.bytes, s.resync_bytes, s.valid_frames()), (1000, 1000, 0));
    assert_eq!(s.last_error, Some(DecodeError::NoSync));
    assert_eq!(
        link_error(s.last_error.as_ref()),
        ipc_types::LinkError::NoSync
    );
    // Frames after the garbage get through and are counted valid; the last refusal stays.
    let frames: Vec<u8> = (0..3).flat_map(frame).collect();
    assert_eq!(push(&mut d, &frames), 3);
    let s = d.stats();
    assert_eq!(s.bytes, 1000 + frames.len() as u64);
    assert_eq!((s.valid_frames(), s.resync_bytes), (3, 1000));
}

#[test]
fn a_bad_crc_is_the_last_error_not_the_bytes_it_claimed() {
    let mut d = Decoder::new();
    let mut bad = frame(1);
    let last = bad.len() - 1;
    bad[last] ^= 0xFF;
    // The rejected frame's own bytes are skipped too, without making it a missing sync word.
    assert_eq!(push(&mut d, &bad), 0);
    let s = d.stats();
    assert_eq!(
        (s.crc_errors, s.malformed, s.bytes),
        (1, 0, bad.len() as u64)
    );
    assert_eq!(s.resync_bytes, bad.len() as u64);
    assert!(
        matches!(s.last_error, Some(DecodeError::CrcMismatch { .. })),
        "{:?}",
        s.last_error
    );
    // Garbage after it is another matter.
    push(&mut d, &garbage(5));
    assert_eq!(d.stats().last_error, Some(DecodeError::NoSync));
    // A valid frame next counts, and a duplicate of it is valid too (withheld, not refused).
    let good = frame(2);
    assert_eq!(push(&mut d, &good), 1);
    assert_eq!(push(&mut d, &good), 0);
    let s = d.stats();
    assert_eq!((s.frames, s.duplicates, s.valid_frames()), (1, 1, 2));
}

#[test]
fn malformed_frames_name_their_fault() {
    // Unknown type byte 9 in an otherwise well-formed header.
    let mut unknown = frame(1);
    unknown[TYPE_OFFSET] = 9;
    let mut d = Decoder::new();
    push(&mut d, &unknown);
    assert_eq!(d.stats().malformed, 1);
    assert!(
        matches!(
            d.stats().last_error,
            Some(DecodeError::UnknownFrameType { value: 9 })
        ),
        "{:?}",
        d.stats().last_error
    );
    assert_eq!(
        link_error(d.stats().last_error.as_ref()),
        ipc_types::LinkError::UnknownFrameType
    );
    // A baro frame announcing 200 payload bytes: implausible for its type.
    let mut d = Decoder::new();
    push(&mut d, &[0xA5, 0x5A, 2, 200, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        link_error(d.stats().last_error.as_ref()),
        ipc_types::LinkError::BadLength
    );
}
