//! Fault injection on the serial line: the simulator unplugs its device under a running pipeline
//! (`rins inject disconnect`, `--inject disconnect=S@T`) and acquisition must ride it out: same
//! process, one reconnect counted, data back within the backoff's bound, the frames of the outage
//! lost and no others; the same for an unplug of 5 s under the built-in configuration the
//! service unit runs (deploy/rins.service), after which the navigation is usable again. Also: an
//! acquisition started before its device waits for it.

mod common;

use std::io::Read;
use std::process::{Child, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use common::{Isolated, PipelineSlot, fails_with, last_json, num, spawn_up, stderr, stop_up};
use ipc_types::{Health, NavMode, NavState, RawImu, ServiceKind, names};
use rins_runtime::ipc::{IpcSettings, TopicSubscriber, create_node};
use rins_test_support::signal::{Signal, send_signal};
use serde_json::Value;

/// Acquisition's backoff (built-in configuration): first retry after 10 ms, doubling, at most
/// 1 s apart.
const BACKOFF_FIRST_S: f64 = 0.010;
const BACKOFF_CAP_S: f64 = 1.0;
/// Slack for opening the port, scheduling and the catch-up of the frames held up meanwhile on a
/// loaded two-core machine.
const SLACK_S: f64 = 0.5;

/// The pipelines of this file measure timing: one at a time, not two sharing the processors.
static ONE_PIPELINE: Mutex<()> = Mutex::new(());

fn one_pipeline() -> std::sync::MutexGuard<'static, ()> {
    ONE_PIPELINE.lock().unwrap_or_else(|e| e.into_inner())
}

/// A child process that is killed if the test fails before it ends it, so that no pipeline or
/// service outlives a failed test.
struct Guard(Option<Child>);

impl Guard {
    fn child(&mut self) -> &mut Child {
        self.0.as_mut().expect("child still guarded")
    }

    fn release(mut self) -> Child {
        self.0.take().expect("child still guarded")
    }
}

