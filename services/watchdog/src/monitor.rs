//! Watches every topic: per-topic rates, sequence gaps of the navigation output, device counters from
//! the heartbeats, and — when a simulator publishes truth — the navigation error.

use anyhow::Result;
use ipc_types::{
    Altitude, FaultApplied, FusedImu, GnssLinkReport, Health, Integrity, LinkReport, NavMode,
    NavReport, NavState, RawBaro, RawImu, RawMag, RedundancyReport, ServiceKind, Truth, names,
};
use rins_navigator::lanes::NavSubscriber;
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{IpcNode, TopicSubscriber};

use crate::accuracy::{Accuracy, ScoredSample};
use crate::device_counters::DeviceCounters;
use crate::fault_tracking::FaultTracker;
use crate::horizontal::Position;
use crate::link::{LinkRate, report_of};
use crate::redundancy_view::{nav_of, redundancy_of};
use crate::seq_gaps::SeqGaps;

/// Truth is kept this many IMU frames back, to meet the navigation output that comes later.
const TRUTH_RING: usize = 8192;

/// Topics counted for the status line, in display order.
pub const COUNTED: [&str; 6] = ["imu", "baro", "mag", "fused", "alt", "nav"];

/// The last heartbeat of one process kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeartbeatSeen {
    /// The process's pid.
    pub pid: u32,
    /// The sender's CLOCK_MONOTONIC time, ns.
    pub at_ns: u64,
    /// The sender said its input is quiet.
    pub input_stale: bool,
}

/// Every topic the watchdog reads, and what it counted of them.
pub struct Monitor {
    imu: TopicSubscriber<RawImu>,
    baro: TopicSubscriber<RawBaro>,
    mag: TopicSubscriber<RawMag>,
    fused: TopicSubscriber<FusedImu>,
    alt: TopicSubscriber<Altitude>,
    /// Both navigator lanes, merged into the stream consumers see.
    nav: NavSubscriber,
    truth: TopicSubscriber<Truth>,
    health: TopicSubscriber<Health>,
    fault_events: TopicSubscriber<FaultApplied>,
    gnss_link: TopicSubscriber<GnssLinkReport>,
    /// The gnss service's latest line report (not heard before the first).
    pub last_gnss_link: GnssLinkReport,
    /// Samples seen per topic of [`COUNTED`], since start.
    pub totals: [u64; COUNTED.len()],
    /// Navigation samples missing from the merged stream.
    pub nav_gaps: SeqGaps,
    /// The newest navigation sample.
    pub last_nav: Option<NavState>,
    /// When the newest navigation sample was taken in (CLOCK_MONOTONIC ns).
    pub last_nav_at_ns: u64,
    /// The newest fused sample: the channel states the operator views show.
    pub last_fused: Option<FusedImu>,
    /// When the newest fused sample was taken in (CLOCK_MONOTONIC ns).
    pub last_fused_at_ns: u64,
    /// Navigation error against the simulator's truth.
    pub accuracy: Accuracy,
    /// Navigation samples after alignment per integrity level (ok, degraded, invalid).
    pub integrity_samples: [u64; 3],
    /// Injected faults, their detection and isolation, and false alarms.
    pub faults: FaultTracker,
    truth_ring: Box<[Truth]>,
    /// Latest acquisition counters per process id (a restarted acquisition starts from zero).
    acquisition: Vec<(u32, DeviceCounters)>,
    /// Last heartbeat per [`ServiceKind`].
    pub heartbeats: [Option<HeartbeatSeen>; ServiceKind::ALL.len()],
    /// The serial line over acquisition's last two heartbeats.
    pub link: LinkRate,
}

impl Monitor {
    /// Subscribes to every topic the watchdog counts, on `node`. Polled: the loop drains them at
    /// its turns and never waits on them, so no publisher spends a notification on the watchdog.
    pub fn new(node: &IpcNode) -> Result<Self> {
        Ok(Self {
            imu: TopicSubscriber::polled(node, names::RAW_IMU)?,
            baro: TopicSubscriber::polled(node, names::RAW_BARO)?,
            mag: TopicSubscriber::polled(node, names::RAW_MAG)?,
            fused: TopicSubscriber::polled(node, names::FUSED_IMU)?,
            alt: TopicSubscriber::polled(node, names::ALTITUDE)?,
            nav: NavSubscriber::polled(node)?,
            truth: TopicSubscriber::polled(node, names::TRUTH)?,
            health: TopicSubscriber::polled(node, names::HEARTBEAT)?,
            fault_events: TopicSubscriber::polled(node, names::SIM_FAULT_APPLIED)?,
            gnss_link: TopicSubscriber::polled(node, names::GNSS_LINK)?,
            last_gnss_link: GnssLinkReport::default(),
            totals: [0; COUNTED.len()],
            nav_gaps: SeqGaps::default(),
            last_nav: None,
            last_nav_at_ns: 0,
            last_fused: None,
            last_fused_at_ns: 0,
            accuracy: Accuracy::default(),
            integrity_samples: [0; 3],
            faults: FaultTracker::new(),
            // version 0 marks an empty slot.
            truth_ring: vec![
                Truth {
                    version: 0,
                    ..Truth::default()
                };
                TRUTH_RING
            ]
            .into_boxed_slice(),
            acquisition: Vec::new(),
            heartbeats: [None; ServiceKind::ALL.len()],
            link: LinkRate::default(),
        })
    }

