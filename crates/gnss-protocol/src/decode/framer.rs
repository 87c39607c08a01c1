//! Splits the receiver's byte stream into UBX frames and NMEA sentences. Allocation-free.
//!
//! A sentence ends in CR LF, as NMEA 0183 prescribes, or in a bare LF, as many receivers send it.
//! Binary data (UBX payloads, other protocols) holds a `$` now and then; a sentence start that
//! meets a byte no sentence holds before its line end is dropped at that byte, and the search
//! goes on from there, so it cannot swallow the sentence or frame that follows. Every byte that
//! ends up in no sentence or good frame is counted ([`FramingStats`]).
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

/// NAV-PVT, the message the decoder uses, and its lengths: 92 bytes from protocol 15 on, 84 in
/// u-blox 7 firmware (protocol 14, without headVeh, magDec and magAcc). A NAV-PVT header
/// declaring another is corrupted, and is refused without waiting for its bytes.
const NAV_PVT: (u8, u8, [usize; 2]) = (0x01, 0x07, [NAV_PVT_LEN, NAV_PVT_PROTO14_LEN]);

/// NAV-PVT's payload length from UBX protocol 15 on.
pub const NAV_PVT_LEN: usize = 92;

/// NAV-PVT's payload length in UBX protocol 14 (u-blox 7): the first 84 bytes of the later form.
pub const NAV_PVT_PROTO14_LEN: usize = 84;

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
    /// An NMEA sentence from `$` through the line end, LF or CR LF (checksum not yet checked).
    Nmea(&'a [u8]),
    /// An NMEA encapsulation sentence (`!`, such as AIS messages from a receiver that is also an
    /// AIS transponder), from `!` through the line end: valid output of no use to a fix.
    Encapsulated {
        /// The sentence's bytes.
        sentence: &'a [u8],
        /// Whether it carries a checksum and the checksum matches.
        checksum_ok: bool,
    },
}

/// What the framer passed over, and how the sentences it framed ended. Together with the items
/// it hands on, these account for every byte: bytes taken in = bytes of the sentences and
/// good UBX frames handed on + `unframed_bytes` + the bytes of an unfinished item it holds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct FramingStats {
    /// Sentences ending in CR LF, as NMEA 0183 prescribes.
    pub lines_crlf: u64,
    /// Sentences ending in a bare LF, as many receivers send them: valid, just not to the letter.
    pub lines_lf: u64,
    /// Sentence starts (`$`, `!`) dropped before a line end: a byte no sentence holds (binary
    /// data, a CR without LF) or another sentence start came first, or no line end within the
    /// longest sentence. Binary messages carry a `$` or `!` now and then; many resyncs on a line
    /// that should carry only NMEA mean corruption.
    pub resyncs: u64,
    /// UBX headers declaring a payload longer than any UBX message has ([`MAX_UBX_PAYLOAD`]):
    /// corrupted. Also counted as malformed by the decoder.
    pub oversized: u64,
    /// UBX headers declaring a length within that bound but not their message's (a NAV-PVT of
    /// another length than 92 or 84), or one whose claimed bytes hold a whole frame or sentence:
    /// corrupted. Also counted as malformed by the decoder.
    pub wrong_length: u64,
    /// Bytes in no sentence or good UBX frame handed on: another protocol's output (RTCM, a
    /// vendor's binary), line noise, dropped sentence starts, the sync bytes of refused UBX
    /// headers and the bytes of UBX frames whose checksum failed.
    pub unframed_bytes: u64,
}

impl FramingStats {
    fn count_line_end(&mut self, sentence: &[u8]) {
        if sentence.ends_with(b"\r\n") {
            self.lines_crlf += 1;
        } else {
            self.lines_lf += 1;
        }
    }
}

/// Streaming framer of UBX frames and NMEA sentences.
pub struct Framer {
    buf: [u8; CAPACITY],
    len: usize,
    stats: FramingStats,
}

impl Default for Framer {
    fn default() -> Self {
        Self {
            buf: [0; CAPACITY],
            len: 0,
            stats: FramingStats::default(),
        }
    }
}

/// What scanning at a byte decided.
enum Step {
    /// Pass over this many bytes, which start nothing.
    Skip(usize),
    /// A sentence start turned out to be none: pass over this many bytes and go on at the byte
    /// that gave it away (it may start the next item).
    Resync(usize),
    /// Report what was found and go on scanning at `next`.
    Item { kind: Kind, next: usize },
    /// The rest is an unfinished frame: keep it for the next bytes.
    Wait,
}

