//! An MCAP file taken apart record by record under this crate's own bounds.
//!
//! Every length in the file is declared by the file, and a damaged (or hostile) file declares
//! anything: a flipped bit in a record or chunk length makes it petabytes. So nothing is
//! allocated from a declared length before it is checked against what the buffer actually holds
//! and against [`MAX_CHUNK_BYTES`]: a record must fit in what remains of the file (or of its
//! chunk), a chunk is decompressed into at most its checked uncompressed size, every string
//! inside a record must fit in the record before the `mcap` crate parses it (its parser reserves
//! a string's declared length up front). Chunks are checked against their CRC before any record
//! of theirs is used, so a damaged chunk is dropped whole and never yields altered messages.
//!
//! When a record's declared length runs past the end of the file the framing is lost; reading
//! resumes at the next place that holds a well-formed chunk record, if any.

use std::borrow::Cow;
use std::ops::Range;

use mcap::records::{Record, op};

/// Largest recording file read, bytes (8 GiB): a recording is read into memory whole, and 8 GiB
/// hold about four hours of every topic at 1 kHz (35 MB a minute).
pub const MAX_RECORDING_BYTES: u64 = 8 << 30;

/// Largest uncompressed chunk accepted, bytes (64 MiB). The writer makes chunks of about
/// [`crate::RecordOptions::chunk_size`] (1 MiB by default, at most half this); a chunk declaring
/// more is damaged, and is skipped rather than allocated.
pub const MAX_CHUNK_BYTES: u64 = 64 << 20;

/// An MCAP record's opcode (1 byte) and body length (8 bytes).
const PREFIX_LEN: usize = 9;

/// A chunk header without its compression string: start and end time, uncompressed size, CRC,
/// the string's length; then the compressed size follows the string.
const CHUNK_HEADER_FIXED: usize = 8 + 8 + 8 + 4 + 4 + 8;

/// What is at a place of a buffer of records.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Framing {
    /// A whole record: its opcode and where its body is; the next record starts at `body.end`.
    Record {
        /// The opcode.
        opcode: u8,
        /// The body's place in the buffer.
        body: Range<usize>,
    },
    /// The buffer ends here.
    End,
    /// A record that does not fit in the rest of the buffer, described.
    Overrun(String),
}

/// The record starting at `pos` of `buf`.
pub(crate) fn frame(buf: &[u8], pos: usize) -> Framing {
    let rest = buf.get(pos..).unwrap_or_default();
    if rest.is_empty() {
        return Framing::End;
    }
    let Some((prefix, after)) = rest.split_first_chunk::<PREFIX_LEN>() else {
        return Framing::Overrun(format!("{} bytes remain, too few for a record", rest.len()));
    };
    let opcode = prefix[0];
    let mut len = [0; 8];
    len.copy_from_slice(&prefix[1..]);
    let len = u64::from_le_bytes(len);
    match usize::try_from(len) {
        Ok(len) if len <= after.len() => {
            let start = pos + PREFIX_LEN;
            Framing::Record {
                opcode,
                body: start..start + len,
            }
        }
        _ => Framing::Overrun(format!(
            "a record (opcode {opcode:#04x}) declares {len} bytes, only {} remain",
            after.len()
        )),
    }
}

/// Walks the length-prefixed fields of a record body, checking that each fits.
struct Fields<'a> {
    rest: &'a [u8],
}

impl Fields<'_> {
    fn skip(&mut self, n: usize) -> bool {
        match self.rest.get(n..) {
            Some(rest) => {
                self.rest = rest;
                true
            }
            None => false,
        }
    }

    fn u32(&mut self) -> Option<u32> {
        let (len, rest) = self.rest.split_first_chunk::<4>()?;
        self.rest = rest;
        Some(u32::from_le_bytes(*len))
    }

    /// A string: u32 length, then that many bytes.
    fn string(&mut self) -> bool {
        self.u32()
            .and_then(|len| usize::try_from(len).ok())
            .is_some_and(|len| self.skip(len))
    }

    /// A map of strings to strings: u32 length in bytes, then key and value strings until that
    /// many bytes are read (the `mcap` crate's reading of it).
    fn string_map(&mut self) -> bool {
        let Some(byte_len) = self.u32() else {
            return false;
        };
        let start = self.rest.len();
        while ((start - self.rest.len()) as u64) < u64::from(byte_len) {
            if !(self.string() && self.string()) {
                return false;
            }
        }
        true
    }
}

