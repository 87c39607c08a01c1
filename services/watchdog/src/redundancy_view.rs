//! What an operator reads of the redundant channels and the navigation mode: the report fields
//! built from fusion's and the navigator's latest samples, and the words the status line and
//! `rins status` print from them (one wording for both).

use ipc_types::{
    ChannelState, FaultReason, FusedImu, Integrity, MAX_CHANNELS, NavMode, NavReport, NavState,
    RedundancyReport, SensorType, aiding, bit_names, fused_flags, integrity_reason,
};
use serde::Serialize;

/// The report fields of a fused sample that is `age_ms` old.
pub fn redundancy_of(fused: &FusedImu, age_ms: u32) -> RedundancyReport {
    RedundancyReport {
        heard: 1,
        n_gyro: fused.n_gyro,
        n_accel: fused.n_accel,
        flags: fused.flags,
        gyro_state: fused.gyro_state,
        accel_state: fused.accel_state,
        gyro_reason: fused.gyro_reason,
        accel_reason: fused.accel_reason,
        gyro_test_statistic: fused.gyro_test_statistic,
        accel_test_statistic: fused.accel_test_statistic,
        age_ms,
        ..RedundancyReport::default()
    }
}

/// A navigation sample older than this means the output stopped (it flows at the IMU rate, and the
/// two lanes cover each other's restarts): from then on the report says so instead of repeating
/// the last sample's mode.
pub const NAV_OUTPUT_STALE_MS: u32 = 1000;

/// Whether a navigation sample `age_ms` old still shows the output flowing.
pub fn nav_output_flowing(age_ms: u32) -> bool {
    age_ms <= NAV_OUTPUT_STALE_MS
}

/// The report fields of a navigation sample that is `age_ms` old. Once it is older than
/// [`NAV_OUTPUT_STALE_MS`] there is no solution to use: the mode and integrity are reported
/// invalid, whatever the last sample said, so that no reader of the report takes a stopped
/// output for a navigating one.
pub fn nav_of(nav: &NavState, age_ms: u32) -> NavReport {
    let flowing = nav_output_flowing(age_ms);
    NavReport {
        heard: 1,
        mode: if flowing {
            nav.mode
        } else {
            NavMode::Invalid as u8
        },
        lane: nav.lane,
        integrity: if flowing {
            nav.integrity
        } else {
            Integrity::Invalid as u8
        },
        aiding: nav.aiding,
        integrity_reasons: nav.integrity_reasons,
        age_ms,
    }
}

/// One fitted channel as printed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelRow {
    /// `gyro2`, `accel0`.
    pub channel: String,
    /// [`ChannelState`] name (a code this build does not know: `state N`).
    pub state: String,
    /// [`FaultReason`] name; `None` for a channel that is Ok.
    pub reason: Option<String>,
}

/// One sensor type as printed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorRow {
    /// Channels fitted.
    pub fitted: usize,
    /// Channels in the solution (Ok or Suspect).
    pub in_use: usize,
    /// Whether the type has a valid solution (three usable channels, not saturated, frame read).
    pub solution: bool,
    /// The parity test statistic (0 without a parity space).
    pub test_statistic: f64,
}

/// The redundancy part of `rins status --json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RedundancyView {
    /// The one-line summary the status line shows, e.g. `gyro 3/4 (gyro2 missing) accel 4/4`.
    pub summary: String,
    /// Gyro channels.
    pub gyro: SensorRow,
    /// Accelerometer channels.
    pub accel: SensorRow,
    /// Names of the fused sample's flags.
    pub flags: Vec<&'static str>,
    /// Every fitted channel, gyros first.
    pub channels: Vec<ChannelRow>,
    /// Age of the fused sample, ms.
    pub age_ms: u32,
}

/// The navigation part of `rins status --json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NavView {
    /// The one-line summary the status line shows, e.g. `coasting: baro stale, lane 1`.
    pub summary: String,
    /// [`NavMode`] name.
    pub mode: String,
    /// The lane in use (0 primary, 1 standby).
    pub lane: u8,
    /// [`Integrity`] name.
    pub integrity: String,
    /// Why the integrity is not ok.
    pub integrity_reasons: Vec<&'static str>,
    /// Aiding sources vouching for the solution now.
    pub aiding: Vec<&'static str>,
    /// Configured aiding sources that went quiet (the solution coasts without them).
    pub stale: Vec<&'static str>,
    /// Age of the navigation sample, ms.
    pub age_ms: u32,
    /// The navigation output flows: its last sample is at most [`NAV_OUTPUT_STALE_MS`] old.
    pub output_flowing: bool,
}

