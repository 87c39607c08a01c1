//! `rins echo --remote ENDPOINT TOPIC` and `rins status --remote ENDPOINT`: a deployment on another
//! host read through the ROS 2 topics its Zenoh bridge publishes, exactly as a ROS 2 node reads
//! them. What arrives comes from the network: a sample that does not decode, or lacks rmw_zenoh's
//! attachment, is ignored and counted, and the count is reported at the end.

use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use rins_bridge::endpoint::Endpoint;
use rins_bridge::ros_graph::{self, RosType};
use rins_ros2_messages::{DiagnosticArray, DiagnosticStatus, Imu, NavSatFix, Odometry, decode};
use serde_json::{Value, json};
use zenoh::Wait;

/// Where the deployment's topics are.
#[derive(Debug, Clone)]
pub struct Remote {
    /// A router, or the bridge's own listening endpoint.
    pub endpoint: String,
    /// The ROS domain id the bridge publishes in.
    pub domain: u32,
    /// The bridge's ROS namespace.
    pub namespace: String,
}

impl Remote {
    /// The remote deployment `args` name, if any.
    pub fn of(args: &rins::cli::RemoteArgs) -> Option<Self> {
        args.remote.as_ref().map(|endpoint| Self {
            endpoint: endpoint.clone(),
            domain: args.domain,
            namespace: args.namespace.clone(),
        })
    }
}

/// The remote topics `rins echo --remote` knows, by rins's short names.
const TOPICS: [(&str, &str, RosType); 4] = [
    ("nav", "odom", ros_graph::ODOMETRY),
    ("imu", "imu", ros_graph::IMU),
    ("fix", "fix", ros_graph::NAV_SAT_FIX),
    ("diagnostics", "/diagnostics", ros_graph::DIAGNOSTIC_ARRAY),
];

/// Roll, pitch and yaw (degrees) of a unit quaternion, as ROS reads them in its ENU/FLU frames
/// (yaw counter-clockwise from east), with rins's heading (clockwise from north) beside them.
fn angles(q: &rins_ros2_messages::messages::Quaternion) -> Value {
    let (w, x, y, z) = (q.w, q.x, q.y, q.z);
    let roll = (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y));
    let pitch = (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin();
    let yaw = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
    json!({
        "roll_deg": roll.to_degrees(),
        "pitch_deg": pitch.to_degrees(),
        "yaw_enu_deg": yaw.to_degrees(),
        "heading_deg": (90.0 - yaw.to_degrees()).rem_euclid(360.0),
    })
}

/// The printed form of the bytes of `topic`, or why they are not its message.
fn render(topic: &str, bytes: &[u8]) -> Result<Value> {
    let mut v = match topic {
        "nav" => {
            let o: Odometry = decode(bytes)?;
            let mut v = serde_json::to_value(&o)?;
            v["angles"] = angles(&o.pose.pose.orientation);
            v
        }
        "imu" => serde_json::to_value(decode::<Imu>(bytes)?)?,
        "fix" => serde_json::to_value(decode::<NavSatFix>(bytes)?)?,
        _ => serde_json::to_value(decode::<DiagnosticArray>(bytes)?)?,
    };
    if let Some(stamp) = v.pointer("/header/stamp").cloned() {
        let s = stamp["sec"].as_f64().unwrap_or(f64::NAN)
            + stamp["nanosec"].as_f64().unwrap_or(f64::NAN) * 1e-9;
        v["stamp_s"] = json!(s);
    }
    Ok(v)
}

/// Samples the remote sent that were not the message, and the last reason.
#[derive(Debug, Default)]
struct Ignored {
    count: u64,
    last: Option<String>,
}

impl Ignored {
    fn note(&mut self, why: String) {
        self.count += 1;
        self.last = Some(why);
    }

    fn report(&self, what: &str) {
        if self.count > 0 {
            eprintln!(
                "rins {what}: ignored {} samples that were not the topic's message (last: {})",
                self.count,
                self.last.as_deref().unwrap_or("-")
            );
        }
    }
}

/// A client session to `remote`, refusing a malformed endpoint first.
fn open(remote: &Remote) -> Result<zenoh::Session> {
    Endpoint::parse(&remote.endpoint)
        .map_err(|why| anyhow!("--remote {:?}: {why}", remote.endpoint))?;
    let mut config = zenoh::Config::default();
    let mut set = |k: &str, v: String| {
        config
            .insert_json5(k, &v)
            .map_err(|e| anyhow!("zenoh: cannot set {k}: {e}"))
    };
    set("mode", "\"client\"".into())?;
    set(
        "connect/endpoints",
        serde_json::to_string(&[&remote.endpoint])?,
    )?;
    set("scouting/multicast/enabled", "false".into())?;
    zenoh::open(config)
        .wait()
        .map_err(|e| anyhow!("cannot reach {}: {e}", remote.endpoint))
}

