//! The names of rins's own recordings: `rins-RRRRRR-PPPP-YYYYMMDDTHHMMSSZ.mcap`, the run's number
//! (one more than the highest in the directory), the part's number within the run (a new part at
//! each size limit) and the UTC time the part was started. The numbers, not the time, order the
//! recordings: a computer without a battery-backed clock (a Raspberry Pi) may boot in the past.

use std::time::{SystemTime, UNIX_EPOCH};

const PREFIX: &str = "rins-";
const SUFFIX: &str = ".mcap";
/// Digits written of a run's number (more once it needs them).
const RUN_DIGITS: usize = 6;
/// Digits written of a part's number.
const PART_DIGITS: usize = 4;

/// Where a recording stands among rins's own: by run, then by part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Sequence {
    /// The run of `rins up` (or `rins record --dir`) that made it.
    pub run: u64,
    /// The part within the run, from 1.
    pub part: u64,
}

/// The file name of `seq`, started at `time`.
pub fn file_name(seq: Sequence, time: SystemTime) -> String {
    format!(
        "{PREFIX}{:0RUN_DIGITS$}-{:0PART_DIGITS$}-{}{SUFFIX}",
        seq.run,
        seq.part,
        utc_stamp(time)
    )
}

/// The sequence of a name [`file_name`] made; `None` for any other name.
pub fn parse(name: &str) -> Option<Sequence> {
    let rest = name.strip_prefix(PREFIX)?.strip_suffix(SUFFIX)?;
    let mut fields = rest.split('-');
    let run = number(fields.next()?, RUN_DIGITS)?;
    let part = number(fields.next()?, PART_DIGITS)?;
    let stamp = fields.next()?;
    if fields.next().is_some() || !is_stamp(stamp) {
        return None;
    }
    Some(Sequence { run, part })
}

/// A number of at least `digits` ASCII digits, no sign.
fn number(text: &str, digits: usize) -> Option<u64> {
    if text.len() < digits || !text.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    text.parse().ok()
}

/// `YYYYMMDDTHHMMSSZ`.
fn is_stamp(text: &str) -> bool {
    let b = text.as_bytes();
    b.len() == 16
        && b[8] == b'T'
        && b[15] == b'Z'
        && b[..8].iter().chain(&b[9..15]).all(u8::is_ascii_digit)
}

/// `time` as `YYYYMMDDTHHMMSSZ` (UTC); a time before 1970 as the epoch.
pub fn utc_stamp(time: SystemTime) -> String {
    let secs = time.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let (days, day_secs) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days);
    format!(
        "{y:04}{m:02}{d:02}T{:02}{:02}{:02}Z",
        day_secs / 3600,
        day_secs / 60 % 60,
        day_secs % 60
    )
}

/// The proleptic Gregorian date of a day count since 1970-01-01 (Howard Hinnant's algorithm).
fn civil_from_days(days: u64) -> (u64, u64, u64) {
    let z = days + 719_468;
    let era = z / 146_097;
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + u64::from(m <= 2);
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn utc_stamps_of_known_times() {
        let at = |s| utc_stamp(UNIX_EPOCH + Duration::from_secs(s));
        assert_eq!(at(0), "19700101T000000Z");
        // 2000-02-29 12:34:56, a leap day of a century leap year.
        assert_eq!(at(951_827_696), "20000229T123456Z");
        // 2026-12-06 04:19:05.
        assert_eq!(at(1_796_530_745), "20261206T041905Z");
        assert_eq!(
            utc_stamp(UNIX_EPOCH - Duration::from_secs(5)),
            "19700101T000000Z"
        );
    }

    #[test]
    fn names_round_trip_and_nothing_else_parses() {
        let seq = Sequence { run: 42, part: 3 };
        let name = file_name(seq, UNIX_EPOCH + Duration::from_secs(951_827_696));
        assert_eq!(name, "rins-000042-0003-20000229T123456Z.mcap");
        assert_eq!(parse(&name), Some(seq));
        let big = Sequence {
            run: 1_234_567,
            part: 12_345,
        };
        assert_eq!(parse(&file_name(big, UNIX_EPOCH)), Some(big));
        for other in [
            "flight.mcap",
            "rins-000042-0003-20000229T123456Z.mcap.tmp",
            "rins-42-0003-20000229T123456Z.mcap",
            "rins-000042-003-20000229T123456Z.mcap",
            "rins-000042-0003-20000229T123456.mcap",
            "rins-000042-0003-20000229X123456Z.mcap",
            "rins-00004a-0003-20000229T123456Z.mcap",
            "rins-+00042-0003-20000229T123456Z.mcap",
            "rins-000042-0003-20000229T123456Z-x.mcap",
            "Rins-000042-0003-20000229T123456Z.mcap",
        ] {
            assert_eq!(parse(other), None, "{other}");
        }
        // Run before part: the order of the recordings.
        assert!(Sequence { run: 2, part: 1 } > Sequence { run: 1, part: 9 });
    }
}
