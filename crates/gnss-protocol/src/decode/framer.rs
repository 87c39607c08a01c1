//! Splits the receiver's byte stream into UBX frames and NMEA sentences. Allocation-free.
//!
//! A UBX frame declares its length before its payload, so a corrupted length would make a framer
//! wait for bytes that never belong to it, holding up (or, with a bounded buffer, losing) the good
//! frames behind it. This framer therefore refuses a declared length that no message it accepts
//! can have at once, counts it, and looks for the next frame from the byte after the sync. A
//! length within that bound is refused the same way as soon as a whole frame or sentence with a
//! good checksum shows up in the bytes it claims: a real frame does not hold another, and the
//! only frame the decoder uses (NAV-PVT) is short, so a long frame of another kind lost to a
//! false alarm costs nothing, while waiting for a corrupted length would hold up every fix behind
//! it for kilobytes.

use ublox::UbxProtocol;
use ublox::proto23::Proto23;

/// The largest UBX payload the framer waits for: the largest any UBX protocol 23 message has
/// (RXM-RAWX, 16 + 32 × 255 measurements = 8176 bytes). Smaller bounds would cut real messages:
/// NAV-SIG on an F9 receiver (8 + 16 bytes per tracked signal) exceeds 1024 bytes with a full
/// sky. A declared length above this is a corrupted header, whatever the class.
pub const MAX_UBX_PAYLOAD: usize = <Proto23 as UbxProtocol>::MAX_PAYLOAD_LEN as usize;

/// NAV-PVT, the message the decoder uses, has one length in every protocol version it reads: a
/// NAV-PVT header declaring another is corrupted, and is refused without waiting for its bytes.
const NAV_PVT: (u8, u8, usize) = (0x01, 0x07, 92);

/// The longest sentence taken, from `$` to the line end inclusive. NMEA 0183 allows 82 bytes, but
/// receivers exceed it (u-blox's high-precision GGA, proprietary PUBX sentences); a sentence's
/// bytes are printable, so a stray `$` in binary data is dropped at its first other byte anyway.
const NMEA_MAX: usize = 256;

const UBX_SYNC: [u8; 2] = [0xB5, 0x62];
const UBX_HEADER: usize = 6;
const UBX_CHECKSUM: usize = 2;
const CAPACITY: usize = UBX_HEADER + MAX_UBX_PAYLOAD + UBX_CHECKSUM;

/// One thing the framer found.
#[derive(Debug, PartialEq, Eq)]
pub enum Framed<'a> {
    /// A UBX frame with a good checksum.
    Ubx {
        /// Message class.
        class: u8,
        /// Message id within the class.
        id: u8,
        /// The payload, without header and checksum.
        payload: &'a [u8],
    },
    /// A UBX frame whose checksum did not match.
    UbxChecksum,
    /// A UBX header whose declared length no accepted message has.
    UbxBadLength,
    /// An NMEA sentence from `$` through the line end (checksum not yet checked).
    Nmea(&'a [u8]),
}

/// Streaming framer of UBX frames and NMEA sentences.
pub struct Framer {
    buf: [u8; CAPACITY],
    len: usize,
}

impl Default for Framer {
    fn default() -> Self {
        Self {
            buf: [0; CAPACITY],
            len: 0,
        }
    }
}

/// What scanning at a sync byte decided.
enum Step {
    /// Skip this many bytes (and report nothing).
    Skip(usize),
    /// Report what was found and go on scanning at `next`.
    Item { kind: Kind, next: usize },
    /// The rest is an unfinished frame: keep it for the next bytes.
    Wait,
}

/// What was found, by its place in the buffer.
#[derive(Clone, Copy)]
enum Kind {
    Ubx { start: usize, end: usize },
    UbxChecksum,
    UbxBadLength,
    Nmea { start: usize, end: usize },
}

