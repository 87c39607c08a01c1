//! The navigator process: fused IMU drives the filter; altitude and magnetometer aid it.
//! A navigation state is published for every fused IMU sample, also while aligning, so consumers see
//! a contiguous sequence.

use std::time::Duration;

use anyhow::{Result, anyhow};
use ipc_types::{
    Altitude, FusedImu, Health, NavState, PAYLOAD_VERSION, RawMag, ServiceKind, Stage, names,
};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::heartbeat::Heartbeat;
use rins_runtime::ipc::{IpcSettings, TopicPublisher, TopicSubscriber, create_node};
use rins_runtime::shutdown::Shutdown;

use crate::config::NavigatorConfig;
use crate::navigator::{Navigator, fused_sample_usable};

const WAIT: Duration = Duration::from_millis(100);

/// Feeds one fused IMU sample to the navigator and returns the state to publish (header copied,
/// navigator stamp left to the caller). Samples without a valid solution are not integrated.
pub fn step(nav: &mut Navigator, imu: &FusedImu, last: &NavState) -> NavState {
    let mut out = NavState {
        header: imu.header,
        ..*last
    };
    if fused_sample_usable(imu.flags)
        && let Some(solution) = nav.on_imu(
            imu.header.origin_device_time_us,
            imu.rate_rps,
            imu.specific_force_mps2,
        )
    {
        solution.write_nav_state(&mut out);
    } else {
        out.mode = nav.mode() as u8;
    }
    out
}

pub fn run(config: &NavigatorConfig, settings: &IpcSettings, shutdown: &Shutdown) -> Result<()> {
    let mut nav = Navigator::new(config.clone()).map_err(|e| anyhow!("{e}"))?;
    let node = create_node("navigator", settings)?;
    let imu_in = TopicSubscriber::<FusedImu>::new(&node, names::FUSED_IMU)?;
    let alt_in = TopicSubscriber::<Altitude>::new(&node, names::ALTITUDE)?;
    let mag_in = TopicSubscriber::<RawMag>::new(&node, names::RAW_MAG)?;
    let output = TopicPublisher::<NavState>::new(&node, names::NAV_STATE)?;
    let mut heartbeat = Heartbeat::new(&node, ServiceKind::Navigator)?;
    let mut counters = Health::default();
    let mut last = NavState::default();

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
        while let Some(imu) = imu_in.receive()? {
            counters.received += 1;
            if imu.version != PAYLOAD_VERSION {
                counters.rejected += 1;
                continue;
            }
            let mut state = step(&mut nav, &imu, &last);
            state.version = PAYLOAD_VERSION;
            state.header.stamp(Stage::Navigator, monotonic_ns());
            output.publish(state)?;
            last = state;
            counters.published += 1;
        }
        counters.lost = nav.rejected_imu_samples();
        heartbeat.tick(&counters)?;
    }
    Ok(())
}