/// Whether every string a record's parser would read from `body` fits in it: the parser
/// reserves a string's declared length before reading it.
pub(crate) fn lengths_fit(opcode: u8, body: &[u8]) -> bool {
    let mut fields = Fields { rest: body };
    match opcode {
        // id; name; encoding (the data's length is checked by the parser).
        op::SCHEMA => fields.skip(2) && fields.string() && fields.string(),
        // id, schema id; topic; message encoding; metadata.
        op::CHANNEL => fields.skip(4) && fields.string() && fields.string() && fields.string_map(),
        // times, uncompressed size and CRC; compression.
        op::CHUNK => fields.skip(8 + 8 + 8 + 4) && fields.string(),
        _ => true,
    }
}

/// The records of a chunk, given the chunk record's body: decompressed into at most
/// [`MAX_CHUNK_BYTES`], checked against the chunk's CRC. The error says why the chunk is
/// unusable.
pub(crate) fn chunk_records(body: &[u8]) -> Result<Cow<'_, [u8]>, String> {
    if !lengths_fit(op::CHUNK, body) {
        return Err("its header overruns the chunk".to_string());
    }
    let (header, data) = match mcap::parse_record(op::CHUNK, body) {
        Ok(Record::Chunk { header, data }) => (header, data),
        Ok(_) => return Err("not a chunk".to_string()),
        Err(e) => return Err(format!("its header is damaged: {e}")),
    };
    let declared = header.uncompressed_size;
    let size = match usize::try_from(declared) {
        Ok(size) if declared <= MAX_CHUNK_BYTES => size,
        _ => {
            return Err(format!(
                "it declares {declared} uncompressed bytes, more than the {MAX_CHUNK_BYTES} allowed"
            ));
        }
    };
    let records = match header.compression.as_str() {
        "" => data,
        "zstd" => {
            // At most `size` bytes are allocated and written, whatever the compressed frames say.
            let out = zstd::bulk::decompress(&data, size)
                .map_err(|e| format!("it does not decompress: {e}"))?;
            Cow::Owned(out)
        }
        other => return Err(format!("unknown compression {other:?}")),
    };
    if records.len() != size {
        return Err(format!(
            "it holds {} bytes of records, its header says {declared}",
            records.len()
        ));
    }
    // A CRC of 0 means none was computed.
    if header.uncompressed_crc != 0 {
        let crc = crc32fast::hash(&records);
        if crc != header.uncompressed_crc {
            return Err(format!(
                "CRC mismatch (stored {:#010x}, computed {crc:#010x})",
                header.uncompressed_crc
            ));
        }
    }
    Ok(records)
}

/// The first place at or after `from` that holds a well-formed chunk record followed by the end
/// of the file or by a record that may follow a chunk: where reading resumes after the framing
/// was lost. Cheap checks only; the chunk's content is checked when it is read.
pub(crate) fn find_chunk(buf: &[u8], from: usize) -> Option<usize> {
    let mut at = from;
    while let Some(found) = buf.get(at..)?.iter().position(|b| *b == op::CHUNK) {
        let pos = at + found;
        if plausible_chunk(buf, pos) {
            return Some(pos);
        }
        at = pos + 1;
    }
    None
}

