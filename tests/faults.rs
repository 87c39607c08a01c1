//! Fault injection through the running pipeline: timed faults applied by the simulator, their
//! detection and isolation in the watchdog's summary, run-time `rins inject`, and the argument
//! errors of `rins inject` / `rins readmit` / `rins up --inject`.

mod common;

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use common::{Isolated, last_json, num, stderr};

fn fails_with(ipc: &Isolated, args: &[&str], expected: &[&str]) {
    let out = ipc.run(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let err = stderr(&out);
    for e in expected {
        assert!(err.contains(e), "{args:?}: stderr lacks {e:?}:\n{err}");
    }
}

#[test]
fn timed_dead_gyro_is_reported_with_device_times() {
    let ipc = Isolated::new("fault_timed");
    let out = ipc.run(&[
        "up",
        "--scenario",
        "static",
        "--duration",
        "4",
        "--json",
        "--inject",
        "gyro1:dead@2.5s",
    ]);
    assert!(out.status.success(), "rins up failed:\n{}", stderr(&out));
    let s = last_json(&out);
    assert_eq!(
        ipc.shm_entries(),
        Vec::<String>::new(),
        "shared memory left"
    );

    let faults = s["faults"].as_array().expect("summary has a faults array");
    assert_eq!(faults.len(), 1, "{s}");
    let f = &faults[0];
    assert_eq!(f["channel"], "gyro1", "{f}");
    assert_eq!(f["kind"], "dead", "{f}");
    // Applied exactly at tick 2500 of the 1 kHz device clock.
    let injected = num(f, "injected_at_s");
    assert!((injected - 2.5).abs() <= 0.002, "{f}");
    // The channel's samples stop: fusion must exclude it within 20 samples, as missing.
    let isolated = f["isolated_at_s"]
        .as_f64()
        .unwrap_or_else(|| panic!("gyro1 was never isolated: {f}"));
    assert!(
        isolated >= injected && isolated - injected <= 0.020,
        "isolation took {} s: {f}",
        isolated - injected
    );
    let detected = num(f, "detected_at_s");
    assert!(detected >= injected && detected <= isolated, "{f}");
    assert_eq!(f["reason"], "missing", "{f}");
    assert_eq!(num(&s, "false_alarms"), 0.0, "{s}");
}

#[test]
fn inject_and_readmit_reject_bad_arguments() {
    let ipc = Isolated::new("fault_args");
    fails_with(
        &ipc,
        &["inject", "gyro", "dead"],
        &["channel \"gyro\"", "index"],
    );
    fails_with(
        &ipc,
        &["inject", "gyro16", "dead"],
        &["channel \"gyro16\"", "0..=15"],
    );
    fails_with(
        &ipc,
        &["inject", "mag0", "dead"],
        &["channel \"mag0\"", "gyro or accel"],
    );
    fails_with(
        &ipc,
        &["inject", "gyro2", "explode"],
        &["fault \"explode\"", "dead, stuck, bias"],
    );
    fails_with(&ipc, &["inject", "gyro2", "bias"], &["bias", "needs STEP"]);
    fails_with(
        &ipc,
        &["inject", "gyro2", "bias", "fast"],
        &["bias STEP \"fast\"", "not a number"],
    );
    fails_with(
        &ipc,
        &["inject", "accel1", "noise", "0.5"],
        &["noise FACTOR = 0.5", ">= 1"],
    );
    fails_with(
        &ipc,
        &["inject", "gyro2", "dead", "3"],
        &["dead \"3\"", "no argument"],
    );
    fails_with(
        &ipc,
        &["inject", "gyro2", "intermittent", "-1"],
        &["intermittent PERIOD_S = -1", "> 0"],
    );
    fails_with(&ipc, &["readmit", "gyro99"], &["channel \"gyro99\""]);
    fails_with(&ipc, &["readmit", "baro0"], &["channel \"baro0\""]);
}

#[test]
fn inject_and_readmit_fail_when_nobody_listens() {
    let ipc = Isolated::new("fault_nobody");
    fails_with(
        &ipc,
        &["inject", "gyro2", "dead"],
        &["no simulator is listening", "rins up"],
    );
    fails_with(
        &ipc,
        &["readmit", "gyro2"],
        &["no fusion process is listening"],
    );
    // A valid negative argument is accepted as a number, not as an option (then nobody listens).
    fails_with(
        &ipc,
        &["inject", "accel0", "bias", "-0.5"],
        &["no simulator is listening"],
    );
}

#[test]
fn up_rejects_bad_timed_faults_before_starting() {
    let ipc = Isolated::new("fault_up_args");
    fails_with(
        &ipc,
        &["up", "--duration", "1", "--inject", "gyro2:dead@soon"],
        &["--inject \"gyro2:dead@soon\"", "time \"soon\""],
    );
    fails_with(
        &ipc,
        &["up", "--duration", "1", "--inject", "gyro2:bias=abc@1s"],
        &["bias STEP \"abc\""],
    );
    // The built-in block has 4 gyros.
    fails_with(
        &ipc,
        &["up", "--duration", "1", "--inject", "gyro5:dead@1s"],
        &["channel \"gyro5\"", "4 gyro channels"],
    );
    let path = std::env::temp_dir().join(format!("rins-faults-{}.toml", std::process::id()));
    std::fs::File::create(&path)
        .and_then(|mut f| {
            f.write_all(
                b"[[fault]]\nchannel = \"gyro1\"\nkind = \"dead\"\nat_s = 1.0\n\n\
                  [[fault]]\nchannel = \"accel0\"\nkind = \"melt\"\nat_s = 2.0\n",
            )
        })
        .expect("cannot write the fault file");
    let file = path.to_str().expect("UTF-8 temporary path");
    fails_with(
        &ipc,
        &["up", "--duration", "1", "--faults", file],
        &[file, "fault[1]", "fault \"melt\""],
    );
    let _ = std::fs::remove_file(&path);
    fails_with(
        &ipc,
        &[
            "up",
            "--duration",
            "1",
            "--faults",
            "/nonexistent/faults.toml",
        ],
        &["cannot read fault file /nonexistent/faults.toml"],
    );
}

/// A `rins up` running in the background, its stdout lines forwarded to a channel.
struct Pipeline {
    child: Child,
    /// Stdout: with --json, the summary alone.
    lines: mpsc::Receiver<String>,
    /// The status lines, on stderr with --json.
    status: mpsc::Receiver<String>,
    seen: Vec<String>,
}

impl Pipeline {
    fn start(ipc: &Isolated, args: &[&str]) -> Self {
        let mut child = ipc
            .command()
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("cannot start rins up");
        let stderr = child.stderr.take().expect("piped stderr");
        let (status_tx, status) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                if line.starts_with("t=") {
                    let _ = status_tx.send(line);
                } else {
                    // Everything else still reaches the test's output.
                    eprintln!("{line}");
                }
            }
        });
        let stdout = child.stdout.take().expect("piped stdout");
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Self {
            child,
            lines,
            status,
            seen: Vec::new(),
        }
    }

    /// Waits for the first status line: the whole pipeline is then streaming.
    fn wait_running(&mut self, limit: Duration) {
        let deadline = Instant::now() + limit;
        while Instant::now() < deadline {
            if let Ok(line) = self.status.recv_timeout(Duration::from_millis(100)) {
                self.seen.push(line);
                return;
            }
        }
        panic!("no status line within {limit:?}: {:?}", self.seen);
    }

    /// Waits for the process to end and returns its last stdout line.
    fn finish(mut self, limit: Duration) -> String {
        let deadline = Instant::now() + limit;
        loop {
            if let Some(status) = self.child.try_wait().expect("cannot poll rins up") {
                assert!(status.success(), "rins up failed: {status}");
                break;
            }
            if Instant::now() >= deadline {
                let _ = self.child.kill();
                panic!("rins up did not stop within {limit:?}");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        // The reader thread ends at end of file.
        while let Ok(line) = self.lines.recv_timeout(Duration::from_secs(2)) {
            self.seen.push(line);
        }
        self.seen.last().cloned().unwrap_or_default()
    }
}

/// Valid-mask bit of gyro `i` in the last of a few raw IMU frames.
fn gyro_valid(ipc: &Isolated, i: u32) -> bool {
    let out = ipc.run_with_timeout(
        &["echo", "raw-imu", "--raw", "--count", "3"],
        Duration::from_secs(10),
    );
    assert!(out.status.success(), "echo failed:\n{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = stdout.lines().last().expect("echo printed nothing");
    let frame: serde_json::Value = serde_json::from_str(last).expect("echo prints JSON");
    let mask = frame["valid_mask"].as_u64().expect("frame has valid_mask");
    mask & (1 << i) != 0
}

#[test]
fn runtime_inject_kills_and_revives_a_channel() {
    let ipc = Isolated::new("fault_runtime");
    let mut up = Pipeline::start(
        &ipc,
        &["up", "--scenario", "static", "--duration", "10", "--json"],
    );
    up.wait_running(Duration::from_secs(30));

    assert!(gyro_valid(&ipc, 2), "gyro2 must start valid");
    let out = ipc.run_with_timeout(&["inject", "gyro2", "dead"], Duration::from_secs(10));
    assert!(out.status.success(), "inject failed:\n{}", stderr(&out));
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains("gyro2 dead: applied at device time"),
        "{said}"
    );
    assert!(
        !gyro_valid(&ipc, 2),
        "gyro2 must be flagged invalid once dead"
    );
    assert!(gyro_valid(&ipc, 1), "other gyros stay valid");

    let out = ipc.run_with_timeout(&["inject", "gyro2", "clear"], Duration::from_secs(10));
    assert!(out.status.success(), "clear failed:\n{}", stderr(&out));
    assert!(gyro_valid(&ipc, 2), "gyro2 must be valid after clear");

    // The block has 4 gyros: the simulator refuses gyro9, and says so.
    let out = ipc.run_with_timeout(&["inject", "gyro9", "dead"], Duration::from_secs(10));
    assert!(!out.status.success(), "gyro9 must be refused");
    assert!(
        stderr(&out).contains("channel \"gyro9\": the simulated sensor block has no such channel"),
        "{}",
        stderr(&out)
    );

    let last = up.finish(Duration::from_secs(30));
    let s: serde_json::Value = serde_json::from_str(&last)
        .unwrap_or_else(|e| panic!("last line is not JSON ({e}): {last:?}"));
    let faults = s["faults"].as_array().expect("summary has a faults array");
    assert_eq!(faults.len(), 1, "{s}");
    let f = &faults[0];
    assert_eq!(f["channel"], "gyro2", "{f}");
    assert_eq!(f["kind"], "dead", "{f}");
    let injected = num(f, "injected_at_s");
    let cleared = num(f, "cleared_at_s");
    assert!(injected > 0.0 && cleared > injected, "{f}");
    assert_eq!(
        ipc.shm_entries(),
        Vec::<String>::new(),
        "shared memory left"
    );
}
