//! From a recording's messages to the series the plots draw: the navigation solution of the lane
//! a consumer would follow, truth, the channel states, the fault and lane-switch events and the
//! per-hop latencies. Everything is put on one time axis: seconds of device time
//! (`Header::origin_device_time_us`, the time base of `FaultApplied` too) since the first sample.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use ipc_types::{
    ChannelState, FaultApplied, FaultOutcome, FusedImu, Header, HealthReport, NAV_STATES, NavMode,
    NavState, SensorType, SimControl, SimFault, Stage, Truth, names,
};
use rins_earth::{LocalOrigin, euler_deg};
use rins_recording::RecordedMessage;

/// One navigation solution of the merged stream.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavPoint {
    /// Time, s since the first sample.
    pub t_s: f64,
    /// `header.origin_seq`, the key that matches it to truth.
    pub seq: u64,
    /// The lane that computed it.
    pub lane: u8,
    /// Attitude quaternion body → NED, scalar first.
    pub quaternion: [f64; 4],
    /// Roll, pitch, yaw, degrees.
    pub euler_deg: [f64; 3],
    /// North, east, down from the local origin, m.
    pub ned_m: [f64; 3],
    /// The filter's covariance diagonal.
    pub covariance_diag: [f64; NAV_STATES],
}

/// One truth sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthPoint {
    /// Time, s since the first sample.
    pub t_s: f64,
    /// True attitude quaternion body → NED, scalar first.
    pub quaternion: [f64; 4],
    /// Roll, pitch, yaw, degrees.
    pub euler_deg: [f64; 3],
    /// North, east, down from the local origin, m.
    pub ned_m: [f64; 3],
}

/// A stretch of time over which a channel kept one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Run {
    /// Start, s.
    pub start_s: f64,
    /// End, s (the next sample's time, or the last sample's).
    pub end_s: f64,
    /// [`ChannelState`] as u8 (an unknown value is drawn as such).
    pub state: u8,
}

/// The state history of one redundant channel.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelRow {
    /// `gyro 0`, `accel 3`...
    pub name: String,
    /// Its states in time order.
    pub runs: Vec<Run>,
}

/// An event marked on the time axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Time, s.
    pub t_s: f64,
    /// What happened.
    pub label: String,
}

/// Latencies of one hop of the pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct Hop {
    /// From where to where.
    pub name: &'static str,
    /// Each sample's latency, µs.
    pub values_us: Vec<f64>,
}

/// The hops measured, as (name, from stamp, to stamp); `None` is the serial receive time.
pub const HOPS: [(&str, Option<Stage>, Stage); 4] = [
    ("serial rx → acquisition", None, Stage::Acquisition),
    (
        "acquisition → fusion",
        Some(Stage::Acquisition),
        Stage::Fusion,
    ),
    ("fusion → navigator", Some(Stage::Fusion), Stage::Navigator),
    ("serial rx → navigator", None, Stage::Navigator),
];

/// Everything the plots draw.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Extracted {
    /// The topics the recording holds.
    pub topics: BTreeSet<String>,
    /// The merged navigation stream, usable solutions only, in time order.
    pub nav: Vec<NavPoint>,
    /// Navigation samples left out because no lane had a usable solution (aligning, invalid).
    pub nav_unusable: usize,
    /// Truth in time order.
    pub truth: Vec<TruthPoint>,
    /// Index into [`Extracted::truth`] by `origin_seq`.
    pub truth_by_seq: HashMap<u64, usize>,
    /// One row per gyro, then per accelerometer channel.
    pub channels: Vec<ChannelRow>,
    /// Fault commands the simulator handled.
    pub faults: Vec<Marker>,
    /// Changes of the lane the consumers follow.
    pub lane_switches: Vec<Marker>,
    /// Per-hop latencies, in [`HOPS`] order.
    pub hops: Vec<Hop>,
}

/// One lane's solution for a frame, as kept until the lanes are merged.
#[derive(Clone, Copy)]
struct LaneSample {
    device_us: u64,
    usable: bool,
    nav: NavState,
}

