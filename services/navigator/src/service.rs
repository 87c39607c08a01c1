//! The navigator process: fused IMU drives the filter; altitude and magnetometer aid it.
//! A navigation state is published for every fused IMU sample, also while aligning, so consumers see
//! a contiguous sequence.

use std::time::Duration;

use anyhow::{Result, anyhow, bail};
use ipc_types::{
    Altitude, FusedImu, Health, Integrity, NavMode, NavState, PAYLOAD_VERSION, RawMag, ServiceKind,
    Stage, integrity_reason, names,
};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::heartbeat::Heartbeat;
use rins_runtime::ipc::{IpcSettings, TopicPublisher, TopicSubscriber, create_node};
use rins_runtime::shutdown::Shutdown;

use crate::config::NavigatorConfig;
use crate::ekf::AidingSource;
use crate::navigator::{Navigator, fused_sample_usable};
use crate::takeover::Handover;

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

/// Runs navigator lane `lane` of `lanes` (lane 0 is the primary, lane 1 the hot standby); each
/// lane publishes on its own topic, [`names::NAV_LANES`].
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

pub fn run(
    config: &NavigatorConfig,
    settings: &IpcSettings,
    shutdown: &Shutdown,
    lane: u8,
    lanes: u8,
) -> Result<()> {
    let kind = match (lane, lanes) {
        (0, 1 | 2) => ServiceKind::Navigator,
        (1, 2) => ServiceKind::NavigatorStandby,
        _ => bail!("navigator lane {lane} of {lanes}: lanes must be 1 or 2 and lane below it"),
    };
    let mut nav = Navigator::new(config.clone()).map_err(|e| anyhow!("{e}"))?;
    let node = create_node(kind.name(), settings)?;
    let imu_in = TopicSubscriber::<FusedImu>::new(&node, names::FUSED_IMU)?;
    let alt_in = TopicSubscriber::<Altitude>::new(&node, names::ALTITUDE)?;
    let mag_in = TopicSubscriber::<RawMag>::new(&node, names::RAW_MAG)?;
    let output = TopicPublisher::<NavState>::new(&node, names::NAV_LANES[usize::from(lane)])?;
    let mut heartbeat = Heartbeat::new(&node, kind)?;
    let mut counters = Health::default();
    let mut last = NavState {
        lane,
        ..NavState::default()
    };
    // With two lanes, a lane that aligns listens to its peer: restarted in flight, it takes the
    // peer's solution over instead of waiting for a rest it will not get (see `takeover`).
    let peer_in = match lanes {
        2 => Some(TopicSubscriber::<NavState>::new(
            &node,
            names::NAV_LANES[usize::from(1 - lane)],
        )?),
        _ => None,
    };
    let mut handover = Handover::default();
    let mut resets = nav.resets();

    while !shutdown.requested() {
        imu_in.wait(WAIT)?;
        // Aiding first: it is older than (or as old as) the IMU sample that woke us.
        while let Some(alt) = alt_in.receive()? {
            if alt.version == PAYLOAD_VERSION {
                let _ = nav.on_baro(
                    alt.header.origin_device_time_us,
                    alt.height_m,
                    alt.height_var,
                    alt.valid != 0,
                );
            } else {
                counters.rejected += 1;
            }
        }
        while let Some(mag) = mag_in.receive()? {
            if mag.version == PAYLOAD_VERSION {
                let _ = nav.on_mag(
                    mag.header.origin_device_time_us,
                    mag.field_ut.map(f64::from),
                );
            } else {
                counters.rejected += 1;
            }
        }
        let listening = peer_in.as_ref().filter(|_| nav.mode() == NavMode::Aligning);
        if let Some(peer_in) = listening {
            while let Some(peer) = peer_in.receive()? {
                handover.push_peer(peer);
            }
        }
        while let Some(imu) = imu_in.receive()? {
            counters.received += 1;
            if imu.version != PAYLOAD_VERSION {
                counters.rejected += 1;
                continue;
            }
            // A restarted fusion replays the raw IMU history it missed, starting before its last
            // output: samples already integrated are skipped, not integrated twice.
            if last.header.origin_seq != 0 && imu.header.origin_seq <= last.header.origin_seq {
                continue;
            }
            let taken_over = match listening {
                Some(_) if nav.mode() == NavMode::Aligning => {
                    handover.push_imu(imu);
                    take_over_if_ready(&mut nav, &mut handover, &mut last)
                }
                _ => None,
            };
            let mut state = match taken_over {
                Some(Some(state)) => state,
                // The peer's solution is ahead of this sample: nothing to publish for it.
                Some(None) => continue,
                None => step(&mut nav, &imu, &last),
            };
            state.version = PAYLOAD_VERSION;
            state.header.stamp(Stage::Navigator, monotonic_ns());
            output.publish(state)?;
            let aligned = NavMode::from_u8(state.mode).is_some_and(|m| m != NavMode::Aligning);
            if aligned && state.integrity != last.integrity {
                log_integrity(&state);
            }
            if nav.resets() != resets {
                log_resets(resets, nav.resets(), state.header.origin_device_time_us);
                resets = nav.resets();
            }
            last = state;
            counters.published += 1;
        }
        counters.lost = nav.rejected_imu_samples();
        heartbeat.tick(&counters)?;
    }
    Ok(())
}
