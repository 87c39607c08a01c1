//! The navigator process: fused IMU drives the filter; the held aiding readings (altitude,
//! magnetometer, airspeed: see [`crate::aiding::readings`]) and GNSS fixes aid it.
//! A navigation state is published for every fused IMU sample, also while aligning, so consumers see
//! a contiguous sequence.

use std::time::Duration;

use anyhow::{Result, bail};
use ipc_types::{
    FusedImu, GnssFix, Health, Integrity, NavMode, NavState, PAYLOAD_VERSION, ServiceKind, Stage,
    integrity_reason, names,
};
use rins_runtime::ipc::{IpcError, TopicSubscriber};
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::stage_io::StageInput;
use rins_runtime::stage_loop::{PipelineStage, StageLoop, StageTopics, Step};

use crate::aiding::gnss::hold::GnssHold;
use crate::aiding::gnss::monitor::{RejectReason, Transition};
use crate::aiding::hold::HOLD_US;
use crate::aiding::readings::AidingQueue;
use crate::ekf::AidingSource;
use crate::held_inputs::HeldInputs;
use crate::lanes::{SelectorConfig, StandbyPacer};
use crate::navigator::{Navigator, fused_sample_usable};
use crate::takeover::Handover;

/// The longest sleep waiting for a fused IMU sample: how often the stop flag and the heartbeat are
/// served when none comes.
const WAIT: Duration = Duration::from_millis(100);

/// Feeds one fused IMU sample to the navigator and returns the state to publish (header copied,
/// navigator stamp left to the caller). Samples without a valid solution are not integrated; they
/// are published with the integrity that says so.
pub fn step(nav: &mut Navigator, imu: &FusedImu, last: &NavState) -> NavState {
    let mut out = NavState {
        header: imu.header,
        ..*last
    };
    let t_us = imu.header.origin_device_time_us;
    let solution = if fused_sample_usable(imu.flags) {
        nav.on_fusion_status(imu.flags, imu.rate_var);
        nav.on_imu(t_us, imu.rate_rps, imu.specific_force_mps2)
    } else {
        nav.on_unusable_imu(t_us)
    };
    match solution {
        Some(solution) => solution.write_nav_state(&mut out),
        None => {
            out.mode = nav.mode() as u8;
            let (integrity, reasons) = nav.integrity();
            out.integrity = integrity as u8;
            out.integrity_reasons = reasons;
        }
    }
    // The first sample of a solution marks its start; aligning has none, nor has a mode that
    // is not one of ours.
    out.solution_start_seq = match NavMode::from_u8(out.mode) {
        Some(NavMode::Aligning) | None => 0,
        _ if last.solution_start_seq == 0 => imu.header.origin_seq,
        _ => last.solution_start_seq,
    };
    out
}

/// When the handover has a peer solution to take over: takes it, integrates the fused IMU samples
/// kept since, and returns `Some(state of the newest kept sample)` — or `Some(None)` when the peer
/// is ahead of every kept sample (`last` then stands at the peer's sequence number, so samples up
/// to it are skipped). `None` while no takeover is possible.
fn take_over_if_ready(
    nav: &mut Navigator,
    handover: &mut Handover,
    last: &mut NavState,
) -> Option<Option<NavState>> {
    let peer = handover.ready()?;
    nav.take_over(&peer).ok()?;
    let seq = peer.header.origin_seq;
    tracing::info!(
        peer_seq = seq,
        peer_lane = peer.lane,
        "took over the other lane's solution"
    );
    *last = NavState {
        header: peer.header,
        lane: last.lane,
        solution_start_seq: 0,
        ..peer
    };
    let mut newest = None;
    for imu in handover.replay(seq) {
        let state = step(nav, imu, last);
        *last = state;
        newest = Some(state);
    }
    handover.clear();
    Some(newest)
}

/// A change of the integrity level, with its reasons (rare: logged off the per-sample path).
fn log_integrity(state: &NavState) {
    // An integrity that cannot be read is not to be trusted.
    let integrity = Integrity::from_u8(state.integrity).unwrap_or(Integrity::Invalid);
    let reasons = integrity_reason::describe(state.integrity_reasons);
    let t = state.header.origin_device_time_us;
    match integrity {
        Integrity::Ok => tracing::info!(device_time_us = t, "navigation integrity ok"),
        Integrity::Degraded => {
            tracing::warn!(device_time_us = t, reasons, "navigation integrity degraded")
        }
        Integrity::Invalid => {
            tracing::error!(device_time_us = t, reasons, "navigation solution invalid")
        }
    }
}

/// A reset of the filter from an aiding source.
fn log_resets(before: [u64; AidingSource::COUNT], now: [u64; AidingSource::COUNT], t: u64) {
    for source in AidingSource::ALL {
        if now[source as usize] != before[source as usize] {
            tracing::warn!(
                source = source.name(),
                device_time_us = t,
                "every update persistently rejected: filter reset from this source"
            );
        }
    }
}