/// Collects the messages, one at a time (a long recording is never held decoded whole).
#[derive(Default)]
pub struct Collector {
    topics: BTreeSet<String>,
    lanes: BTreeMap<u64, [Option<LaneSample>; 2]>,
    truth: Vec<(u64, Truth)>,
    fused: Vec<(u64, FusedImu)>,
    faults: Vec<FaultApplied>,
    health: Vec<HealthReport>,
    hops: [Vec<f64>; HOPS.len()],
    fused_hops: [Vec<f64>; HOPS.len()],
    /// CLOCK_MONOTONIC minus device time, ns, from the first frame that has both.
    monotonic_offset_ns: Option<i128>,
}

fn record_hops(header: &Header, into: &mut [Vec<f64>; HOPS.len()]) {
    for ((_, from, to), values) in HOPS.iter().zip(into.iter_mut()) {
        let start = from.map_or(header.origin_rx_ns, |s| header.stage_ns(s));
        let end = header.stage_ns(*to);
        if start != 0 && end != 0 && end >= start {
            values.push((end - start) as f64 / 1000.0);
        }
    }
}

impl Collector {
    /// Takes one message in; messages of topics the plots do not use only count as present.
    pub fn add(&mut self, message: &RecordedMessage) {
        let topic: &str = &message.topic;
        if !self.topics.contains(topic) {
            self.topics.insert(topic.to_string());
        }
        // A message that does not decode as its topic's type was already refused by the reader
        // for its channel; one that still fails is left out rather than misread.
        if let Some(lane) = names::NAV_LANES.iter().position(|t| *t == topic) {
            if let Ok(nav) = message.decode::<NavState>() {
                self.add_nav(lane, nav);
            }
        } else if topic == names::TRUTH {
            if let Ok(t) = message.decode::<Truth>() {
                self.truth.push((t.header.origin_device_time_us, t));
            }
        } else if topic == names::FUSED_IMU {
            if let Ok(f) = message.decode::<FusedImu>() {
                record_hops(&f.header, &mut self.fused_hops);
                self.fused.push((f.header.origin_device_time_us, f));
            }
        } else if topic == names::SIM_FAULT_APPLIED {
            if let Ok(f) = message.decode::<FaultApplied>() {
                self.faults.push(f);
            }
        } else if topic == names::HEALTH
            && let Ok(h) = message.decode::<HealthReport>()
        {
            self.health.push(h);
        }
    }

    fn add_nav(&mut self, lane: usize, nav: NavState) {
        record_hops(&nav.header, &mut self.hops);
        if self.monotonic_offset_ns.is_none() && nav.header.origin_rx_ns != 0 {
            self.monotonic_offset_ns = Some(
                i128::from(nav.header.origin_rx_ns)
                    - i128::from(nav.header.origin_device_time_us) * 1000,
            );
        }
        let usable = NavMode::from_u8(nav.mode).is_some_and(NavMode::is_usable);
        let entry = self.lanes.entry(nav.header.origin_seq).or_default();
        entry[lane] = Some(LaneSample {
            device_us: nav.header.origin_device_time_us,
            usable,
            nav,
        });
    }

