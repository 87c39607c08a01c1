//! HDR histogram interval logs: what `rins latency --hdr FILE` writes. One histogram per hop and
//! interval, tagged with the hop, in the format HdrHistogram's own tools (HistogramLogAnalyzer,
//! `hdr-plot`) read; the values are nanoseconds.

use std::io::Write;
use std::time::{Duration, SystemTime};

use anyhow::{Result, anyhow};
use hdrhistogram::Histogram;
use hdrhistogram::serialization::V2DeflateSerializer;
use hdrhistogram::serialization::interval_log::{IntervalLogWriter, IntervalLogWriterBuilder, Tag};

/// A tag for a hop: the log format's tags hold no separators or white space.
pub fn tag_of(hop: &str) -> String {
    hop.chars()
        .filter_map(|c| match c {
            c if c.is_ascii_alphanumeric() => Some(c),
            '>' => None,
            _ => Some('_'),
        })
        .collect::<String>()
        .split('_')
        .filter(|s| !s.is_empty() && *s != "-")
        .collect::<Vec<_>>()
        .join("_")
}

/// An open interval log.
pub struct IntervalLog<'a, W: Write> {
    writer: IntervalLogWriter<'a, 'a, W, V2DeflateSerializer>,
    started: SystemTime,
}

impl<'a, W: Write> IntervalLog<'a, W> {
    /// Starts a log on `out` whose interval times count from `started`.
    pub fn begin(
        out: &'a mut W,
        serializer: &'a mut V2DeflateSerializer,
        started: SystemTime,
    ) -> Result<Self> {
        let writer = IntervalLogWriterBuilder::new()
            .add_comment("rins latency: per-hop latency, ns")
            .with_start_time(started)
            .with_max_value_divisor(1000.0)
            .begin_log_with(out, serializer)
            .map_err(|e| anyhow!("writing the HDR log header: {e}"))?;
        Ok(Self { writer, started })
    }

    /// Writes one interval of one hop: `from`..`to` (wall clock) holds `histogram`.
    pub fn interval(
        &mut self,
        hop: &str,
        histogram: &Histogram<u64>,
        from: SystemTime,
        to: SystemTime,
    ) -> Result<()> {
        let tag = tag_of(hop);
        let start = from.duration_since(self.started).unwrap_or(Duration::ZERO);
        let length = to.duration_since(from).unwrap_or(Duration::ZERO);
        self.writer
            .write_histogram(histogram, start, length, Tag::new(&tag))
            .map_err(|e| anyhow!("writing the HDR log interval of {hop}: {e}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hdrhistogram::serialization::interval_log::{IntervalLogIterator, LogEntry};

    #[test]
    fn hop_names_become_tags_the_format_accepts() {
        assert_eq!(
            tag_of("serial rx -> nav state published"),
            "serial_rx_nav_state_published"
        );
        assert!(Tag::new(&tag_of("navigator published -> consumer received")).is_some());
    }

    #[test]
    fn an_interval_reads_back_with_its_tag_and_values() {
        let mut h = Histogram::<u64>::new_with_bounds(1, 10_000_000_000, 3).unwrap();
        for v in [10_000, 20_000, 30_000] {
            h.record(v).unwrap();
        }
        let started = SystemTime::UNIX_EPOCH + Duration::from_secs(1_700_000_000);
        let mut buf = Vec::new();
        let mut ser = V2DeflateSerializer::new();
        {
            let mut log = IntervalLog::begin(&mut buf, &mut ser, started).unwrap();
            log.interval(
                "fusion -> navigator published",
                &h,
                started + Duration::from_secs(2),
                started + Duration::from_secs(3),
            )
            .unwrap();
        }
        let mut intervals = 0;
        for entry in IntervalLogIterator::new(&buf) {
            if let LogEntry::Interval(i) = entry.unwrap() {
                intervals += 1;
                assert_eq!(
                    i.tag().map(|t| t.as_str()),
                    Some("fusion_navigator_published")
                );
                assert_eq!(i.start_timestamp(), Duration::from_secs(2));
                assert_eq!(i.duration(), Duration::from_secs(1));
                // The largest value, in µs (the log's value divisor).
                assert!((i.max() - 30.0).abs() < 0.05, "{}", i.max());
                assert!(!i.encoded_histogram().is_empty());
            }
        }
        assert_eq!(intervals, 1);
    }
}