fn plausible_chunk(buf: &[u8], pos: usize) -> bool {
    let Framing::Record { opcode, body } = frame(buf, pos) else {
        return false;
    };
    let next = buf.get(body.end).copied();
    let followed = matches!(
        next,
        None | Some(op::CHUNK | op::MESSAGE_INDEX | op::DATA_END)
    );
    let body = &buf[body];
    if opcode != op::CHUNK || !followed || !lengths_fit(op::CHUNK, body) {
        return false;
    }
    let Ok(Record::Chunk { header, .. }) = mcap::parse_record(op::CHUNK, body) else {
        return false;
    };
    // The writer leaves nothing between the compressed data and the end of the record.
    let header_len = CHUNK_HEADER_FIXED as u64 + header.compression.len() as u64;
    matches!(header.compression.as_str(), "" | "zstd")
        && header.uncompressed_size <= MAX_CHUNK_BYTES
        && header_len.checked_add(header.compressed_size) == Some(body.len() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(opcode: u8, body: &[u8]) -> Vec<u8> {
        let mut out = vec![opcode];
        out.extend_from_slice(&(body.len() as u64).to_le_bytes());
        out.extend_from_slice(body);
        out
    }

    fn chunk_body(compression: &str, uncompressed: &[u8], data: &[u8], crc: u32) -> Vec<u8> {
        let mut body = Vec::new();
        body.extend_from_slice(&1u64.to_le_bytes());
        body.extend_from_slice(&2u64.to_le_bytes());
        body.extend_from_slice(&(uncompressed.len() as u64).to_le_bytes());
        body.extend_from_slice(&crc.to_le_bytes());
        body.extend_from_slice(&(compression.len() as u32).to_le_bytes());
        body.extend_from_slice(compression.as_bytes());
        body.extend_from_slice(&(data.len() as u64).to_le_bytes());
        body.extend_from_slice(data);
        body
    }

    #[test]
    fn a_record_longer_than_the_buffer_is_an_overrun() {
        let mut buf = record(op::DATA_END, &[0; 4]);
        assert_eq!(
            frame(&buf, 0),
            Framing::Record {
                opcode: op::DATA_END,
                body: 9..13
            }
        );
        assert_eq!(frame(&buf, 13), Framing::End);
        buf[1..9].copy_from_slice(&(1u64 << 51).to_le_bytes());
        let Framing::Overrun(why) = frame(&buf, 0) else {
            panic!("not an overrun");
        };
        assert!(
            why.contains("2251799813685248 bytes, only 4 remain"),
            "{why}"
        );
        assert!(matches!(frame(&buf, 8), Framing::Overrun(_)));
    }

    #[test]
    fn a_string_longer_than_its_record_does_not_fit() {
        let mut channel = vec![1, 0, 0, 0];
        channel.extend_from_slice(&u32::MAX.to_le_bytes());
        assert!(!lengths_fit(op::CHANNEL, &channel));
        let mut channel = vec![1, 0, 0, 0];
        for s in ["topic", "cdr"] {
            channel.extend_from_slice(&(s.len() as u32).to_le_bytes());
            channel.extend_from_slice(s.as_bytes());
        }
        let mut map = Vec::new();
        for s in ["k", "v"] {
            map.extend_from_slice(&(s.len() as u32).to_le_bytes());
            map.extend_from_slice(s.as_bytes());
        }
        channel.extend_from_slice(&(map.len() as u32).to_le_bytes());
        channel.extend_from_slice(&map);
        assert!(lengths_fit(op::CHANNEL, &channel));
        // A map claiming more bytes than follow.
        let at = channel.len() - map.len() - 4;
        channel[at..at + 4].copy_from_slice(&1000u32.to_le_bytes());
        assert!(!lengths_fit(op::CHANNEL, &channel));
    }

    #[test]
    fn a_chunk_declaring_a_huge_size_is_refused_before_decompressing() {
        let records = record(op::DATA_END, &[0; 4]);
        let crc = crc32fast::hash(&records);
        let ok = chunk_body("", &records, &records, crc);
        assert_eq!(chunk_records(&ok).unwrap(), &records[..]);

        let mut huge = ok.clone();
        huge[16..24].copy_from_slice(&(1u64 << 51).to_le_bytes());
        let why = chunk_records(&huge).unwrap_err();
        assert!(why.contains("2251799813685248 uncompressed bytes"), "{why}");

        let compressed = zstd::bulk::compress(&records, 3).unwrap();
        let zstd = chunk_body("zstd", &records, &compressed, crc);
        assert_eq!(chunk_records(&zstd).unwrap(), &records[..]);
        // Declared smaller than the frame decompresses to: an error, not a larger buffer.
        let mut short = zstd.clone();
        short[16..24].copy_from_slice(&4u64.to_le_bytes());
        assert!(chunk_records(&short).is_err());

        let mut flipped = ok.clone();
        let last = flipped.len() - 1;
        flipped[last] ^= 0x10;
        let why = chunk_records(&flipped).unwrap_err();
        assert!(why.contains("CRC mismatch"), "{why}");
    }

    #[test]
    fn reading_resumes_at_the_next_well_formed_chunk() {
        let records = record(op::DATA_END, &[0; 4]);
        let chunk = record(
            op::CHUNK,
            &chunk_body("", &records, &records, crc32fast::hash(&records)),
        );
        let mut buf = vec![op::CHUNK, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 7];
        let at = buf.len();
        buf.extend_from_slice(&chunk);
        buf.extend_from_slice(&record(op::DATA_END, &[0; 4]));
        assert_eq!(find_chunk(&buf, 1), Some(at));
        assert_eq!(find_chunk(&buf, at + 1), None);
    }
}