    /// The series, once every message is in.
    pub fn finish(mut self) -> Extracted {
        let firsts = [
            self.lanes
                .values()
                .flat_map(|l| l.iter().flatten().map(|s| s.device_us))
                .min(),
            self.truth.iter().map(|(t, _)| *t).min(),
            self.fused.iter().map(|(t, _)| *t).min(),
        ];
        let t0_us = firsts.iter().flatten().min().copied().unwrap_or(0);
        let seconds = |device_us: u64| (device_us as f64 - t0_us as f64) / 1e6;

        // The merged stream: lane 0 while it has a usable solution, lane 1 otherwise (the
        // consumers' selector also waits for a restarted lane to settle; a plot need not).
        let mut chosen: Vec<LaneSample> = Vec::with_capacity(self.lanes.len());
        let mut nav_unusable = 0;
        for lanes in self.lanes.values() {
            match lanes.iter().flatten().find(|s| s.usable) {
                Some(s) => chosen.push(*s),
                None => nav_unusable += 1,
            }
        }
        chosen.sort_by_key(|s| s.device_us);
        let origin = chosen
            .first()
            .map(|s| (s.nav.latitude_rad, s.nav.longitude_rad, s.nav.altitude_m))
            .or_else(|| {
                self.truth
                    .iter()
                    .map(|(_, t)| (t.latitude_rad, t.longitude_rad, t.altitude_m))
                    .next()
            })
            .map(|(lat, lon, alt)| LocalOrigin::new(lat, lon, alt));
        let ned =
            |lat: f64, lon: f64, alt: f64| origin.map_or([f64::NAN; 3], |o| o.ned(lat, lon, alt));
        let nav: Vec<NavPoint> = chosen
            .iter()
            .map(|s| NavPoint {
                t_s: seconds(s.device_us),
                seq: s.nav.header.origin_seq,
                lane: s.nav.lane,
                quaternion: s.nav.quaternion,
                euler_deg: euler_deg(s.nav.quaternion),
                ned_m: ned(s.nav.latitude_rad, s.nav.longitude_rad, s.nav.altitude_m),
                covariance_diag: s.nav.covariance_diag,
            })
            .collect();

        self.truth.sort_by_key(|(t, _)| *t);
        let truth: Vec<TruthPoint> = self
            .truth
            .iter()
            .map(|(t, tr)| TruthPoint {
                t_s: seconds(*t),
                quaternion: tr.quaternion,
                euler_deg: euler_deg(tr.quaternion),
                ned_m: ned(tr.latitude_rad, tr.longitude_rad, tr.altitude_m),
            })
            .collect();
        let truth_by_seq = self
            .truth
            .iter()
            .enumerate()
            .map(|(i, (_, t))| (t.header.origin_seq, i))
            .collect();

        self.fused.sort_by_key(|(t, _)| *t);
        let channels = channel_rows(&self.fused, seconds);
        let faults = self
            .faults
            .iter()
            .map(|f| Marker {
                t_s: seconds(f.device_time_us),
                label: fault_label(f),
            })
            .collect();
        let lane_switches = match self.health_lane_switches(&seconds) {
            Some(switches) => switches,
            None => stream_lane_switches(&nav),
        };
        // The navigator's stamps cover every hop; a file without navigation still has fusion's.
        let hop_values = if self.hops.iter().any(|h| !h.is_empty()) {
            self.hops
        } else {
            self.fused_hops
        };
        let hops = HOPS
            .iter()
            .zip(hop_values)
            .map(|((name, _, _), values_us)| Hop { name, values_us })
            .collect();
        Extracted {
            topics: self.topics,
            nav,
            nav_unusable,
            truth,
            truth_by_seq,
            channels,
            faults,
            lane_switches,
            hops,
        }
    }

    /// Lane switches as the watchdog reported them (the lane the consumers follow), when the
    /// file has its reports and the monotonic clock can be put on the device time axis.
    fn health_lane_switches(&self, seconds: &impl Fn(u64) -> f64) -> Option<Vec<Marker>> {
        let offset = self.monotonic_offset_ns?;
        let mut heard = self.health.iter().filter(|h| h.nav.heard != 0).peekable();
        heard.peek()?;
        let mut switches = Vec::new();
        let mut previous: Option<u8> = None;
        for h in heard {
            if let Some(p) = previous
                && p != h.nav.lane
            {
                let device_us = (i128::from(h.now_ns) - offset) / 1000;
                let t = seconds(u64::try_from(device_us.max(0)).unwrap_or(u64::MAX));
                switches.push(Marker {
                    t_s: t,
                    label: format!("lane {p} → {}", h.nav.lane),
                });
            }
            previous = Some(h.nav.lane);
        }
        Some(switches)
    }
}

/// Where the lane of the merged stream changes.
fn stream_lane_switches(nav: &[NavPoint]) -> Vec<Marker> {
    nav.windows(2)
        .filter(|w| w[0].lane != w[1].lane)
        .map(|w| Marker {
            t_s: w[1].t_s,
            label: format!("lane {} → {}", w[0].lane, w[1].lane),
        })
        .collect()
}

