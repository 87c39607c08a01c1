//! The two constants that assemble NMEA epochs, measured on the real-receiver corpus
//! (crates/gnss-protocol/tests/captures, the captures with NMEA position sentences):
//!
//! - `SAME_EPOCH_US` (10 ms): sentences whose UTC times differ by less are one epoch. It must be
//!   above the largest difference between the time fields of one epoch's sentences (one instant
//!   printed with 2 or 3 decimals, rounded or truncated) and not above the shortest time between
//!   two epochs.
//! - `EPOCH_QUIET_NS` (1 s): an epoch the receiver has sent nothing for this long is handed out.
//!   It must be above the largest line-time gap between two timed sentences of one epoch (a
//!   burst of GSV between them), or epochs would be handed out before their last sentence. Above
//!   it, the bound is the receivers' own period: capture files keep no idle line time, so in the
//!   replay epochs follow each other back to back; at 1 Hz and faster the next epoch's first
//!   sentence closes an epoch first, and only for receivers slower than 1 Hz does the timeout
//!   hand an epoch out earlier, which it does while below their shortest period.
//!
//! Epochs are told apart here by the receivers' own output, not by the constants under test: a
//! timed sentence starts a new epoch when its time is 50 ms (the period of the fastest NMEA
//! output, 20 Hz) or more from the epoch's first, or when its address (talker and kind) already
//! came in the epoch with another time. The line time of a sentence is that of the read that
//! completes it in the evaluation's replay: 64-byte reads at 9600 baud. A capture whose bytes
//! take longer at 9600 baud than the receiver time they cover was recorded on a faster line; its
//! gaps at 9600 baud are not a receiver's and are printed, not bounded.
//!
//! `cargo test -p rins-eval --test nmea_epoch_timing -- --nocapture` prints the figures.

use std::path::PathBuf;

use rins_eval::gnss_captures::replay::{self, CHUNK_BYTES, NS_PER_BYTE, ProtocolGroup};
use rins_gnss_protocol::decode::framer::{Framed, Framer};
use rins_gnss_protocol::decode::{EPOCH_QUIET_NS, SAME_EPOCH_US};

const DAY_US: u64 = 86_400_000_000;
/// The period of the fastest NMEA output (20 Hz): sentence times this far apart are two epochs.
const SPLIT_US: u64 = 50_000;

fn corpus() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../crates/gnss-protocol/tests/captures")
}

/// `hhmmss[.f…]` as µs of the day.
fn time_of_day_us(field: &str) -> Option<u64> {
    let (whole, fraction) = field.split_once('.').unwrap_or((field, ""));
    if whole.len() != 6 || !whole.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let n = |r: std::ops::Range<usize>| whole[r].parse::<u64>().ok();
    let (h, m, s) = (n(0..2)?, n(2..4)?, n(4..6)?);
    let mut us = 0;
    let mut scale = 100_000;
    for d in fraction.bytes().take(6) {
        us += u64::from(d.checked_sub(b'0').filter(|d| *d < 10)?) * scale;
        scale /= 10;
    }
    (h < 24 && m < 60 && s < 61).then_some(((h * 60 + m) * 60 + s) * 1_000_000 + us)
}

/// The address (talker and kind) and UTC time of a sentence with a good checksum that the
/// decoder places by its time (GGA, GNS, RMC, GST, GLL).
fn sentence_time_us(sentence: &[u8]) -> Option<([u8; 5], u64)> {
    let text = std::str::from_utf8(sentence).ok()?;
    let line = text.trim_end().strip_prefix('$')?.trim_start_matches('$');
    let (body, checksum) = line.rsplit_once('*')?;
    let xor = body.bytes().fold(0u8, |c, b| c ^ b);
    if u8::from_str_radix(checksum, 16).ok()? != xor {
        return None;
    }
    let fields: Vec<&str> = body.split(',').collect();
    let address = fields.first()?;
    let at = match address.get(2..)? {
        "GGA" | "GNS" | "RMC" | "GST" => 1,
        "GLL" => 5,
        _ => return None,
    };
    let address: [u8; 5] = address.as_bytes().try_into().ok()?;
    Some((address, time_of_day_us(fields.get(at)?)?))
}

