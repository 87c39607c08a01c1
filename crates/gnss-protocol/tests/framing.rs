//! Framing real receivers' output: the captures in `tests/captures` (the GPSD project's regression
//! logs) hold sentences ending in LF as well as CR LF, AIS sentences (`!`), UBX frames whose
//! payload carries `$`, and other protocols' bytes between them. Every sentence and UBX frame with a good checksum that a
//! search of the whole file finds must come out of the streaming framer, whatever the read size,
//! and every other byte must be counted.

mod common;

use std::path::PathBuf;

use common::{captures_dir, receiver_bytes};
use proptest::prelude::*;
use rins_gnss_protocol::decode::GnssDecoder;
use rins_gnss_protocol::decode::framer::{Framed, Framer, FramingStats, MAX_UBX_PAYLOAD};

/// The captures, by name, with the receiver's bytes (after the leading `#` comment lines).
fn captures() -> Vec<(String, Vec<u8>)> {
    let dir = captures_dir();
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "log"))
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            let name = p
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            (name, receiver_bytes(&bytes).to_vec())
        })
        .collect()
}

/// A sentence or good UBX frame as the framer hands it on, as owned bytes (UBX: class, id,
/// payload).
#[derive(Debug, PartialEq, Eq)]
enum Item {
    Sentence(Vec<u8>),
    Ubx(Vec<u8>),
}

fn frame_in_reads(bytes: &[u8], read: usize) -> (Vec<Item>, Framer) {
    let mut framer = Framer::default();
    let mut items = Vec::new();
    for piece in bytes.chunks(read) {
        framer.push(piece, |item| match item {
            Framed::Nmea(s) | Framed::Encapsulated { sentence: s, .. } => {
                items.push(Item::Sentence(s.to_vec()))
            }
            Framed::Ubx { class, id, payload } => {
                items.push(Item::Ubx([&[class, id], payload].concat()))
            }
            Framed::UbxChecksum | Framed::UbxBadLength => {}
        });
    }
    (items, framer)
}

/// The bytes an item took from the stream.
fn stream_len(item: &Item) -> usize {
    match item {
        Item::Sentence(s) => s.len(),
        // Sync, class, id, length, payload, checksum.
        Item::Ubx(b) => b.len() + 6,
    }
}

/// Whether `sentence` is `$body*hh` or `!body*hh` and a line end, printable, with a good checksum.
fn sentence_checksum_ok(sentence: &[u8]) -> bool {
    let line = sentence.strip_suffix(b"\n").unwrap_or(sentence);
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    let [b'$' | b'!', body @ .., b'*', high, low] = line else {
        return false;
    };
    let printable = body
        .iter()
        .all(|&x| (x.is_ascii_graphic() || x == b' ') && x != b'$' && x != b'!');
    let given = std::str::from_utf8(&[*high, *low])
        .ok()
        .filter(|h| h.bytes().all(|x| x.is_ascii_hexdigit()))
        .and_then(|h| u8::from_str_radix(h, 16).ok());
    printable && given == Some(body.iter().fold(0, |c, &x| c ^ x))
}

/// The reference: a search of the whole file, left to right, for a UBX frame with a good checksum
/// or a sentence (`$` or `!`) with a good checksum ending in LF or CR LF within 256 bytes; taken whole, the
/// search goes on after it, otherwise at the next byte.
fn whole_file_search(bytes: &[u8]) -> Vec<Item> {
    let mut found = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let rest = &bytes[at..];
        if let [0xB5, 0x62, class, id, l0, l1, ..] = *rest {
            let len = usize::from(u16::from_le_bytes([l0, l1]));
            if len <= MAX_UBX_PAYLOAD && rest.len() >= 8 + len {
                let (mut a, mut b) = (0u8, 0u8);
                for &x in &rest[2..6 + len] {
                    a = a.wrapping_add(x);
                    b = b.wrapping_add(a);
                }
                if rest[6 + len..8 + len] == [a, b] {
                    found.push(Item::Ubx([&[class, id], &rest[6..6 + len]].concat()));
                    at += 8 + len;
                    continue;
                }
            }
        }
        if (rest[0] == b'$' || rest[0] == b'!')
            && let Some(lf) = rest.iter().take(256).position(|&x| x == b'\n')
            && sentence_checksum_ok(&rest[..=lf])
        {
            found.push(Item::Sentence(rest[..=lf].to_vec()));
            at += lf + 1;
            continue;
        }
        at += 1;
    }
    found
}

#[test]
fn every_good_sentence_and_frame_of_the_captures_is_framed_whatever_the_read_size() {
    let captures = captures();
    assert!(captures.len() >= 50, "{} captures", captures.len());
    let mut total = (0usize, 0usize, FramingStats::default());
    for (name, bytes) in &captures {
        let reference = whole_file_search(bytes);
        for read in [1, 7, 64, 4096] {
            let (items, framer) = frame_in_reads(bytes, read);
            let good: Vec<&Item> = items
                .iter()
                .filter(|i| match i {
                    Item::Sentence(s) => sentence_checksum_ok(s),
                    Item::Ubx(_) => true,
                })
                .collect();
            let expected: Vec<&Item> = reference.iter().collect();
            assert!(
                good == expected,
                "{name}, reads of {read}: {} of {} found; first difference at {:?}",
                good.len(),
                expected.len(),
                good.iter()
                    .zip(&expected)
                    .position(|(g, e)| g != e)
                    .map(|k| (good.get(k), expected.get(k)))
            );
            // Every byte is in an item handed on, counted as unframed, or held for the next read.
            let s = framer.stats();
            let in_items: usize = items.iter().map(stream_len).sum();
            assert_eq!(
                in_items + s.unframed_bytes as usize + framer.buffered(),
                bytes.len(),
                "{name}, reads of {read}: {s:?}"
            );
            let sentences = items
                .iter()
                .filter(|i| matches!(i, Item::Sentence(_)))
                .count();
            assert_eq!((s.lines_crlf + s.lines_lf) as usize, sentences, "{name}");
            if read == 64 {
                total.0 += good.len();
                total.1 += items.len();
                let t = &mut total.2;
                t.lines_crlf += s.lines_crlf;
                t.lines_lf += s.lines_lf;
                t.resyncs += s.resyncs;
                t.oversized += s.oversized;
                t.wrong_length += s.wrong_length;
                t.unframed_bytes += s.unframed_bytes;
            }
        }
    }
    eprintln!(
        "{} captures: {} items framed, {} with a good checksum; {:?}",
        captures.len(),
        total.1,
        total.0,
        total.2
    );
}

