//! GNSS aiding end to end: the simulated receiver on its own pseudo-terminal, the gnss service,
//! the navigator's updates, and the receiver's faults injected through `rins up --inject`, as the
//! run summary reports them.

mod common;

use std::time::Duration;

use common::{Isolated, last_json, num, spawn_up_navigating, stderr, stop_up};

fn gnss_faults(summary: &serde_json::Value) -> Vec<serde_json::Value> {
    summary["faults"]
        .as_array()
        .expect("summary has a faults array")
        .iter()
        .filter(|f| f["channel"] == "gnss")
        .cloned()
        .collect()
}

/// `rins up --scenario uav --gnss --json` for `seconds` with `faults` scheduled; the summary.
fn fly(test: &str, seconds: &str, faults: &[&str]) -> serde_json::Value {
    let ipc = Isolated::new(test);
    let mut args = vec![
        "up",
        "--scenario",
        "uav",
        "--gnss",
        "--duration",
        seconds,
        "--json",
    ];
    for f in faults {
        args.extend(["--inject", f]);
    }
    let out = ipc.run_with_timeout(&args, std::time::Duration::from_secs(240));
    assert!(out.status.success(), "rins up failed:\n{}", stderr(&out));
    last_json(&out)
}

/// A jump of 50 m from 30 s to 45 s, then a drift of 0.5 m/s from 60 s to 100 s, in one flight.
#[test]
fn a_jump_is_rejected_within_a_second_and_a_drift_within_30_s() {
    let s = fly(
        "gnss_jump_drift",
        "105",
        &[
            "gnss:jump=50@30s",
            "gnss:clear@45s",
            "gnss:drift=0.5@60s",
            "gnss:clear@100s",
        ],
    );
    assert_jump_then_drift_rejected_in_time(&s);
}

/// The summary `s` of a flight with a 50 m jump and then a 0.5 m/s drift: the jump rejected
/// within a second without moving the solution, the drift within 30 s, and no false alarm.
fn assert_jump_then_drift_rejected_in_time(s: &serde_json::Value) {
    let faults = gnss_faults(s);
    assert_eq!(faults.len(), 2, "{s}");
    let (jump, drift) = (&faults[0], &faults[1]);
    assert_eq!(jump["kind"], "gnss-jump", "{jump}");
    let jump_delay = num(jump, "detected_at_s") - num(jump, "injected_at_s");
    assert!(
        (0.0..=1.0).contains(&jump_delay),
        "jump detected after {jump_delay} s: {jump}"
    );
    assert_eq!(drift["kind"], "gnss-drift", "{drift}");
    let drift_delay = num(drift, "detected_at_s") - num(drift, "injected_at_s");
    assert!(
        (0.0..=30.0).contains(&drift_delay),
        "drift detected after {drift_delay} s: {drift}"
    );
    // The jump never reached the solution: no step the vehicle's motion does not explain.
    let step = num(jump, "horiz_step_m_max");
    assert!(
        step <= 1.0,
        "the solution stepped {step} m during the jump: {jump}"
    );
    assert_eq!(num(s, "false_alarms"), 0.0, "{s}");
}

/// Faults injected at run time, as an operator does (`rins inject gnss jump 50`, `clear`, then
/// `drift 0.5`, into a running deployment): the summary reports them with the bounds of the
/// scheduled ones. The drift starts about 30 s into the flight, a phase where the innovation
/// test alone never saw it.
#[test]
fn faults_injected_at_run_time_are_rejected_in_time() {
    let ipc = Isolated::new("gnss_inject_run_time");
    let up = spawn_up_navigating(
        &ipc,
        &["--scenario", "uav", "--gnss", "--duration", "600", "--json"],
    );
    let inject = |args: &[&str]| {
        let out = ipc.run(&[&["inject", "gnss"], args].concat());
        assert!(
            out.status.success(),
            "rins inject gnss {args:?}: {}",
            stderr(&out)
        );
    };
    // Aided for a while first.
    std::thread::sleep(Duration::from_secs(15));
    inject(&["jump", "50"]);
    std::thread::sleep(Duration::from_secs(8));
    inject(&["clear"]);
    // Re-admitted 3 s after the jump ends.
    std::thread::sleep(Duration::from_secs(8));
    inject(&["drift", "0.5"]);
    std::thread::sleep(Duration::from_secs(25));
    inject(&["clear"]);
    assert_jump_then_drift_rejected_in_time(&stop_up(&ipc, up));
}

/// A 60 s outage: reported as such, the solution coasts, and the drift at its end is reported.
#[test]
fn an_outage_coasts_and_reports_its_drift() {
    let s = fly("gnss_outage", "95", &["gnss:outage=60@30s"]);
    let faults = gnss_faults(&s);
    assert_eq!(faults.len(), 1, "{s}");
    let outage = &faults[0];
    assert_eq!(outage["kind"], "gnss-outage", "{outage}");
    // Reported stale after the aiding timeout (1 s) and the fix period.
    let delay = num(outage, "detected_at_s") - num(outage, "injected_at_s");
    assert!(
        (0.0..=2.0).contains(&delay),
        "outage seen after {delay} s: {outage}"
    );
    // The coast drifts, and the navigator's σ says so: the error is within 3σ of what it reported.
    let err = num(outage, "coast_horiz_err_m");
    let sigma = num(outage, "coast_horiz_sigma_m");
    assert!(err.is_finite() && sigma > 0.0, "{outage}");
    assert!(
        err <= 3.0 * sigma * std::f64::consts::SQRT_2,
        "{err} m against σ {sigma} m"
    );
    // Aided again afterwards: five seconds after the outage the error is that of a GNSS-aided
    // solution again, and the receiver's return was no false alarm.
    assert!(num(&s, "horiz_end_err_m") < 5.0, "{s}");
    assert_eq!(num(&s, "false_alarms"), 0.0, "{s}");
}
