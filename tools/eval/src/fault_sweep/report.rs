//! The sweep's report: one row per run, the clean run, the summary; as a table or JSON.

use std::fmt::Write as _;

use serde::Serialize;

use super::config::{Prepared, SweepConfig, TARGET_ATT_ERR_DEG};
use super::run::{CleanRun, FaultRun};

/// The sweep's verdict.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepSummary {
    /// Largest `att_err_deg_max_while_ok` of any run (the references included), degrees.
    pub worst_att_err_deg_max_while_ok: Option<f64>,
    /// The run it came from: `gyro2 bias 20σ at 120 s`.
    pub worst_run: Option<String>,
    /// The target for it, degrees.
    pub target_deg: f64,
    /// The worst is within the target (true when no sample was ok at all).
    pub target_met: bool,
    /// Faulted runs fusion never flagged.
    pub undetected: usize,
    /// Faulted runs whose channel fusion never excluded.
    pub not_isolated: usize,
    /// Faulted runs in which fusion excluded another channel of the same type.
    pub wrongly_isolated: usize,
    /// False alarms of the clean run.
    pub false_alarms: usize,
}

/// Everything the sweep measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepReport {
    /// Simulator seed of every run.
    pub seed: u64,
    /// Per-sample σ of each gyro channel fault detection uses, rad/s.
    pub gyro_sigma_rps: Vec<f64>,
    /// The same of each accelerometer channel, m/s².
    pub accel_sigma_mps2: Vec<f64>,
    /// Injection times, s of device time.
    pub inject_at_s: Vec<f64>,
    /// Flight after each injection, s.
    pub window_s: f64,
    /// One row per run, by injection time, channel and fault; each injection time starts with
    /// its fault-free reference (`channel` `-`).
    pub runs: Vec<FaultRun>,
    /// The fault-free flight from the start to the end of the latest window.
    pub clean: CleanRun,
    /// The verdict.
    pub summary: SweepSummary,
}

impl SweepReport {
    pub(crate) fn new(
        prepared: &Prepared,
        config: &SweepConfig,
        runs: Vec<FaultRun>,
        clean: CleanRun,
    ) -> Self {
        let worst = runs
            .iter()
            .filter_map(|r| r.att_err_deg_max_while_ok.map(|e| (e, r)))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        let faulted = || runs.iter().filter(|r| r.kind != "none");
        let summary = SweepSummary {
            worst_att_err_deg_max_while_ok: worst.map(|(e, _)| e),
            worst_run: worst.map(|(_, r)| run_name(r)),
            target_deg: TARGET_ATT_ERR_DEG,
            target_met: worst.is_none_or(|(e, _)| e <= TARGET_ATT_ERR_DEG),
            undetected: faulted().filter(|r| r.detected_after_s.is_none()).count(),
            not_isolated: faulted().filter(|r| r.isolated_after_s.is_none()).count(),
            wrongly_isolated: faulted().filter(|r| r.wrongly_excluded.is_some()).count(),
            false_alarms: clean.false_alarms,
        };
        Self {
            seed: prepared.seed,
            gyro_sigma_rps: prepared.fdi_sigma[0].clone(),
            accel_sigma_mps2: prepared.fdi_sigma[1].clone(),
            inject_at_s: config.inject_at_s.clone(),
            window_s: config.window_s,
            runs,
            clean,
            summary,
        }
    }

    /// The report as a text table with the summary below it.
    pub fn to_table(&self) -> String {
        let mut out = String::new();
        let sigma = |v: &[f64]| {
            let first = v.first().copied().unwrap_or(f64::NAN);
            if v.iter().all(|&s| s == first) {
                format!("{first:.6}")
            } else {
                format!("{v:?}")
            }
        };
        let _ = writeln!(
            out,
            "fault sweep: seed {}, σ gyro {} rad/s, accel {} m/s², {} s after each injection",
            self.seed,
            sigma(&self.gyro_sigma_rps),
            sigma(&self.accel_sigma_mps2),
            self.window_s
        );
        let _ = writeln!(
            out,
            "{:>7}  {:<7}  {:<14}  {:>9}  {:>9}  {:<20}  {:<14}  {:>8}  {:>11}  {:>11}  {:>6}  {:>6}",
            "at_s",
            "channel",
            "fault",
            "detect_s",
            "isolate_s",
            "reason",
            "wrong_excl",
            "att_max°",
            "att_max_ok°",
            "horiz_ok_m",
            "ok_%",
            "unis_%"
        );
        for r in &self.runs {
            let _ = writeln!(
                out,
                "{:>7.1}  {:<7}  {:<14}  {:>9}  {:>9}  {:<20}  {:<14}  {:>8}  {:>11}  {:>11}  {:>6.1}  {:>6.1}",
                r.inject_at_s,
                r.channel,
                r.label,
                opt(r.detected_after_s, 3),
                opt(r.isolated_after_s, 3),
                r.reason.unwrap_or("-"),
                match (&r.wrongly_excluded, r.wrongly_excluded_after_s) {
                    (Some(c), Some(t)) => format!("{c}@{t:.3}"),
                    _ => "-".into(),
                },
                opt(r.att_err_deg_max, 3),
                opt(r.att_err_deg_max_while_ok, 3),
                opt(r.horiz_err_m_max_while_ok, 2),
                100.0 * r.ok_share,
                100.0 * r.unisolated_share,
            );
        }
        let c = &self.clean;
        let _ = writeln!(
            out,
            "clean run 0–{:.0} s: false alarms {} (flagged {:.3} s{}), att_max {}°, att_max_ok {}° (tilt {}°), ok {:.1} %",
            c.duration_s,
            c.false_alarms,
            c.flagged_s,
            c.first_false_alarm_s
                .map(|t| format!(", first at {t:.3} s"))
                .unwrap_or_default(),
            opt(c.att_err_deg_max, 3),
            opt(c.att_err_deg_max_while_ok, 3),
            opt(c.tilt_err_deg_max_while_ok, 3),
            100.0 * c.ok_share,
        );
        let s = &self.summary;
        let _ = writeln!(
            out,
            "summary: worst att_err_deg_max_while_ok {}°{} (target ≤ {}°: {}); undetected {}, not isolated {}, wrongly isolated {}; false alarms in the clean run {}",
            opt(s.worst_att_err_deg_max_while_ok, 3),
            s.worst_run
                .as_deref()
                .map(|r| format!(" ({r})"))
                .unwrap_or_default(),
            s.target_deg,
            if s.target_met { "met" } else { "MISSED" },
            s.undetected,
            s.not_isolated,
            s.wrongly_isolated,
            s.false_alarms,
        );
        out
    }
}

fn run_name(r: &FaultRun) -> String {
    if r.kind == "none" {
        format!("no fault, window from {} s", r.inject_at_s)
    } else {
        format!("{} {} at {} s", r.channel, r.label, r.inject_at_s)
    }
}

fn opt(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "-".into(), |v| format!("{v:.decimals$}"))
}