    /// Samples seen so far on the [`COUNTED`] topic `name`.
    fn topic_total(&self, name: &str) -> Option<u64> {
        COUNTED
            .iter()
            .position(|c| *c == name)
            .map(|i| self.totals[i])
    }

    /// Samples seen so far on the output topic of `kind` (each navigator lane on its own topic);
    /// `None` for a process without an output the monitor counts.
    pub fn output_count(&self, kind: ServiceKind) -> Option<u64> {
        let topic = |name: &str| self.topic_total(name);
        match kind {
            ServiceKind::Acquisition => topic("imu"),
            ServiceKind::Fusion => topic("fused"),
            ServiceKind::Altimeter => topic("alt"),
            ServiceKind::Navigator => Some(self.nav.lane_totals()[0]),
            ServiceKind::NavigatorStandby => Some(self.nav.lane_totals()[1]),
            ServiceKind::Simulator
            | ServiceKind::Watchdog
            | ServiceKind::Mavlink
            | ServiceKind::Gnss
            | ServiceKind::Bridge => None,
        }
    }

    /// Samples seen so far on the input topic of `kind`, for the stages whose input the monitor
    /// counts; `None` for the others (acquisition reads the serial line).
    pub fn input_count(&self, kind: ServiceKind) -> Option<u64> {
        let topic = |name: &str| self.topic_total(name);
        match kind {
            ServiceKind::Fusion => topic("imu"),
            ServiceKind::Altimeter => topic("baro"),
            ServiceKind::Navigator | ServiceKind::NavigatorStandby => topic("fused"),
            ServiceKind::Acquisition
            | ServiceKind::Simulator
            | ServiceKind::Watchdog
            | ServiceKind::Mavlink
            | ServiceKind::Gnss
            | ServiceKind::Bridge => None,
        }
    }

    /// The navigation stream's reader: lane totals and switches.
    pub fn nav_lanes(&self) -> &NavSubscriber {
        &self.nav
    }

    /// Samples of another payload version the readers dropped since start, every topic together.
    pub fn other_version(&self) -> u64 {
        self.imu.rejected()
            + self.baro.rejected()
            + self.mag.rejected()
            + self.fused.rejected()
            + self.alt.rejected()
            + self.nav.rejected()
            + self.truth.rejected()
            + self.health.rejected()
            + self.fault_events.rejected()
            + self.gnss_link.rejected()
    }

    /// Takes everything queued on every topic.
    pub fn drain(&mut self) -> Result<()> {
        self.totals[0] += drain_count(&self.imu)?;
        self.totals[1] += drain_count(&self.baro)?;
        self.totals[2] += drain_count(&self.mag)?;
        // Fault events before fused outputs: the simulator announces a fault before the frame
        // that carries it, so the fault is known when fusion's reaction arrives.
        while let Some(e) = self.fault_events.receive()? {
            self.faults.on_fault_applied(&e);
        }
        while let Some(f) = self.fused.receive()? {
            self.totals[3] += 1;
            self.faults.on_fused(&f);
            self.last_fused = Some(f);
            self.last_fused_at_ns = monotonic_ns();
        }
        self.totals[4] += drain_count(&self.alt)?;
        // Truth first, so a navigation sample finds the truth of its own frame.
        while let Some(t) = self.truth.receive()? {
            self.truth_ring[(t.header.origin_seq as usize) % TRUTH_RING] = t;
        }
        while let Some(nav) = self.nav.receive()? {
            self.totals[5] += 1;
            self.on_nav(nav);
            self.last_nav_at_ns = monotonic_ns();
        }
        while let Some(h) = self.health.receive()? {
            self.on_health(&h);
        }
        while let Some(g) = self.gnss_link.receive()? {
            self.last_gnss_link = g;
        }
        Ok(())
    }

