//! The hot-standby navigator in flight: SIGKILL the navigator lane that delivers, and the stream
//! consumers read stays contiguous (no sequence number missing), switches to the other lane, and
//! keeps navigating; the killed lane comes back by taking over its peer's solution, so the peer can
//! be killed next and the stream goes on, still navigating.

mod common;

use std::io::{BufRead, BufReader};
use std::process::{Child, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use common::{Isolated, PipelineSlot, num, spawn_up, stop_up};
use rins_test_support::signal::{Signal, send_signal};
use serde_json::Value;

/// One navigation sample as `rins echo nav` prints it.
#[derive(Debug, Clone, Copy)]
struct Sample {
    seq: u64,
    lane: u64,
    mode: u64,
}

/// `rins echo nav` in the background, its samples on a channel.
fn echo_nav(ipc: &Isolated) -> (Child, Receiver<Sample>) {
    let mut child = ipc
        .command()
        .args(["echo", "nav", "--raw", "--timeout", "60"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("cannot start rins echo");
    let stdout = child.stdout.take().expect("echo stdout");
    let (tx, rx) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            let v: Value = serde_json::from_str(&line).expect("echo prints JSON");
            let sample = Sample {
                seq: v["header"]["origin_seq"].as_u64().expect("origin_seq"),
                lane: v["lane"].as_u64().expect("lane"),
                mode: v["mode"].as_u64().expect("mode"),
            };
            if tx.send(sample).is_err() {
                break;
            }
        }
    });
    (child, rx)
}

fn pid_of(ipc: &Isolated, name: &str) -> u64 {
    let report = ipc.status();
    let service = report["services"]
        .as_array()
        .expect("services")
        .iter()
        .find(|s| s["service"] == name && s["state"] == "running")
        .unwrap_or_else(|| panic!("{name} not running: {report}"))
        .clone();
    service["pid"].as_u64().expect("pid")
}

/// Takes samples for `span`, checking that each one follows the previous without a gap.
fn follow(rx: &Receiver<Sample>, last: &mut u64, span: Duration) -> Vec<Sample> {
    let end = Instant::now() + span;
    let mut got = Vec::new();
    while Instant::now() < end {
        let s = rx
            .recv_timeout(Duration::from_secs(5))
            .expect("navigation stream stopped");
        assert_eq!(s.seq, *last + 1, "gap or repeat after {last}: {s:?}");
        *last = s.seq;
        got.push(s);
    }
    got
}

const NAVIGATING: u64 = 1;

/// The process of each navigator lane.
const LANES: [&str; 2] = ["navigator", "navigator-standby"];

#[test]
fn killing_either_navigator_lane_loses_no_sample_and_navigation_goes_on() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("standby");
    let up = spawn_up(&ipc, &["--scenario", "uav", "--duration", "300", "--json"]);
    let (mut echo, rx) = echo_nav(&ipc);
    // Alignment (3 s at rest in the scenario) and the lane selector's 2 s settling time.
    let first = rx
        .recv_timeout(Duration::from_secs(120))
        .expect("no navigation output");
    let mut last = first.seq;
    let warm = follow(&rx, &mut last, Duration::from_secs(8));
    // Whichever lane delivers (the one whose samples reached this consumer first) is navigating.
    let delivering = warm.last().map_or(0, |s| s.lane);
    assert!(
        warm.iter()
            .rev()
            .take(100)
            .all(|s| s.mode == NAVIGATING && s.lane == delivering),
        "not navigating from one lane after the warm-up"
    );

    // Kill the delivering lane: the other delivers from the next sequence number on.
    let first_victim = LANES[delivering as usize];
    let killed = pid_of(&ipc, first_victim);
    // A process of this test's own pipeline.
    send_signal(killed, Signal::Kill).expect("SIGKILL");
    let after_first = follow(&rx, &mut last, Duration::from_secs(6));
    assert!(
        after_first.iter().all(|s| s.mode == NAVIGATING),
        "stopped navigating"
    );
    assert!(
        after_first.iter().any(|s| s.lane == 1 - delivering),
        "the other lane never delivered"
    );

    // The killed lane was restarted in flight: it took over the other lane's solution (a static
    // alignment is impossible while flying). Which lane delivers now is the selector's choice: it
    // stays on the surviving lane, or — when a loaded machine kept that lane silent for longer
    // than the dead time while the restarted one published — on the restarted one, with no
    // preferred lane to return to. Kill whichever delivers, so the switch is exercised again.
    assert_ne!(pid_of(&ipc, first_victim), killed);
    let now_delivering = after_first.last().map_or(0, |s| s.lane);
    let second_victim = LANES[now_delivering as usize];
    let other = pid_of(&ipc, second_victim);
    send_signal(other, Signal::Kill).expect("SIGKILL");
    let after_second = follow(&rx, &mut last, Duration::from_secs(4));
    assert!(
        after_second.iter().all(|s| s.mode == NAVIGATING),
        "navigation stopped after the second kill"
    );
    assert!(
        after_second.iter().any(|s| s.lane == 1 - now_delivering),
        "the other lane never delivered after the second kill"
    );

    // Our own child; already gone is fine too.
    let _ = send_signal(u64::from(echo.id()), Signal::Terminate);
    let _ = echo.wait();
    let summary = stop_up(&ipc, up);
    assert_eq!(num(&summary, "restarts"), 2.0, "{summary}");
    // Both killed processes and both that replaced them are counted in the CPU figures.
    let lane_incarnations: u64 = summary["processes"]
        .as_array()
        .expect("processes")
        .iter()
        .filter(|p| LANES.contains(&p["name"].as_str().unwrap_or("")))
        .map(|p| p["incarnations"].as_u64().unwrap_or(0))
        .sum();
    assert_eq!(lane_incarnations, 4, "{summary}");
    // The taken-over solution is as good as the one it came from (same bound as the uav run).
    assert!(num(&summary, "att_err_deg_max") < 3.0, "{summary}");
}