/// `gyro 1 dead`, `accel 0 bias 0.05`, `device disconnect 2` (with the outcome when the fault was
/// not applied).
pub fn fault_label(f: &FaultApplied) -> String {
    let fault = SimFault::from_u8(f.fault).map_or("unknown fault", SimFault::name);
    let target = if f.sensor == SimControl::WHOLE_DEVICE {
        "device".to_string()
    } else {
        let sensor = SensorType::from_u8(f.sensor).map_or("sensor ?", SensorType::name);
        format!("{sensor} {}", f.channel)
    };
    let param = match SimFault::from_u8(f.fault) {
        Some(SimFault::Clear | SimFault::Dead | SimFault::Stuck | SimFault::Saturate) | None => {
            String::new()
        }
        Some(_) => format!(" {}", f.param),
    };
    let outcome = match FaultOutcome::from_u8(f.outcome) {
        Some(FaultOutcome::Applied) => String::new(),
        other => format!(" ({})", other.map_or("unknown outcome", FaultOutcome::name)),
    };
    format!("{target} {fault}{param}{outcome}")
}

/// One row per gyro channel then per accelerometer channel fitted (the most any sample had),
/// each the runs of equal state.
fn channel_rows(fused: &[(u64, FusedImu)], seconds: impl Fn(u64) -> f64) -> Vec<ChannelRow> {
    let n_gyro = fused.iter().map(|(_, f)| f.n_gyro).max().unwrap_or(0);
    let n_accel = fused.iter().map(|(_, f)| f.n_accel).max().unwrap_or(0);
    let mut rows = Vec::new();
    for (kind, count) in [("gyro", n_gyro), ("accel", n_accel)] {
        for channel in 0..usize::from(count) {
            let state_of = |f: &FusedImu| {
                let (states, fitted) = if kind == "gyro" {
                    (&f.gyro_state, f.n_gyro)
                } else {
                    (&f.accel_state, f.n_accel)
                };
                if channel < usize::from(fitted) {
                    states
                        .get(channel)
                        .copied()
                        .unwrap_or(ChannelState::Absent as u8)
                } else {
                    ChannelState::Absent as u8
                }
            };
            let mut runs: Vec<Run> = Vec::new();
            for (i, (t, f)) in fused.iter().enumerate() {
                let start = seconds(*t);
                let end = fused.get(i + 1).map_or(start, |(next, _)| seconds(*next));
                let state = state_of(f);
                match runs.last_mut() {
                    Some(run) if run.state == state => run.end_s = end,
                    _ => runs.push(Run {
                        start_s: start,
                        end_s: end,
                        state,
                    }),
                }
            }
            rows.push(ChannelRow {
                name: format!("{kind} {channel}"),
                runs,
            });
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fused(t_us: u64, g1: ChannelState) -> (u64, FusedImu) {
        let mut f = FusedImu {
            n_gyro: 2,
            n_accel: 1,
            ..FusedImu::default()
        };
        f.gyro_state[0] = ChannelState::Ok as u8;
        f.gyro_state[1] = g1 as u8;
        f.accel_state[0] = ChannelState::Ok as u8;
        (t_us, f)
    }

    #[test]
    fn channel_states_become_runs() {
        let samples = [
            fused(0, ChannelState::Ok),
            fused(1_000_000, ChannelState::Suspect),
            fused(2_000_000, ChannelState::Excluded),
            fused(3_000_000, ChannelState::Excluded),
        ];
        let rows = channel_rows(&samples, |t| t as f64 / 1e6);
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[1].name, "gyro 1");
        let states: Vec<(f64, f64, u8)> = rows[1]
            .runs
            .iter()
            .map(|r| (r.start_s, r.end_s, r.state))
            .collect();
        assert_eq!(states, vec![(0.0, 1.0, 0), (1.0, 2.0, 1), (2.0, 3.0, 2)]);
        assert_eq!(rows[2].name, "accel 0");
        assert_eq!(rows[2].runs.len(), 1);
    }

    #[test]
    fn fault_labels_name_channel_fault_and_outcome() {
        let f = FaultApplied {
            sensor: SensorType::Gyro as u8,
            channel: 1,
            fault: SimFault::BiasStep as u8,
            param: 0.05,
            ..FaultApplied::default()
        };
        assert_eq!(fault_label(&f), "gyro 1 bias 0.05");
        let f = FaultApplied {
            sensor: SimControl::WHOLE_DEVICE,
            fault: SimFault::Dead as u8,
            outcome: FaultOutcome::NoSuchChannel as u8,
            ..FaultApplied::default()
        };
        assert_eq!(fault_label(&f), "device dead (no-such-channel)");
    }

    fn message<T: rins_recording::Recordable>(topic: &str, payload: &T) -> RecordedMessage {
        RecordedMessage {
            topic: topic.into(),
            layout: T::layout(),
            log_time_ns: 0,
            publish_time_ns: 0,
            sequence: 0,
            payload: payload.as_bytes().to_vec(),
        }
    }

    fn nav(seq: u64, lane: u8, mode: NavMode) -> NavState {
        let mut header = Header {
            origin_seq: seq,
            origin_device_time_us: 1_000_000 + seq * 10_000,
            origin_rx_ns: 7_000_000_000 + seq * 10_000_000,
            ..Header::default()
        };
        header.stamp(Stage::Navigator, header.origin_rx_ns + 300_000);
        NavState {
            lane,
            mode: mode as u8,
            header,
            latitude_rad: 0.8,
            longitude_rad: 0.1,
            altitude_m: 400.0,
            ..NavState::default()
        }
    }

    #[test]
    fn lanes_merge_on_lane_0_while_usable_and_truth_matches_by_sequence() {
        let mut c = Collector::default();
        for seq in 0..10 {
            let mode0 = if seq < 5 {
                NavMode::Navigating
            } else {
                NavMode::Invalid
            };
            c.add(&message(names::NAV_LANES[0], &nav(seq, 0, mode0)));
            c.add(&message(
                names::NAV_LANES[1],
                &nav(seq, 1, NavMode::Navigating),
            ));
        }
        let truth = Truth {
            header: Header {
                origin_seq: 7,
                origin_device_time_us: 1_070_000,
                ..Header::default()
            },
            latitude_rad: 0.8,
            longitude_rad: 0.1,
            altitude_m: 390.0,
            ..Truth::default()
        };
        c.add(&message(names::TRUTH, &truth));
        let d = c.finish();
        assert_eq!(d.nav.len(), 10);
        assert_eq!(d.nav_unusable, 0);
        let lanes: Vec<u8> = d.nav.iter().map(|p| p.lane).collect();
        assert_eq!(lanes, [0, 0, 0, 0, 0, 1, 1, 1, 1, 1]);
        assert_eq!(d.lane_switches.len(), 1);
        assert_eq!(d.lane_switches[0].label, "lane 0 → 1");
        assert!((d.lane_switches[0].t_s - 0.05).abs() < 1e-9);
        assert_eq!(d.nav[0].t_s, 0.0);
        assert_eq!(d.nav[0].ned_m, [0.0, 0.0, 0.0]);
        let t = &d.truth[d.truth_by_seq[&7]];
        assert!((t.t_s - 0.07).abs() < 1e-9);
        assert!((t.ned_m[2] - 10.0).abs() < 1e-9, "{:?}", t.ned_m);
        // Every navigation sample of both lanes is a latency sample of its hops.
        assert_eq!(d.hops[3].values_us.len(), 20);
        assert!(d.hops[3].values_us.iter().all(|v| *v == 300.0));
        assert!(d.hops[0].values_us.is_empty());
    }

    #[test]
    fn lane_changes_of_the_stream_are_switches() {
        let p = |t_s: f64, lane: u8| NavPoint {
            t_s,
            seq: 0,
            lane,
            quaternion: [1.0, 0.0, 0.0, 0.0],
            euler_deg: [0.0; 3],
            ned_m: [0.0; 3],
            covariance_diag: [0.0; NAV_STATES],
        };
        let s = stream_lane_switches(&[p(0.0, 0), p(1.0, 1), p(2.0, 1), p(3.0, 0)]);
        assert_eq!(
            s,
            vec![
                Marker {
                    t_s: 1.0,
                    label: "lane 0 → 1".into()
                },
                Marker {
                    t_s: 3.0,
                    label: "lane 1 → 0".into()
                }
            ]
        );
    }
}
