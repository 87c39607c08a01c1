//! The attachment rmw_zenoh puts on every sample and its subscribers require (a sample without one
//! is dropped): the publisher's sequence number, the source timestamp (system clock, ns since
//! 1970) and the publisher's 16-byte GID, serialized as Zenoh's serializer writes them (rmw_zenoh
//! 0.2.4 and later, ROS 2 Jazzy and newer): two little-endian `i64`, then the GID as a sequence,
//! its length as a LEB128 varint (one byte, 16) before the bytes. 33 bytes in all.

/// The attachment's length.
pub const LEN: usize = 8 + 8 + 1 + 16;

/// The attachment of sample `sequence` (from 1) of publisher `gid`, published at `timestamp_ns`.
pub fn attachment(sequence: i64, timestamp_ns: i64, gid: &[u8; 16]) -> [u8; LEN] {
    let mut out = [0u8; LEN];
    out[..8].copy_from_slice(&sequence.to_le_bytes());
    out[8..16].copy_from_slice(&timestamp_ns.to_le_bytes());
    out[16] = 16;
    out[17..].copy_from_slice(gid);
    out
}

/// A publisher's GID as rmw_zenoh makes it: the 128-bit XXH3 hash of its liveliness token, low
/// half first, little endian.
pub fn gid_of(token: &str) -> [u8; 16] {
    xxhash_rust::xxh3::xxh3_128(token.as_bytes()).to_le_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_layout_is_two_integers_then_a_counted_gid() {
        let gid: [u8; 16] = std::array::from_fn(|k| k as u8 + 1);
        let a = attachment(1, 0x0102_0304_0506_0708, &gid);
        assert_eq!(&a[..8], &[1, 0, 0, 0, 0, 0, 0, 0]);
        assert_eq!(&a[8..16], &[8, 7, 6, 5, 4, 3, 2, 1]);
        assert_eq!(a[16], 16);
        assert_eq!(&a[17..], &gid);
    }

    #[test]
    fn gids_differ_between_publishers_and_stay_for_one() {
        assert_eq!(gid_of("a"), gid_of("a"));
        assert_ne!(gid_of("@ros2_lv/0/x/0/1/MP"), gid_of("@ros2_lv/0/x/0/2/MP"));
    }
}
