//! Recordings that are damaged, or not recordings at all: whatever is at the path, reading ends
//! promptly with what could be read and a count of what could not, or with an error naming the
//! path; it never aborts, hangs or allocates what a damaged length declares.
//!
//! The seed corpus of the `recording` fuzz target (fuzz/corpus/recording) is made here: a small
//! recording from the writer, cut off and bit-flipped variants. Every committed seed is read here
//! too; regenerate them with
//! `RINS_WRITE_FUZZ_SEEDS=1 cargo test -p rins-recording --test hostile_files`.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use ipc_types::{NavState, names};
use rins_recording::{
    MAX_RECORDING_BYTES, Messages, ReadError, RecordOptions, Recorder, Recording, read_bytes,
    read_file,
};

/// Messages in the sample recording.
const MESSAGES: u64 = 300;

/// A fresh scratch directory for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rins-hostile-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn nav(seq: u64) -> NavState {
    let mut nav = NavState {
        mode: 2,
        altitude_m: seq as f64,
        ..Default::default()
    };
    nav.header.origin_seq = seq;
    nav
}

/// A small recording of [`MESSAGES`] navigation samples in several chunks, as the writer makes it.
fn sample_recording() -> Vec<u8> {
    let dir = scratch(&format!("sample-{:?}", std::thread::current().id()));
    let path = dir.join("sample.mcap");
    let options = RecordOptions {
        chunk_size: 4096,
        ..Default::default()
    };
    let mut recorder = Recorder::create(&path, &options).unwrap();
    let ch = recorder.channel_for::<NavState>(names::NAV_STATE).unwrap();
    for seq in 0..MESSAGES {
        recorder.write_payload(ch, seq, seq, &nav(seq)).unwrap();
    }
    recorder.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_dir_all(dir).unwrap();
    bytes
}

/// Where each record outside a chunk starts, with its opcode and length: the file's framing.
fn records(bytes: &[u8]) -> Vec<(usize, u8, u64)> {
    let mut out = Vec::new();
    let mut pos = 8;
    while pos + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().unwrap());
        out.push((pos, bytes[pos], len));
        if bytes[pos] == 0x0F {
            break;
        }
        pos += 9 + len as usize;
    }
    out
}

/// Where the chunk records start.
fn chunks(bytes: &[u8]) -> Vec<usize> {
    let chunks: Vec<usize> = records(bytes)
        .into_iter()
        .filter(|(_, opcode, _)| *opcode == 0x06)
        .map(|(pos, _, _)| pos)
        .collect();
    assert!(chunks.len() >= 4, "the sample has {} chunks", chunks.len());
    chunks
}

/// The sequence numbers read.
fn sequences(recording: &Recording) -> Vec<u64> {
    recording
        .messages
        .iter()
        .map(|m| m.decode::<NavState>().unwrap().header.origin_seq)
        .collect()
}

/// Runs `f` in a thread and gives up after a few seconds: a read that blocks must fail the test,
/// not hang it.
fn within_seconds<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(5))
        .expect("reading did not end within 5 s")
}

/// The sample with 16 bits of its second chunk's compressed data flipped.
fn flipped_chunk(bytes: &[u8]) -> Vec<u8> {
    flipped(bytes, 1)
}

/// The sample with 16 bits of the compressed data of its chunk `index` flipped.
fn flipped(bytes: &[u8], index: usize) -> Vec<u8> {
    let mut damaged = bytes.to_vec();
    let start = chunks(bytes)[index];
    let len = u64::from_le_bytes(bytes[start + 1..start + 9].try_into().unwrap()) as usize;
    let end = start + 9 + len;
    // Past the chunk's header (at most 60 bytes with "zstd"), inside its data.
    let middle = start + 60 + (end - start - 60 - 48) / 2;
    for i in 0..16 {
        damaged[middle + i * 3] ^= 1 << (i % 8);
    }
    damaged
}

/// The sample with its second chunk's record length given bit 51: the framing is lost there.
fn huge_record_length(bytes: &[u8]) -> Vec<u8> {
    let mut damaged = bytes.to_vec();
    let at = chunks(bytes)[1];
    damaged[at + 1 + 6] ^= 0x08;
    damaged
}

/// The sample with its second chunk's declared uncompressed size given bit 51.
fn huge_chunk_size(bytes: &[u8]) -> Vec<u8> {
    let mut damaged = bytes.to_vec();
    let at = chunks(bytes)[1];
    // Opcode, length, start time, end time: then the uncompressed size.
    damaged[at + 9 + 16 + 6] ^= 0x08;
    damaged
}

#[test]
fn the_sample_reads_whole() {
    let recording = read_bytes(&sample_recording(), "sample").unwrap();
    assert_eq!(sequences(&recording), (0..MESSAGES).collect::<Vec<_>>());
    assert_eq!(recording.damaged_chunk_count, 0);
    assert_eq!(recording.skipped_count, 0);
    assert_eq!(recording.damage, None);
}

