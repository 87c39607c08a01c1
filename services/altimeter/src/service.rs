//! The altimeter process: raw barometer samples in, barometric altitude out.

use std::time::Duration;

use anyhow::Result;
use ipc_types::{Altitude, Health, PAYLOAD_VERSION, RawBaro, ServiceKind, Stage, names};
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::stage_loop::{PipelineStage, StageLoop, StageTopics, Step};

use crate::estimator::{AltitudeEstimator, AltitudeOutput};

/// The longest sleep waiting for a barometer sample: how often the stop flag and the heartbeat are
/// served when none comes.
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

/// The altimeter as a stage of the pipeline: one altitude per barometer sample.
struct AltimeterStage {
    estimator: AltitudeEstimator,
}

impl PipelineStage for AltimeterStage {
    type Input = RawBaro;
    type Output = Altitude;

    fn step(&mut self, raw: &RawBaro) -> Step<Altitude> {
        let out = self
            .estimator
            .update(raw.header.origin_device_time_us, raw.pressure_pa);
        Step::Publish(altitude_message(raw, &out))
    }

    fn after_input(&mut self, _received: u64, counters: &mut Health) {
        // Samples the estimator refused (out of range, time not advancing) count as rejected too.
        counters.rejected = counters.rejected.max(self.estimator.rejected_count());
    }
}

/// The altimeter process: the estimator driven by the barometer topic until a stop is requested.
pub struct AltimeterService {
    /// The estimator built from the configuration.
    pub estimator: AltitudeEstimator,
}

impl Service for AltimeterService {
    fn run(self, ctx: ServiceContext) -> Result<()> {
        let node = ctx.create_node(ServiceKind::Altimeter)?;
        let topics = StageTopics {
            kind: ServiceKind::Altimeter,
            stage: Stage::Altimeter,
            input: names::RAW_BARO,
            output: names::ALTITUDE,
            wait: WAIT,
        };
        let mut stage = AltimeterStage {
            estimator: self.estimator,
        };
        StageLoop::new(&node, &topics, &ctx.shutdown)?
            .with_wait_strategy(ctx.wait)
            .run(&mut stage)?;
        Ok(())
    }
}
