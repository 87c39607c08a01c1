//! MAVLink 2 message signing: the secret key from its file, the signing of what rins sends, and
//! the verification of what it receives.
//!
//! The key file holds the 32-byte key as exactly 64 hexadecimal digits, optionally followed by one
//! newline. Text rather than raw bytes because the tools that set up the other end of the link
//! speak hexadecimal: `sha256sum` prints the key a ground station derives from a passphrase in
//! that form, and pymavlink's `bytes.fromhex` reads it back; a stray newline or a truncated copy is
//! seen at once instead of becoming a different key. The file must be a regular file owned by the
//! user rins runs as, with no permission for group or others: anyone who can read it can command
//! the vehicle's navigation.
//!
//! A signature is SHA-256 over the key and the frame, cut to 48 bits, with a 48-bit timestamp in
//! units of 10 µs since 2015-01-01 and the link id (the MAVLink signing specification). A receiver
//! keeps the newest timestamp of each (link, system, component) stream and refuses one not newer:
//! a recorded frame sent again is not accepted.

use std::collections::HashMap;
use std::os::unix::fs::MetadataExt;
use std::path::Path;
use std::time::SystemTime;

use std::io::Read;

use anyhow::{Context, Result, anyhow, bail};
use mavlink::{MAVLinkV2MessageRaw, SigningConfig, SigningData};

use crate::config::MavlinkConfig;

/// The key's length in bytes, as the signing specification fixes it.
pub const KEY_BYTES: usize = 32;
/// The key file's largest accepted size: the digits and one newline.
const KEY_FILE_LIMIT: u64 = 2 * KEY_BYTES as u64 + 1;
/// Permission bits the key file must not have: any access by group or others.
const GROUP_OTHER_BITS: u32 = 0o077;
/// The signing epoch, 2015-01-01T00:00:00Z, in seconds since the Unix epoch.
const SIGNING_EPOCH_S: u64 = 1_420_070_400;
/// How far behind the newest timestamp seen a new stream may start, in 10 µs units: one minute,
/// as the specification sets it.
const NEW_STREAM_WINDOW: u64 = 60 * 100_000;
/// Streams whose timestamps are remembered; beyond it the one heard from longest ago is
/// forgotten. Only holders of the key can add one.
const MAX_STREAMS: usize = 256;

/// The 32-byte key from its file's text: exactly 64 hexadecimal digits, optionally followed by one
/// newline (`\n`). The error says what is wrong, without showing the text.
pub fn parse_key(text: &str) -> Result<[u8; KEY_BYTES], String> {
    let digits = text.strip_suffix('\n').unwrap_or(text);
    if digits.len() != 2 * KEY_BYTES {
        return Err(format!(
            "holds {} characters{}; expected exactly {} hexadecimal digits (a 32-byte key), optionally followed by one newline",
            digits.chars().count(),
            if digits.ends_with(['\n', '\r', ' ']) {
                " ending in white space"
            } else {
                ""
            },
            2 * KEY_BYTES
        ));
    }
    let mut key = [0u8; KEY_BYTES];
    for (i, pair) in digits.as_bytes().chunks_exact(2).enumerate() {
        let (Some(hi), Some(lo)) = (hex_value(pair[0]), hex_value(pair[1])) else {
            return Err(format!(
                "character {} is not a hexadecimal digit; expected exactly {} hexadecimal digits",
                2 * i + usize::from(hex_value(pair[0]).is_some()) + 1,
                2 * KEY_BYTES
            ));
        };
        key[i] = hi << 4 | lo;
    }
    Ok(key)
}

fn hex_value(c: u8) -> Option<u8> {
    match c {
        b'0'..=b'9' => Some(c - b'0'),
        b'a'..=b'f' => Some(c - b'a' + 10),
        b'A'..=b'F' => Some(c - b'A' + 10),
        _ => None,
    }
}

/// Reads the key at `path`, refusing a file that is not a regular file owned by `owner` with no
/// permission for group or others, or not exactly in the key format. Errors name the field, the
/// path and what was found. The owner and mode checked are those of the file opened, not of
/// whatever is at the path a moment before or after.
pub fn load_key(path: &Path, owner: u32) -> Result<[u8; KEY_BYTES]> {
    let what = "mavlink.signing_key_file";
    let shown = path.display();
    let (file, _) =
        rins_regular_file::open_regular(path, KEY_FILE_LIMIT).map_err(|e| anyhow!("{what} {e}"))?;
    let meta = file
        .metadata()
        .map_err(|e| anyhow!("{what} {shown}: cannot inspect: {e}"))?;
    if meta.uid() != owner {
        bail!(
            "{what} {shown}: owned by {}, not by {} that rins runs as: the key must be the running user's own",
            rins_runtime::user::describe(meta.uid()),
            rins_runtime::user::describe(owner)
        );
    }
    let mode = meta.mode() & 0o7777;
    if mode & GROUP_OTHER_BITS != 0 {
        bail!(
            "{what} {shown}: mode {mode:04o} lets group or others access the key: `chmod 600 {shown}`"
        );
    }
    let mut bytes = Vec::new();
    // Bounded even if the file grows after the size check.
    file.take(KEY_FILE_LIMIT + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| anyhow!("{what} {shown}: cannot read: {e}"))?;
    let text = std::str::from_utf8(&bytes).map_err(|_| {
        anyhow!(
            "{what} {shown}: not text; expected exactly {} hexadecimal digits",
            2 * KEY_BYTES
        )
    })?;
    parse_key(text).map_err(|why| anyhow!("{what} {shown}: {why}"))
}