impl Framer {
    /// Takes `bytes` and hands every complete item to `on_item`, in stream order.
    pub fn push(&mut self, mut bytes: &[u8], mut on_item: impl FnMut(Framed<'_>)) {
        while !bytes.is_empty() {
            let n = bytes.len().min(CAPACITY - self.len);
            self.buf[self.len..self.len + n].copy_from_slice(&bytes[..n]);
            self.len += n;
            bytes = &bytes[n..];
            self.scan(&mut on_item);
        }
    }

    /// Reports every complete item in the buffer and keeps only an unfinished one. The buffer
    /// holds the largest acceptable frame, so what is kept always leaves room to progress.
    fn scan(&mut self, on_item: &mut impl FnMut(Framed<'_>)) {
        let mut at = 0;
        while at < self.len {
            match self.step(at) {
                Step::Skip(n) => at += n,
                Step::Wait => break,
                Step::Item { kind, next } => {
                    on_item(match kind {
                        Kind::Ubx { start, end } => Framed::Ubx {
                            class: self.buf[start + 2],
                            id: self.buf[start + 3],
                            payload: &self.buf[start + UBX_HEADER..end - UBX_CHECKSUM],
                        },
                        Kind::UbxChecksum => Framed::UbxChecksum,
                        Kind::UbxBadLength => Framed::UbxBadLength,
                        Kind::Nmea { start, end } => Framed::Nmea(&self.buf[start..end]),
                    });
                    at = next;
                }
            }
        }
        self.buf.copy_within(at..self.len, 0);
        self.len -= at;
    }

    fn step(&self, at: usize) -> Step {
        let rest = &self.buf[at..self.len];
        match rest[0] {
            0xB5 => Self::ubx(rest, at),
            b'$' => Self::nmea(rest, at),
            // Bytes between frames are neither: passed over.
            _ => Step::Skip(1),
        }
    }

    fn ubx(rest: &[u8], at: usize) -> Step {
        if rest.len() < 2 {
            return Step::Wait;
        }
        if rest[1] != UBX_SYNC[1] {
            return Step::Skip(1);
        }
        if rest.len() < UBX_HEADER {
            return Step::Wait;
        }
        let (class, id) = (rest[2], rest[3]);
        let declared = usize::from(u16::from_le_bytes([rest[4], rest[5]]));
        let wrong_pvt = (class, id) == (NAV_PVT.0, NAV_PVT.1) && declared != NAV_PVT.2;
        if declared > MAX_UBX_PAYLOAD || wrong_pvt {
            // Resynchronise from the byte after the sync: the next frame may start there.
            return Step::Item {
                kind: Kind::UbxBadLength,
                next: at + UBX_SYNC.len(),
            };
        }
        let total = UBX_HEADER + declared + UBX_CHECKSUM;
        if rest.len() < total {
            if holds_a_whole_frame(&rest[UBX_SYNC.len()..]) {
                return Step::Item {
                    kind: Kind::UbxBadLength,
                    next: at + UBX_SYNC.len(),
                };
            }
            return Step::Wait;
        }
        if !ubx_checksum_ok(&rest[..total]) {
            // The sync may have been payload of something lost: look again right after it.
            return Step::Item {
                kind: Kind::UbxChecksum,
                next: at + UBX_SYNC.len(),
            };
        }
        Step::Item {
            kind: Kind::Ubx {
                start: at,
                end: at + total,
            },
            next: at + total,
        }
    }

    fn nmea(rest: &[u8], at: usize) -> Step {
        for (i, &x) in rest.iter().enumerate().take(NMEA_MAX).skip(1) {
            match x {
                b'\n' if rest[i - 1] == b'\r' => {
                    return Step::Item {
                        kind: Kind::Nmea {
                            start: at,
                            end: at + i + 1,
                        },
                        next: at + i + 1,
                    };
                }
                // A sentence is printable ASCII up to its line end: anything else (another `$`, a
                // UBX sync) means this `$` started no sentence.
                b'\r' => {}
                b'$' => return Step::Skip(1),
                0x20..=0x7E => {}
                _ => return Step::Skip(1),
            }
        }
        if rest.len() >= NMEA_MAX {
            Step::Skip(1)
        } else {
            Step::Wait
        }
    }
}

/// Whether `frame` (sync to checksum) carries the checksum of its class, id, length and payload.
fn ubx_checksum_ok(frame: &[u8]) -> bool {
    let Some(body_end) = frame.len().checked_sub(UBX_CHECKSUM) else {
        return false;
    };
    let (mut a, mut b) = (0u8, 0u8);
    for &x in frame.get(UBX_SYNC.len()..body_end).unwrap_or_default() {
        a = a.wrapping_add(x);
        b = b.wrapping_add(a);
    }
    frame[body_end..] == [a, b]
}

/// Whether `bytes` hold a whole UBX frame or NMEA sentence whose checksum is good.
fn holds_a_whole_frame(bytes: &[u8]) -> bool {
    (0..bytes.len()).any(|i| {
        let rest = &bytes[i..];
        match rest[0] {
            0xB5 => ubx_frame_at(rest),
            b'$' => nmea_sentence_at(rest),
            _ => false,
        }
    })
}

/// Whether `rest` starts with a whole UBX frame of an acceptable length and a good checksum.
fn ubx_frame_at(rest: &[u8]) -> bool {
    if rest.len() < UBX_HEADER || rest[1] != UBX_SYNC[1] {
        return false;
    }
    let declared = usize::from(u16::from_le_bytes([rest[4], rest[5]]));
    let total = UBX_HEADER + declared + UBX_CHECKSUM;
    declared <= MAX_UBX_PAYLOAD && rest.len() >= total && ubx_checksum_ok(&rest[..total])
}

/// Whether `rest` starts with a whole NMEA sentence `$body*hh\r\n` whose checksum is good.
fn nmea_sentence_at(rest: &[u8]) -> bool {
    let Some(end) = rest
        .iter()
        .take(NMEA_MAX)
        .position(|&x| x == b'\n')
        .filter(|&e| e >= 5 && rest[e - 1] == b'\r')
    else {
        return false;
    };
    let (body, tail) = rest[1..end - 1].split_at(end - 5);
    let printable = body
        .iter()
        .all(|&x| (0x20..=0x7E).contains(&x) && x != b'$');
    let given = std::str::from_utf8(tail)
        .ok()
        .and_then(|t| t.strip_prefix('*'))
        .and_then(|h| u8::from_str_radix(h, 16).ok());
    printable && given == Some(body.iter().fold(0, |c, &x| c ^ x))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn collect(bytes: &[u8]) -> Vec<String> {
        let mut f = Framer::default();
        let mut out = Vec::new();
        f.push(bytes, |item| out.push(format!("{item:?}")));
        out
    }

    #[test]
    fn a_stray_dollar_does_not_swallow_a_following_sentence() {
        let items = collect(b"x$GP\x01$GPGGA,1*00\r\n");
        assert_eq!(
            items,
            vec!["Nmea([36, 71, 80, 71, 71, 65, 44, 49, 42, 48, 48, 13, 10])"]
        );
    }

    #[test]
    fn a_sentence_without_a_line_end_is_dropped_after_the_longest_sentence() {
        let mut long = vec![b'$'];
        long.extend([b'A'; NMEA_MAX]);
        long.extend(b"$GPGGA*00\r\n");
        let items = collect(&long);
        assert_eq!(items.len(), 1);
        assert!(items[0].starts_with("Nmea([36, 71, 80"), "{items:?}");
    }

    #[test]
    fn a_header_whose_bytes_hold_a_whole_frame_is_refused() {
        // Class 0x02 (RXM), 4 807 bytes declared; a sentence with a good checksum follows.
        let mut bytes = vec![0xB5, 0x62, 0x02, 0x22, 0xC7, 0x12];
        bytes.extend(b"$GPTXT,01*62\r\n");
        let items = collect(&bytes);
        assert_eq!(items.len(), 2, "{items:?}");
        assert_eq!(items[0], "UbxBadLength");
        assert!(items[1].starts_with("Nmea("), "{items:?}");
        // With a bad checksum, it is no evidence: the header may still be a real frame's.
        let mut bytes = vec![0xB5, 0x62, 0x02, 0x22, 0xC7, 0x12];
        bytes.extend(b"$GPTXT,01*63\r\n");
        assert_eq!(collect(&bytes), Vec::<String>::new());
    }

    #[test]
    fn a_nav_pvt_header_with_another_length_is_refused_at_once() {
        let items = collect(&[0xB5, 0x62, 0x01, 0x07, 93, 0]);
        assert_eq!(items, vec!["UbxBadLength"]);
    }
}
