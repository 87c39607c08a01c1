//! `rins echo TOPIC`: print every sample of a topic, as JSON lines or CSV, in its readable form
//! (see [`super::echo_readable`]) or, with `--raw`, exactly as it travels.

use std::io::Write;
use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use ipc_types::{NavState, names};
use rins_navigator::lanes::NavSubscriber;
use rins_runtime::ipc::{IpcNode, SampleSource, TopicSubscriber};
use rins_runtime::payload::{OtherVersionWarning, Versioned};
use rins_runtime::setup_guard::SetupGuard;
use rins_runtime::shutdown::Shutdown;
use rins_runtime::tool_node::ToolNode;
use serde_json::Value;

use super::echo_readable::{BIT_FIELDS, Readable};

/// Flattens nested objects and arrays into `a.b.0`-style columns. A list of bit names (a field of
/// [`BIT_FIELDS`]) is one cell, its names joined by `|`: its length changes from row to row, the
/// columns must not.
fn flatten(prefix: &str, value: &Value, out: &mut Vec<(String, String)>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                let key = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                flatten(&key, v, out);
            }
        }
        Value::Array(items) if is_bit_field(prefix) => {
            let names: Vec<String> = items
                .iter()
                .map(|v| v.as_str().map_or_else(|| v.to_string(), str::to_string))
                .collect();
            out.push((prefix.to_string(), names.join("|")));
        }
        Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                flatten(&format!("{prefix}.{i}"), v, out);
            }
        }
        // A name is written without JSON quotes; none contains a comma.
        Value::String(text) => out.push((prefix.to_string(), text.clone())),
        other => out.push((prefix.to_string(), other.to_string())),
    }
}

/// Whether the column `path` (`a.b.c`) is a bit set listed by name.
fn is_bit_field(path: &str) -> bool {
    let last = path.rsplit('.').next().unwrap_or(path);
    BIT_FIELDS.contains(&last)
}

/// The JSON object printed for `sample`: the wire form with `raw`, else the readable form.
fn render<T: Readable>(sample: &T, raw: bool) -> serde_json::Result<Value> {
    if raw {
        serde_json::to_value(sample)
    } else {
        sample.readable()
    }
}

/// The CSV columns of `value`: names for the header line, values for a row.
fn csv_columns(value: &Value) -> Vec<(String, String)> {
    let mut columns = Vec::new();
    flatten("", value, &mut columns);
    columns
}

/// What to print and when to give up.
#[derive(Clone, Copy)]
struct EchoOptions {
    count: Option<u64>,
    csv: bool,
    /// The wire form, padding and unused slots included, enums and bit sets as numbers.
    raw: bool,
    /// Longest wait for the next sample; `None` waits for ever.
    timeout: Option<Duration>,
}

