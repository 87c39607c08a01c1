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
    // The bare chain: the same hops measured from the same stamps, every sample of the source
    // through both relays to this consumer, and the pipeline's figures as ratios to its own.
    assert_eq!(r["wait"], "event", "{r}");
    let chain = r["chain"].as_array().unwrap();
    let e2e = chain
        .iter()
        .find(|h| h["hop"] == "serial rx -> nav state published")
        .unwrap();
    assert_eq!(e2e["samples"], 1000, "{e2e}");
    let chain_p50 = r["chain_p50_us"].as_f64().unwrap();
    assert_eq!(e2e["p50_us"].as_f64().unwrap(), chain_p50);
    // Two event hops cannot take less than a few microseconds, nor does a quiet relay of no work
    // take a whole sample period at p50.
    assert!(chain_p50 > 2.0 && chain_p50 < 1000.0, "{r}");
    assert!(chain_p50 <= r["chain_p99_us"].as_f64().unwrap(), "{r}");
    assert!((r["ratio_chain_p50"].as_f64().unwrap() - p50 / chain_p50).abs() < 1e-9);
    let relayed: Vec<&str> = chain
        .iter()
        .filter(|h| h["samples"] == 1000)
        .map(|h| h["hop"].as_str().unwrap())
        .collect();
    assert!(
        relayed.contains(&"fusion -> navigator published"),
        "{relayed:?}"
    );
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
