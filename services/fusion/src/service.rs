//! The fusion process: raw IMU frames in, fused body rate and specific force out.

use std::time::Duration;

use ipc_types::{
    ChannelState, FusedImu, FusionControl, FusionReply, Health, PAYLOAD_VERSION, RawImu,
    ReadmitOutcome, SensorType, ServiceKind, Stage, fused_flags, names,
};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::input_watch::{InputChange, InputWatch};
use rins_runtime::ipc::{IpcError, TopicPublisher};
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::stage_io::StageInput;
use rins_runtime::stage_loop::{PipelineStage, StageLoop, StageTopics, Step};

use crate::fuser::{ACCEL_MASK_SHIFT, Fused, ImuFuser};
use crate::readmit_probation::{ReadmitProbation, ReadmitResult};

// The wire's valid mask and the fuser agree on where the accelerometer bits start.
const _: () = assert!(ACCEL_MASK_SHIFT == 16);

/// Longest sleep waiting for input; also how often the input deadline is checked.
const WAIT: Duration = Duration::from_millis(10);

/// The fused message for one raw frame: estimate, fault-detection fields and the raw frame's header
/// (the fusion stamp is left to the caller).
pub fn fused_message(raw: &RawImu, fused: &Fused, n_gyro: usize, n_accel: usize) -> FusedImu {
    let mut msg = FusedImu {
        version: PAYLOAD_VERSION,
        n_gyro: n_gyro as u8,
        n_accel: n_accel as u8,
        header: raw.header,
        rate_rps: fused.rate,
        specific_force_mps2: fused.specific_force,
        rate_var: fused.rate_var,
        specific_force_var: fused.specific_force_var,
        ..FusedImu::default()
    };
    fused.write_fdi(&mut msg);
    msg
}

/// The message for a raw frame that does not match the configured sensor block: no estimate, the
/// flags saying why, the channel states as they stand. Published rather than dropped, so that the
/// navigator sees its input arrive unusable (and says so) and the watchdog sees fusion answer.
pub fn rejected_message(raw: &RawImu, fuser: &ImuFuser) -> FusedImu {
    let (gyro, accel) = (
        fuser.monitor(SensorType::Gyro),
        fuser.monitor(SensorType::Accel),
    );
    FusedImu {
        version: PAYLOAD_VERSION,
        n_gyro: fuser.gyro_geometry().n() as u8,
        n_accel: fuser.accel_geometry().n() as u8,
        flags: fused_flags::INPUT_REJECTED
            | fused_flags::GYRO_INSUFFICIENT
            | fused_flags::ACCEL_INSUFFICIENT,
        header: raw.header,
        gyro_state: gyro.status().states.map(|s| s as u8),
        accel_state: accel.status().states.map(|s| s as u8),
        gyro_reason: gyro.status().reasons.map(|r| r as u8),
        accel_reason: accel.status().reasons.map(|r| r as u8),
        ..FusedImu::default()
    }
}

/// Every channel state change is a structured event (rare: faults, exclusions, re-admissions).
fn log_events(fused: &Fused, device_time_us: u64) {
    for status in [&fused.gyro_status, &fused.accel_status] {
        if status.auto_readmitted != 0 {
            tracing::warn!(
                channels = format!("{:#06b}", status.auto_readmitted),
                device_time_us,
                "sensor type had no solution: excluded channels consistent again, re-admitted automatically"
            );
        }
    }
    for e in fused.events.as_slice() {
        let fields = (
            e.sensor.name(),
            e.channel,
            format!("{:?}", e.old_state).to_lowercase(),
            format!("{:?}", e.new_state).to_lowercase(),
            e.reason.name(),
        );
        if e.new_state == ChannelState::Ok {
            tracing::info!(sensor = fields.0, channel = fields.1, from = %fields.2, to = %fields.3, device_time_us, "channel state");
        } else {
            tracing::warn!(sensor = fields.0, channel = fields.1, from = %fields.2, to = %fields.3, reason = fields.4, device_time_us, "channel state");
        }
    }
}

/// Applies a re-admission command (the only way an excluded channel returns) and logs it; the
/// answer follows from [`ReadmitProbation`].
fn readmit(fuser: &mut ImuFuser, sensor: SensorType, channel: usize) -> ReadmitResult {
    match fuser.readmit(sensor, channel) {
        Ok(true) => {
            tracing::warn!(
                sensor = sensor.name(),
                channel,
                "channel re-admitted by command, on probation"
            );
            ReadmitResult::Readmitted
        }
        Ok(false) => {
            tracing::info!(
                sensor = sensor.name(),
                channel,
                "re-admission: channel was not excluded"
            );
            ReadmitResult::NotExcluded
        }
        Err(e) => {
            tracing::warn!(sensor = sensor.name(), channel, error = %e, "re-admission refused");
            ReadmitResult::NoSuchChannel
        }
    }
}

/// Logs the answers that are not plain successes, so that the log says what the operator was told.
fn log_reply(reply: &FusionReply) {
    let outcome = ReadmitOutcome::from_u8(reply.outcome);
    if outcome == Some(ReadmitOutcome::FaultStillPresent) {
        tracing::warn!(
            sensor = reply.sensor,
            channel = reply.channel,
            reason = ipc_types::FaultReason::from_u8(reply.reason).map_or("?", |r| r.name()),
            "re-admitted channel excluded again during its probation: fault still present"
        );
    }
}

/// How long fusion waits for raw IMU before it reports acquisition stale: twenty sample periods,
/// at least 50 ms (a few lost frames are not an outage).
pub fn input_deadline(sample_rate_hz: f64) -> Duration {
    Duration::from_secs_f64((20.0 / sample_rate_hz).max(0.05))
}

