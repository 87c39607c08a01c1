//! The JSON object `rins up --json` prints on its last line.

use serde::Serialize;

use crate::fault_tracking::FaultRecord;
use crate::process_usage::ProcessUsage;

/// Navigation samples per integrity level.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq, Eq)]
pub struct IntegritySamples {
    /// Samples with integrity ok.
    pub ok: u64,
    /// Samples with integrity degraded.
    pub degraded: u64,
    /// Samples with integrity invalid.
    pub invalid: u64,
}

/// Lane switches of the selector by cause.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq, Eq)]
pub struct LaneSwitchCauses {
    /// The selected lane silent for the dead time while the other was ahead.
    pub silent: u64,
    /// The selected lane behind by the switch lag, samples without publish times.
    pub behind: u64,
    /// The other lane's pending samples filled the selector's ring and the selected lane was
    /// silent for the dead time.
    pub ring_full: u64,
    /// The selected lane aligning, invalid or too young while the other was trusted.
    pub untrusted: u64,
}

impl From<rins_navigator::lanes::SwitchCounts> for LaneSwitchCauses {
    fn from(c: rins_navigator::lanes::SwitchCounts) -> Self {
        Self {
            silent: c.silent,
            behind: c.behind,
            ring_full: c.ring_full,
            untrusted: c.untrusted,
        }
    }
}

impl From<[u64; 3]> for IntegritySamples {
    fn from([ok, degraded, invalid]: [u64; 3]) -> Self {
        Self {
            ok,
            degraded,
            invalid,
        }
    }
}

/// What `rins up --json` prints at the end of a run.
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct Summary {
    /// Length of the run, s.
    pub duration_s: f64,
    /// IMU frames published by acquisition.
    pub frames: u64,
    /// Barometer frames published by acquisition.
    pub baro_frames: u64,
    /// Magnetometer frames published by acquisition.
    pub mag_frames: u64,
    /// IMU frames sent by the device for which no navigation output appeared (serial losses and
    /// pipeline losses together), between the first and the last navigation output.
    pub dropped: u64,
    /// Serial frames with a bad CRC.
    pub crc_errors: u64,
    /// Frames with a valid CRC but malformed content (unknown type, bad length, counts beyond 12
    /// bits), as counted by acquisition.
    pub malformed_frames: u64,
    /// Frames missing from the device's sequence numbers, as counted by acquisition (a late frame
    /// is taken back out).
    pub lost_frames: u64,
    /// Frames whose sequence number had been received before: not published.
    pub duplicate_frames: u64,
    /// Frames that arrived after a later one of their type (reordered): not published, not lost.
    pub late_frames: u64,
    /// Sequence-counter discontinuities of the device, re-based without counting losses.
    pub seq_jumps: u64,
    /// Device-clock discontinuities, re-based on the receive clock.
    pub time_rebases: u64,
    /// Bytes read from the serial device.
    pub bytes_received: u64,
    /// Serial frames with a valid CRC and sane content (published, or withheld as duplicate or
    /// late).
    pub valid_frames: u64,
    /// Bytes discarded while looking for frames.
    pub discarded_bytes: u64,
    /// Why the last undecodable bytes were refused: `none`, `no-sync`, `unknown-frame-type`,
    /// `bad-length`, `crc-mismatch`, `bad-content`.
    pub last_decode_error: String,
    /// Navigation samples of the merged stream.
    pub nav_samples: u64,
    /// Child restarts.
    pub restarts: u64,
    /// The services given up during the run (over their restart limit, or failing every start):
    /// their stage was down when the run ended.
    pub failed_services: Vec<String>,
    /// Longest time from a child's exit to the first sample of its output topic from its
    /// successor, ms, and how many restarts were timed so (0 and 0 without restarts).
    pub restart_to_publish_ms_max: f64,
    /// Restarts whose restart-to-publish time was measured.
    pub restart_measurements: u64,
    /// Per service: name, longest exit-to-publish time (ms), restarts timed.
    pub restart_to_publish_ms_by_service: Vec<(String, f64, u64)>,
    /// Samples received from each navigator lane; lane changes of the selector and samples it took
    /// from the other lane to fill a hole of the delivering one.
    pub nav_lane_samples: [u64; 2],
    /// Switches between navigator lanes.
    pub nav_lane_switches: u64,
    /// Those switches by cause.
    pub nav_lane_switch_causes: LaneSwitchCauses,
    /// The last switch and why, as the watchdog's log line said (`None` without switches).
    pub nav_lane_last_switch: Option<String>,
    /// Samples of one lane filled in from the other.
    pub nav_lane_filled: u64,
    /// Navigation samples after alignment the navigator judged ok, degraded and invalid.
    pub nav_integrity_samples: IntegritySamples,
    /// Attitude error against simulator truth after alignment, degrees (simulator mode only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub att_err_deg_rms: Option<f64>,
    /// Largest attitude error, degrees (simulator only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub att_err_deg_max: Option<f64>,
    /// Largest attitude error while the navigator's integrity said ok, degrees (simulator only;
    /// `None` when no sample was ok).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub att_err_deg_max_while_ok: Option<f64>,
    /// Altitude error against simulator truth after alignment, metres (simulator mode only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alt_err_m_rms: Option<f64>,
    /// Largest altitude error, m (simulator only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alt_err_m_max: Option<f64>,
    /// Horizontal position error against simulator truth after alignment, RMS, m (simulator
    /// only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub horiz_pos_err_m_rms: Option<f64>,
    /// Largest horizontal position error, m (simulator only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub horiz_pos_err_m_max: Option<f64>,
    /// Largest horizontal position error while the navigator's integrity said ok, m (simulator
    /// only; `None` when no sample was ok).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub horiz_err_m_max_while_ok: Option<f64>,
    /// Largest step of the horizontal solution from one sample to the next that the truth's
    /// motion does not explain, m (simulator only): what an accepted bad fix would show.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub horiz_step_m_max: Option<f64>,
    /// Horizontal distance the truth travelled after alignment, m (simulator only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distance_m: Option<f64>,
    /// Horizontal position error of the last navigation sample against truth, m (simulator
    /// only): a walk's end-point error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub horiz_end_err_m: Option<f64>,
    /// `horiz_end_err_m` as a percentage of `distance_m` (simulator only, and only once the truth
    /// travelled a metre).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub horiz_end_err_pct: Option<f64>,
    /// Shared-memory entries of this deployment left after shutdown.
    pub shm_leaked: u64,
    /// The deployment profile that ran (`rins up --profile`): `shared` or `dedicated`.
    pub profile: String,
    /// Why that profile ran: the CPUs counted and, under `dedicated`, which stage had which CPU.
    pub profile_reason: String,
    /// CPU time and peak resident memory per process (`watchdog` is `rins up` itself), from
    /// `/proc`.
    pub processes: Vec<ProcessUsage>,
    /// The CPU of every process but the simulator, % of one core over the run.
    pub pipeline_cpu_pct: f64,
    /// Wake-ups (voluntary context switches) of every process but the simulator per IMU frame.
    pub pipeline_wakeups_per_frame: f64,
    /// Every fault injected (scheduled or at run time), with detection and isolation times.
    pub faults: Vec<FaultRecord>,
    /// Channels leaving Ok, or faults detected but not isolated, on a sensor type with no
    /// injected fault active, counted as events.
    pub false_alarms: u64,
    /// The GNSS receiver's line at the end of the run, every counter of the gnss service's last
    /// report (absent without a gnss service, or when it never reported).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gnss: Option<crate::gnss_line::GnssRow>,
}
