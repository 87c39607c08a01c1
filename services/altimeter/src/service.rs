//! The altimeter process: raw barometer samples in, barometric altitude out.

use std::time::Duration;

use anyhow::Result;
use ipc_types::{Altitude, Health, PAYLOAD_VERSION, RawBaro, ServiceKind, Stage, names};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::heartbeat::Heartbeat;
use rins_runtime::ipc::{IpcSettings, TopicPublisher, TopicSubscriber, create_node};
use rins_runtime::shutdown::Shutdown;

use crate::estimator::{AltitudeEstimator, AltitudeOutput};

const WAIT: Duration = Duration::from_millis(100);

/// The altitude message for one barometer sample (fusion stamp left to the caller).
pub fn altitude_message(raw: &RawBaro, out: &AltitudeOutput) -> Altitude {
    Altitude {
        version: PAYLOAD_VERSION,
        valid: u8::from(out.valid),
        header: raw.header,
        height_m: out.height_m,
        vertical_speed_mps: out.vertical_speed_mps,
        height_var: out.height_var,
        ..Altitude::default()
    }
}

pub fn run(
    mut estimator: AltitudeEstimator,
    settings: &IpcSettings,
    shutdown: &Shutdown,
) -> Result<()> {
    let node = create_node("altimeter", settings)?;
    let input = TopicSubscriber::<RawBaro>::new(&node, names::RAW_BARO)?;
    let output = TopicPublisher::<Altitude>::new(&node, names::ALTITUDE)?;
    let mut heartbeat = Heartbeat::new(&node, ServiceKind::Altimeter)?;
    let mut counters = Health::default();

    while !shutdown.requested() {
        input.wait(WAIT)?;
        while let Some(raw) = input.receive()? {
            counters.received += 1;
            if raw.version != PAYLOAD_VERSION {
                counters.rejected += 1;
                continue;
            }
            let out = estimator.update(raw.header.origin_device_time_us, raw.pressure_pa);
            let mut msg = altitude_message(&raw, &out);
            msg.header.stamp(Stage::Altimeter, monotonic_ns());
            output.publish(msg)?;
            counters.published += 1;
        }
        counters.rejected = counters.rejected.max(estimator.rejected_count());
        heartbeat.tick(&counters)?;
    }
    Ok(())
}