    fn on_nav(&mut self, nav: NavState) {
        let seq = nav.header.origin_seq;
        self.nav_gaps.observe(seq);
        // Scored once aligned; a mode that cannot be read is no solution to score, and an
        // integrity that cannot be read counts as invalid.
        if NavMode::from_u8(nav.mode).is_some_and(|m| m != NavMode::Aligning) {
            let integrity = Integrity::from_u8(nav.integrity).unwrap_or(Integrity::Invalid);
            self.integrity_samples[integrity as usize] += 1;
            let truth = &self.truth_ring[(seq as usize) % TRUTH_RING];
            let known = truth.header.origin_seq == seq && truth.version != 0;
            let err_ne =
                known.then(|| {
                    let at = |lat_rad, lon_rad, height_m| Position {
                        lat_rad,
                        lon_rad,
                        height_m,
                    };
                    at(truth.latitude_rad, truth.longitude_rad, truth.altitude_m)
                        .north_east_to(&at(nav.latitude_rad, nav.longitude_rad, nav.altitude_m))
                });
            let sigma = nav.covariance_diag[6]
                .max(nav.covariance_diag[7])
                .max(0.0)
                .sqrt();
            self.faults.on_nav(
                nav.header.origin_device_time_us as f64 / 1e6,
                nav.aiding,
                err_ne,
                sigma,
            );
            if known {
                self.accuracy.push(&ScoredSample {
                    truth_q: truth.quaternion,
                    nav_q: nav.quaternion,
                    truth: Position {
                        lat_rad: truth.latitude_rad,
                        lon_rad: truth.longitude_rad,
                        height_m: truth.altitude_m,
                    },
                    nav: Position {
                        lat_rad: nav.latitude_rad,
                        lon_rad: nav.longitude_rad,
                        height_m: nav.altitude_m,
                    },
                    integrity_ok: integrity == Integrity::Ok,
                    position_known: nav.integrity_reasons
                        & ipc_types::integrity_reason::POSITION_UNKNOWN
                        == 0,
                });
            }
        }
        self.last_nav = Some(nav);
    }

    fn on_health(&mut self, h: &Health) {
        let Some(kind) = ServiceKind::from_u8(h.service) else {
            return;
        };
        self.heartbeats[kind as usize] = Some(HeartbeatSeen {
            pid: h.pid,
            at_ns: h.now_ns,
            input_stale: h.input_stale != 0,
        });
        if kind != ServiceKind::Acquisition {
            return;
        }
        let counters = DeviceCounters::from_heartbeat(h);
        self.link.observe(h.pid, h.now_ns, &counters);
        match self.acquisition.iter_mut().find(|(pid, _)| *pid == h.pid) {
            Some(entry) => entry.1 = counters,
            None => self.acquisition.push((h.pid, counters)),
        }
    }

    /// The report's redundancy part from the newest fused sample, as of `now_ns` (not heard
    /// before the first).
    pub fn redundancy_report(&self, now_ns: u64) -> RedundancyReport {
        self.last_fused.map_or_else(RedundancyReport::default, |f| {
            redundancy_of(&f, age_ms(now_ns, self.last_fused_at_ns))
        })
    }

    /// The report's navigation part from the newest navigation sample, as of `now_ns`.
    pub fn nav_report(&self, now_ns: u64) -> NavReport {
        self.last_nav.map_or_else(NavReport::default, |n| {
            nav_of(&n, age_ms(now_ns, self.last_nav_at_ns))
        })
    }

    /// Acquisition counters summed over every acquisition process seen.
    pub fn device_counters(&self) -> DeviceCounters {
        self.acquisition
            .iter()
            .fold(DeviceCounters::default(), |acc, (_, c)| acc.plus(c))
    }
}

/// The health report's `link`: acquisition's counters (summed over its restarts), or nothing
/// heard while no heartbeat of acquisition has arrived.
pub fn link_report(monitor: &Monitor) -> LinkReport {
    let heard = monitor.heartbeats[ServiceKind::Acquisition as usize].is_some();
    report_of(&monitor.device_counters(), heard)
}

/// Milliseconds from `then_ns` to `now_ns`, saturating.
fn age_ms(now_ns: u64, then_ns: u64) -> u32 {
    u32::try_from(now_ns.saturating_sub(then_ns) / 1_000_000).unwrap_or(u32::MAX)
}

fn drain_count<
    T: rins_runtime::payload::Versioned + std::fmt::Debug + Copy + iceoryx2::prelude::ZeroCopySend,
>(
    sub: &TopicSubscriber<T>,
) -> Result<u64> {
    let mut n = 0;
    while sub.receive()?.is_some() {
        n += 1;
    }
    Ok(n)
}