/// A change of the GNSS receiver's standing (rare: logged off the per-sample path).
fn log_gnss(transition: Option<Transition>) {
    match transition {
        Some(Transition::Rejected { t_us, reason }) => {
            let why = match reason {
                RejectReason::Jump => "its fixes jumped away from the inertial solution",
                RejectReason::Drift => "its fixes drift away from the inertial solution",
            };
            tracing::warn!(
                device_time_us = t_us,
                "GNSS receiver rejected: {why}; coasting on the inertial solution"
            );
        }
        Some(Transition::Readmitted { t_us }) => tracing::info!(
            device_time_us = t_us,
            "GNSS receiver re-admitted: its fixes agree with the inertial solution again"
        ),
        None => {}
    }
}

/// The navigator as a stage of the pipeline: one navigation state per fused IMU sample, the
/// aiding topics read before each sample, the peer lane listened to while aligning.
struct NavigatorStage {
    nav: Navigator,
    /// The topics of the held aiding readings.
    held_in: HeldInputs,
    /// Receiver fixes, when GNSS aiding is on.
    gnss_in: Option<StageInput<GnssFix>>,
    /// Fixes waiting for the IMU stream to place them.
    gnss_hold: GnssHold,
    /// The receiver's last change of standing, already logged.
    gnss_transition: Option<Transition>,
    /// The other lane's output, with two lanes.
    peer_in: Option<TopicSubscriber<NavState>>,
    /// Whether this batch listens to the peer (the lane aligns and has one).
    listening: bool,
    /// When the standby lane reads in batches (the standby of two lanes only).
    pacer: Option<StandbyPacer>,
    /// Whether it reads in batches, as last logged.
    batching: bool,
    handover: Handover,
    resets: [u64; AidingSource::COUNT],
    /// The last state published.
    last: NavState,
    /// Aiding readings waiting for the IMU stream to reach their time.
    aiding: AidingQueue,
    /// Late readings already logged.
    late_logged: u64,
}

impl PipelineStage for NavigatorStage {
    type Input = FusedImu;
    type Output = NavState;

    fn before_sample(&mut self, counters: &mut Health) -> Result<(), IpcError> {
        // Aiding is held, not applied: it meets the filter where the IMU stream passes its time.
        // Taken before every sample: a reading published before the sample's frame is in hand.
        self.held_in
            .drain(counters, &mut self.aiding, &mut self.nav)?;
        if let Some(gnss_in) = &self.gnss_in {
            let hold = &mut self.gnss_hold;
            gnss_in.drain(counters, |fix| hold.push(fix))?;
        }
        Ok(())
    }

    fn before_input(&mut self, _counters: &mut Health) -> Result<(), IpcError> {
        self.listening = self.peer_in.is_some()
            && self.nav.mode() == NavMode::Aligning
            && !self.nav.start_pending();
        // The peer is read while this lane aligns (a solution to take over) and, on the standby,
        // always (whether the primary serves).
        if let Some(peer_in) = self
            .peer_in
            .as_ref()
            .filter(|_| self.listening || self.pacer.is_some())
        {
            while let Some(peer) = peer_in.receive()? {
                if let Some(pacer) = &mut self.pacer {
                    pacer.peer(&peer);
                }
                if self.listening {
                    self.handover.push_peer(peer);
                }
            }
        }
        Ok(())
    }

    fn batch_period(&self) -> Option<Duration> {
        self.pacer.as_ref().and_then(StandbyPacer::batch_period)
    }

    fn step(&mut self, imu: &FusedImu) -> Step<NavState> {
        // A restarted fusion replays the raw IMU history it missed, starting before its last
        // output: samples already integrated are skipped, not integrated twice.
        if self.last.header.origin_seq != 0 && imu.header.origin_seq <= self.last.header.origin_seq
        {
            return Step::Skip;
        }
        if let Some(pacer) = &mut self.pacer {
            pacer.input(imu.header.origin_seq);
        }
        self.aiding
            .release_to(imu.header.origin_device_time_us, &mut self.nav);
        let nav = &mut self.nav;
        self.gnss_hold.release(
            imu.header.origin_device_time_us,
            imu.header.origin_rx_ns,
            |fix, t_us| {
                let _ = nav.on_gnss(fix, t_us);
            },
        );
        let taken_over = if self.listening && self.nav.mode() == NavMode::Aligning {
            self.handover.push_imu(*imu);
            take_over_if_ready(&mut self.nav, &mut self.handover, &mut self.last)
        } else {
            None
        };
        let mut state = match taken_over {
            Some(Some(state)) => state,
            // The peer's solution is ahead of this sample: nothing to publish for it.
            Some(None) => return Step::Skip,
            None => step(&mut self.nav, imu, &self.last),
        };
        state.version = PAYLOAD_VERSION;
        Step::Publish(state)
    }

