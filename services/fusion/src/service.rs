//! The fusion process: raw IMU frames in, fused body rate and specific force out.

use std::time::Duration;

use anyhow::Result;
use ipc_types::{
    ChannelState, FusedImu, Health, PAYLOAD_VERSION, RawImu, ServiceKind, Stage, fused_flags, names,
};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::heartbeat::Heartbeat;
use rins_runtime::ipc::{IpcSettings, TopicPublisher, TopicSubscriber, create_node};
use rins_runtime::shutdown::Shutdown;

use crate::fuser::{ACCEL_MASK_SHIFT, Fused, ImuFuser};

// The wire's valid mask and the fuser agree on where the accelerometer bits start.
const _: () = assert!(ACCEL_MASK_SHIFT == 16);

/// Longest sleep between looks at the shutdown flag and the heartbeat.
const WAIT: Duration = Duration::from_millis(100);

/// Per-channel states for the fused message: used channels Ok, fitted but unused Excluded.
fn channel_states(n: usize, used_mask: u32) -> [u8; ipc_types::MAX_CHANNELS] {
    let mut states = [ChannelState::Absent as u8; ipc_types::MAX_CHANNELS];
    for (i, s) in states.iter_mut().enumerate().take(n) {
        *s = if used_mask & (1 << i) != 0 {
            ChannelState::Ok as u8
        } else {
            ChannelState::Excluded as u8
        };
    }
    states
}

/// The fused message for one raw frame (header copied, fusion stamp left to the caller).
pub fn fused_message(raw: &RawImu, fused: &Fused, n_gyro: usize, n_accel: usize) -> FusedImu {
    let mut flags = 0;
    if !fused.gyro_ok {
        flags |= fused_flags::GYRO_INSUFFICIENT;
    }
    if !fused.accel_ok {
        flags |= fused_flags::ACCEL_INSUFFICIENT;
    }
    FusedImu {
        version: PAYLOAD_VERSION,
        n_gyro: n_gyro as u8,
        n_accel: n_accel as u8,
        flags,
        header: raw.header,
        rate_rps: fused.rate,
        specific_force_mps2: fused.specific_force,
        rate_var: fused.rate_var,
        specific_force_var: fused.specific_force_var,
        gyro_state: channel_states(n_gyro, fused.gyro_mask),
        accel_state: channel_states(n_accel, fused.accel_mask),
        gyro_reason: [0; ipc_types::MAX_CHANNELS],
        accel_reason: [0; ipc_types::MAX_CHANNELS],
        gyro_test_statistic: 0.0,
        accel_test_statistic: 0.0,
    }
}

pub fn run(mut fuser: ImuFuser, settings: &IpcSettings, shutdown: &Shutdown) -> Result<()> {
    let node = create_node("fusion", settings)?;
    let input = TopicSubscriber::<RawImu>::new(&node, names::RAW_IMU)?;
    let output = TopicPublisher::<FusedImu>::new(&node, names::FUSED_IMU)?;
    let mut heartbeat = Heartbeat::new(&node, ServiceKind::Fusion)?;
    let (n_gyro, n_accel) = (fuser.gyro_geometry().n(), fuser.accel_geometry().n());
    let mut counters = Health::default();
    let mut last_seq: Option<u64> = None;
    let mut mismatch_reported = false;

    while !shutdown.requested() {
        input.wait(WAIT)?;
        while let Some(raw) = input.receive()? {
            counters.received += 1;
            if let Some(last) = last_seq
                && raw.header.origin_seq > last + 1
            {
                counters.lost += raw.header.origin_seq - last - 1;
            }
            last_seq = Some(raw.header.origin_seq);
            if raw.version != PAYLOAD_VERSION
                || usize::from(raw.n_gyro) != n_gyro
                || usize::from(raw.n_accel) != n_accel
            {
                counters.rejected += 1;
                if !mismatch_reported {
                    mismatch_reported = true;
                    tracing::error!(
                        version = raw.version,
                        n_gyro = raw.n_gyro,
                        n_accel = raw.n_accel,
                        expected_gyro = n_gyro,
                        expected_accel = n_accel,
                        "raw IMU frame does not match the configured sensor block; rejecting such frames"
                    );
                }
                continue;
            }
            // Invalid channels are dropped from the solution; the accel bits sit above the gyro bits.
            let fused = fuser.fuse(
                &raw.gyro_counts[..n_gyro],
                &raw.accel_counts[..n_accel],
                raw.valid_mask,
            );
            let mut msg = fused_message(&raw, &fused, n_gyro, n_accel);
            msg.header.stamp(Stage::Fusion, monotonic_ns());
            output.publish(msg)?;
            counters.published += 1;
        }
        heartbeat.tick(&counters)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_states_mark_used_excluded_and_absent() {
        let s = channel_states(4, 0b1011);
        assert_eq!(
            &s[..5],
            &[
                ChannelState::Ok as u8,
                ChannelState::Ok as u8,
                ChannelState::Excluded as u8,
                ChannelState::Ok as u8,
                ChannelState::Absent as u8
            ]
        );
    }
}
