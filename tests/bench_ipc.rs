//! `rins bench ipc`: the bare hops and the pipeline measured in one invocation, every IPC hop set
//! against the bare hop of its payload, and nothing left behind.

mod common;

use common::{Isolated, PipelineSlot, last_json};

#[test]
fn the_bench_sets_each_pipeline_hop_against_its_bare_hop() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("benchipc");
    let out = ipc.run_with_timeout(
        &["bench", "ipc", "--seconds", "1", "--warmup", "1", "--json"],
        std::time::Duration::from_secs(300),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = last_json(&out);
    let (p50, p99, p999) = (
        r["e2e_p50_us"].as_f64().unwrap(),
        r["e2e_p99_us"].as_f64().unwrap(),
        r["e2e_p999_us"].as_f64().unwrap(),
    );
    assert!(0.0 < p50 && p50 <= p99 && p99 <= p999, "{r}");
    let hops = r["hops"].as_array().unwrap();
    let names: Vec<&str> = hops.iter().map(|h| h["hop"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "acquisition -> fusion published",
            "fusion -> navigator published",
            "navigator published -> consumer received"
        ]
    );
    for h in hops {
        let (p50, bare) = (
            h["p50_us"].as_f64().unwrap(),
            h["bare_p50_us"].as_f64().unwrap(),
        );
        assert!(p50 > 0.0 && bare > 0.0, "{h}");
        assert!(
            (h["ratio_p50"].as_f64().unwrap() - p50 / bare).abs() < 1e-9,
            "{h}"
        );
        assert!(h["bare_p99_us"].as_f64().unwrap() >= bare, "{h}");
    }
    // 1 s at 1 kHz per bare payload: every sample sent was received.
    for b in r["bare"].as_array().unwrap() {
        assert_eq!(b["samples"], 1000, "{b}");
    }
    // The bench's own deployment is gone (no other test runs a bench), and it never touched the
    // test's.
    let leftovers: Vec<String> = std::fs::read_dir("/dev/shm")
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("rinsbench"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    assert!(ipc.shm_entries().is_empty());
}