/// The key the configuration names, read and checked; `None` when no key is set.
pub fn key_for(config: &MavlinkConfig) -> Result<Option<[u8; KEY_BYTES]>> {
    let Some(path) = &config.signing_key_file else {
        return Ok(None);
    };
    let key = load_key(Path::new(path), rins_runtime::user::effective_uid())
        .context("the MAVLink signing key cannot be used")?;
    Ok(Some(key))
}

/// What signs rins's outgoing frames: the crate's signer, which stamps each frame with the
/// current time in the specification's units and never repeats a timestamp.
pub fn outgoing(key: [u8; KEY_BYTES], link_id: u8) -> SigningData {
    SigningData::from_config(SigningConfig::new(key, link_id, true, false))
}

/// Now as a signing timestamp: 10 µs units since 2015-01-01 (0 for a clock set before it).
pub fn timestamp_now() -> u64 {
    let us = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .map(|d| d.as_micros())
        .unwrap_or(0);
    (us.saturating_sub(u128::from(SIGNING_EPOCH_S) * 1_000_000) / 10) as u64
}

/// What the signature of a received frame showed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SignatureCheck {
    /// No key is configured: nothing was checked.
    NotChecked,
    /// The frame carries no signature.
    Unsigned,
    /// Signed with the key, newer than anything of its stream.
    Valid,
    /// Signed, but not with the key (or altered on the way).
    BadSignature,
    /// Signed with the key, but not newer than what its stream sent before (a replay), or a new
    /// stream more than a minute behind.
    Replayed,
}

/// The receiving side: the key and the newest timestamp of each stream.
pub struct Verifier {
    key: [u8; KEY_BYTES],
    /// Newest timestamp per (link id, system, component).
    streams: HashMap<(u8, u32, u8), u64>,
    /// Newest timestamp seen or read from the clock.
    newest: u64,
}

impl std::fmt::Debug for Verifier {
    // Never the key.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Verifier")
            .field("streams", &self.streams.len())
            .field("newest", &self.newest)
            .finish_non_exhaustive()
    }
}

impl Verifier {
    /// A verifier of frames signed with `key`.
    pub fn new(key: [u8; KEY_BYTES]) -> Self {
        Self {
            key,
            streams: HashMap::new(),
            newest: 0,
        }
    }