/// What was found, by its place in the buffer.
#[derive(Clone, Copy)]
enum Kind {
    Ubx {
        start: usize,
        end: usize,
    },
    UbxChecksum,
    /// Declared length beyond any UBX message.
    UbxOversized,
    /// Declared length not the message's, or belied by a whole frame inside.
    UbxWrongLength,
    Nmea {
        start: usize,
        end: usize,
    },
    Encapsulated {
        start: usize,
        end: usize,
    },
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

    /// What it passed over and how the sentences ended, so far.
    pub fn stats(&self) -> FramingStats {
        self.stats
    }

    /// Bytes held as the start of an unfinished item.
    pub fn buffered(&self) -> usize {
        self.len
    }

    /// Ends the stream: the unfinished item held (a sentence without its line end, a UBX frame
    /// cut short) will not be completed, so its bytes are counted as unframed and dropped.
    pub fn flush(&mut self) {
        self.stats.unframed_bytes += self.len as u64;
        self.len = 0;
    }

    /// Reports every complete item in the buffer and keeps only an unfinished one. The buffer
    /// holds the largest acceptable frame, so what is kept always leaves room to progress.
    fn scan(&mut self, on_item: &mut impl FnMut(Framed<'_>)) {
        let mut at = 0;
        while at < self.len {
            match self.step(at) {
                Step::Skip(n) => {
                    self.stats.unframed_bytes += n as u64;
                    at += n;
                }
                Step::Resync(n) => {
                    self.stats.resyncs += 1;
                    self.stats.unframed_bytes += n as u64;
                    at += n;
                }
                Step::Wait => break,
                Step::Item { kind, next } => {
                    on_item(match kind {
                        Kind::Ubx { start, end } => Framed::Ubx {
                            class: self.buf[start + 2],
                            id: self.buf[start + 3],
                            payload: &self.buf[start + UBX_HEADER..end - UBX_CHECKSUM],
                        },
                        Kind::UbxChecksum => {
                            self.stats.unframed_bytes += (next - at) as u64;
                            Framed::UbxChecksum
                        }
                        Kind::UbxOversized => {
                            self.stats.oversized += 1;
                            self.stats.unframed_bytes += (next - at) as u64;
                            Framed::UbxBadLength
                        }
                        Kind::UbxWrongLength => {
                            self.stats.wrong_length += 1;
                            self.stats.unframed_bytes += (next - at) as u64;
                            Framed::UbxBadLength
                        }
                        Kind::Nmea { start, end } => {
                            let sentence = &self.buf[start..end];
                            self.stats.count_line_end(sentence);
                            Framed::Nmea(sentence)
                        }
                        Kind::Encapsulated { start, end } => {
                            let sentence = &self.buf[start..end];
                            self.stats.count_line_end(sentence);
                            Framed::Encapsulated {
                                sentence,
                                checksum_ok: sentence_checksum_ok(sentence),
                            }
                        }
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
            b'$' | b'!' => Self::nmea(rest, at),
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
        // Refused headers and failed checksums resynchronise from the byte after the sync: the
        // sync may have been payload of something lost, and the next frame may start there.
        let refused = |kind| Step::Item {
            kind,
            next: at + UBX_SYNC.len(),
        };
        let (class, id) = (rest[2], rest[3]);
        let declared = usize::from(u16::from_le_bytes([rest[4], rest[5]]));
        if declared > MAX_UBX_PAYLOAD {
            return refused(Kind::UbxOversized);
        }
        if (class, id) == (NAV_PVT.0, NAV_PVT.1) && !NAV_PVT.2.contains(&declared) {
            return refused(Kind::UbxWrongLength);
        }
        let total = UBX_HEADER + declared + UBX_CHECKSUM;
        if rest.len() < total {
            if holds_a_whole_frame(&rest[UBX_SYNC.len()..]) {
                return refused(Kind::UbxWrongLength);
            }
            return Step::Wait;
        }
        if !ubx_checksum_ok(&rest[..total]) {
            return refused(Kind::UbxChecksum);
        }
        Step::Item {
            kind: Kind::Ubx {
                start: at,
                end: at + total,
            },
            next: at + total,
        }
    }

    /// A sentence is printable ASCII from `$` (or `!`) to its line end, LF or CR LF. Whatever
    /// else comes first means this start was none: scanning goes on at that byte, which may be
    /// the start of the next item (another `$` or `!`, which NMEA 0183 reserves as sentence
    /// starts, or a UBX sync), so a stray `$` in binary data costs nothing behind it.
    fn nmea(rest: &[u8], at: usize) -> Step {
        for (i, &x) in rest.iter().enumerate().take(NMEA_MAX).skip(1) {
            match x {
                b'\n' => {
                    let (start, end) = (at, at + i + 1);
                    let kind = match rest[0] {
                        b'$' => Kind::Nmea { start, end },
                        _ => Kind::Encapsulated { start, end },
                    };
                    return Step::Item { kind, next: end };
                }
                // Only as the line end, right before the LF.
                b'\r' => match rest.get(i + 1) {
                    Some(b'\n') | None => {}
                    Some(_) => return Step::Resync(i),
                },
                b'$' | b'!' => return Step::Resync(i),
                0x20..=0x7E => {}
                _ => return Step::Resync(i),
            }
        }
        if rest.len() >= NMEA_MAX {
            // No line end within the longest sentence; every byte before this one is printable
            // and starts nothing.
            Step::Resync(NMEA_MAX)
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
            b'$' | b'!' => nmea_sentence_at(rest),
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

/// Whether `rest` starts with a whole sentence whose checksum is good.
fn nmea_sentence_at(rest: &[u8]) -> bool {
    rest.iter()
        .take(NMEA_MAX)
        .position(|&x| x == b'\n')
        .is_some_and(|lf| sentence_checksum_ok(&rest[..=lf]))
}

/// Whether `sentence` is `$body*hh` or `!body*hh` with its line end (LF or CR LF), printable,
/// with a checksum that matches.
fn sentence_checksum_ok(sentence: &[u8]) -> bool {
    let line = sentence.strip_suffix(b"\n").unwrap_or(sentence);
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    let [b'$' | b'!', body @ .., b'*', high, low] = line else {
        return false;
    };
    let printable = body
        .iter()
        .all(|&x| (0x20..=0x7E).contains(&x) && x != b'$' && x != b'!');
    let given = match (hex_digit(*high), hex_digit(*low)) {
        (Some(h), Some(l)) => h << 4 | l,
        _ => return false,
    };
    printable && given == body.iter().fold(0, |c, &x| c ^ x)
}

fn hex_digit(x: u8) -> Option<u8> {
    char::from(x)
        .to_digit(16)
        .and_then(|d| u8::try_from(d).ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What the framer handed on, in a readable form, and what it counted.
    fn frame(bytes: &[u8]) -> (Vec<String>, FramingStats) {
        let mut f = Framer::default();
        let mut out = Vec::new();
        f.push(bytes, |item| {
            out.push(match item {
                Framed::Nmea(s) => String::from_utf8_lossy(s).into_owned(),
                Framed::Ubx { class, id, payload } => {
                    format!("UBX {class:02X} {id:02X} {}", payload.len())
                }
                other => format!("{other:?}"),
            })
        });
        (out, f.stats())
    }

    /// A UBX frame of `class`, `id` and `payload` with its checksum.
    fn ubx_frame(class: u8, id: u8, payload: &[u8]) -> Vec<u8> {
        let len = u16::try_from(payload.len()).expect("short payload");
        let mut frame = vec![0xB5, 0x62, class, id];
        frame.extend(len.to_le_bytes());
        frame.extend(payload);
        let (mut a, mut b) = (0u8, 0u8);
        for &x in &frame[2..] {
            a = a.wrapping_add(x);
            b = b.wrapping_add(a);
        }
        frame.extend([a, b]);
        frame
    }

    const GGA: &str = "$GPGGA,1*00";

    #[test]
    fn lines_ending_in_lf_or_cr_lf_are_both_sentences_and_counted_by_their_end() {
        let (items, s) = frame(format!("{GGA}\n{GGA}\r\n{GGA}\n").as_bytes());
        assert_eq!(
            items,
            vec![format!("{GGA}\n"), format!("{GGA}\r\n"), format!("{GGA}\n")]
        );
        assert_eq!((s.lines_lf, s.lines_crlf), (2, 1));
        assert_eq!((s.resyncs, s.unframed_bytes), (0, 0));
    }

    #[test]
    fn an_encapsulation_sentence_is_framed_apart_with_its_checksum_checked() {
        // An AIS position report as an AIS transponder with a GPS sends it.
        let ais = "!AIVDM,1,1,,B,13njCt031t0DA=lN2:jKmad60l1p,0*12\n";
        let corrupted = ais.replace("13nj", "13mj");
        let (items, s) = frame(format!("{ais}{corrupted}{GGA}\r\n").as_bytes());
        let sentence = |x: &str| format!("{:?}", x.as_bytes());
        assert_eq!(
            items,
            vec![
                format!(
                    "Encapsulated {{ sentence: {}, checksum_ok: true }}",
                    sentence(ais)
                ),
                format!(
                    "Encapsulated {{ sentence: {}, checksum_ok: false }}",
                    sentence(&corrupted)
                ),
                format!("{GGA}\r\n"),
            ]
        );
        assert_eq!((s.lines_lf, s.lines_crlf, s.unframed_bytes), (2, 1, 0));
    }

    #[test]
    fn a_stray_dollar_does_not_swallow_a_following_sentence() {
        let (items, s) = frame(format!("x$GP\x01{GGA}\r\n").as_bytes());
        assert_eq!(items, vec![format!("{GGA}\r\n")]);
        // `x`, then `$GP` dropped at the 0x01, which is passed over too.
        assert_eq!((s.resyncs, s.unframed_bytes), (1, 5));
    }

    #[test]
    fn a_dollar_in_binary_data_gives_way_to_a_ubx_frame_at_the_byte_that_ends_it() {
        // The tail of a frame whose start was lost: `$GP` and then a whole frame.
        let mut bytes = b"$GP".to_vec();
        bytes.extend(ubx_frame(0x01, 0x07, &[0; 92]));
        let (items, s) = frame(&bytes);
        assert_eq!(items, vec!["UBX 01 07 92"]);
        assert_eq!((s.resyncs, s.unframed_bytes), (1, 3));
    }

    #[test]
    fn a_dollar_inside_a_whole_ubx_frame_is_payload() {
        let mut bytes = ubx_frame(0x02, 0x15, format!("{GGA}\r\n").as_bytes());
        bytes.extend(format!("{GGA}\n").as_bytes());
        let (items, s) = frame(&bytes);
        assert_eq!(items, vec!["UBX 02 15 13".to_string(), format!("{GGA}\n")]);
        assert_eq!((s.resyncs, s.unframed_bytes, s.lines_lf), (0, 0, 1));
    }

    #[test]
    fn another_dollar_before_the_line_end_starts_the_next_sentence() {
        // A receiver that lost a line end: the first sentence is dropped, the second kept.
        let (items, s) = frame(format!("{GGA}{GGA}\r\n").as_bytes());
        assert_eq!(items, vec![format!("{GGA}\r\n")]);
        assert_eq!((s.resyncs, s.unframed_bytes), (1, GGA.len() as u64));
    }

    #[test]
    fn a_cr_without_lf_ends_no_sentence() {
        let (items, s) = frame(format!("{GGA}\r{GGA}\r\n").as_bytes());
        assert_eq!(items, vec![format!("{GGA}\r\n")]);
        assert_eq!((s.resyncs, s.unframed_bytes), (1, GGA.len() as u64 + 1));
    }

    #[test]
    fn a_cr_at_the_end_of_a_read_waits_for_its_lf() {
        let mut f = Framer::default();
        let mut n = 0;
        f.push(format!("{GGA}\r").as_bytes(), |_| n += 1);
        assert_eq!((n, f.buffered()), (0, GGA.len() + 1));
        f.push(b"\n", |_| n += 1);
        assert_eq!((n, f.buffered(), f.stats().lines_crlf), (1, 0, 1));
    }

    #[test]
    fn a_sentence_without_a_line_end_is_dropped_after_the_longest_sentence() {
        let mut long = vec![b'$'];
        long.extend([b'A'; NMEA_MAX]);
        long.extend(format!("{GGA}\r\n").as_bytes());
        let (items, s) = frame(&long);
        assert_eq!(items, vec![format!("{GGA}\r\n")]);
        assert_eq!((s.resyncs, s.unframed_bytes), (1, NMEA_MAX as u64 + 1));
    }

    #[test]
    fn a_sentence_of_the_longest_length_is_taken() {
        let mut longest = vec![b'$'];
        longest.extend([b'A'; NMEA_MAX - 3]);
        longest.extend(b"\r\n");
        let (items, s) = frame(&longest);
        assert_eq!(items.len(), 1);
        assert_eq!((s.resyncs, s.lines_crlf), (0, 1));
    }

    #[test]
    fn an_oversized_ubx_header_is_counted_and_what_follows_its_sync_is_found() {
        let mut bytes = vec![0xB5, 0x62, 0x01, 0x07, 0xFF, 0xFF];
        bytes.extend(ubx_frame(0x01, 0x07, &[0; 92]));
        bytes.extend(format!("{GGA}\n").as_bytes());
        let (items, s) = frame(&bytes);
        assert_eq!(
            items,
            vec![
                "UbxBadLength".to_string(),
                "UBX 01 07 92".into(),
                format!("{GGA}\n")
            ]
        );
        assert_eq!((s.oversized, s.wrong_length), (1, 0));
        // The whole refused header: its sync, then class, id and length passed over.
        assert_eq!(s.unframed_bytes, 6);
    }

    #[test]
    fn a_header_whose_bytes_hold_a_whole_frame_is_refused() {
        // Class 0x02 (RXM), 4 807 bytes declared; a sentence with a good checksum follows.
        let mut bytes = vec![0xB5, 0x62, 0x02, 0x22, 0xC7, 0x12];
        bytes.extend(b"$GPTXT,01*62\r\n");
        let (items, s) = frame(&bytes);
        assert_eq!(items, vec!["UbxBadLength", "$GPTXT,01*62\r\n"]);
        assert_eq!((s.oversized, s.wrong_length, s.unframed_bytes), (0, 1, 6));
        // The same with an LF line end.
        let mut bytes = vec![0xB5, 0x62, 0x02, 0x22, 0xC7, 0x12];
        bytes.extend(b"$GPTXT,01*62\n");
        assert_eq!(frame(&bytes).0, vec!["UbxBadLength", "$GPTXT,01*62\n"]);
        // With a bad checksum, it is no evidence: the header may still be a real frame's.
        let mut bytes = vec![0xB5, 0x62, 0x02, 0x22, 0xC7, 0x12];
        bytes.extend(b"$GPTXT,01*63\r\n");
        assert_eq!(frame(&bytes).0, Vec::<String>::new());
    }

    #[test]
    fn a_nav_pvt_header_with_another_length_is_refused_at_once() {
        let (items, s) = frame(&[0xB5, 0x62, 0x01, 0x07, 93, 0]);
        assert_eq!(items, vec!["UbxBadLength"]);
        assert_eq!((s.oversized, s.wrong_length), (0, 1));
    }

    #[test]
    fn a_nav_pvt_of_protocol_14_is_framed() {
        let (items, s) = frame(&ubx_frame(0x01, 0x07, &[0; NAV_PVT_PROTO14_LEN]));
        assert_eq!(items, vec!["UBX 01 07 84"]);
        assert_eq!(s.wrong_length, 0);
    }

    #[test]
    fn a_ubx_checksum_failure_counts_the_frames_bytes_as_unframed() {
        let mut bytes = ubx_frame(0x01, 0x07, &[0; 92]);
        bytes[50] ^= 1;
        let (items, s) = frame(&bytes);
        assert_eq!(items, vec!["UbxChecksum"]);
        assert_eq!(s.unframed_bytes, 100);
    }

    #[test]
    fn flushing_counts_an_unfinished_item_as_unframed() {
        let mut f = Framer::default();
        f.push(b"$GPGGA,12", |_| {});
        assert_eq!(f.buffered(), 9);
        f.flush();
        assert_eq!((f.buffered(), f.stats().unframed_bytes), (0, 9));
    }

    #[test]
    fn checksums_of_sentences_are_read_as_two_hex_digits() {
        assert!(nmea_sentence_at(b"$GPTXT,01*62\n"));
        assert!(nmea_sentence_at(b"$GPTXT,01*62\r\n"));
        assert!(!nmea_sentence_at(b"$GPTXT,01*+2\r\n"));
        assert!(!nmea_sentence_at(b"$*\r\n"));
        assert!(nmea_sentence_at(b"$*00\n"));
    }
}
