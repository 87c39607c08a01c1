//! The run's summary as text, what `rins up --duration S` prints at the end without `--json`.

use crate::summary::Summary;

/// A few lines for a person: the run and its losses, the deployment profile, then, in simulator
/// mode, the navigation error against truth (attitude, altitude, and the horizontal end-point error
/// as a share of the distance travelled), then the faults.
pub fn summary_text(s: &Summary) -> String {
    let mut out = format!(
        "summary: {:.1} s, {} IMU frames, {} dropped, {} lost on the line, {} CRC errors, {} restarts, {} shared-memory entries left\n",
        s.duration_s, s.frames, s.dropped, s.lost_frames, s.crc_errors, s.restarts, s.shm_leaked
    );
    if !s.failed_services.is_empty() {
        out.push_str(&format!(
            "  FAILED: {} given up (restarts kept failing); the stage was down at the end\n",
            s.failed_services.join(", ")
        ));
    }
    if !s.profile.is_empty() {
        out.push_str(&format!(
            "  profile: {} — {}\n",
            s.profile, s.profile_reason
        ));
    }
    if s.nav_lane_switches > 0 {
        let c = &s.nav_lane_switch_causes;
        let last = s
            .nav_lane_last_switch
            .as_deref()
            .map_or_else(String::new, |l| format!("; last {l}"));
        out.push_str(&format!(
            "  navigation lane switches: {} (silent {}, behind {}, ring full {}, untrusted {}){last}\n",
            s.nav_lane_switches, c.silent, c.behind, c.ring_full, c.untrusted
        ));
    }
    if !s.processes.is_empty() {
        let peak: u64 = s.processes.iter().map(|p| p.peak_rss_kib).sum();
        out.push_str(&format!(
            "  CPU: {:.1} % of one core without the simulator, {:.1} wake-ups per IMU frame; peak memory {:.1} MiB over {} processes\n",
            s.pipeline_cpu_pct,
            s.pipeline_wakeups_per_frame,
            peak as f64 / 1024.0,
            s.processes.len()
        ));
    }
    if let (Some(rms), Some(max)) = (s.att_err_deg_rms, s.att_err_deg_max) {
        let while_ok = s.att_err_deg_max_while_ok.map_or_else(String::new, |ok| {
            format!(" (max {ok:.2}° while integrity ok)")
        });
        out.push_str(&format!(
            "  attitude error after alignment: RMS {rms:.2}°, max {max:.2}°{while_ok}\n"
        ));
    }
    if let (Some(rms), Some(max)) = (s.alt_err_m_rms, s.alt_err_m_max) {
        out.push_str(&format!(
            "  altitude error after alignment: RMS {rms:.2} m, max {max:.2} m\n"
        ));
    }
    if let (Some(rms), Some(max)) = (s.horiz_pos_err_m_rms, s.horiz_pos_err_m_max) {
        let while_ok = s.horiz_err_m_max_while_ok.map_or_else(String::new, |ok| {
            format!(" (max {ok:.2} m while integrity ok)")
        });
        out.push_str(&format!(
            "  horizontal position error after alignment: RMS {rms:.2} m, max {max:.2} m{while_ok}\n"
        ));
    }
    if let (Some(err), Some(distance)) = (s.horiz_end_err_m, s.distance_m) {
        let share = s
            .horiz_end_err_pct
            .map_or_else(String::new, |pct| format!(" ({pct:.2} % of"));
        let of = if share.is_empty() {
            format!(", {distance:.1} m travelled")
        } else {
            format!("{share} {distance:.1} m travelled)")
        };
        out.push_str(&format!("  horizontal end-point error: {err:.2} m{of}\n"));
    }
    if let Some(gnss) = &s.gnss {
        out.push_str(&crate::gnss_line::summary_line(gnss));
    }
    if !s.faults.is_empty() || s.false_alarms > 0 {
        let isolated = s
            .faults
            .iter()
            .filter(|f| f.isolated_at_s.is_some())
            .count();
        out.push_str(&format!(
            "  faults: {} injected, {isolated} isolated, {} false alarms\n",
            s.faults.len(),
            s.false_alarms
        ));
        for f in s.faults.iter().filter(|f| f.channel == "gnss") {
            let detected = f.detected_at_s.map_or("not detected".to_string(), |t| {
                format!("detected after {:.2} s", t - f.injected_at_s)
            });
            let coast = match (f.coast_horiz_err_m, f.coast_horiz_sigma_m) {
                (Some(err), Some(sigma)) => {
                    format!(", horizontal error {err:.2} m at its end (σ reported {sigma:.2} m)")
                }
                _ => String::new(),
            };
            out.push_str(&format!(
                "  gnss {} at {:.1} s: {detected}{coast}\n",
                f.kind, f.injected_at_s
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn summary() -> Summary {
        Summary {
            duration_s: 112.0,
            frames: 112_000,
            baro_frames: 0,
            mag_frames: 0,
            dropped: 0,
            crc_errors: 0,
            malformed_frames: 0,
            lost_frames: 0,
            duplicate_frames: 0,
            late_frames: 0,
            seq_jumps: 0,
            time_rebases: 0,
            bytes_received: 0,
            valid_frames: 0,
            discarded_bytes: 0,
            last_decode_error: "none".into(),
            nav_samples: 0,
            restarts: 0,
            failed_services: Vec::new(),
            restart_to_publish_ms_max: 0.0,
            restart_measurements: 0,
            restart_to_publish_ms_by_service: Vec::new(),
            nav_lane_samples: [0, 0],
            nav_lane_switches: 0,
            nav_lane_switch_causes: Default::default(),
            nav_lane_last_switch: None,
            nav_lane_filled: 0,
            nav_integrity_samples: Default::default(),
            att_err_deg_rms: Some(1.5),
            att_err_deg_max: Some(2.38),
            att_err_deg_max_while_ok: Some(0.61),
            alt_err_m_rms: None,
            alt_err_m_max: None,
            horiz_pos_err_m_rms: Some(0.84),
            horiz_pos_err_m_max: Some(1.3),
            horiz_err_m_max_while_ok: Some(0.9),
            horiz_step_m_max: Some(0.2),
            distance_m: Some(125.8),
            horiz_end_err_m: Some(1.11),
            horiz_end_err_pct: Some(0.882),
            shm_leaked: 0,
            profile: String::new(),
            profile_reason: String::new(),
            processes: Vec::new(),
            pipeline_cpu_pct: 0.0,
            pipeline_wakeups_per_frame: 0.0,
            faults: Vec::new(),
            false_alarms: 0,
            gnss: None,
        }
    }

    #[test]
    fn a_walk_reads_its_end_point_error_and_distance() {
        let text = summary_text(&summary());
        assert!(
            text.starts_with("summary: 112.0 s, 112000 IMU frames"),
            "{text}"
        );
        assert!(
            text.contains(
                "attitude error after alignment: RMS 1.50°, max 2.38° (max 0.61° while integrity ok)"
            ),
            "{text}"
        );
        assert!(
            text.contains("RMS 0.84 m, max 1.30 m (max 0.90 m while integrity ok)"),
            "{text}"
        );
        assert!(!text.contains("altitude"), "{text}");
        assert!(
            text.contains("horizontal end-point error: 1.11 m (0.88 % of 125.8 m travelled)"),
            "{text}"
        );
        assert!(!text.contains("faults"), "{text}");
    }

    #[test]
    fn standing_still_gives_the_error_without_a_share() {
        let s = Summary {
            distance_m: Some(0.0),
            horiz_end_err_m: Some(0.2),
            horiz_end_err_pct: None,
            ..summary()
        };
        let text = summary_text(&s);
        assert!(
            text.contains("horizontal end-point error: 0.20 m, 0.0 m travelled"),
            "{text}"
        );
    }

    /// Lane switches are a line with their causes and the last one, none without switches.
    #[test]
    fn lane_switches_are_counted_by_cause() {
        assert!(!summary_text(&summary()).contains("lane switches"));
        let s = Summary {
            nav_lane_switches: 3,
            nav_lane_switch_causes: crate::summary::LaneSwitchCauses {
                silent: 2,
                untrusted: 1,
                ..Default::default()
            },
            nav_lane_last_switch: Some(
                "lane 1 → 0 at seq 9: lane 1 aligning, lane 0 trusted".into(),
            ),
            ..summary()
        };
        let text = summary_text(&s);
        assert!(
            text.contains(
                "navigation lane switches: 3 (silent 2, behind 0, ring full 0, untrusted 1); last lane 1 → 0 at seq 9: lane 1 aligning, lane 0 trusted\n"
            ),
            "{text}"
        );
    }

    /// The profile is a line of its own, after the failures, absent when none was recorded.
    #[test]
    fn the_profile_is_named_with_its_reason() {
        assert!(!summary_text(&summary()).contains("profile"));
        let text = summary_text(&Summary {
            profile: "dedicated".into(),
            profile_reason: "dedicated as asked: 4 usable CPUs (acquisition on CPU 3, fusion on \
                             2, navigator on 1; the rest on 0)"
                .into(),
            ..summary()
        });
        assert_eq!(
            text.lines().nth(1),
            Some(
                "  profile: dedicated — dedicated as asked: 4 usable CPUs (acquisition on CPU 3, \
                 fusion on 2, navigator on 1; the rest on 0)"
            ),
            "{text}"
        );
    }

    /// A service given up is the summary's second line, by name, and absent otherwise.
    #[test]
    fn a_service_given_up_is_named_as_failed() {
        let ok = summary_text(&summary());
        assert!(!ok.contains("FAILED"), "{ok}");
        let text = summary_text(&Summary {
            failed_services: vec!["fusion".into()],
            ..summary()
        });
        assert_eq!(
            text.lines().nth(1),
            Some(
                "  FAILED: fusion given up (restarts kept failing); the stage was down at the end"
            ),
            "{text}"
        );
    }
}