/// Receives samples of one topic until `count` are taken or none comes for `timeout`, handing
/// each decoded one to `take`.
fn receive(
    remote: &Remote,
    topic: &str,
    count: Option<u64>,
    timeout: Option<Duration>,
    mut take: impl FnMut(Value) -> Result<()>,
) -> Result<Ignored> {
    let Some((_, ros_topic, ty)) = TOPICS.iter().find(|(short, ..)| *short == topic) else {
        let known: Vec<&str> = TOPICS.iter().map(|(s, ..)| *s).collect();
        bail!(
            "remote topic {topic:?}: the bridge publishes {}",
            known.join(", ")
        );
    };
    let session = open(remote)?;
    let full = ros_graph::topic_name(&remote.namespace, ros_topic);
    let key = ros_graph::topic_key(remote.domain, &full, *ty);
    let subscriber = session
        .declare_subscriber(key.clone())
        .wait()
        .map_err(|e| anyhow!("cannot subscribe to {key}: {e}"))?;
    let shutdown = rins_runtime::shutdown::Shutdown::install()?;
    let mut ignored = Ignored::default();
    let mut taken = 0u64;
    let mut last = Instant::now();
    while count.is_none_or(|n| taken < n) && !shutdown.requested() {
        let sample = subscriber
            .recv_timeout(Duration::from_millis(100))
            .map_err(|e| anyhow!("{key}: {e}"))?;
        let Some(sample) = sample else {
            if let Some(t) = timeout
                && last.elapsed() >= t
            {
                ignored.report("echo --remote");
                bail!(
                    "no {topic} sample from {} within {} s: is the bridge publishing there (domain {}, namespace {})?",
                    remote.endpoint,
                    t.as_secs_f64(),
                    remote.domain,
                    remote.namespace
                );
            }
            continue;
        };
        last = Instant::now();
        let attached = sample
            .attachment()
            .is_some_and(|a| a.len() == rins_bridge::attachment::LEN);
        if !attached {
            ignored.note("no rmw_zenoh attachment".into());
            continue;
        }
        match render(topic, &sample.payload().to_bytes()) {
            Ok(v) => {
                take(v)?;
                taken += 1;
            }
            Err(e) => ignored.note(format!("{e:#}")),
        }
    }
    drop(subscriber);
    let _ = session.close().wait();
    Ok(ignored)
}

/// `rins echo --remote`: every sample as a JSON line.
pub fn echo(
    remote: &Remote,
    topic: &str,
    count: Option<u64>,
    timeout: Option<Duration>,
) -> Result<()> {
    use std::io::Write;
    let stdout = std::io::stdout();
    let ignored = receive(remote, topic, count, timeout, |v| {
        let mut out = stdout.lock();
        writeln!(out, "{v}").context("cannot write to stdout")
    })?;
    ignored.report("echo --remote");
    Ok(())
}

/// `rins status --remote`: the latest diagnostics, as a table or one JSON object.
pub fn status(remote: &Remote, json_out: bool, timeout_s: f64) -> Result<()> {
    if !(timeout_s.is_finite() && timeout_s > 0.0) {
        bail!("--timeout {timeout_s}: must be a positive number of seconds");
    }
    let mut latest = None;
    let ignored = receive(
        remote,
        "diagnostics",
        Some(1),
        Some(Duration::from_secs_f64(timeout_s)),
        |v| {
            latest = Some(v);
            Ok(())
        },
    )?;
    ignored.report("status --remote");
    let v = latest.ok_or_else(|| anyhow!("no diagnostics from {}", remote.endpoint))?;
    if json_out {
        println!("{v}");
        return Ok(());
    }
    let array: DiagnosticArray = serde_json::from_value(v)?;
    print!("{}", table(&array));
    Ok(())
}

/// One line per status (level, name, message), its figures indented below.
fn table(array: &DiagnosticArray) -> String {
    let mut out = String::new();
    for s in &array.status {
        out.push_str(&format!(
            "{:<6} {:<26} {}\n",
            DiagnosticStatus::level_name(s.level),
            s.name,
            s.message
        ));
        for kv in &s.values {
            out.push_str(&format!("         {:<34} {}\n", kv.key, kv.value));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_heading_east_reads_as_yaw_zero_in_ros_and_ninety_in_rins() {
        let q = rins_ros2_messages::messages::Quaternion::default();
        let a = angles(&q);
        assert_eq!(a["yaw_enu_deg"], 0.0);
        assert_eq!(a["heading_deg"], 90.0);
    }

    #[test]
    fn garbage_is_an_error_not_a_sample() {
        assert!(render("nav", &[0, 1, 0, 0, 1, 2]).is_err());
        assert!(render("diagnostics", b"not cdr").is_err());
    }
}
