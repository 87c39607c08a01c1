//! A damaged recording is plotted from what it still holds, with the damage counted; a path that
//! is no recording file is refused at once, naming it.

use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Duration;

use ipc_types::{NavMode, NavState, names};
use rins_recording::{RecordOptions, Recorder};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rins-plot-damaged-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Where each chunk record of an MCAP file starts, with its length.
fn chunks(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut pos = 8;
    while pos + 9 <= bytes.len() && bytes[pos] != 0x0F {
        let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().unwrap()) as usize;
        if bytes[pos] == 0x06 {
            out.push((pos, len));
        }
        pos += 9 + len;
    }
    out
}

#[test]
fn a_chunk_with_flipped_bits_is_counted_and_the_rest_plotted() {
    let dir = scratch("flipped");
    let file = dir.join("run.mcap");
    let options = RecordOptions {
        chunk_size: 4096,
        ..Default::default()
    };
    let mut rec = Recorder::create(&file, &options).unwrap();
    let ch = rec.channel_for::<NavState>(names::NAV_LANES[0]).unwrap();
    for i in 0..400u64 {
        let mut nav = NavState {
            mode: NavMode::Navigating as u8,
            quaternion: [1.0, 0.0, 0.0, 0.0],
            altitude_m: 500.0,
            ..NavState::default()
        };
        nav.header.origin_seq = i;
        nav.header.origin_rx_ns = 1_000_000_000 + i * 10_000_000;
        nav.header.origin_device_time_us = i * 10_000;
        let t = nav.header.origin_rx_ns;
        rec.write_payload(ch, t, t, &nav).unwrap();
    }
    rec.finish().unwrap();
    let mut bytes = std::fs::read(&file).unwrap();
    let chunks = chunks(&bytes);
    assert!(chunks.len() >= 3, "{} chunks", chunks.len());
    let (start, len) = chunks[1];
    let middle = start + 9 + len / 2;
    for i in 0..16 {
        bytes[middle + i] ^= 1 << (i % 8);
    }
    std::fs::write(&file, &bytes).unwrap();

    let report = rins_plot::plot_recording(&file, &dir.join("plots"), |_| {}).unwrap();
    assert_eq!(report.damaged_chunks, 1);
    assert_eq!(report.damaged_messages, 0);
    assert_eq!(report.damage, None);
    assert!(!report.written.is_empty(), "{:?}", report.skipped);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn dev_zero_is_refused_at_once_naming_it() {
    let dir = scratch("zero");
    let out = dir.join("plots");
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let result = rins_plot::plot_recording("/dev/zero".as_ref(), &out, |_| {});
        let _ = tx.send(result.map(|r| r.written.len()).map_err(|e| e.to_string()));
    });
    let result = rx
        .recv_timeout(Duration::from_secs(5))
        .expect("plotting /dev/zero did not end within 5 s");
    assert_eq!(
        result,
        Err("/dev/zero is a character device, not a regular file".to_string())
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
