//! Fifty SIGKILLs under a running pipeline, one service after the other: every service comes back
//! and publishes again, no navigation sample is lost that the serial line did not lose, the
//! watchdog survives, no zombie is left, and the shared memory of the deployment does not grow.
//! How fast a service is back is measured (the summary's `restart_to_publish_ms_*`, printed), not
//! asserted: it is a figure of the machine.

mod common;

use std::time::{Duration, Instant};

use common::{Isolated, PipelineSlot, num, spawn_up_navigating, stop_up};
use rins_test_support::signal::{Signal, send_signal};
use serde_json::Value;

const KILLS: usize = 50;

/// The tests of this file run one at a time: the restart times they assert are the pipeline's
/// own, not those of two pipelines sharing two cores.
static ALONE: std::sync::Mutex<()> = std::sync::Mutex::new(());
const VICTIMS: [&str; 5] = [
    "fusion",
    "altimeter",
    "acquisition",
    "navigator",
    "navigator-standby",
];

/// (name, pid) of every service the report shows running; `None` until all of them are.
fn all_running(report: &Value) -> Option<Vec<(String, u64)>> {
    let services = report["services"].as_array()?;
    services
        .iter()
        .map(|s| {
            (s["state"] == "running").then(|| {
                (
                    s["service"].as_str().unwrap_or_default().to_string(),
                    s["pid"].as_u64().unwrap_or(0),
                )
            })
        })
        .collect()
}

fn wait_all_running(ipc: &Isolated, limit: Duration) -> Vec<(String, u64)> {
    let start = Instant::now();
    loop {
        let r = ipc.status();
        if let Some(pids) = all_running(&r) {
            return pids;
        }
        assert!(start.elapsed() < limit, "not everything came back: {r}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Children of `parent` in state Z (exited, not reaped).
fn zombies_of(parent: u64) -> Vec<u64> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir("/proc").expect("/proc").flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u64>() else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
            continue;
        };
        // "pid (comm) state ppid ...": the command may hold spaces, so split after the ')'.
        let Some(rest) = stat.rsplit_once(')').map(|(_, r)| r) else {
            continue;
        };
        let mut fields = rest.split_whitespace();
        let (state, ppid) = (fields.next(), fields.next().and_then(|p| p.parse().ok()));
        if state == Some("Z") && ppid == Some(parent) {
            found.push(pid);
        }
    }
    found
}

#[test]
fn fifty_kills_leave_no_zombie_no_shared_memory_growth_and_a_live_watchdog() {
    let _alone = ALONE.lock().unwrap_or_else(|e| e.into_inner());
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("storm");
    let up = spawn_up_navigating(
        &ipc,
        &["--scenario", "static", "--duration", "600", "--json"],
    );
    let pids = wait_all_running(&ipc, Duration::from_secs(30));
    let watchdog = pids
        .iter()
        .find(|(n, _)| n == "watchdog")
        .map(|p| p.1)
        .expect("watchdog");
    let shm_before = ipc.shm_entries().len();

    let mut killed = Vec::new();
    for k in 0..KILLS {
        let victim = VICTIMS[k % VICTIMS.len()];
        let pids = wait_all_running(&ipc, Duration::from_secs(20));
        let (_, pid) = pids
            .iter()
            .find(|(n, _)| n == victim)
            .unwrap_or_else(|| panic!("no {victim} in {pids:?}"));
        // A process of this test's own pipeline.
        send_signal(*pid, Signal::Kill).unwrap_or_else(|e| panic!("{victim}: {e}"));
        killed.push(*pid);
    }
    let after = wait_all_running(&ipc, Duration::from_secs(20));
    let watchdog_after = after.iter().find(|(n, _)| n == "watchdog").map(|p| p.1);
    assert_eq!(watchdog_after, Some(watchdog), "the watchdog changed");
    assert_eq!(zombies_of(watchdog), Vec::<u64>::new());
    for pid in killed {
        // Reaped: the pid no longer names a process of ours (kill with signal 0 fails), or it
        // was reused by an unrelated process, which /proc shows without our watchdog as parent.
        let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
        let ppid = stat
            .rsplit_once(')')
            .and_then(|(_, r)| r.split_whitespace().nth(1))
            .and_then(|p| p.parse::<u64>().ok());
        assert_ne!(ppid, Some(watchdog), "pid {pid} still a child: {stat}");
    }
    // Restarted processes create their ports anew and the dead ones' are removed: the count of
    // shared-memory entries is what it was before the first kill.
    assert_eq!(
        ipc.shm_entries().len(),
        shm_before,
        "{:?}",
        ipc.shm_entries()
    );

    let summary = stop_up(&ipc, up);
    // The figures for the record (`cargo test --test kill_storm -- --nocapture`).
    eprintln!("{summary}");
    assert_eq!(num(&summary, "restarts"), KILLS as f64, "{summary}");
    // Back at all, not hung: 10 ms of backoff and a process start, far below a second.
    assert!(
        num(&summary, "restart_to_publish_ms_max") <= 1_000.0,
        "{summary}"
    );
    assert_eq!(num(&summary, "restart_measurements"), KILLS as f64);
    // No navigation output lost: the standby lane covers a killed navigator, the serial line holds
    // what the device sends while acquisition restarts, the raw IMU history what fusion misses.
    // Two exceptions, both the serial line's: frames the device could not write to a reader that
    // was too slow (counted in `lost_frames`), and at most the one frame a SIGKILLed acquisition
    // had half read — its bytes die with the process, as they would on a real serial port.
    let acquisition_kills = (0..KILLS)
        .filter(|k| VICTIMS[k % VICTIMS.len()] == "acquisition")
        .count() as f64;
    assert!(
        num(&summary, "dropped") <= num(&summary, "lost_frames") + acquisition_kills,
        "{summary}"
    );
}

#[test]
fn the_watchdog_frees_the_shared_memory_of_a_killed_process_it_did_not_start() {
    let _alone = ALONE.lock().unwrap_or_else(|e| e.into_inner());
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("deadnode");
    let up = spawn_up_navigating(
        &ipc,
        &["--scenario", "static", "--duration", "120", "--json"],
    );
    wait_all_running(&ipc, Duration::from_secs(30));
    let before = ipc.shm_entries().len();
    // A consumer on the deployment's prefix, killed without a chance to clean up: its node and
    // subscriber ports stay in /dev/shm until someone notices the node is dead.
    let mut echo = ipc
        .command()
        .args(["echo", "nav", "--timeout", "60"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("cannot start rins echo");
    // Killed only once it has printed a sample: its node and ports are then complete. A process
    // killed halfway through creating them leaves a node iceoryx2 cannot yet call dead.
    let stdout = echo.stdout.take().expect("echo's stdout is piped");
    let (first_line, got_line) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = std::io::BufRead::read_line(&mut std::io::BufReader::new(stdout), &mut line);
        let _ = first_line.send(line);
    });
    let line = got_line
        .recv_timeout(Duration::from_secs(10))
        .expect("echo printed no sample in 10 s");
    assert!(!line.is_empty(), "echo exited before printing a sample");
    assert!(ipc.shm_entries().len() > before, "echo created nothing");
    echo.kill().expect("SIGKILL echo");
    echo.wait().expect("reap echo");
    // The watchdog's dead-node sweep (every 250 ms) removes them; nothing else here creates a node.
    let start = Instant::now();
    while ipc.shm_entries().len() > before {
        assert!(
            start.elapsed() < Duration::from_secs(2),
            "{:?}",
            ipc.shm_entries()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let summary = stop_up(&ipc, up);
    assert_eq!(num(&summary, "restarts"), 0.0, "{summary}");
}
