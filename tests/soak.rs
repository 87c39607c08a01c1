//! `rins soak` for a quarter of a minute: every kill is a real SIGKILL to a service of a real
//! pipeline, and every one must come back.

mod common;

use common::{Isolated, PipelineSlot, last_json};

#[test]
fn a_short_soak_restarts_every_killed_service_and_leaks_nothing() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("soak");
    let out = ipc
        .command()
        .args([
            "soak",
            "--minutes",
            "0.25",
            "--min-interval",
            "2",
            "--max-interval",
            "3",
        ])
        .output()
        .expect("cannot run rins soak");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = last_json(&out);
    // 15 s, the last 3 s without kills, a kill every 2–3 s: 3 to 5 kills (one may miss a
    // service that is still restarting).
    let kills = s["kills"].as_u64().unwrap();
    assert!((2..=5).contains(&kills), "{s}");
    assert_eq!(s["restarts"].as_u64().unwrap(), kills, "{s}");
    assert_eq!(s["shm_leaked"], 0, "{s}");
    assert!(s["nav_samples"].as_u64().unwrap() > 5_000, "{s}");
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
}