/// Time difference across midnight too, µs.
fn apart_us(a: u64, b: u64) -> u64 {
    let d = a.abs_diff(b) % DAY_US;
    d.min(DAY_US - d)
}

/// What one capture's NMEA epochs show.
#[derive(Debug, Default, Clone, Copy)]
struct Timing {
    /// Largest time-field difference between sentences of one epoch, µs.
    within_epoch_us: u64,
    /// Shortest period between consecutive epochs, µs.
    period_us: Option<u64>,
    /// Largest line-time gap between consecutive timed sentences of one epoch, ns.
    within_epoch_gap_ns: u64,
    /// Shortest line time from an epoch's last timed sentence to the next epoch's first, ns.
    between_epochs_gap_ns: Option<u64>,
    /// Line time of the bytes over the receiver time they cover: above 1, the receiver sent
    /// faster than a 9600-baud line carries.
    line_load: f64,
}

/// A sentence the decoder places by its time: line time of the read that completed it, address,
/// UTC time of day.
type Timed = (u64, [u8; 5], u64);

/// The timed sentences of `bytes` with the line time of the read that completed each.
fn timed_sentences(bytes: &[u8]) -> Vec<Timed> {
    let mut framer = Box::<Framer>::default();
    let mut out = Vec::new();
    let mut received = 0u64;
    for chunk in bytes.chunks(CHUNK_BYTES) {
        received += chunk.len() as u64;
        let rx_ns = received * NS_PER_BYTE;
        framer.push(chunk, |item| {
            if let Framed::Nmea(s) = item
                && let Some((address, t)) = sentence_time_us(s)
            {
                out.push((rx_ns, address, t));
            }
        });
    }
    out
}

/// The epochs of `sentences`, as index ranges: a sentence starts a new epoch when its time is
/// [`SPLIT_US`] or more from the epoch's first, or when its address already occurred in the
/// epoch with another time (a receiver sends each sentence once per epoch; a repeat of the same
/// time is the same epoch's sentence sent twice).
fn epochs(sentences: &[Timed]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..sentences.len() {
        let (_, address, time) = sentences[i];
        let epoch = &sentences[start..i];
        let far = apart_us(epoch[0].2, time) >= SPLIT_US;
        let repeated = epoch.iter().any(|s| s.1 == address && s.2 != time);
        if far || repeated {
            out.push(start..i);
            start = i;
        }
    }
    if start < sentences.len() {
        out.push(start..sentences.len());
    }
    out
}

fn timing(bytes: &[u8]) -> Timing {
    let sentences = timed_sentences(bytes);
    let epochs = epochs(&sentences);
    let mut t = Timing::default();
    for (k, range) in epochs.iter().enumerate() {
        let epoch = &sentences[range.clone()];
        for (a, b) in epoch.iter().zip(&epoch[1..]) {
            t.within_epoch_gap_ns = t.within_epoch_gap_ns.max(b.0 - a.0);
        }
        for a in epoch {
            for b in epoch {
                t.within_epoch_us = t.within_epoch_us.max(apart_us(a.2, b.2));
            }
        }
        if let Some(next) = epochs.get(k + 1) {
            let next = &sentences[next.clone()];
            let period = apart_us(epoch[0].2, next[0].2);
            t.period_us = Some(t.period_us.map_or(period, |p| p.min(period)));
            let gap = next[0].0 - epoch[epoch.len() - 1].0;
            t.between_epochs_gap_ns = Some(t.between_epochs_gap_ns.map_or(gap, |g| g.min(gap)));
        }
    }
    if let (Some(first), Some(last)) = (epochs.first(), epochs.last())
        && epochs.len() > 1
    {
        let span_us = apart_us(sentences[first.start].2, sentences[last.start].2);
        let covered = sentences[last.start].0 - sentences[first.start].0;
        t.line_load = covered as f64 / (span_us as f64 * 1e3);
    }
    t
}

/// One capture's figures, named.
struct Measured {
    name: String,
    timing: Timing,
}

fn measured_nmea_captures() -> Vec<Measured> {
    let mut names: Vec<String> = std::fs::read_dir(corpus())
        .expect("the corpus is readable")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".log"))
        .collect();
    names.sort();
    let mut out = Vec::new();
    for name in names {
        let log = std::fs::read(corpus().join(&name)).expect("a capture is readable");
        let bytes = replay::receiver_bytes(&log);
        let group = replay::protocols_seen(bytes).group();
        if matches!(group, ProtocolGroup::NmeaOnly | ProtocolGroup::Mixed) {
            out.push(Measured {
                name,
                timing: timing(bytes),
            });
        }
    }
    out
}