/// 16 flipped bits in a chunk cost that chunk's messages only: the chunks after it are read, the
/// damaged one is counted.
#[test]
fn a_chunk_with_flipped_bits_is_skipped_and_counted() {
    let bytes = sample_recording();
    let good = sequences(&read_bytes(&bytes, "sample").unwrap());
    let recording = read_bytes(&flipped_chunk(&bytes), "flipped").unwrap();
    assert_eq!(
        recording.damaged_chunk_count, 1,
        "{:?}",
        recording.damaged_chunks
    );
    assert_eq!(recording.damaged_chunks[0].offset, chunks(&bytes)[1] as u64);
    assert_eq!(recording.damage, None);
    let read = sequences(&recording);
    // The last message is read: reading went on to the end.
    assert_eq!(read.last(), Some(&(MESSAGES - 1)));
    assert!(
        read.len() < good.len() && read.len() > good.len() / 2,
        "{}",
        read.len()
    );
    // Every message read is one of the file's, unaltered, in order.
    assert!(read.windows(2).all(|w| w[0] < w[1]));
    for message in &recording.messages {
        let nav = message.decode::<NavState>().unwrap();
        assert_eq!(nav, self::nav(nav.header.origin_seq));
    }
}

/// The first chunk holds the only definition of the channel in the data section; the summary
/// repeats it, so the later chunks are still read.
#[test]
fn a_damaged_first_chunk_leaves_the_channel_defined_by_the_summary() {
    let bytes = sample_recording();
    let recording = read_bytes(&flipped(&bytes, 0), "first").unwrap();
    assert_eq!(
        recording.damaged_chunk_count, 1,
        "{:?}",
        recording.damaged_chunks
    );
    assert_eq!(recording.skipped_count, 0, "{:?}", recording.skipped);
    let read = sequences(&recording);
    assert_eq!(read.last(), Some(&(MESSAGES - 1)));
    assert!(read.len() > MESSAGES as usize / 2, "{}", read.len());

    // Without the summary (a recorder killed before it wrote it), they are counted as messages
    // of a channel never defined.
    let cut = &flipped(&bytes, 0)[..chunks(&bytes)[3]];
    let recording = read_bytes(cut, "first-cut").unwrap();
    assert!(recording.messages.is_empty());
    assert!(recording.skipped_count > 0);
    assert_eq!(
        recording.skipped[0].reason,
        rins_recording::SkipReason::UnknownChannel { channel: 1 }
    );
}

/// A record length of 2^51 (one flipped bit) is neither allocated nor trusted: reading resumes
/// at the next chunk.
#[test]
fn a_huge_record_length_is_not_allocated() {
    let bytes = sample_recording();
    let recording = read_bytes(&huge_record_length(&bytes), "huge").unwrap();
    assert_eq!(
        recording.damaged_chunk_count, 1,
        "{:?}",
        recording.damaged_chunks
    );
    let why = &recording.damaged_chunks[0].reason;
    assert!(why.contains("declares 2251799813685"), "{why}");
    assert_eq!(sequences(&recording).last(), Some(&(MESSAGES - 1)));
    assert_eq!(recording.damage, None);
}

/// A chunk declaring 2^51 uncompressed bytes is skipped before anything is decompressed.
#[test]
fn a_huge_chunk_size_is_not_allocated() {
    let bytes = sample_recording();
    let recording = read_bytes(&huge_chunk_size(&bytes), "huge").unwrap();
    assert_eq!(
        recording.damaged_chunk_count, 1,
        "{:?}",
        recording.damaged_chunks
    );
    let why = &recording.damaged_chunks[0].reason;
    assert!(why.contains("more than the 67108864 allowed"), "{why}");
    assert_eq!(sequences(&recording).last(), Some(&(MESSAGES - 1)));
}

/// A record inside an uncompressed chunk without a CRC (as another writer may make it) declaring
/// 2^51 bytes: the chunk is damaged, nothing is allocated.
#[test]
fn a_huge_length_inside_a_chunk_is_not_allocated() {
    let dir = scratch("inner");
    let path = dir.join("plain.mcap");
    let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    let mut writer = mcap::WriteOptions::new()
        .compression(None)
        .calculate_chunk_crcs(false)
        .create(file)
        .unwrap();
    let schema = writer
        .add_schema("rins/msg/NavState", "ros2msg", b"uint16 version\n")
        .unwrap();
    let version = ipc_types::PAYLOAD_VERSION.to_string();
    let metadata = [
        ("type_name".to_string(), "rins::NavState".to_string()),
        ("payload_version".to_string(), version),
    ]
    .into_iter()
    .collect();
    let channel = writer
        .add_channel(schema, names::NAV_STATE, "cdr", &metadata)
        .unwrap();
    let mut message = Vec::new();
    rins_recording::cdr::encode_into(rins_recording::Recordable::as_bytes(&nav(7)), &mut message);
    let header = mcap::records::MessageHeader {
        channel_id: channel,
        sequence: 0,
        log_time: 7,
        publish_time: 7,
    };
    writer.write_to_known_channel(&header, &message).unwrap();
    writer.finish().unwrap();
    drop(writer);
    let mut bytes = std::fs::read(&path).unwrap();
    std::fs::remove_dir_all(dir).unwrap();
    assert_eq!(read_bytes(&bytes, "plain").unwrap().messages.len(), 1);
    // The message record: opcode 5, then its length (22 header bytes and the message).
    let len = (22 + message.len()) as u64;
    let mut pattern = vec![0x05];
    pattern.extend_from_slice(&len.to_le_bytes());
    let at = bytes
        .windows(pattern.len())
        .position(|w| w == pattern)
        .unwrap();
    bytes[at + 1 + 6] ^= 0x08;
    let recording = read_bytes(&bytes, "plain").unwrap();
    assert!(recording.messages.is_empty());
    assert_eq!(
        recording.damaged_chunk_count, 1,
        "{:?}",
        recording.damaged_chunks
    );
    assert!(recording.damaged_chunks[0].reason.contains("2251799813685"));
}

