//! The once-a-second status line.

use ipc_types::{Integrity, NavMode, NavState, RedundancyReport, integrity_reason};
pub use rins_earth::euler_deg;

use crate::device_counters::DeviceCounters;
use crate::monitor::COUNTED;
use crate::redundancy_view::{nav_of, nav_summary, redundancy_summary};

/// One status line: per-topic rates over the last period, losses, the redundant channels in use
/// and why any is out, and the current solution with its mode, lane and aiding.
pub fn status_line(
    elapsed_s: f64,
    rates_hz: &[f64; COUNTED.len()],
    dropped: u64,
    device: &DeviceCounters,
    redundancy: &RedundancyReport,
    nav: Option<&NavState>,
) -> String {
    let mut line = format!("t={elapsed_s:6.1}s");
    for (name, rate) in COUNTED.iter().zip(rates_hz) {
        line.push_str(&format!(" {name} {rate:4.0}/s"));
    }
    line.push_str(&format!(
        " | dropped {dropped} crc {} lost {}",
        device.crc_errors, device.lost_frames
    ));
    // The rarer device counters only when there is something to say, so the usual line keeps
    // its width.
    for (what, n) in [
        ("malformed", device.malformed_frames),
        ("duplicates", device.duplicate_frames),
        ("late", device.late_frames),
        ("seq jumps", device.seq_jumps),
        ("time rebases", device.time_rebases),
    ] {
        if n > 0 {
            line.push_str(&format!(" {what} {n}"));
        }
    }
    if redundancy.heard != 0 {
        line.push_str(&format!(" | {}", redundancy_summary(redundancy)));
    }
    // No sample over the last period: the output stopped, whatever the last sample said.
    let nav_flowing = COUNTED
        .iter()
        .zip(rates_hz)
        .any(|(name, rate)| *name == "nav" && *rate > 0.0);
    match nav {
        Some(_) if !nav_flowing => line.push_str(" | no navigation output"),
        Some(nav) => {
            let [r, p, y] = euler_deg(nav.quaternion);
            let mode = NavMode::from_u8(nav.mode);
            line.push_str(&format!(
                " | {} | roll {r:6.2} pitch {p:6.2} yaw {y:7.2} alt {:7.1} m",
                nav_summary(&nav_of(nav, 0)),
                nav.altitude_m
            ));
            // An integrity that cannot be read is not to be trusted: shown as invalid.
            let integrity = Integrity::from_u8(nav.integrity).unwrap_or(Integrity::Invalid);
            if integrity != Integrity::Ok && mode != Some(NavMode::Aligning) {
                line.push_str(&format!(
                    " | integrity {}: {}",
                    integrity.name().to_uppercase(),
                    integrity_reason::describe(nav.integrity_reasons)
                ));
            }
        }
        None => line.push_str(" | no navigation output yet"),
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;

    const ALL_FLOWING: [f64; COUNTED.len()] = [1000.0, 50.0, 100.0, 1000.0, 50.0, 1000.0];

    /// The line at 3 s with `rates`, nothing dropped, quiet device counters and no redundancy
    /// report.
    fn line_of(rates: &[f64; COUNTED.len()], nav: &NavState) -> String {
        status_line(
            3.0,
            rates,
            0,
            &DeviceCounters::default(),
            &RedundancyReport::default(),
            Some(nav),
        )
    }

    #[test]
    fn euler_of_a_known_attitude() {
        let u = UnitQuaternion::from_euler_angles(0.1, 0.2, -0.3);
        let e = euler_deg([u.w, u.i, u.j, u.k]);
        for (got, want) in e.iter().zip([0.1f64, 0.2, -0.3]) {
            assert!((got - want.to_degrees()).abs() < 1e-9);
        }
    }

    #[test]
    fn line_names_every_topic_and_the_mode() {
        let nav = NavState {
            mode: NavMode::Navigating as u8,
            altitude_m: 12.5,
            ..NavState::default()
        };
        let line = line_of(&ALL_FLOWING, &nav);
        for name in COUNTED {
            assert!(line.contains(name), "{line}");
        }
        assert!(
            line.contains("navigating") && line.contains("12.5"),
            "{line}"
        );
        assert!(!line.contains("stale"), "{line}");
        let coasting = NavState {
            aiding: ipc_types::aiding::BARO_STALE,
            ..nav
        };
        let line = line_of(&[1000.0, 0.0, 100.0, 1000.0, 0.0, 1000.0], &coasting);
        assert!(
            line.contains("| navigating: baro stale, lane 0 |"),
            "{line}"
        );
        assert!(!line.contains("mag stale"), "{line}");
        assert!(!line.contains("integrity"), "{line}");
        let invalid = NavState {
            mode: NavMode::Invalid as u8,
            integrity: Integrity::Invalid as u8,
            integrity_reasons: integrity_reason::IMU_UNUSABLE | integrity_reason::COVARIANCE,
            ..nav
        };
        let line = line_of(&ALL_FLOWING, &invalid);
        assert!(
            line.contains("| invalid, lane 0 | roll")
                && line.contains("integrity INVALID: imu-unusable,covariance"),
            "{line}"
        );
        assert!(!line.contains("navigating"), "{line}");
    }

    /// The last sample said navigating, but none came over the period: the line says the output
    /// stopped, not "navigating" beside `nav 0/s`.
    #[test]
    fn a_stopped_navigation_output_is_not_shown_as_navigating() {
        let nav = NavState {
            mode: NavMode::Navigating as u8,
            ..NavState::default()
        };
        let line = line_of(&[1000.0, 50.0, 100.0, 0.0, 50.0, 0.0], &nav);
        assert!(line.ends_with("| no navigation output"), "{line}");
        assert!(!line.contains("navigating"), "{line}");
    }

    #[test]
    fn a_mode_or_integrity_that_cannot_be_read_is_shown_as_such() {
        let unknown = NavState {
            mode: 200,
            integrity: 200,
            ..NavState::default()
        };
        let line = line_of(&ALL_FLOWING, &unknown);
        assert!(
            line.contains("| mode 200, lane 0 | roll") && line.contains("integrity INVALID: "),
            "{line}"
        );
        assert!(!line.contains("aligning"), "{line}");
    }

    #[test]
    fn the_line_shows_the_channels_in_use_and_why_one_is_out() {
        let mut fused = ipc_types::FusedImu {
            n_gyro: 4,
            n_accel: 4,
            ..ipc_types::FusedImu::default()
        };
        fused.gyro_state[..4].fill(ipc_types::ChannelState::Ok as u8);
        fused.accel_state[..4].fill(ipc_types::ChannelState::Ok as u8);
        fused.gyro_state[2] = ipc_types::ChannelState::Excluded as u8;
        fused.gyro_reason[2] = ipc_types::FaultReason::Missing as u8;
        let nav = NavState {
            mode: NavMode::Navigating as u8,
            aiding: ipc_types::aiding::BARO | ipc_types::aiding::MAG,
            ..NavState::default()
        };
        let line = status_line(
            5.0,
            &ALL_FLOWING,
            0,
            &DeviceCounters::default(),
            &crate::redundancy_view::redundancy_of(&fused, 0),
            Some(&nav),
        );
        assert!(
            line.contains(
                "| gyro 3/4 (gyro2 missing) accel 4/4 | navigating, lane 0, aiding baro+mag | roll"
            ),
            "{line}"
        );
    }

    #[test]
    fn rare_device_counters_appear_only_when_non_zero() {
        let rates = ALL_FLOWING;
        let none = RedundancyReport::default();
        let quiet = status_line(4.0, &rates, 0, &DeviceCounters::default(), &none, None);
        assert!(
            quiet.ends_with("| dropped 0 crc 0 lost 0 | no navigation output yet"),
            "{quiet}"
        );
        let device = DeviceCounters {
            crc_errors: 1,
            lost_frames: 2,
            malformed_frames: 12_000,
            late_frames: 3,
            time_rebases: 2,
            ..DeviceCounters::default()
        };
        let line = status_line(4.0, &rates, 3, &device, &none, None);
        assert!(
            line.contains(
                "| dropped 3 crc 1 lost 2 malformed 12000 late 3 time rebases 2 | no navigation"
            ),
            "{line}"
        );
        assert!(
            !line.contains("duplicates") && !line.contains("seq jumps"),
            "{line}"
        );
    }
}