    fn published(&mut self, state: &NavState) {
        if let Some(pacer) = &mut self.pacer {
            pacer.own(state);
        }
        let aligned = NavMode::from_u8(state.mode).is_some_and(|m| m != NavMode::Aligning);
        if aligned && state.integrity != self.last.integrity {
            log_integrity(state);
        }
        if self.nav.resets() != self.resets {
            log_resets(
                self.resets,
                self.nav.resets(),
                state.header.origin_device_time_us,
            );
            self.resets = self.nav.resets();
        }
        let transition = self.nav.gnss_monitor().last_transition();
        if transition != self.gnss_transition {
            log_gnss(transition);
            self.gnss_transition = transition;
        }
        self.last = *state;
    }

    fn after_input(&mut self, _received: u64, counters: &mut Health) {
        if let Some(pacer) = self
            .pacer
            .as_ref()
            .filter(|p| p.batching() != self.batching)
        {
            // Rare: the primary failed or came back.
            self.batching = pacer.batching();
            match self.batching {
                true => tracing::info!("standby: the primary serves; reading input in batches"),
                false => tracing::info!("standby: serving sample by sample"),
            }
        }
        counters.lost = self.nav.rejected_imu_samples();
        counters.late = self.aiding.late();
        if self.aiding.late() != self.late_logged {
            // Rare by design (the hold is long): each one means the lanes may differ slightly. While
            // the lane aligns no filter runs for them to differ in, and a reading late at the start
            // (the altimeter's first output on a loaded machine, behind a primary that no longer
            // shares its CPU with the standby) is no news: counted, logged at debug.
            if self.nav.mode() == NavMode::Aligning {
                tracing::debug!(
                    late = self.aiding.late(),
                    hold_us = HOLD_US,
                    "aiding readings arrived after their place in the IMU stream while aligning"
                );
            } else {
                tracing::warn!(
                    late = self.aiding.late(),
                    hold_us = HOLD_US,
                    "aiding readings arrived after their place in the IMU stream"
                );
            }
            self.late_logged = self.aiding.late();
        }
    }
}

/// Navigator lane `lane` of `lanes` (lane 0 is the primary, lane 1 the hot standby), with the
/// navigator built from the configuration; each lane publishes on its own topic,
/// [`names::NAV_LANES`].
pub struct NavigatorService {
    /// The navigator built from the configuration.
    pub navigator: Navigator,
    /// This process's lane.
    pub lane: u8,
    /// How many lanes the deployment runs (1 or 2).
    pub lanes: u8,
    /// The block's IMU rate, Hz: the standby's batches are sized by it.
    pub imu_rate_hz: f64,
}

impl Service for NavigatorService {
    fn run(self, ctx: ServiceContext) -> Result<()> {
        let (lane, lanes) = (self.lane, self.lanes);
        // The two lanes run the same code and log the same lines: each line this lane logs
        // carries `lane=N`. Entered once for the whole run, so the per-sample path pays nothing;
        // at the error level so that it is enabled whatever `RINS_LOG` lets through.
        let _lane_span = tracing::error_span!("navigator", lane).entered();
        let kind = match (lane, lanes) {
            (0, 1 | 2) => ServiceKind::Navigator,
            (1, 2) => ServiceKind::NavigatorStandby,
            _ => bail!("navigator lane {lane} of {lanes}: lanes must be 1 or 2 and lane below it"),
        };
        let node = ctx.create_node(kind)?;
        let topics = StageTopics {
            kind,
            stage: Stage::Navigator,
            input: names::FUSED_IMU,
            output: names::NAV_LANES[usize::from(lane)],
            wait: WAIT,
        };
        let stage_loop =
            StageLoop::new(&node, &topics, &ctx.shutdown)?.with_wait_strategy(ctx.wait);
        // With two lanes, a lane that aligns listens to its peer: restarted in flight, it takes the
        // peer's solution over instead of waiting for a rest it will not get (see `takeover`).
        let peer_in = match lanes {
            // Read between samples, never waited on: no listener for the peer to notify.
            2 => Some(TopicSubscriber::<NavState>::polled(
                &node,
                names::NAV_LANES[usize::from(1 - lane)],
            )?),
            _ => None,
        };
        let gnss = self.navigator.config().gnss;
        let gnss_in = match gnss.enabled {
            true => Some(StageInput::new(&node, names::GNSS)?),
            false => None,
        };
        let held_in = HeldInputs::new(&node, self.navigator.config())?;
        let mut stage = NavigatorStage {
            gnss_in,
            gnss_hold: GnssHold::new(gnss.delay_s),
            gnss_transition: None,
            resets: self.navigator.resets(),
            nav: self.navigator,
            held_in,
            peer_in,
            listening: false,
            pacer: (kind == ServiceKind::NavigatorStandby)
                .then(|| StandbyPacer::new(self.imu_rate_hz, SelectorConfig::default().settle)),
            batching: false,
            handover: Handover::default(),
            last: NavState {
                lane,
                ..NavState::default()
            },
            aiding: AidingQueue::default(),
            late_logged: 0,
        };
        stage_loop.run(&mut stage)?;
        Ok(())
    }
}
