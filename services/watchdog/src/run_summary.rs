//! The summary of a run, gathered from what the watchdog counted once its children are stopped.

use std::time::Duration;

use crate::link::link_error_name;
use crate::monitor::Monitor;
use crate::process_usage::{pipeline_cpu_pct, pipeline_wakeups_per_frame};
use crate::restart_timing::RestartTiming;
use crate::summary::Summary;
use crate::supervisor::Supervisor;

/// The run's summary; the accuracy figures only when the simulator was the device (they compare
/// with its truth). `shm_leaked` is left 0: it is known only once the shared memory is removed;
/// `profile` and `profile_reason` are left empty: `rins up` chose them, not the watchdog.
pub fn summarise(
    monitor: &Monitor,
    supervisor: &Supervisor,
    timing: &RestartTiming,
    elapsed: Duration,
    simulate: bool,
) -> Summary {
    let (restart_worst, restart_measurements) = timing.worst();
    let usage = supervisor.usage(elapsed);
    let device = monitor.device_counters();
    let acc = &monitor.accuracy;
    let sim = |v: Option<f64>| if simulate { v } else { None };
    Summary {
        duration_s: elapsed.as_secs_f64(),
        frames: monitor.totals[0],
        baro_frames: monitor.totals[1],
        mag_frames: monitor.totals[2],
        dropped: monitor.nav_gaps.missing,
        crc_errors: device.crc_errors,
        malformed_frames: device.malformed_frames,
        lost_frames: device.lost_frames,
        duplicate_frames: device.duplicate_frames,
        late_frames: device.late_frames,
        seq_jumps: device.seq_jumps,
        time_rebases: device.time_rebases,
        bytes_received: device.bytes_received,
        // Acquisition's count is as old as its last heartbeat (up to a second): the frames the
        // watchdog saw published are valid frames too, and may be the fresher count.
        valid_frames: device
            .valid_frames
            .max(monitor.totals[0] + monitor.totals[1] + monitor.totals[2]),
        discarded_bytes: device.resync_bytes,
        last_decode_error: link_error_name(device.last_decode_error),
        nav_samples: monitor.totals[5],
        restarts: supervisor.restarts(),
        failed_services: supervisor.given_up(),
        restart_to_publish_ms_max: restart_worst.as_secs_f64() * 1e3,
        restart_measurements,
        restart_to_publish_ms_by_service: timing
            .by_kind()
            .into_iter()
            .map(|(kind, worst, n)| (kind.name().to_string(), worst.as_secs_f64() * 1e3, n))
            .collect(),
        nav_lane_samples: monitor.nav_lanes().lane_totals(),
        nav_lane_switches: monitor.nav_lanes().switches().0,
        nav_lane_switch_causes: monitor.nav_lanes().switch_counts().into(),
        nav_lane_last_switch: monitor.nav_lanes().switches().1.map(|s| s.to_string()),
        nav_lane_filled: monitor.nav_lanes().filled(),
        nav_integrity_samples: monitor.integrity_samples.into(),
        att_err_deg_rms: sim(acc.attitude_deg.rms()),
        att_err_deg_max: sim(acc.attitude_deg.max()),
        att_err_deg_max_while_ok: sim(acc.attitude_deg_while_ok.max()),
        alt_err_m_rms: sim(acc.altitude_m.rms()),
        alt_err_m_max: sim(acc.altitude_m.max()),
        horiz_pos_err_m_rms: sim(acc.horizontal.errors().rms()),
        horiz_pos_err_m_max: sim(acc.horizontal.errors().max()),
        horiz_err_m_max_while_ok: sim(acc.horizontal_m_while_ok.max()),
        horiz_step_m_max: sim(acc.horizontal.largest_step_m()),
        distance_m: sim(acc.horizontal.distance_m()),
        horiz_end_err_m: sim(acc.horizontal.end_error_m()),
        horiz_end_err_pct: sim(acc.horizontal.end_error_pct()),
        shm_leaked: 0,
        profile: String::new(),
        profile_reason: String::new(),
        pipeline_cpu_pct: pipeline_cpu_pct(&usage),
        pipeline_wakeups_per_frame: pipeline_wakeups_per_frame(&usage, monitor.totals[0]),
        processes: usage,
        faults: monitor.faults.records().to_vec(),
        false_alarms: monitor.faults.false_alarms(),
        gnss: crate::gnss_line::gnss_row(&monitor.last_gnss_link),
    }
}