/// The capture with the largest `key`, and that value.
fn largest<T: PartialOrd + Copy>(of: &[&Measured], key: impl Fn(&Timing) -> T) -> (String, T) {
    let best = of
        .iter()
        .max_by(|a, b| key(&a.timing).partial_cmp(&key(&b.timing)).unwrap())
        .expect("captures");
    (best.name.clone(), key(&best.timing))
}

/// The capture with the smallest `key` where it has one, and that value.
fn smallest(of: &[&Measured], key: impl Fn(&Timing) -> Option<u64>) -> (String, u64) {
    of.iter()
        .filter_map(|m| Some((m.name.clone(), key(&m.timing)?)))
        .min_by_key(|(_, v)| *v)
        .expect("captures with two epochs")
}

#[test]
fn the_epoch_constants_lie_between_what_the_receivers_do() {
    let captures = measured_nmea_captures();
    assert_eq!(captures.len(), 91, "NMEA captures (NMEA only and mixed)");
    let all: Vec<&Measured> = captures.iter().collect();
    let s = |ns: u64| ns as f64 / 1e9;

    // The window: one instant printed differently, against the shortest period.
    let (within_name, within_us) = largest(&all, |t| t.within_epoch_us);
    let (period_name, period_us) = smallest(&all, |t| t.period_us);
    println!(
        "same-epoch window {} ms: largest time difference within an epoch {} ms ({within_name}), \
         shortest period {} ms ({period_name})",
        SAME_EPOCH_US as f64 / 1e3,
        within_us as f64 / 1e3,
        period_us as f64 / 1e3
    );
    // Times closer than the window are one epoch: the window may equal the shortest period.
    assert!(within_us < SAME_EPOCH_US && SAME_EPOCH_US <= period_us);
    assert_eq!((within_us, period_us), (5_000, 10_000));

    // The quiet timeout: gaps within one epoch's burst at 9600 baud, for the receivers whose
    // output a 9600-baud line carries; the others were recorded on a faster line.
    let fits: Vec<&Measured> = all
        .iter()
        .copied()
        .filter(|m| m.timing.line_load <= 1.0)
        .collect();
    let faster: Vec<&Measured> = all
        .iter()
        .copied()
        .filter(|m| m.timing.line_load > 1.0)
        .collect();
    let (gap_name, gap_ns) = largest(&fits, |t| t.within_epoch_gap_ns);
    for m in &faster {
        println!(
            "  recorded faster than 9600 baud carries ({:.2} times): {}, gap within an epoch {:.3} s \
             at 9600 baud",
            m.timing.line_load,
            m.name,
            s(m.timing.within_epoch_gap_ns)
        );
    }
    let (between_name, between_ns) = smallest(&all, |t| t.between_epochs_gap_ns);
    let slow: Vec<&Measured> = all
        .iter()
        .copied()
        .filter(|m| m.timing.period_us.is_some_and(|p| p > 1_000_000))
        .collect();
    let (slow_name, slow_period_us) = smallest(&slow, |t| t.period_us);
    println!(
        "quiet timeout {} s: largest gap within an epoch {:.3} s ({gap_name}, of {} captures a \
         9600-baud line carries); shortest line time between epochs {:.3} s ({between_name}); \
         shortest period of the receivers slower than 1 Hz {:.3} s ({slow_name})",
        s(EPOCH_QUIET_NS),
        s(gap_ns),
        fits.len(),
        s(between_ns),
        slow_period_us as f64 / 1e6
    );
    assert!(gap_ns < EPOCH_QUIET_NS && EPOCH_QUIET_NS < slow_period_us * 1_000);
    assert!(gap_ns <= 733_400_000, "{gap_name}: {gap_ns} ns");
    // Capture files hold no idle line time: epochs follow each other back to back.
    assert!(between_ns < 50_000_000, "{between_name}: {between_ns} ns");
    assert_eq!(faster.len(), 4, "captures recorded faster than 9600 baud");
}