/// Sentences of a capture, with their line ends, as the framer hands them on.
fn sentences_of(name: &str) -> (Vec<Vec<u8>>, FramingStats) {
    let (_, bytes) = captures()
        .into_iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("capture {name}"));
    let (items, framer) = frame_in_reads(&bytes, 64);
    let sentences = items
        .into_iter()
        .filter_map(|i| match i {
            Item::Sentence(s) => Some(s),
            Item::Ubx(_) => None,
        })
        .collect();
    (sentences, framer.stats())
}

#[test]
fn a_receiver_ending_its_lines_in_a_bare_lf_is_framed_line_by_line() {
    // A Garmin Geko 201: NMEA only, every line ending in LF alone.
    let (sentences, s) = sentences_of("garmin-geko201.log");
    assert_eq!(sentences.len(), 213, "{s:?}");
    assert_eq!((s.lines_lf, s.lines_crlf, s.resyncs), (213, 0, 0), "{s:?}");
    // One of them, `$GPBOD,,T,,M,,*`, carries no checksum digits: framed, for the parser to refuse.
    let good = sentences.iter().filter(|x| sentence_checksum_ok(x)).count();
    assert_eq!(good, 212);
}

#[test]
fn ais_sentences_of_a_receiver_that_is_also_a_transponder_are_framed_apart() {
    // An AIT-250 AIS transponder: its GPS sentences (`$`) and AIS sentences (`!AIVDM`, `!AIVDO`).
    let (_, bytes) = captures()
        .into_iter()
        .find(|(n, _)| n == "ait250.log")
        .expect("capture ait250.log");
    let mut framer = Framer::default();
    let (mut nmea, mut ais, mut ais_checksum_ok) = (0, 0, 0);
    for piece in bytes.chunks(64) {
        framer.push(piece, |item| match item {
            Framed::Nmea(_) => nmea += 1,
            Framed::Encapsulated {
                sentence,
                checksum_ok,
            } => {
                assert!(sentence.starts_with(b"!AIVD"));
                ais += 1;
                ais_checksum_ok += u32::from(checksum_ok);
            }
            other => panic!("{other:?}"),
        });
    }
    let s = framer.stats();
    assert_eq!((nmea, ais, ais_checksum_ok), (67, 75, 75), "{s:?}");
    assert_eq!(
        (s.lines_lf, s.resyncs, s.unframed_bytes),
        (142, 0, 0),
        "{s:?}"
    );
}

#[test]
fn a_receiver_mixing_both_line_ends_has_both_counted() {
    // A BT-451: 45 sentences end in CR LF, the others in LF.
    let (sentences, s) = sentences_of("bt451.log");
    assert_eq!(s.lines_crlf, 45, "{s:?}");
    assert_eq!(s.lines_lf as usize, sentences.len() - 45, "{s:?}");
}

#[test]
fn the_decoder_reports_the_framing_and_takes_fixes_from_lf_lines() {
    // A u-blox LEA-4S in NMEA mode, every line ending in LF: no fix came through while only
    // CR LF ended a sentence.
    let (_, bytes) = captures()
        .into_iter()
        .find(|(n, _)| n == "ublox-lea-4s.log")
        .expect("capture ublox-lea-4s.log");
    let mut decoder = GnssDecoder::new();
    let mut fixes = 0;
    for piece in bytes.chunks(64) {
        decoder.push(piece, 1, |_| fixes += 1);
    }
    let s = decoder.stats();
    assert_eq!(
        (s.framing.lines_lf, s.framing.lines_crlf, s.framing.resyncs),
        (27, 0, 0),
        "{s:?}"
    );
    assert!(fixes >= 2, "{fixes} fixes: {s:?}");
}

proptest! {
    #[test]
    fn any_bytes_are_accounted_for_and_framed_alike_whatever_the_reads(
        pieces in prop::collection::vec(
            prop_oneof![
                prop::collection::vec(any::<u8>(), 0..40),
                Just(b"$GPGGA,1*00\r\n".to_vec()),
                Just(b"!AIVDM,1*00\n".to_vec()),
                Just(vec![0xB5, 0x62, 0x01, 0x07, 0xFF, 0xFF]),
                Just(vec![0xB5, 0x62, 0x0A, 0x04, 0, 0, 0x0E, 0x34]),
            ],
            0..60,
        ),
        read in 1usize..300,
    ) {
        let bytes = pieces.concat();
        let (whole, _) = frame_in_reads(&bytes, bytes.len().max(1));
        let (items, framer) = frame_in_reads(&bytes, read);
        prop_assert_eq!(&whole, &items);
        let in_items: usize = items.iter().map(stream_len).sum();
        prop_assert_eq!(
            in_items + framer.stats().unframed_bytes as usize + framer.buffered(),
            bytes.len()
        );
    }
}
