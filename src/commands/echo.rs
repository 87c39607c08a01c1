//! `rins echo TOPIC`: print every sample of a topic, as JSON lines or CSV.

use std::io::Write;
use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use ipc_types::{
    Altitude, FusedImu, Health, HealthReport, NavState, RawAux, RawBaro, RawImu, RawMag, Truth,
    names,
};
use rins_runtime::ipc::{IpcNode, SampleSource, TopicSubscriber, create_node};
use rins_runtime::nav_subscriber::NavSubscriber;
use rins_runtime::shutdown::Shutdown;
use serde::Serialize;
use serde_json::Value;

/// Flattens nested objects and arrays into `a.b.0`-style columns.
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
        Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                flatten(&format!("{prefix}.{i}"), v, out);
            }
        }
        other => out.push((prefix.to_string(), other.to_string())),
    }
}

/// What to print and when to give up.
#[derive(Clone, Copy)]
struct EchoOptions {
    count: Option<u64>,
    csv: bool,
    /// Longest wait for the next sample; `None` waits for ever.
    timeout: Option<Duration>,
}

fn echo_topic<T>(name: &'static str, opts: EchoOptions) -> Result<()>
where
    T: std::fmt::Debug + Copy + Serialize + ReceivedAt + iceoryx2::prelude::ZeroCopySend + 'static,
{
    echo_from(name, opts, |node| TopicSubscriber::<T>::new(node, name))
}

/// When a sample's originating frame was received (CLOCK_MONOTONIC ns), for payloads that say.
trait ReceivedAt {
    fn received_ns(&self) -> Option<u64>;
}

macro_rules! received_at {
    (with header: $($t:ty),*; without: $($u:ty),*) => {
        $(impl ReceivedAt for $t {
            fn received_ns(&self) -> Option<u64> {
                Some(self.header.origin_rx_ns)
            }
        })*
        $(impl ReceivedAt for $u {
            fn received_ns(&self) -> Option<u64> {
                None
            }
        })*
    };
}

received_at!(
    with header: RawImu, RawBaro, RawMag, RawAux, FusedImu, Altitude, NavState;
    // Truth comes from the simulator, not from a received frame: no receive time.
    without: Truth, Health, HealthReport
);

/// Prints what `open` yields, a topic or the merged navigation stream. Samples from before the
/// start (a topic's history, kept for restarted services) are skipped: echo shows what comes.
fn echo_from<T, S>(
    name: &'static str,
    opts: EchoOptions,
    open: impl FnOnce(&IpcNode) -> Result<S, rins_runtime::ipc::IpcError>,
) -> Result<()>
where
    T: Serialize + ReceivedAt,
    S: SampleSource<T>,
{
    let started_ns = rins_runtime::clock::monotonic_ns();
    let shutdown = Shutdown::install()?;
    let settings = rins_runtime::join_check::settings_to_join()?;
    let node = create_node(&format!("echo-{}", std::process::id()), &settings)?;
    let mut sub = open(&node)?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let mut printed = 0u64;
    let mut columns = Vec::new();
    let EchoOptions {
        count,
        csv,
        timeout,
    } = opts;
    let mut last_sample = Instant::now();
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
            let value = serde_json::to_value(sample)?;
            if csv {
                columns.clear();
                flatten("", &value, &mut columns);
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
        out.flush()?;
    }
    Ok(())
}

pub fn run(topic: &str, count: Option<u64>, csv: bool, timeout_s: f64) -> Result<()> {
    if !(timeout_s.is_finite() && timeout_s >= 0.0) {
        bail!(
            "--timeout {timeout_s}: must be zero (wait for ever) or a positive number of seconds"
        );
    }
    let opts = EchoOptions {
        count,
        csv,
        timeout: (timeout_s > 0.0).then(|| Duration::from_secs_f64(timeout_s)),
    };
    let Some((_, service)) = names::TOPICS.iter().find(|(short, _)| *short == topic) else {
        let known: Vec<&str> = names::TOPICS.iter().map(|(s, _)| *s).collect();
        bail!(
            "unknown topic {topic:?}: expected one of {}",
            known.join(", ")
        );
    };
    match *service {
        names::RAW_IMU => echo_topic::<RawImu>(names::RAW_IMU, opts),
        names::RAW_BARO => echo_topic::<RawBaro>(names::RAW_BARO, opts),
        names::RAW_MAG => echo_topic::<RawMag>(names::RAW_MAG, opts),
        names::RAW_AUX => echo_topic::<RawAux>(names::RAW_AUX, opts),
        names::FUSED_IMU => echo_topic::<FusedImu>(names::FUSED_IMU, opts),
        names::ALTITUDE => echo_topic::<Altitude>(names::ALTITUDE, opts),
        // The stream consumers see: both navigator lanes through the lane selector.
        names::NAV_STATE => echo_from::<NavState, _>(names::NAV_STATE, opts, NavSubscriber::new),
        names::TRUTH => echo_topic::<Truth>(names::TRUTH, opts),
        names::HEARTBEAT => echo_topic::<Health>(names::HEARTBEAT, opts),
        _ => echo_topic::<HealthReport>(names::HEALTH, opts),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flatten_names_nested_columns() {
        let v = serde_json::json!({"a": 1, "b": {"c": [2, 3]}});
        let mut out = Vec::new();
        flatten("", &v, &mut out);
        let keys: Vec<&str> = out.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(keys, ["a", "b.c.0", "b.c.1"]);
        assert_eq!(out[2].1, "3");
    }
}