/// Fusion as a stage of the pipeline: one fused sample (or a rejected one) per raw IMU frame;
/// re-admission commands read before each batch of frames; the acquisition deadline checked after.
struct FusionStage {
    fuser: ImuFuser,
    control: StageInput<FusionControl>,
    replies: TopicPublisher<FusionReply>,
    probation: ReadmitProbation,
    n_gyro: usize,
    n_accel: usize,
    last_seq: Option<u64>,
    mismatch_reported: bool,
    deadline: Duration,
    acquisition: InputWatch,
}

impl FusionStage {
    /// The message for a frame fusion cannot use (another payload version or another sensor
    /// block), said once in the log.
    fn reject(&mut self, raw: &RawImu) -> FusedImu {
        if !self.mismatch_reported {
            self.mismatch_reported = true;
            tracing::error!(
                version = raw.version,
                n_gyro = raw.n_gyro,
                n_accel = raw.n_accel,
                expected_gyro = self.n_gyro,
                expected_accel = self.n_accel,
                "raw IMU frame does not match the configured sensor block; rejecting such frames"
            );
        }
        rejected_message(raw, &self.fuser)
    }
}

impl PipelineStage for FusionStage {
    type Input = RawImu;
    type Output = FusedImu;

    fn before_input(&mut self, counters: &mut Health) -> Result<(), IpcError> {
        let (fuser, probation) = (&mut self.fuser, &mut self.probation);
        self.control.drain(counters, |cmd| {
            probation.on_request(&cmd, |sensor, channel| readmit(fuser, sensor, channel))
        })?;
        let mut result = Ok(());
        let replies = &self.replies;
        self.probation.take_replies(|reply| {
            log_reply(&reply);
            if result.is_ok() {
                result = replies.publish(reply);
            }
        });
        result
    }

    fn received(&mut self, raw: &RawImu, counters: &mut Health) {
        if let Some(last) = self.last_seq
            && raw.header.origin_seq > last + 1
        {
            counters.lost += raw.header.origin_seq - last - 1;
        }
        self.last_seq = Some(raw.header.origin_seq);
    }

    fn step(&mut self, raw: &RawImu) -> Step<FusedImu> {
        if usize::from(raw.n_gyro) != self.n_gyro || usize::from(raw.n_accel) != self.n_accel {
            return Step::Rejected(self.reject(raw));
        }
        let fused = self.fuser.fuse_raw(raw);
        if !fused.events.is_empty() {
            log_events(&fused, raw.header.origin_device_time_us);
        }
        let msg = fused_message(raw, &fused, self.n_gyro, self.n_accel);
        let fuser = &self.fuser;
        self.probation.on_fused(&msg, |sensor, channel| {
            fuser.monitor(sensor).on_probation(channel)
        });
        Step::Publish(msg)
    }

    fn other_version(&mut self, raw: &RawImu) -> Option<FusedImu> {
        Some(self.reject(raw))
    }

    fn after_input(&mut self, received: u64, counters: &mut Health) {
        let now = monotonic_ns();
        let change = if received > 0 {
            self.acquisition.input(now)
        } else {
            self.acquisition.idle(now)
        };
        match change {
            InputChange::WentStale => tracing::warn!(
                deadline_ms = self.deadline.as_millis() as u64,
                "no raw IMU from acquisition within the deadline: no fused output until it returns"
            ),
            InputChange::CameBack(gap) => tracing::warn!(
                gap_ms = gap.as_millis() as u64,
                "raw IMU from acquisition again"
            ),
            InputChange::None => {}
        }
        counters.stale_input_episodes = self.acquisition.episodes;
        counters.input_stale = u8::from(self.acquisition.is_stale());
    }
}

/// The fusion process: the fuser driven by the raw IMU topic until a stop is requested.
pub struct FusionService {
    /// The fuser built from the configuration.
    pub fuser: ImuFuser,
    /// How long fusion waits for raw IMU before it reports acquisition stale ([`input_deadline`]).
    pub input_deadline: Duration,
    /// Fused samples a channel re-admitted by command that the monitor returned at once (no
    /// solution to test it against) stays watched before the command is answered
    /// ([`ReadmitProbation`]); otherwise the monitor's own probation decides.
    pub readmit_probation_samples: u32,
}

impl Service for FusionService {
    fn run(self, ctx: ServiceContext) -> anyhow::Result<()> {
        let node = ctx.create_node(ServiceKind::Fusion)?;
        let topics = StageTopics {
            kind: ServiceKind::Fusion,
            stage: Stage::Fusion,
            input: names::RAW_IMU,
            output: names::FUSED_IMU,
            wait: WAIT,
        };
        let stage_loop =
            StageLoop::new(&node, &topics, &ctx.shutdown)?.with_wait_strategy(ctx.wait);
        let mut stage = FusionStage {
            n_gyro: self.fuser.gyro_geometry().n(),
            n_accel: self.fuser.accel_geometry().n(),
            fuser: self.fuser,
            control: StageInput::new(&node, names::FUSION_CONTROL)?,
            replies: TopicPublisher::new(&node, names::FUSION_REPLY)?,
            probation: ReadmitProbation::new(self.readmit_probation_samples, std::process::id()),
            last_seq: None,
            mismatch_reported: false,
            deadline: self.input_deadline,
            acquisition: InputWatch::new(self.input_deadline),
        };
        stage_loop.run(&mut stage)?;
        Ok(())
    }
}
