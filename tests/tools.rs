//! `rins echo` and `rins latency` against a running pipeline.

mod common;

use std::collections::HashMap;
use std::path::Path;

use common::{Isolated, Scratch, last_json, spawn_up, stop_up};
use hdrhistogram::Histogram;
use hdrhistogram::serialization::Deserializer;
use hdrhistogram::serialization::interval_log::{IntervalLogIterator, LogEntry};

#[test]
fn echo_and_latency_read_a_running_pipeline() {
    let ipc = Isolated::new("tools");
    // Long enough for any machine load; the test stops it itself below.
    let up = spawn_up(
        &ipc,
        &["--scenario", "static", "--duration", "300", "--json"],
    );

    // Waits until the pipeline publishes: the navigator's first samples.
    let echo = ipc.run(&["echo", "nav", "--count", "5", "--csv", "--timeout", "120"]);
    assert!(
        echo.status.success(),
        "{}",
        String::from_utf8_lossy(&echo.stderr)
    );
    let text = String::from_utf8_lossy(&echo.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 6, "header + 5 rows:\n{text}");
    let header: Vec<&str> = lines[0].split(',').collect();
    assert!(
        header.contains(&"quaternion.0") && header.contains(&"header.origin_seq"),
        "{}",
        lines[0]
    );
    // Consecutive navigation samples carry consecutive origin sequence numbers.
    let seq_col = header
        .iter()
        .position(|h| *h == "header.origin_seq")
        .unwrap();
    let seqs: Vec<u64> = lines[1..]
        .iter()
        .map(|l| l.split(',').nth(seq_col).unwrap().parse().unwrap())
        .collect();
    for pair in seqs.windows(2) {
        assert_eq!(pair[1], pair[0] + 1, "{seqs:?}");
    }

    // A reader that closes the pipe after one line (`rins echo nav | head -1`): echo ends quietly
    // with success instead of reporting a broken pipe.
    let mut reader = ipc
        .command()
        .args(["echo", "nav", "--timeout", "120"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("cannot start rins echo");
    let stdout = reader.stdout.take().expect("piped stdout");
    let mut first = String::new();
    std::io::BufRead::read_line(&mut std::io::BufReader::new(stdout), &mut first)
        .expect("one line from echo");
    assert!(first.starts_with('{'), "{first}");
    let closed = reader.wait_with_output().expect("echo did not finish");
    assert!(
        closed.status.success(),
        "echo into a closed pipe: {:?} {}",
        closed.status,
        String::from_utf8_lossy(&closed.stderr)
    );
    assert!(
        closed.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&closed.stderr)
    );

    let scratch = Scratch::new("tools", "latency");
    let trace_path = scratch.path().join("trace.json");
    let hdr_path = scratch.path().join("latency.hdr");
    let latency = ipc.run(&[
        "latency",
        "--seconds",
        "2",
        "--json",
        "--trace",
        trace_path.to_str().unwrap(),
        "--hdr",
        hdr_path.to_str().unwrap(),
    ]);
    assert!(
        latency.status.success(),
        "{}",
        String::from_utf8_lossy(&latency.stderr)
    );
    let hops = last_json(&latency);
    let hops = hops
        .as_array()
        .expect("latency --json prints an array of hops");
    let end_to_end = hops
        .iter()
        .find(|h| h["hop"] == "serial rx -> nav state published")
        .expect("end-to-end hop");
    // 2 s at 1 kHz.
    assert!(
        end_to_end["samples"].as_f64().unwrap() > 1_500.0,
        "{end_to_end}"
    );
    let (p50, p99, max) = (
        end_to_end["p50_us"].as_f64().unwrap(),
        end_to_end["p99_us"].as_f64().unwrap(),
        end_to_end["max_us"].as_f64().unwrap(),
    );
    assert!(p50 > 0.0 && p50 <= p99 && p99 <= max, "{end_to_end}");
    let received = hops
        .iter()
        .find(|h| h["hop"] == "navigator published -> consumer received")
        .expect("consumer hop")["samples"]
        .as_u64()
        .unwrap();
    check_trace(&trace_path, received);
    check_hdr_log(&hdr_path, end_to_end["samples"].as_u64().unwrap());

    // SIGTERM is how an operator stops the pipeline: it must shut down cleanly and still report.
    let summary = stop_up(&ipc, up);
    assert_eq!(summary["dropped"], 0, "{summary}");
}

/// The trace parses as Chrome Trace Event JSON and draws one flow per sample the consumer took:
/// each starts at acquisition (serial receive), steps through fusion and the navigator and ends at
/// the consumer, in time order.
fn check_trace(path: &Path, received: u64) {
    let text = std::fs::read_to_string(path).expect("the trace file");
    let trace: serde_json::Value = serde_json::from_str(&text).expect("trace JSON");
    let events = trace["traceEvents"].as_array().expect("traceEvents");
    let drawn = trace["otherData"]["samples"].as_u64().unwrap();
    let incomplete = trace["otherData"]["samples_incomplete"].as_u64().unwrap();
    assert_eq!(drawn + incomplete, received, "{}", trace["otherData"]);
    // Every stage stamps every sample of a healthy pipeline.
    assert!(incomplete * 100 <= received, "{}", trace["otherData"]);
    let mut flows: HashMap<u64, Vec<(String, u64, f64)>> = HashMap::new();
    for e in events.iter().filter(|e| e["cat"] == "sample") {
        flows.entry(e["id"].as_u64().unwrap()).or_default().push((
            e["ph"].as_str().unwrap().to_string(),
            e["pid"].as_u64().unwrap(),
            e["ts"].as_f64().unwrap(),
        ));
    }
    assert_eq!(flows.len() as u64, drawn);
    for (id, path) in &flows {
        let phases: Vec<(&str, u64)> = path
            .iter()
            .map(|(ph, pid, _)| (ph.as_str(), *pid))
            .collect();
        assert_eq!(
            phases,
            [("s", 1), ("t", 2), ("t", 3), ("f", 4)],
            "flow {id}"
        );
        assert!(
            path.windows(2).all(|w| w[0].2 <= w[1].2),
            "flow {id}: {path:?}"
        );
    }
    let slices = events.iter().filter(|e| e["ph"] == "X").count() as u64;
    assert_eq!(slices, 4 * drawn);
}

/// The HDR log holds intervals of every hop whose counts add up to the run's.
fn check_hdr_log(path: &Path, end_to_end: u64) {
    use base64::Engine;
    let bytes = std::fs::read(path).expect("the HDR log");
    let mut intervals = 0;
    let mut counted = 0;
    for entry in IntervalLogIterator::new(&bytes) {
        if let LogEntry::Interval(i) = entry.expect("a well-formed log entry")
            && i.tag().map(|t| t.as_str()) == Some("serial_rx_nav_state_published")
        {
            intervals += 1;
            let raw = base64::engine::general_purpose::STANDARD
                .decode(i.encoded_histogram())
                .expect("base64 histogram");
            let h: Histogram<u64> = Deserializer::new()
                .deserialize(&mut raw.as_slice())
                .expect("a histogram");
            counted += h.len();
        }
    }
    // 2 s in 1 s intervals (the last one cut short).
    assert!((2..=3).contains(&intervals), "{intervals} intervals");
    assert_eq!(counted, end_to_end);
}

#[test]
fn geometry_reports_the_seed_pyramid_and_its_z_axis_penalty() {
    let ipc = Isolated::new("geometry");
    let out = ipc.run(&["geometry", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let reports = last_json(&out);
    let gyro = &reports[0];
    assert_eq!(gyro["sensor"], "gyro");
    let c = &gyro["capability"];
    // docs/design.md §4: at α = 28.7° the x/y variance is 1/(2cos²α) = 0.65σ², z is 1/(4sin²α) = 1.084σ².
    let v = |i: usize| c["variance_factors"][i].as_f64().unwrap();
    assert!(
        (v(0) - 0.650).abs() < 1e-3 && (v(2) - 1.084).abs() < 1e-3,
        "{c}"
    );
    assert_eq!(c["parity_dimension"], 1);
    assert_eq!(
        (c["detect"].as_bool(), c["isolate_one"].as_bool()),
        (Some(true), Some(false))
    );
    // At the optimal 35.26° every axis is 3/N = 0.75.
    let opt = &gyro["optimal_pyramid"]["capability"]["variance_factors"];
    assert!((opt[2].as_f64().unwrap() - 0.75).abs() < 1e-9, "{opt}");
}