fn sensor_arrays(r: &RedundancyReport, sensor: SensorType) -> (&[u8], &[u8]) {
    let (n, states, reasons) = match sensor {
        SensorType::Gyro => (r.n_gyro, &r.gyro_state, &r.gyro_reason),
        SensorType::Accel => (r.n_accel, &r.accel_state, &r.accel_reason),
    };
    let n = usize::from(n).min(MAX_CHANNELS);
    (&states[..n], &reasons[..n])
}

fn state_name(code: u8) -> String {
    ChannelState::from_u8(code).map_or_else(|| format!("state {code}"), |s| s.name().into())
}

fn reason_name(code: u8) -> String {
    FaultReason::from_u8(code).map_or_else(|| format!("reason {code}"), |r| r.name().into())
}

/// In the solution: Ok or Suspect (a state this build cannot read is not counted in).
fn in_use(state: u8) -> bool {
    matches!(
        ChannelState::from_u8(state),
        Some(ChannelState::Ok | ChannelState::Suspect)
    )
}

fn sensor_row(r: &RedundancyReport, sensor: SensorType) -> SensorRow {
    let (states, _) = sensor_arrays(r, sensor);
    let (unusable, statistic) = match sensor {
        SensorType::Gyro => (
            fused_flags::GYRO_INSUFFICIENT | fused_flags::GYRO_SATURATED,
            r.gyro_test_statistic,
        ),
        SensorType::Accel => (
            fused_flags::ACCEL_INSUFFICIENT | fused_flags::ACCEL_SATURATED,
            r.accel_test_statistic,
        ),
    };
    SensorRow {
        fitted: states.len(),
        in_use: states.iter().filter(|s| in_use(**s)).count(),
        solution: r.flags & (unusable | fused_flags::INPUT_REJECTED) == 0,
        test_statistic: f64::from(statistic),
    }
}

/// Per sensor type, channels in use of those fitted and why any is not Ok:
/// `gyro 3/4 (gyro2 missing) accel 4/4`; a type without a solution says so.
pub fn redundancy_summary(r: &RedundancyReport) -> String {
    let mut parts = Vec::with_capacity(2);
    for sensor in SensorType::ALL {
        let row = sensor_row(r, sensor);
        let (states, reasons) = sensor_arrays(r, sensor);
        let mut part = format!("{} {}/{}", sensor.name(), row.in_use, row.fitted);
        let notes: Vec<String> = states
            .iter()
            .zip(reasons)
            .enumerate()
            .filter_map(|(i, (&state, &reason))| {
                let channel = format!("{}{i}", sensor.name());
                match ChannelState::from_u8(state) {
                    Some(ChannelState::Ok | ChannelState::Absent) => None,
                    Some(ChannelState::Excluded) => {
                        Some(format!("{channel} {}", reason_name(reason)))
                    }
                    Some(ChannelState::Suspect) => {
                        Some(format!("{channel} suspect: {}", reason_name(reason)))
                    }
                    None => Some(format!("{channel} {}", state_name(state))),
                }
            })
            .collect();
        if !notes.is_empty() {
            part.push_str(&format!(" ({})", notes.join(", ")));
        }
        if !row.solution {
            part.push_str(" NO SOLUTION");
        }
        parts.push(part);
    }
    parts.join(" ")
}

/// The printable redundancy part of a report; `None` before fusion was heard.
pub fn redundancy_view(r: &RedundancyReport) -> Option<RedundancyView> {
    if r.heard == 0 {
        return None;
    }
    let mut channels = Vec::new();
    for sensor in SensorType::ALL {
        let (states, reasons) = sensor_arrays(r, sensor);
        for (i, (&state, &reason)) in states.iter().zip(reasons).enumerate() {
            channels.push(ChannelRow {
                channel: format!("{}{i}", sensor.name()),
                state: state_name(state),
                reason: (reason != FaultReason::None as u8).then(|| reason_name(reason)),
            });
        }
    }
    Some(RedundancyView {
        summary: redundancy_summary(r),
        gyro: sensor_row(r, SensorType::Gyro),
        accel: sensor_row(r, SensorType::Accel),
        flags: bit_names(r.flags, &fused_flags::NAMES),
        channels,
        age_ms: r.age_ms,
    })
}

