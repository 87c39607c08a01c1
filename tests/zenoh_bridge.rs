//! The Zenoh bridge seen from another host: `rins up --zenoh` here, a ROS 2 reader without ROS
//! (Python `eclipse-zenoh` on rmw_zenoh's key expressions, decoding with ROS 2's own message
//! definitions) and `rins echo --remote` in a second network namespace joined by a veth pair, so
//! that the bytes cross a network interface. The reader runs the Zenoh router, as `rmw_zenohd`
//! does on a ROS 2 computer.

mod common;

use std::path::PathBuf;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

use common::netns::Link;
use common::{Isolated, PipelineSlot, last_json, num, spawn_up};
use rins_runtime::clock::monotonic_to_realtime_ns;
use serde_json::Value;

const PORT: u16 = 7447;
const SCRIPT: &str = "crates/ros2-messages/tests/python/ros2_subscriber.py";

/// The reader on the far side: a router listening at `endpoint`, subscribed for `seconds` after
/// its first odometry sample, writing what it got to `out`.
fn start_reader(
    python: &PathBuf,
    link: &Link,
    endpoint: &str,
    seconds: f64,
    out: &PathBuf,
) -> Child {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(SCRIPT);
    link.command(python)
        .arg(script)
        .args(["--listen", endpoint, "--seconds", &seconds.to_string()])
        .args(["--timeout", "120", "--out"])
        .arg(out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot start the Python reader")
}

/// Waits until `ip:port` takes TCP connections (the router is up), at most 30 s.
fn wait_listening(ip: &str, port: u16) {
    let address: std::net::SocketAddr = format!("{ip}:{port}").parse().expect("an address");
    let deadline = Instant::now() + Duration::from_secs(30);
    while std::net::TcpStream::connect_timeout(&address, Duration::from_millis(200)).is_err() {
        assert!(
            Instant::now() < deadline,
            "the reader's router never listened at {address}"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// What the reader wrote, after checking that it ended well.
fn reader_result(child: Child, out: &PathBuf) -> Value {
    let o = child.wait_with_output().expect("the reader did not finish");
    assert!(
        o.status.success(),
        "the reader failed: {:?}\n{}\n{}",
        o.status,
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let text = std::fs::read_to_string(out).expect("the reader wrote no result");
    let _ = std::fs::remove_file(out);
    serde_json::from_str(&text).expect("the reader's result is not JSON")
}

/// Samples of `topic` made within `seconds` of the earliest one.
fn count_in_window(result: &Value, topic: &str, seconds: f64) -> usize {
    // Windowed on when each sample was made (arrival minus its latency, both from the
    // attachment's source stamp), not on arrival: under load the first samples can arrive
    // late and the rest catch up, which would count more than the rate in an arrival window.
    let t = &result["topics"][topic];
    let times: Vec<i128> = t["received_ns"]
        .as_array()
        .expect("receive times")
        .iter()
        .zip(t["latency_ns"].as_array().expect("latencies"))
        .filter_map(|(r, l)| Some(i128::from(r.as_u64()?) - i128::from(l.as_i64()?)))
        .collect();
    let Some(&first) = times.iter().min() else {
        return 0;
    };
    let end = first + (seconds * 1e9) as i128;
    times.iter().filter(|&&t| t < end).count()
}

fn f(v: &Value) -> f64 {
    f64::from_bits(v.as_u64().expect("a float's bits"))
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().expect("an array").iter().map(f).collect()
}

/// Hamilton product of quaternions [w, x, y, z].
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// `v` rotated by the inverse of unit quaternion `q` (world to body).
fn to_body(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let conj = [q[0], -q[1], -q[2], -q[3]];
    let r = mul(mul(conj, [0.0, v[0], v[1], v[2]]), q);
    [r[1], r[2], r[3]]
}

fn array<const N: usize>(v: &Value) -> [f64; N] {
    let a: Vec<f64> = v
        .as_array()
        .expect("an array")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect();
    a.try_into().expect("the length")
}

/// A test's far side: the namespace `tag` on subnet `subnet`, the router's endpoint there, and
/// the file its reader writes.
struct FarSide {
    link: Link,
    endpoint: String,
    out: PathBuf,
}

impl FarSide {
    fn new(tag: &str, subnet: u8) -> Self {
        let link = Link::new(tag, subnet);
        let endpoint = format!("tcp/{}:{PORT}", link.far_ip);
        let out =
            std::env::temp_dir().join(format!("rins-zenoh-{tag}-{}.json", std::process::id()));
        Self {
            link,
            endpoint,
            out,
        }
    }

    /// Starts a reader for `seconds` and waits for its router to listen.
    fn reader(&self, python: &PathBuf, seconds: f64) -> Child {
        let child = start_reader(python, &self.link, &self.endpoint, seconds, &self.out);
        wait_listening(&self.link.far_ip, PORT);
        child
    }
}

#[test]
fn a_ros2_reader_in_another_namespace_gets_odometry_at_50_hz_equal_to_echo_nav() {
    let Some(python) = common::python::interpreter("zenoh_bridge") else {
        return;
    };
    let _slot = PipelineSlot::take();
    let far = FarSide::new("a", 1);
    let (link, endpoint, out) = (&far.link, &far.endpoint, &far.out);
    let reader = far.reader(&python, 10.0);
    let ipc = Isolated::new("zenoh_values");
    // One navigator lane: the bridge and `rins echo` then read the same samples (with two, each
    // reader's lane selector may take an instant from either lane, and the lanes differ in the
    // last digits).
    let config = common::TempFile::new("zenoh", "toml", "[deployment]\nnavigator_lanes = 1\n");
    let up = common::spawn_up_navigating(
        &ipc,
        &[
            "--scenario",
            "static",
            "--config",
            config.path(),
            "--zenoh",
            endpoint,
            "--duration",
            "30",
            "--json",
        ],
    );
    // This host's own reading of the navigation, every sample.
    let echo = ipc
        .command()
        .args(["echo", "nav", "--raw", "--timeout", "60"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot start rins echo");
    // Drained as it prints: a full pipe would stop it.
    let mut echo = echo;
    let echo_stdout = echo.stdout.take().expect("piped");
    let echo_reader = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = std::io::Read::read_to_string(&mut { echo_stdout }, &mut text);
        text
    });
    // rins's own tool on the far side, through the router there.
    let remote = link
        .command(common::RINS)
        .args([
            "echo",
            "--remote",
            endpoint,
            "nav",
            "--count",
            "3",
            "--timeout",
            "60",
        ])
        .output()
        .expect("cannot run rins echo --remote");
    let result = reader_result(reader, out);
    let up_out = up.wait_with_output().expect("rins up did not finish");
    let _ = echo.kill();
    let echoed = echo.wait_with_output().expect("rins echo");
    let echoed_stdout = echo_reader.join().expect("the echo reader");
    assert!(up_out.status.success(), "rins up: {}", ipc.up_stderr());
    let summary = last_json(&up_out);
    assert_eq!(num(&summary, "dropped"), 0.0);
    assert_eq!(num(&summary, "false_alarms"), 0.0);

    // rins echo --remote printed the navigation state.
    assert!(
        remote.status.success(),
        "{}",
        String::from_utf8_lossy(&remote.stderr)
    );
    let lines: Vec<Value> = String::from_utf8_lossy(&remote.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0]["header"]["frame_id"], "map");
    assert!(lines[0]["angles"]["heading_deg"].as_f64().is_some());

    // The rates, over 10 s from the first sample: odometry 50 ± 1 Hz, the IMU its 100 Hz.
    let odometry = count_in_window(&result, "odom", 10.0);
    assert!(
        (490..=510).contains(&odometry),
        "odometry: {odometry} in 10 s"
    );
    let imu = count_in_window(&result, "imu", 10.0);
    assert!((980..=1020).contains(&imu), "imu: {imu} in 10 s");
    for topic in ["odom", "imu", "fix", "/diagnostics"] {
        let t = &result["topics"][topic];
        assert!(num(t, "count") > 0.0, "{topic}: nothing received");
        for counter in ["bad_attachment", "undecodable", "sequence_gaps"] {
            assert_eq!(num(t, counter), 0.0, "{topic}: {counter}");
        }
    }
    // The graph: the node and its four publishers, as rmw_zenoh's liveliness tokens.
    let tokens: Vec<&str> = result["tokens"]
        .as_array()
        .expect("tokens")
        .iter()
        .filter_map(Value::as_str)
        .collect();
    assert_eq!(
        tokens
            .iter()
            .filter(|t| t.contains("/NN/%/%rins/rins"))
            .count(),
        1,
        "{tokens:?}"
    );
    assert_eq!(
        tokens.iter().filter(|t| t.contains("/MP/")).count(),
        4,
        "{tokens:?}"
    );

    // Every odometry sample equals the navigation sample it was made from: the same instant,
    // the orientation turned from NED/FRD to ENU/FLU (q_enu_flu = q_M ⊗ q ⊗ q_B with
    // M the NED → ENU swap, B the FRD → FLU flip), the velocity turned into the body.
    let navs: Vec<Value> = echoed_stdout
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect();
    assert!(
        navs.len() > 10_000,
        "echo nav printed {} samples: {}",
        navs.len(),
        String::from_utf8_lossy(&echoed.stderr)
    );
    let real: Vec<u64> = navs
        .iter()
        .map(|n| monotonic_to_realtime_ns(n["header"]["origin_rx_ns"].as_u64().expect("rx")))
        .collect();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let (q_m, q_b) = ([0.0, h, h, 0.0], [0.0, 1.0, 0.0, 0.0]);
    let mut matched = 0;
    for s in result["topics"]["odom"]["samples"]
        .as_array()
        .expect("samples")
    {
        let stamp = s["stamp"][0].as_u64().expect("sec") * 1_000_000_000
            + s["stamp"][1].as_u64().expect("nanosec");
        let Some((k, gap)) = real
            .iter()
            .enumerate()
            .map(|(k, &t)| (k, t.abs_diff(stamp)))
            .min_by_key(|&(_, d)| d)
        else {
            continue;
        };
        // Not printed by echo (it started a moment later, or stopped earlier).
        if gap > 1_000 {
            continue;
        }
        matched += 1;
        let [x, y, z, w]: [f64; 4] = floats(&s["orientation"]).try_into().expect("4");
        let got = [w, x, y, z];
        // Frames read in one burst carry receive times nanoseconds apart: the samples within a
        // microsecond of the stamp are its candidates, and the one the message was made from is
        // among them.
        let difference = |n: &Value| {
            let e = mul(mul(q_m, array(&n["quaternion"])), q_b);
            let sign = if got.iter().zip(&e).map(|(a, b)| a * b).sum::<f64>() < 0.0 {
                -1.0
            } else {
                1.0
            };
            (0..4)
                .map(|i| (sign * got[i] - e[i]).abs())
                .fold(0.0, f64::max)
        };
        let (n, worst) = (k.saturating_sub(50)..(k + 50).min(navs.len()))
            .filter(|&j| real[j].abs_diff(stamp) < 1_000)
            .map(|j| (&navs[j], difference(&navs[j])))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("the nearest sample is a candidate");
        assert!(
            worst < 1e-12,
            "orientation {got:?} differs by {worst} from echo nav's"
        );
        let q: [f64; 4] = array(&n["quaternion"]);
        let v_frd = to_body(q, array(&n["velocity_ned_mps"]));
        let v_flu = [v_frd[0], -v_frd[1], -v_frd[2]];
        let linear = floats(&s["linear"]);
        for i in 0..3 {
            assert!(
                (linear[i] - v_flu[i]).abs() < 1e-9,
                "velocity {linear:?} vs {v_flu:?}"
            );
        }
    }
    assert!(
        matched > 300,
        "only {matched} odometry samples matched echo nav"
    );

    // A known attitude: the static block sits level, so the IMU reads +g up in FLU.
    for s in result["topics"]["imu"]["samples"]
        .as_array()
        .expect("samples")
    {
        let a = floats(&s["linear_acceleration"]);
        assert!(a[0].abs() < 0.3 && a[1].abs() < 0.3, "level: {a:?}");
        assert!((a[2] - 9.81).abs() < 0.3, "+g up in FLU: {a:?}");
    }
}

#[test]
fn killing_the_router_for_5_s_loses_no_navigation_sample_and_the_stream_resumes() {
    let Some(python) = common::python::interpreter("zenoh_router_kill") else {
        return;
    };
    let _slot = PipelineSlot::take();
    let far = FarSide::new("b", 2);
    let (endpoint, out) = (&far.endpoint, &far.out);
    let first = far.reader(&python, 3.0);
    let ipc = Isolated::new("zenoh_router_kill");
    let up = spawn_up(&ipc, &["--zenoh", endpoint, "--duration", "35", "--json"]);
    let before = reader_result(first, out);
    assert!(num(&before["topics"]["odom"], "count") > 100.0);
    // The router is gone (its process ended with the reader); 5 s later a new one starts.
    std::thread::sleep(Duration::from_secs(5));
    let second = start_reader(&python, &far.link, endpoint, 3.0, out);
    let after = reader_result(second, out);
    let resumed = count_in_window(&after, "odom", 3.0);
    assert!(
        resumed >= 140,
        "odometry after the router came back: {resumed} in 3 s"
    );
    let up_out = up.wait_with_output().expect("rins up did not finish");
    assert!(up_out.status.success(), "rins up: {}", ipc.up_stderr());
    let summary = last_json(&up_out);
    assert_eq!(num(&summary, "dropped"), 0.0, "navigation samples dropped");
    assert_eq!(num(&summary, "restarts"), 0.0);
    assert_eq!(num(&summary, "false_alarms"), 0.0);
}

#[test]
fn a_malformed_endpoint_is_refused_at_start_naming_it() {
    common::fails_with(
        "zenoh_bad_endpoint",
        &["up", "--zenoh", "udp/10.0.0.2:7447", "--duration", "5"],
        &[
            "--zenoh \"udp/10.0.0.2:7447\"",
            "protocol \"udp\" is not carried",
        ],
    );
    common::fails_with(
        "zenoh_bad_listen",
        &["up", "--zenoh-listen", "tcp/0.0.0.0", "--duration", "5"],
        &["--zenoh-listen \"tcp/0.0.0.0\"", "no port"],
    );
}

/// Puts `count` samples of garbage on the odometry key through `endpoint`, with and without an
/// attachment, as a hostile peer would.
const GARBAGE: &str = r#"
import sys, time, zenoh
conf = zenoh.Config()
conf.insert_json5("mode", '"client"')
conf.insert_json5("connect/endpoints", '["' + sys.argv[1] + '"]')
s = zenoh.open(conf)
key = "0/rins/odom/nav_msgs::msg::dds_::Odometry_/RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0"
p = s.declare_publisher(key)
end = time.monotonic() + float(sys.argv[2])
while time.monotonic() < end:
    p.put(b"\x00\x01\x00\x00garbage", attachment=bytes(33))
    p.put(b"no attachment at all")
    time.sleep(0.01)
s.close()
"#;

#[test]
fn remote_tools_read_a_listening_bridge_and_ignore_and_count_garbage_on_its_keys() {
    let Some(python) = common::python::interpreter("zenoh_remote_tools") else {
        return;
    };
    let _slot = PipelineSlot::take();
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port");
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let ipc = Isolated::new("zenoh_remote_tools");
    let up = common::spawn_up_navigating(
        &ipc,
        &["--zenoh-listen", &endpoint, "--duration", "25", "--json"],
    );
    let garbage = std::process::Command::new(&python)
        .args(["-c", GARBAGE, &endpoint, "8"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot start the garbage publisher");
    std::thread::sleep(Duration::from_secs(1));
    // Its own --timeout bounds it; its output is larger than a pipe holds, so it is read as it
    // comes.
    let echo = ipc
        .command()
        .args([
            "echo",
            "--remote",
            &endpoint,
            "nav",
            "--count",
            "100",
            "--timeout",
            "20",
        ])
        .output()
        .expect("cannot run rins echo --remote");
    let status = ipc.run_with_timeout(
        &["status", "--remote", &endpoint, "--timeout", "10"],
        Duration::from_secs(30),
    );
    let g = garbage.wait_with_output().expect("the garbage publisher");
    assert!(g.status.success(), "{}", String::from_utf8_lossy(&g.stderr));
    let up_out = up.wait_with_output().expect("rins up did not finish");
    assert!(up_out.status.success(), "rins up: {}", ipc.up_stderr());
    assert_eq!(num(&last_json(&up_out), "dropped"), 0.0);

    assert!(echo.status.success(), "{}", common::stderr(&echo));
    let lines: Vec<Value> = String::from_utf8_lossy(&echo.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("only decoded samples are printed"))
        .collect();
    assert_eq!(lines.len(), 100);
    assert!(lines.iter().all(|l| l["child_frame_id"] == "base_link"));
    let err = common::stderr(&echo);
    assert!(
        err.contains("ignored") && err.contains("samples that were not the topic's message"),
        "{err}"
    );

    assert!(status.status.success(), "{}", common::stderr(&status));
    let table = String::from_utf8_lossy(&status.stdout);
    for part in [
        "rins: navigator",
        "rins: fusion",
        "rins: bridge",
        "rins: navigation",
        "rins: redundancy",
    ] {
        assert!(table.contains(part), "{part} missing from:\n{table}");
    }
}
