//! `rins eval gnss-captures --live` end to end: three real receivers' captures (NMEA with bare LF
//! line ends, UBX, UBX and NMEA mixed) written through pseudo-terminals to running gnss services
//! score exactly as the in-process decoder, every byte written is read, and the published fixes
//! equal the in-process decoder's.

mod common;

use std::path::Path;
use std::time::Duration;

use common::{Isolated, Scratch, last_json};
use serde_json::Value;

const CAPTURES: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/crates/gnss-protocol/tests/captures"
);
/// The mixed capture is 1.2 MB; its first bytes (cut at a line end) hold both protocols.
const MIXED: &str = "ublox-zed-f9p_hpg1.11.log";
const MIXED_BYTES: usize = 16_000;

/// The receiver's bytes of a capture: what follows the `#` comment lines.
fn receiver_bytes(log: &[u8]) -> usize {
    let mut rest = log;
    while rest.first() == Some(&b'#') {
        rest = rest
            .iter()
            .position(|&b| b == b'\n')
            .map_or(&[][..], |end| &rest[end + 1..]);
    }
    rest.len()
}

fn copy_captures(dir: &Path) {
    let from = Path::new(CAPTURES);
    for name in ["garmin17n.log", "ublox-neo-m8n.log"] {
        for file in [name.to_string(), format!("{name}.chk")] {
            std::fs::copy(from.join(&file), dir.join(&file)).expect("copy a capture");
        }
    }
    let mixed = std::fs::read(from.join(MIXED)).expect("the mixed capture");
    let end = mixed[..MIXED_BYTES]
        .iter()
        .rposition(|&b| b == b'\n')
        .expect("a line end")
        + 1;
    std::fs::write(dir.join(MIXED), &mixed[..end]).expect("write the mixed capture's start");
    let chk = format!("{MIXED}.chk");
    std::fs::copy(from.join(&chk), dir.join(&chk)).expect("copy the mixed reference");
}

fn eval(ipc: &Isolated, dir: &Path, live: bool) -> Value {
    let dir = dir.to_str().expect("UTF-8 path");
    let mut args = vec!["eval", "gnss-captures", dir, "--json"];
    if live {
        args.extend(["--live", "--baud", "115200", "--jobs", "3"]);
    }
    let out = ipc.run_with_timeout(&args, Duration::from_secs(60));
    assert!(
        out.status.success(),
        "rins {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    last_json(&out)
}

fn by_name<'a>(list: &'a Value, name: &str) -> &'a Value {
    list.as_array()
        .expect("a list")
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("{name} not in {list}"))
}

#[test]
fn live_service_scores_as_in_process_and_reads_every_byte() {
    let ipc = Isolated::new("eval_gnss_live");
    let scratch = Scratch::new("eval-gnss-live", "captures");
    copy_captures(scratch.path());
    let in_process = eval(&ipc, scratch.path(), false);
    let live = eval(&ipc, scratch.path(), true);

    assert_eq!(live["mode"], "live");
    assert_eq!(live["baud"], 115_200);
    assert_eq!(live["failures"].as_array().map(Vec::len), Some(0), "{live}");
    let groups: Vec<Option<&str>> = ["garmin17n.log", "ublox-neo-m8n.log", MIXED]
        .iter()
        .map(|n| by_name(&live["captures"], n)["protocols"].as_str())
        .collect();
    assert_eq!(groups, [Some("nmea-only"), Some("ubx-only"), Some("mixed")]);
    // The NMEA receiver ends its sentences with a bare LF.
    let garmin = by_name(&live["captures"], "garmin17n.log");
    assert!(garmin["decoder"]["framing"]["lines_lf"].as_u64() > Some(0));
    assert_eq!(garmin["decoder"]["framing"]["lines_crlf"], 0);

    assert!(live["totals"]["matched"].as_u64() > Some(0));
    assert_eq!(live["totals"]["matched"], in_process["totals"]["matched"]);
    assert_eq!(
        live["totals"]["within_1cm"],
        in_process["totals"]["within_1cm"]
    );
    for c in in_process["captures"].as_array().expect("captures") {
        let name = c["name"].as_str().expect("a name");
        let l = by_name(&live["captures"], name);
        assert!(l["score"]["matched"].as_u64() > Some(0), "{name}: {l}");
        assert_eq!(l["score"], c["score"], "{name}");

        let run = by_name(&live["live"], name);
        let log = std::fs::read(scratch.path().join(name)).expect("the capture");
        assert_eq!(run["bytes_written"], receiver_bytes(&log), "{name}");
        assert_eq!(run["bytes_read_by_service"], run["bytes_written"], "{name}");
        assert_eq!(run["fixes_received"], run["fixes_in_process"], "{name}");
        let d = &run["live_vs_in_process_differences"];
        assert_eq!(
            (&d["live_only"], &d["in_process_only"]),
            (&0.into(), &0.into()),
            "{name}: {run}"
        );
    }
    assert_eq!(
        live["live_totals"]["byte_mismatches"],
        Value::Array(Vec::new())
    );
}