    /// Checks `frame`'s signature; `now` is the local clock as a signing timestamp
    /// ([`timestamp_now`]). A valid frame advances its stream's timestamp.
    pub fn check(&mut self, frame: &MAVLinkV2MessageRaw, now: u64) -> SignatureCheck {
        if frame.incompatibility_flags() & mavlink::consts::v2::IFLAG_SIGNED == 0 {
            return SignatureCheck::Unsigned;
        }
        let mut expected = [0u8; mavlink::consts::v2::SIGNATURE_VALUE_SIZE];
        frame.calculate_signature(&self.key, &mut expected);
        if expected != frame.signature_value() {
            return SignatureCheck::BadSignature;
        }
        self.newest = self.newest.max(now);
        let timestamp = frame.signature_timestamp();
        let stream = (
            frame.signature_link_id(),
            frame.system_id(),
            frame.component_id(),
        );
        let fresh = match self.streams.get(&stream) {
            Some(&last) => timestamp > last,
            None => timestamp.saturating_add(NEW_STREAM_WINDOW) >= self.newest,
        };
        if !fresh {
            return SignatureCheck::Replayed;
        }
        if self.streams.len() >= MAX_STREAMS && !self.streams.contains_key(&stream) {
            let oldest = self
                .streams
                .iter()
                .min_by_key(|(_, t)| **t)
                .map(|(k, _)| *k);
            if let Some(oldest) = oldest {
                self.streams.remove(&oldest);
            }
        }
        self.streams.insert(stream, timestamp);
        self.newest = self.newest.max(timestamp);
        SignatureCheck::Valid
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dialect::{COMMAND_LONG_DATA, MavMessage};
    use mavlink::MavHeader;
    use std::os::unix::fs::PermissionsExt;

    const KEY: [u8; 32] = [7; 32];

    /// A COMMAND_LONG frame signed by `signer` (or unsigned), as the wire carries it.
    fn frame(signer: Option<&SigningData>, system: u8) -> MAVLinkV2MessageRaw {
        let header = MavHeader {
            system_id: u32::from(system),
            component_id: 190,
            sequence: 0,
        };
        let mut bytes = Vec::new();
        mavlink::write_v2_msg_signed(
            &mut bytes,
            header,
            &MavMessage::COMMAND_LONG(COMMAND_LONG_DATA::default()),
            signer,
        )
        .unwrap();
        let mut raw = MAVLinkV2MessageRaw::new();
        raw.as_mut_slice()[..bytes.len()].copy_from_slice(&bytes);
        raw
    }

    #[test]
    fn a_key_file_is_64_hex_digits_and_an_optional_newline() {
        let hex = "00ff".repeat(16);
        let mut expected = [0u8; 32];
        for pair in expected.chunks_exact_mut(2) {
            pair[1] = 0xff;
        }
        assert_eq!(parse_key(&hex), Ok(expected));
        assert_eq!(parse_key(&format!("{hex}\n")), Ok(expected));
        assert_eq!(parse_key(&hex.to_uppercase()), Ok(expected));
        let e = parse_key(&format!("{hex}\n\n")).unwrap_err();
        assert!(
            e.starts_with("holds 65 characters ending in white space"),
            "{e}"
        );
        assert!(
            parse_key(&hex[..62])
                .unwrap_err()
                .starts_with("holds 62 characters")
        );
        let e = parse_key(&format!("{}g", &hex[..63])).unwrap_err();
        assert!(e.starts_with("character 64 is not"), "{e}");
        let e = parse_key(&format!("x{}", &hex[1..])).unwrap_err();
        assert!(e.starts_with("character 1 is not"), "{e}");
        assert!(parse_key("").is_err());
    }

    fn scratch(name: &str) -> std::path::PathBuf {
        rins_test_support::scratch::scratch_dir("mavkey", name)
    }

    fn write_key(path: &Path, text: &str, mode: u32) {
        std::fs::write(path, text).unwrap();
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode)).unwrap();
    }

    #[test]
    fn a_key_file_readable_by_others_is_refused_naming_path_and_mode() {
        let dir = scratch("mode");
        let path = dir.join("key");
        let me = rins_runtime::user::effective_uid();
        write_key(&path, &"ab".repeat(32), 0o644);
        let e = format!("{:#}", load_key(&path, me).unwrap_err());
        assert!(
            e.starts_with(&format!(
                "mavlink.signing_key_file {}: mode 0644",
                path.display()
            )),
            "{e}"
        );
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
        assert_eq!(load_key(&path, me).unwrap(), [0xab; 32]);
        // Someone else's file, even private, is not the key of the user rins runs as.
        let e = format!("{:#}", load_key(&path, me.wrapping_add(1)).unwrap_err());
        assert!(e.contains("owned by"), "{e}");
        // 32 raw bytes are not the format.
        write_key(&path, "0123456789abcdef0123456789abcdef", 0o600);
        let e = format!("{:#}", load_key(&path, me).unwrap_err());
        assert!(
            e.contains("holds 32 characters; expected exactly 64"),
            "{e}"
        );
        // Not a regular file.
        let e = format!("{:#}", load_key(&dir, me).unwrap_err());
        assert!(e.contains("is a directory"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn only_frames_signed_with_the_key_and_newer_than_their_stream_pass() {
        let now = timestamp_now();
        let signer = outgoing(KEY, 3);
        let other = outgoing([8; 32], 3);
        let mut v = Verifier::new(KEY);
        let first = frame(Some(&signer), 255);
        assert_eq!(first.signature_link_id(), 3);
        assert_eq!(v.check(&first, now), SignatureCheck::Valid);
        // The same frame again: a replay.
        assert_eq!(v.check(&first, now), SignatureCheck::Replayed);
        assert_eq!(
            v.check(&frame(Some(&signer), 255), now),
            SignatureCheck::Valid
        );
        assert_eq!(v.check(&frame(None, 255), now), SignatureCheck::Unsigned);
        assert_eq!(
            v.check(&frame(Some(&other), 255), now),
            SignatureCheck::BadSignature
        );
        // The signed flag with a garbage signature.
        let mut garbage = frame(Some(&signer), 255);
        garbage.signature_value_mut().copy_from_slice(&[0x5a; 6]);
        assert_eq!(v.check(&garbage, now), SignatureCheck::BadSignature);
        // A changed byte of the frame breaks the signature.
        let mut altered = frame(Some(&signer), 255);
        altered.as_mut_slice()[12] ^= 1;
        assert_eq!(v.check(&altered, now), SignatureCheck::BadSignature);
        // A new stream far behind the clock: a recording from long ago.
        let mut late = Verifier::new(KEY);
        let old = frame(Some(&signer), 254);
        assert_eq!(
            late.check(&old, old.signature_timestamp() + 2 * NEW_STREAM_WINDOW),
            SignatureCheck::Replayed
        );
    }
}