fn echo_topic<T>(name: &'static str, opts: EchoOptions) -> Result<()>
where
    T: std::fmt::Debug
        + Copy
        + Readable
        + ReceivedAt
        + Versioned
        + iceoryx2::prelude::ZeroCopySend
        + 'static,
{
    echo_from(name, opts, |node| TopicSubscriber::<T>::new(node, name))
}

/// When a sample's originating frame was received (CLOCK_MONOTONIC ns), for payloads that say.
trait ReceivedAt {
    fn received_ns(&self) -> Option<u64>;
}

/// The receive time of every payload of the topic table.
macro_rules! received_at {
    // Truth comes from the simulator, not from a received frame: no receive time.
    (@one Truth stamped) => {
        received_at!(@one Truth unstamped);
    };
    (@one $payload:ident stamped) => {
        impl ReceivedAt for ipc_types::$payload {
            fn received_ns(&self) -> Option<u64> {
                Some(self.header.origin_rx_ns)
            }
        }
    };
    (@one $payload:ident unstamped) => {
        impl ReceivedAt for ipc_types::$payload {
            fn received_ns(&self) -> Option<u64> {
                None
            }
        }
    };
    ($($payload:ident $kind:ident;)+) => {
        $(received_at!(@one $payload $kind);)+
    };
}

ipc_types::for_each_topic!(payloads => received_at);

/// The payload `rins echo` shows for each short name the topic table gives (every payload has a
/// [`Readable`] form).
macro_rules! echo_by_short_name {
    ($($short:literal $constant:ident $payload:ident $kind:ident;)+) => {
        /// Prints the topic whose echo short name is `short`; `None` for a name the table does
        /// not give.
        fn echo_by_short_name(short: &str, opts: EchoOptions) -> Option<Result<()>> {
            match short {
                $($short => Some(echo_topic::<ipc_types::$payload>(names::$constant, opts)),)+
                _ => None,
            }
        }
    };
}

ipc_types::for_each_topic!(echo => echo_by_short_name);

/// Prints what `open` yields, a topic or the merged navigation stream. Samples from before the
/// start (a topic's history, kept for restarted services) are skipped: echo shows what comes.
fn echo_from<T, S>(
    name: &'static str,
    opts: EchoOptions,
    open: impl FnOnce(&IpcNode) -> Result<S, rins_runtime::ipc::IpcError>,
) -> Result<()>
where
    T: Readable + ReceivedAt,
    S: SampleSource<T>,
{
    let started_ns = rins_runtime::clock::monotonic_ns();
    let shutdown = Shutdown::install()?;
    // Joining and subscribing keep the timeout and stop on a signal, whatever the deployment's
    // files hold: iceoryx2 waits for ever on some damaged ones, and never looks at the flag.
    let guard = SetupGuard::arm(
        format!("echo: subscribing to {name:?}"),
        opts.timeout,
        Some(shutdown.clone()),
    );
    // Ports are made after the tool node, so they are dropped before it cleans up.
    let tool = ToolNode::join("echo")?;
    let node = tool.node();
    let mut sub = open(node)?;
    guard.disarm();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let mut printed = 0u64;
    let EchoOptions {
        count,
        csv,
        raw,
        timeout,
    } = opts;
    let mut last_sample = Instant::now();
    let mut version_warning = OtherVersionWarning::new();
    while !shutdown.requested() && count.is_none_or(|c| printed < c) {
        if let Some(limit) = timeout
            && last_sample.elapsed() > limit
        {
            bail!(
                "no sample on topic {name:?} for {:.1} s after {printed} printed: \
                 is the pipeline running (`rins up`) with the same RINS_IPC_PREFIX?",
                limit.as_secs_f64()
            );
        }
        sub.wait(Duration::from_millis(100))?;
        while let Some(sample) = sub.receive()? {
            if sample.received_ns().is_some_and(|t| t < started_ns) {
                continue;
            }
            last_sample = Instant::now();
            let value = render(&sample, raw)?;
            if csv {
                let columns = csv_columns(&value);
                if printed == 0 {
                    let header: Vec<&str> = columns.iter().map(|(k, _)| k.as_str()).collect();
                    writeln!(out, "{}", header.join(","))?;
                }
                let row: Vec<&str> = columns.iter().map(|(_, v)| v.as_str()).collect();
                writeln!(out, "{}", row.join(","))?;
            } else {
                writeln!(out, "{value}")?;
            }
            printed += 1;
            if count.is_some_and(|c| printed >= c) {
                break;
            }
        }
        version_warning.check("echo", sub.rejected());
        out.flush()?;
    }
    Ok(())
}

/// Prints `topic` (its short name, e.g. `nav`) until `count` samples, a stop or `timeout_s`
/// seconds without a sample (0: wait for ever); `raw` prints the wire form.
pub fn run(topic: &str, count: Option<u64>, csv: bool, raw: bool, timeout_s: f64) -> Result<()> {
    if !(timeout_s.is_finite() && timeout_s >= 0.0) {
        bail!(
            "--timeout {timeout_s}: must be zero (wait for ever) or a positive number of seconds"
        );
    }
    let opts = EchoOptions {
        count,
        csv,
        raw,
        timeout: (timeout_s > 0.0).then(|| Duration::from_secs_f64(timeout_s)),
    };
    let Some((_, service)) = names::TOPICS.iter().find(|(short, _)| *short == topic) else {
        let known: Vec<&str> = names::TOPICS.iter().map(|(s, _)| *s).collect();
        bail!(
            "unknown topic {topic:?}: expected one of {}",
            known.join(", ")
        );
    };
    // The stream consumers see: both navigator lanes through the lane selector.
    if *service == names::NAV_STATE {
        return echo_from::<NavState, _>(names::NAV_STATE, opts, NavSubscriber::new);
    }
    match echo_by_short_name(topic, opts) {
        Some(echoed) => echoed,
        // Unreachable while the short name comes from the same table; refused, never guessed.
        None => bail!("topic {topic:?} ({service}) cannot be echoed"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::FusedImu;

    #[test]
    fn flatten_names_nested_columns() {
        let v = serde_json::json!({"a": 1, "b": {"c": [2, 3]}});
        let mut out = Vec::new();
        flatten("", &v, &mut out);
        let keys: Vec<&str> = out.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(keys, ["a", "b.c.0", "b.c.1"]);
        assert_eq!(out[2].1, "3");
    }

    fn four_gyro_fused() -> FusedImu {
        let mut f = FusedImu {
            n_gyro: 4,
            n_accel: 4,
            flags: ipc_types::fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED
                | ipc_types::fused_flags::GYRO_REST_BIAS_PENDING,
            ..FusedImu::default()
        };
        f.gyro_state[..4].fill(ipc_types::ChannelState::Ok as u8);
        f.accel_state[..4].fill(ipc_types::ChannelState::Ok as u8);
        f.gyro_state[1] = ipc_types::ChannelState::Suspect as u8;
        f
    }

    #[test]
    fn csv_of_a_four_gyro_fused_sample_has_the_four_channels_by_name() {
        let columns = csv_columns(&render(&four_gyro_fused(), false).unwrap());
        let keys: Vec<&str> = columns.iter().map(|(k, _)| k.as_str()).collect();
        let gyro_state: Vec<(&str, &str)> = columns
            .iter()
            .filter(|(k, _)| k.starts_with("gyro_state."))
            .map(|(k, v)| (k.as_str(), v.as_str()))
            .collect();
        assert_eq!(
            gyro_state,
            [
                ("gyro_state.0", "ok"),
                ("gyro_state.1", "suspect"),
                ("gyro_state.2", "ok"),
                ("gyro_state.3", "ok"),
            ]
        );
        for per_channel in ["gyro_reason", "accel_state", "accel_reason"] {
            let n = keys.iter().filter(|k| k.starts_with(per_channel)).count();
            assert_eq!(n, 4, "{per_channel}: {keys:?}");
        }
        assert!(!keys.iter().any(|k| k.contains("_pad")), "{keys:?}");
        let flags = columns.iter().find(|(k, _)| k == "flags").unwrap();
        assert_eq!(flags.1, "gyro-fault-not-isolated|gyro-rest-bias-pending");
        assert!(keys.contains(&"header.stage_pub_ns.navigator"), "{keys:?}");
        // 41 columns where the wire form has 89.
        assert_eq!(columns.len(), 41, "{keys:?}");
    }

    #[test]
    fn raw_keeps_the_wire_form() {
        let f = four_gyro_fused();
        let raw = render(&f, true).unwrap();
        assert_eq!(raw, serde_json::to_value(f).unwrap());
        assert_eq!(raw["gyro_state"].as_array().unwrap().len(), 16);
        assert_eq!(raw["gyro_state"][1], ipc_types::ChannelState::Suspect as u8);
        assert_eq!(raw["flags"], f.flags);
        let columns = csv_columns(&raw);
        assert_eq!(columns.len(), 89);
    }
}