impl Drop for Guard {
    fn drop(&mut self) {
        if let Some(child) = &mut self.0
            && child.try_wait().ok().flatten().is_none()
        {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// What a test-side subscriber saw of the pipeline.
#[derive(Default)]
struct Seen {
    /// Raw IMU samples: extended sequence number, device time (µs) and when they arrived.
    imu: Vec<(u64, u64, Instant)>,
    /// Navigation outputs (lane 0): origin sequence number, [`NavMode`] and arrival.
    nav: Vec<(u64, u8, Instant)>,
    /// Acquisition's heartbeats, in order.
    acquisition: Vec<Health>,
}

/// Subscribes to raw IMU, navigation output and heartbeats on the test's namespace, on a thread
/// of its own (iceoryx2 ports stay on the thread that made them).
struct Collector {
    seen: Arc<Mutex<Seen>>,
    stop: Arc<AtomicBool>,
    thread: std::thread::JoinHandle<()>,
}

impl Collector {
    fn start(ipc: &Isolated) -> Self {
        let settings = IpcSettings::new(ipc.prefix.clone(), format!("{}/", ipc.root.display()));
        let seen = Arc::new(Mutex::new(Seen::default()));
        let stop = Arc::new(AtomicBool::new(false));
        let (s, st) = (seen.clone(), stop.clone());
        let thread = std::thread::spawn(move || {
            let node = create_node(&format!("test-collector-{}", std::process::id()), &settings)
                .expect("test node");
            let imu = TopicSubscriber::<RawImu>::new(&node, names::RAW_IMU).expect("raw IMU");
            let nav = TopicSubscriber::<NavState>::new(&node, names::NAV_STATE).expect("nav");
            let beats = TopicSubscriber::<Health>::new(&node, names::HEARTBEAT).expect("beats");
            while !st.load(Ordering::Relaxed) {
                imu.wait(Duration::from_millis(20)).expect("wait");
                let now = Instant::now();
                let mut seen = s.lock().expect("collector lock");
                while let Some(m) = imu.receive().expect("receive raw IMU") {
                    let h = m.header;
                    seen.imu.push((h.origin_seq, h.origin_device_time_us, now));
                }
                while let Some(n) = nav.receive().expect("receive nav") {
                    seen.nav.push((n.header.origin_seq, n.mode, now));
                }
                while let Some(h) = beats.receive().expect("receive heartbeat") {
                    if h.service == ServiceKind::Acquisition as u8 {
                        seen.acquisition.push(h);
                    }
                }
            }
            // The ports and the node go here, before the pipeline's shutdown checks /dev/shm.
        });
        Self { seen, stop, thread }
    }

    /// Waits until `done` holds for what was seen, failing after `limit`.
    fn wait_for(&self, what: &str, limit: Duration, done: impl Fn(&Seen) -> bool) {
        let start = Instant::now();
        while !done(&self.seen.lock().expect("collector lock")) {
            assert!(start.elapsed() < limit, "gave up waiting for {what}");
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    fn finish(self) -> Seen {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.join().expect("collector thread");
        let seen = self.seen.lock().expect("collector lock");
        Seen {
            imu: seen.imu.clone(),
            nav: seen.nav.clone(),
            acquisition: seen.acquisition.clone(),
        }
    }
}

fn acquisition(report: &Value) -> (u64, u64, String) {
    let a = report["services"]
        .as_array()
        .and_then(|s| s.iter().find(|s| s["service"] == "acquisition"))
        .unwrap_or_else(|| panic!("no acquisition in {report}"));
    (
        a["pid"].as_u64().expect("pid"),
        a["restarts"].as_u64().expect("restarts"),
        a["state"].as_str().unwrap_or_default().to_string(),
    )
}

/// The longest pause between consecutive arrivals at or after `from`: (index of the sample
/// after it, its length).
fn longest_pause(arrivals: impl Iterator<Item = Instant>, from: Instant) -> (usize, Duration) {
    let mut last: Option<Instant> = None;
    let mut longest = (0, Duration::ZERO);
    for (i, t) in arrivals.enumerate() {
        if let Some(prev) = last
            && t >= from
            && t - prev > longest.1
        {
            longest = (i, t - prev);
        }
        last = Some(t);
    }
    longest
}

#[test]
fn acquisition_rides_out_a_disconnect_under_a_running_pipeline() {
    rides_out_an_unplug("reconnect", 1.0);
}

/// An unplug of 5 s (a connector reseated in flight): the deployment as the service unit runs it
/// (the built-in configuration, whose restart policy the watchdog applies) keeps every process,
/// and navigates again, usably, once the block is back.
#[test]
fn the_pipeline_navigates_again_after_an_unplug_of_five_seconds() {
    rides_out_an_unplug("reconnect_5s", 5.0);
}

/// Unplugs the simulated device for `outage_s` under a navigating pipeline and checks that
/// acquisition rides it out: same process, one reconnect, data and navigation back within the
/// outage plus the backoff's bound, only the outage's frames lost, navigation usable after it.
fn rides_out_an_unplug(name: &str, outage_s: f64) {
    let _one = one_pipeline();
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new(name);
    let up = Guard(Some(spawn_up(
        &ipc,
        &["--scenario", "static", "--duration", "300", "--json"],
    )));
    let collector = Collector::start(&ipc);
    // Unplugged while navigating: the case that matters.
    collector.wait_for("navigation and a heartbeat", Duration::from_secs(30), |s| {
        !s.acquisition.is_empty() && s.nav.last().is_some_and(|n| n.1 != NavMode::Aligning as u8)
    });
    let (pid, restarts, state) = acquisition(&ipc.status());
    assert_eq!((restarts, state.as_str()), (0, "running"));
    let reconnects_before = collector.seen.lock().expect("lock").acquisition[0].reconnects;
    assert_eq!(reconnects_before, 0);

    let sent = Instant::now();
    let out = ipc.run_with_timeout(
        &["inject", "disconnect", "--duration", &outage_s.to_string()],
        Duration::from_secs(10),
    );
    assert!(out.status.success(), "inject failed:\n{}", stderr(&out));
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains(&format!("disconnect {outage_s} s: applied at device time")),
        "{said}"
    );

    // Data back, and a heartbeat that counts the reconnect (heartbeats come once a second).
    let bound = Duration::from_secs_f64(outage_s + BACKOFF_CAP_S + SLACK_S);
    collector.wait_for("the reconnect", bound + Duration::from_secs(3), |s| {
        s.acquisition.last().is_some_and(|h| h.reconnects > 0)
            && s.imu
                .last()
                .is_some_and(|&(_, _, t)| t > sent + bound.min(Duration::from_secs(2)))
    });
    // One more heartbeat, so that a second reconnect would show.
    let beats = collector.seen.lock().expect("lock").acquisition.len();
    collector.wait_for("one more heartbeat", Duration::from_secs(3), |s| {
        s.acquisition.len() > beats
    });
    // Navigation usable again after the outage (not aligning, not invalid).
    collector.wait_for(
        "usable navigation after the outage",
        Duration::from_secs(10),
        |s| {
            s.nav.last().is_some_and(|n| {
                n.2 > sent + Duration::from_secs_f64(outage_s)
                    && NavMode::from_u8(n.1).is_some_and(NavMode::is_usable)
            })
        },
    );
    let seen = collector.finish();

    let last = seen.acquisition.last().expect("heartbeats");
    assert_eq!(last.reconnects, reconnects_before + 1, "{last:?}");
    assert_eq!(u64::from(last.pid), pid, "acquisition was replaced");

    // The outage is the longest pause of the raw IMU stream after the command; it lasts the
    // outage plus the wait for acquisition's next retry, which the backoff cap bounds.
    let (i, pause) = longest_pause(seen.imu.iter().map(|s| s.2), sent);
    let (seq_before, t_before, _) = seen.imu[i - 1];
    let (seq_after, t_after, _) = seen.imu[i];
    let reconnect_s = pause.as_secs_f64() - outage_s;
    eprintln!(
        "raw IMU pause {:.3} s for an outage of {outage_s} s: data back {:.0} ms after the device \
         (backoff {} ms doubling to {} ms)",
        pause.as_secs_f64(),
        reconnect_s * 1e3,
        BACKOFF_FIRST_S * 1e3,
        BACKOFF_CAP_S * 1e3
    );
    assert!(
        pause.as_secs_f64() > 0.9 * outage_s,
        "no outage seen: {pause:?}"
    );
    assert!(
        pause < bound,
        "data back only after {pause:?} (bound {bound:?})"
    );
    let (j, nav_pause) = longest_pause(seen.nav.iter().map(|n| n.2), sent);
    assert!(
        nav_pause < bound,
        "navigation back only after {nav_pause:?}"
    );
    // Navigation goes on from the first frame after the outage, still navigating.
    let (nav_before, nav_after) = (seen.nav[j - 1], seen.nav[j]);
    eprintln!(
        "navigation: frame {} then {} (mode {})",
        nav_before.0, nav_after.0, nav_after.1
    );
    assert_eq!((nav_before.0, nav_after.0), (seq_before, seq_after));
    assert!(
        seen.nav[j..].iter().all(|n| n.1 != NavMode::Aligning as u8),
        "navigation restarted its alignment"
    );
    // And usable again: flagged invalid for a moment after a long gap, then navigating.
    let usable_after = seen.nav[j..]
        .iter()
        .position(|n| NavMode::from_u8(n.1).is_some_and(NavMode::is_usable))
        .expect("no usable navigation after the outage");
    eprintln!(
        "navigation usable again {usable_after} outputs after the outage (mode {} first)",
        nav_after.1
    );

    // Frames lost: those the device made while unplugged, plus those it made after coming back
    // until acquisition reopened it (a real line drops what nobody reads), less what the terminal
    // held meanwhile. Sequence numbers run on across the outage.
    let period_us = seen
        .imu
        .windows(2)
        .map(|w| w[1].1 - w[0].1)
        .min()
        .expect("samples");
    let rate_hz = 1e6 / period_us as f64;
    let lost = seq_after - seq_before - 1;
    let outage_frames = outage_s * rate_hz;
    eprintln!("frames lost {lost} ({outage_frames} made during the outage)");
    assert!(lost as f64 >= outage_frames - 2.0, "lost {lost}");
    assert!(
        (lost as f64) <= outage_frames + reconnect_s.max(0.0) * rate_hz + 20.0,
        "lost {lost} of {outage_frames} + {reconnect_s:.3} s"
    );
    assert_eq!(
        t_after - t_before,
        (lost + 1) * period_us,
        "device time runs on"
    );
    // Nothing else lost beyond the line: a frame or two may overflow the pseudo-terminal of a
    // loaded test machine (the line is the limit, not the pipeline), up to one in a thousand, and
    // acquisition must have counted every frame missing, the outage's and those.
    let other_gaps: Vec<(u64, u64)> = seen
        .imu
        .windows(2)
        .map(|w| (w[0].0, w[1].0))
        .filter(|&(a, b)| b != a + 1 && a != seq_before)
        .collect();
    let other_lost: u64 = other_gaps.iter().map(|&(a, b)| b - a - 1).sum();
    assert!(
        other_lost as f64 <= (seen.imu.len() as f64 / 1000.0).max(1.0),
        "other gaps: {other_gaps:?}"
    );

    let (pid_after, restarts, state) = acquisition(&ipc.status());
    assert_eq!((pid_after, restarts, state.as_str()), (pid, 0, "running"));
    let summary = stop_up(&ipc, up.release());
    assert_eq!(summary["restarts"], 0, "{summary}");
    assert!(
        num(&summary, "lost_frames") >= (lost + other_lost) as f64,
        "frames missing from the stream but not counted as lost: {summary}"
    );
}

/// Takes everything a child wrote to a pipe so far, without waiting for its end.
fn read_available(pipe: &mut std::process::ChildStderr, into: &mut String) {
    let fd = std::os::fd::AsRawFd::as_raw_fd(pipe);
    // SAFETY: only changes the flags of our own pipe descriptor.
    unsafe {
        let flags = libc::fcntl(fd, libc::F_GETFL);
        libc::fcntl(fd, libc::F_SETFL, flags | libc::O_NONBLOCK);
    }
    let mut buf = [0u8; 4096];
    while let Ok(n @ 1..) = pipe.read(&mut buf) {
        into.push_str(&String::from_utf8_lossy(&buf[..n]));
    }
}

fn terminate(child: &mut Child) {
    // Our own child process, not reaped yet.
    send_signal(u64::from(child.id()), Signal::Terminate).expect("SIGTERM to our own child");
}

#[test]
fn acquisition_waits_for_a_device_that_comes_late() {
    let ipc = Isolated::new("late_device");
    // The root is private to the deployment's user: every process refuses one others may read.
    std::os::unix::fs::DirBuilderExt::mode(&mut std::fs::DirBuilder::new(), 0o700)
        .create(&ipc.root)
        .expect("root");
    let link = ipc.root.join("late-tty");
    let link_text = link.to_string_lossy().into_owned();
    let mut acq = Guard(Some(
        ipc.command()
            .env("RINS_LOG", "info")
            .args(["service", "acquisition", "--port", &link_text])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("cannot start acquisition"),
    ));
    let mut log = String::new();
    let mut pipe = acq.child().stderr.take().expect("stderr");
    // Well past several retries: still there, and it said once what it waits for.
    std::thread::sleep(Duration::from_millis(700));
    assert!(
        acq.child().try_wait().expect("poll").is_none(),
        "acquisition gave up"
    );
    read_available(&mut pipe, &mut log);
    let waiting = format!("waiting for serial device {link_text}");
    assert_eq!(log.matches(&waiting).count(), 1, "{log}");

    let mut sim = Guard(Some(
        ipc.command()
            .args(["sim", "--scenario", "static", "--link", &link_text])
            .args(["--duration", "30"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("cannot start the simulator"),
    ));
    let start = Instant::now();
    while !log.contains("serial device open") {
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "never opened:\n{log}"
        );
        std::thread::sleep(Duration::from_millis(20));
        read_available(&mut pipe, &mut log);
    }
    assert_eq!(log.matches(&waiting).count(), 1, "{log}");
    terminate(sim.child());
    terminate(acq.child());
    assert!(sim.child().wait().expect("sim").success());
    let status = acq.child().wait().expect("acquisition");
    read_available(&mut pipe, &mut log);
    assert!(status.success(), "{status:?}\n{log}");
    assert!(!log.contains("panicked"), "{log}");
}

#[test]
fn a_timed_disconnect_from_the_command_line_is_ridden_out() {
    let _one = one_pipeline();
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("timed_disconnect");
    let out = ipc
        .command()
        .env("RINS_LOG", "info")
        .args(["up", "--scenario", "static", "--duration", "4", "--json"])
        .args(["--inject", "disconnect=0.5@1.5s"])
        .output()
        .expect("cannot run rins up");
    let log = stderr(&out);
    assert!(out.status.success(), "{log}");
    let s = last_json(&out);
    assert_eq!(num(&s, "restarts"), 0.0, "{s}");
    assert_eq!(num(&s, "shm_leaked"), 0.0, "{s}");
    // The device fault is no channel's fault: nothing to detect, no false alarm.
    assert_eq!(s["faults"], serde_json::json!([]), "{s}");
    assert_eq!(num(&s, "false_alarms"), 0.0, "{s}");
    // Navigation misses the outage and the wait for the next retry, no more.
    let missing = num(&s, "dropped");
    eprintln!("timed disconnect of 0.5 s: {missing} navigation samples missing");
    assert!(
        (0.5 * 1000.0 - 2.0..=(0.5 + BACKOFF_CAP_S + SLACK_S) * 1000.0).contains(&missing),
        "{s}"
    );
    for line in [
        "serial line unplugged",
        "serial device lost: reopening with backoff",
        "serial line plugged back in",
        "serial device back: resynchronising",
    ] {
        assert_eq!(log.matches(line).count(), 1, "{line:?} in\n{log}");
    }
    assert!(log.contains("reconnects=1"), "{log}");
}

#[test]
fn disconnect_arguments_are_checked_naming_field_and_value() {
    let t = "disconnect_args";
    fails_with(
        t,
        &["inject", "disconnect"],
        &["disconnect", "needs --duration"],
    );
    fails_with(
        t,
        &["inject", "disconnect", "--duration", "soon"],
        &["disconnect --duration \"soon\"", "> 0"],
    );
    fails_with(
        t,
        &["inject", "disconnect", "--duration", "-1"],
        &["disconnect --duration = -1", "> 0"],
    );
    fails_with(
        t,
        &["inject", "disconnect", "--duration", "7200"],
        &["disconnect --duration = 7200", "3600"],
    );
    fails_with(
        t,
        &["inject", "gyro2", "dead", "--duration", "1"],
        &["--duration \"1\"", "only the disconnect"],
    );
    fails_with(
        t,
        &["inject", "gyro2", "disconnect"],
        &["channel \"gyro2\"", "whole device"],
    );
    fails_with(
        t,
        &["up", "--duration", "1", "--inject", "disconnect=0@1s"],
        &["--inject \"disconnect=0@1s\"", "disconnect DURATION_S = 0"],
    );
    fails_with(
        t,
        &["up", "--duration", "1", "--inject", "disconnect@1s"],
        &["disconnect", "needs DURATION_S"],
    );
    // Well formed, but nobody to unplug.
    fails_with(
        t,
        &["inject", "disconnect", "--duration", "1"],
        &["no simulator is listening"],
    );
}
