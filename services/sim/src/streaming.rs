//! The simulator's tick, as the runtime's paced loop runs it once per IMU period: the commands
//! that arrived since the last tick (scheduled faults, [`ipc_types::names::SIM_CONTROL`]), then
//! one step of the simulated device: its truth published, its frames on the serial line, the GNSS
//! receiver's bytes on its own.

use ipc_types::{FaultApplied, Header, Health, PAYLOAD_VERSION, SimControl, Truth, names};
use rins_protocol::{FrameType, MAX_FRAME_LEN, encode};
use rins_runtime::ipc::{IpcError, IpcNode, TopicPublisher, TopicSubscriber};
use rins_runtime::paced_loop::PacedSource;

use crate::device::Device;
use crate::fault_command::WhiteNoise;
use crate::fault_schedule::{FaultSchedule, ScheduledFault};
use crate::simulator::{Simulator, TickOutput, TruthSample};

/// Frames of one tick at most: one of each frame type.
const FRAMES_PER_TICK: usize = FrameType::COUNT;

/// The simulated device streaming: the simulator, its lines and the topics of its process.
pub(crate) struct Streaming<'a> {
    sim: Simulator,
    device: Device,
    schedule: FaultSchedule,
    /// Configured white noise, the unit of noise-factor faults.
    noise: &'a WhiteNoise,
    truth: TopicPublisher<Truth>,
    fault_events: TopicPublisher<FaultApplied>,
    control: TopicSubscriber<SimControl>,
    /// The frames of the tick, reused.
    out: TickOutput,
    /// Their bytes, reused.
    buf: [u8; FRAMES_PER_TICK * MAX_FRAME_LEN],
}

impl<'a> Streaming<'a> {
    /// `sim` streaming on `device`, with the `faults` scheduled and the commands of `node`'s
    /// control topic; `noise` is the unit of noise-factor faults.
    pub(crate) fn new(
        sim: Simulator,
        device: Device,
        faults: &[ScheduledFault],
        noise: &'a WhiteNoise,
        node: &IpcNode,
    ) -> Result<Self, IpcError> {
        Ok(Self {
            schedule: FaultSchedule::new(faults, 1.0 / sim.imu_period_s()),
            sim,
            device,
            noise,
            truth: TopicPublisher::new(node, names::TRUTH)?,
            fault_events: TopicPublisher::new(node, names::SIM_FAULT_APPLIED)?,
            control: TopicSubscriber::new(node, names::SIM_CONTROL)?,
            out: TickOutput::default(),
            buf: [0; FRAMES_PER_TICK * MAX_FRAME_LEN],
        })
    }
}

impl PacedSource for Streaming<'_> {
    fn between_ticks(&mut self, tick: u64, _: &mut Health) -> Result<(), IpcError> {
        debug_assert_eq!(
            tick,
            self.sim.tick(),
            "the loop's ticks are the simulator's steps"
        );
        self.device.reconnect_if_due(&self.sim);
        // Faults first, announced before the frame leaves: whoever measures detection delays
        // must know of a fault before any output derived from the faulty sample.
        while let Some(command) = self.schedule.next_due(tick) {
            let applied = self.device.apply(&mut self.sim, &command, self.noise);
            self.fault_events.publish(applied)?;
        }
        while let Some(command) = self.control.receive()? {
            let applied = self
                .device
                .handle_control(&mut self.sim, &command, self.noise);
            self.fault_events.publish(applied)?;
        }
        Ok(())
    }

    fn tick(&mut self, _: u64, counters: &mut Health) -> Result<(), IpcError> {
        self.sim.step(&mut self.out);
        // Truth first: whoever compares against it must find it before the frame's navigation output.
        self.truth.publish(truth_message(&self.out.truth))?;
        if let Some(gnss) = &mut self.device.gnss {
            gnss.tick(&self.out.truth);
        }
        let len = encode_tick(&self.out, &mut self.buf);
        // Unplugged, or nobody reads the line (acquisition restarting): the frames are lost, and
        // the device's time and sequence numbers go on regardless.
        if self.device.line.send(&self.buf[..len]) {
            counters.published += 1;
        } else {
            counters.lost += 1;
        }
        Ok(())
    }
}

/// The truth topic's sample for one tick of the simulated trajectory.
pub fn truth_message(t: &TruthSample) -> Truth {
    Truth {
        version: PAYLOAD_VERSION,
        header: Header {
            origin_seq: t.imu_seq,
            origin_device_time_us: t.device_time_us,
            ..Header::default()
        },
        quaternion: t.quaternion,
        velocity_ned_mps: t.velocity_ned_mps,
        latitude_rad: t.latitude_rad,
        longitude_rad: t.longitude_rad,
        altitude_m: t.altitude_m,
        ..Truth::default()
    }
}

/// Encodes the frames of one tick into `buf`, returning the byte count.
fn encode_tick(out: &TickOutput, buf: &mut [u8]) -> usize {
    let mut len = 0;
    for frame in out.frames().into_iter().flatten() {
        // The simulator only produces valid frames, and the buffer holds one of the largest per
        // frame type.
        if let Ok(n) = encode(frame, &mut buf[len..]) {
            len += n;
        }
    }
    len
}