#[test]
fn a_cut_off_sample_keeps_its_whole_chunks() {
    let bytes = sample_recording();
    let cut = &bytes[..chunks(&bytes)[3] + 20];
    let recording = read_bytes(cut, "cut").unwrap();
    let damage = recording.damage.as_deref().unwrap();
    assert!(damage.contains("cut off"), "{damage}");
    assert_eq!(recording.damaged_chunk_count, 0);
    let read = sequences(&recording);
    assert!(!read.is_empty());
    assert_eq!(read, (0..read.len() as u64).collect::<Vec<_>>());
}

#[test]
fn dev_zero_is_refused_at_once_naming_it() {
    let err = within_seconds(|| read_file("/dev/zero").map(|r| r.messages.len()));
    let text = err.unwrap_err().to_string();
    assert_eq!(text, "/dev/zero is a character device, not a regular file");
}

#[test]
fn a_fifo_is_refused_without_waiting_for_a_writer() {
    let dir = scratch("fifo");
    let fifo = dir.join("rec.mcap");
    let c = std::ffi::CString::new(fifo.to_string_lossy().as_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let path = fifo.clone();
    let err = within_seconds(move || read_file(&path).map(|r| r.messages.len())).unwrap_err();
    let text = err.to_string();
    assert_eq!(
        text,
        format!("{} is a FIFO, not a regular file", fifo.display())
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_directory_is_refused_naming_it() {
    let dir = scratch("directory");
    let err = read_file(&dir).unwrap_err();
    assert!(matches!(err, ReadError::File(_)), "{err}");
    assert_eq!(
        err.to_string(),
        format!("{} is a directory, not a regular file", dir.display())
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_file_above_the_ceiling_is_refused_naming_it() {
    let dir = scratch("large");
    let path = dir.join("large.mcap");
    // Sparse: no disk is used.
    let file = std::fs::File::create(&path).unwrap();
    file.set_len(MAX_RECORDING_BYTES + 1).unwrap();
    let err = within_seconds({
        let path = path.clone();
        move || read_file(&path).map(|r| r.messages.len())
    })
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "{} has {} bytes, more than the {MAX_RECORDING_BYTES} allowed",
            path.display(),
            MAX_RECORDING_BYTES + 1
        )
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_file_that_is_not_mcap_is_refused_naming_it() {
    let dir = scratch("text");
    let path = dir.join("notes.mcap");
    std::fs::write(&path, "not a recording\n").unwrap();
    let text = read_file(&path).unwrap_err().to_string();
    assert!(
        text.starts_with(&format!("{}: not an MCAP recording", path.display())),
        "{text}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// The seeds: name and bytes.
fn seeds() -> Vec<(&'static str, Vec<u8>)> {
    let bytes = sample_recording();
    let chunk = chunks(&bytes);
    vec![
        ("cut-in-chunk.mcap", bytes[..chunk[2] + 40].to_vec()),
        ("cut-half.mcap", bytes[..bytes.len() / 2].to_vec()),
        ("flipped-chunk.mcap", flipped_chunk(&bytes)),
        ("flipped-first-chunk.mcap", flipped(&bytes, 0)),
        ("huge-record-length.mcap", huge_record_length(&bytes)),
        ("huge-chunk-size.mcap", huge_chunk_size(&bytes)),
        ("valid.mcap", bytes),
    ]
}

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus/recording")
}

/// Every committed seed (and any crash input added to them) is read to its end.
#[test]
fn every_fuzz_seed_is_read_to_its_end() {
    let dir = corpus_dir();
    if std::env::var_os("RINS_WRITE_FUZZ_SEEDS").is_some() {
        std::fs::create_dir_all(&dir).unwrap();
        for (name, bytes) in seeds() {
            std::fs::write(dir.join(name), bytes).unwrap();
        }
    }
    let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    for (name, _) in seeds() {
        assert!(names.contains(&dir.join(name)), "seed {name} is missing");
    }
    for path in names {
        let bytes = std::fs::read(&path).unwrap();
        let Ok(mut messages) = Messages::new(&bytes, &path.display().to_string()) else {
            continue;
        };
        for message in &mut messages {
            match message {
                Ok(m) => assert_eq!(m.payload.len(), m.layout.size),
                Err(_) => break,
            }
        }
        assert!(messages.next().is_none(), "{}", path.display());
    }
}
