//! What `rins up` writes to stderr at its default log level: no warning for the simulator's link
//! that appears moments after acquisition starts, no bare terminal path, and each navigator lane's
//! lines labelled with its lane.

mod common;

use common::{Isolated, PipelineSlot, stderr};

#[test]
fn a_healthy_start_is_quiet_and_the_lanes_are_labelled() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("startup_log");
    // Long enough for both lanes to align (2 s of device time) on a loaded machine.
    let out = ipc
        .command()
        .env("RINS_LOG", "info")
        .args(["up", "--scenario", "static", "--duration", "6"])
        .output()
        .expect("cannot run rins up");
    let err = stderr(&out);
    assert!(out.status.success(), "{:?}\n{err}", out.status);
    let alarming: Vec<&str> = err
        .lines()
        .filter(|l| l.contains(" WARN ") || l.contains(" ERROR "))
        .collect();
    assert!(alarming.is_empty(), "{alarming:#?}\n{err}");
    assert!(
        !err.lines().any(|l| l.starts_with("/dev/")),
        "a bare device path:\n{err}"
    );
    for lane in ["navigator{lane=0}", "navigator{lane=1}"] {
        assert!(
            err.lines().any(|l| l.contains(lane)),
            "no line from {lane}:\n{err}"
        );
    }
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
}