/// The navigation mode with what it coasts without, the lane and the aiding sources:
/// `navigating, lane 0, aiding baro+mag`, `coasting: baro stale, lane 1, aiding mag`.
/// A report whose sample is older than [`NAV_OUTPUT_STALE_MS`] reads `no navigation output for
/// 3.2 s`.
pub fn nav_summary(n: &NavReport) -> String {
    if !nav_output_flowing(n.age_ms) {
        return format!(
            "no navigation output for {:.1} s",
            f64::from(n.age_ms) * 1e-3
        );
    }
    let mode =
        NavMode::from_u8(n.mode).map_or_else(|| format!("mode {}", n.mode), |m| m.name().into());
    let mut out = mode;
    let stale = bit_names(n.aiding, &aiding::STALE_NAMES);
    if !stale.is_empty() {
        out.push_str(&format!(": {} stale", stale.join("+")));
    }
    if n.aiding & aiding::GNSS_REJECTED != 0 {
        out.push_str(", gnss rejected");
    }
    out.push_str(&format!(", lane {}", n.lane));
    let sources = bit_names(n.aiding, &aiding::SOURCE_NAMES);
    if !sources.is_empty() {
        out.push_str(&format!(", aiding {}", sources.join("+")));
    }
    out
}

/// The printable navigation part of a report; `None` before a navigation sample was heard.
pub fn nav_view(n: &NavReport) -> Option<NavView> {
    if n.heard == 0 {
        return None;
    }
    Some(NavView {
        summary: nav_summary(n),
        mode: NavMode::from_u8(n.mode)
            .map_or_else(|| format!("mode {}", n.mode), |m| m.name().into()),
        lane: n.lane,
        // An integrity that cannot be read is not to be trusted.
        integrity: Integrity::from_u8(n.integrity)
            .unwrap_or(Integrity::Invalid)
            .name()
            .into(),
        integrity_reasons: bit_names(n.integrity_reasons, &integrity_reason::NAMES),
        aiding: bit_names(n.aiding, &aiding::SOURCE_NAMES),
        stale: bit_names(n.aiding, &aiding::STALE_NAMES),
        age_ms: n.age_ms,
        output_flowing: nav_output_flowing(n.age_ms),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn four_and_four() -> FusedImu {
        let mut f = FusedImu {
            n_gyro: 4,
            n_accel: 4,
            gyro_test_statistic: 1.5,
            ..FusedImu::default()
        };
        f.gyro_state[..4].fill(ChannelState::Ok as u8);
        f.accel_state[..4].fill(ChannelState::Ok as u8);
        f
    }

    /// A stopped output is not shown as the last sample's mode: not "navigating" once the newest
    /// sample is older than a second, in the summary, the view and the report itself.
    #[test]
    fn a_stopped_navigation_output_is_reported_as_such() {
        let nav = NavState {
            mode: NavMode::Navigating as u8,
            integrity: Integrity::Ok as u8,
            aiding: aiding::BARO,
            ..NavState::default()
        };
        let fresh = nav_of(&nav, NAV_OUTPUT_STALE_MS);
        assert_eq!(nav_summary(&fresh), "navigating, lane 0, aiding baro");
        assert!(nav_view(&fresh).expect("heard").output_flowing);
        let stopped = nav_of(&nav, 3200);
        assert_eq!(NavMode::from_u8(stopped.mode), Some(NavMode::Invalid));
        assert_eq!(
            Integrity::from_u8(stopped.integrity),
            Some(Integrity::Invalid)
        );
        assert_eq!(nav_summary(&stopped), "no navigation output for 3.2 s");
        let view = nav_view(&stopped).expect("heard");
        assert!(!view.output_flowing);
        assert_eq!(
            (view.mode.as_str(), view.integrity.as_str()),
            ("invalid", "invalid")
        );
    }

    #[test]
    fn a_healthy_block_reads_all_in_use() {
        let r = redundancy_of(&four_and_four(), 3);
        assert_eq!(redundancy_summary(&r), "gyro 4/4 accel 4/4");
        let v = redundancy_view(&r).expect("heard");
        assert_eq!(v.channels.len(), 8);
        assert!(
            v.channels
                .iter()
                .all(|c| c.state == "ok" && c.reason.is_none())
        );
        assert_eq!(
            (v.gyro.in_use, v.gyro.fitted, v.gyro.solution),
            (4, 4, true)
        );
        assert_eq!(v.gyro.test_statistic, 1.5);
        assert_eq!(v.age_ms, 3);
        assert!(v.flags.is_empty());
    }

    #[test]
    fn an_excluded_and_a_suspect_channel_are_named_with_their_reasons() {
        let mut f = four_and_four();
        f.gyro_state[2] = ChannelState::Excluded as u8;
        f.gyro_reason[2] = FaultReason::Missing as u8;
        f.accel_state[0] = ChannelState::Suspect as u8;
        f.accel_reason[0] = FaultReason::Parity as u8;
        let r = redundancy_of(&f, 0);
        assert_eq!(
            redundancy_summary(&r),
            "gyro 3/4 (gyro2 missing) accel 4/4 (accel0 suspect: parity)"
        );
        let v = redundancy_view(&r).expect("heard");
        assert_eq!(
            v.channels[2],
            ChannelRow {
                channel: "gyro2".into(),
                state: "excluded".into(),
                reason: Some("missing".into())
            }
        );
        assert_eq!(v.channels[4].reason.as_deref(), Some("parity"));
        assert_eq!((v.gyro.in_use, v.accel.in_use), (3, 4));
    }

    #[test]
    fn a_type_without_a_solution_says_so() {
        let mut f = four_and_four();
        for i in 1..3 {
            f.gyro_state[i] = ChannelState::Excluded as u8;
            f.gyro_reason[i] = FaultReason::Stuck as u8;
        }
        f.flags = fused_flags::GYRO_INSUFFICIENT;
        let r = redundancy_of(&f, 0);
        assert_eq!(
            redundancy_summary(&r),
            "gyro 2/4 (gyro1 stuck, gyro2 stuck) NO SOLUTION accel 4/4"
        );
        let v = redundancy_view(&r).expect("heard");
        assert!(!v.gyro.solution && v.accel.solution);
        assert_eq!(v.flags, ["gyro-insufficient"]);
    }

    #[test]
    fn codes_this_build_does_not_know_are_not_counted_in_and_are_named_by_number() {
        let mut f = four_and_four();
        f.gyro_state[3] = 200;
        let r = redundancy_of(&f, 0);
        assert_eq!(
            redundancy_summary(&r),
            "gyro 3/4 (gyro3 state 200) accel 4/4"
        );
    }

    #[test]
    fn nothing_heard_is_no_view() {
        assert!(redundancy_view(&RedundancyReport::default()).is_none());
        assert!(nav_view(&NavReport::default()).is_none());
    }

    #[test]
    fn nav_summary_names_mode_stale_sources_lane_and_aiding() {
        let nav = NavState {
            mode: NavMode::Coasting as u8,
            lane: 1,
            aiding: aiding::BARO_STALE | aiding::MAG | aiding::GRAVITY,
            integrity: Integrity::Degraded as u8,
            integrity_reasons: integrity_reason::AIDING_STALE,
            ..NavState::default()
        };
        let n = nav_of(&nav, 12);
        assert_eq!(
            nav_summary(&n),
            "coasting: baro stale, lane 1, aiding mag+gravity"
        );
        let v = nav_view(&n).expect("heard");
        assert_eq!(
            (v.mode.as_str(), v.lane, v.integrity.as_str()),
            ("coasting", 1, "degraded")
        );
        assert_eq!(v.integrity_reasons, ["aiding-stale"]);
        assert_eq!((v.aiding, v.stale), (vec!["mag", "gravity"], vec!["baro"]));
        let plain = nav_of(
            &NavState {
                mode: NavMode::Navigating as u8,
                ..NavState::default()
            },
            0,
        );
        assert_eq!(nav_summary(&plain), "navigating, lane 0");
        let unknown = nav_of(
            &NavState {
                integrity: 99,
                ..NavState::default()
            },
            0,
        );
        assert_eq!(nav_view(&unknown).expect("heard").integrity, "invalid");
    }
}
