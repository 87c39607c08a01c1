//! The simulator: one call per IMU period fills the frames the sensor block would send.
//!
//! The base tick is the IMU period. The frames of the slower sensors (those listed in
//! `slow_sensor_list.rs`) are emitted on the ticks where `⌊k·rate/imu_rate⌋` advances (and on tick
//! 0), so any rate up to the IMU rate works without drift and without requiring an integer ratio.

use rins_protocol::{Frame, FrameType, ImuFrame, Payload};

use crate::config::SimConfig;
use crate::error::SimError;
use crate::sensor_model::SensorModel;
use crate::sensor_model::fault::{ChannelFault, InertialSensor};
use crate::slow_sensor::{SampleAt, SlowSensor};
use crate::slow_sensors::slow_sensors;
use crate::trajectory::Trajectory;

/// Ground truth published alongside each IMU frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthSample {
    /// Device time of the IMU sample, µs since start (not wrapped).
    pub device_time_us: u64,
    /// IMU sequence number (not wrapped).
    pub imu_seq: u64,
    /// Attitude body → NED, [w, x, y, z].
    pub quaternion: [f64; 4],
    /// Velocity NED, m/s.
    pub velocity_ned_mps: [f64; 3],
    /// Geodetic latitude, rad.
    pub latitude_rad: f64,
    /// Longitude, rad.
    pub longitude_rad: f64,
    /// Altitude above mean sea level, m.
    pub altitude_m: f64,
}

impl Default for TruthSample {
    fn default() -> Self {
        Self {
            device_time_us: 0,
            imu_seq: 0,
            quaternion: [1.0, 0.0, 0.0, 0.0],
            velocity_ned_mps: [0.0; 3],
            latitude_rad: 0.0,
            longitude_rad: 0.0,
            altitude_m: 0.0,
        }
    }
}

/// Caller-owned output of one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickOutput {
    /// The IMU frame (every tick).
    pub imu: Frame,
    /// The slower sensors' frames at their frame type's [`FrameType::index`], `None` where none
    /// fell due (the IMU's slot stays `None`: its frame is `imu`). One slot per type, so a new
    /// frame type needs no field here.
    slow: [Option<Frame>; FrameType::COUNT],
    /// Truth at the IMU sample time.
    pub truth: TruthSample,
}

impl TickOutput {
    /// The tick's frame of type `frame`, `None` where none fell due (or the sensor is not fitted).
    pub fn frame(&self, frame: FrameType) -> Option<&Frame> {
        match frame {
            FrameType::Imu => Some(&self.imu),
            _ => self.slow[frame.index()].as_ref(),
        }
    }

    /// The frames of the tick in frame-type order, `None` where none fell due.
    pub fn frames(&self) -> [Option<&Frame>; FrameType::COUNT] {
        FrameType::ALL.map(|t| self.frame(t))
    }
}

impl Default for TickOutput {
    fn default() -> Self {
        Self {
            imu: Frame {
                seq: 0,
                device_time_us: 0,
                payload: Payload::Imu(ImuFrame::default()),
            },
            slow: [None; FrameType::COUNT],
            truth: TruthSample::default(),
        }
    }
}

fn next(seq: &mut u16) -> u16 {
    let s = *seq;
    *seq = seq.wrapping_add(1);
    s
}

/// Whether a frame at `rate_hz` falls due on IMU tick `k` of `imu_rate_hz`.
fn due(k: u64, rate_hz: f64, imu_rate_hz: f64) -> bool {
    if k == 0 {
        return true;
    }
    // Multiply before dividing: with integer rates both products are exact integers and the
    // quotient is exact whenever it is whole, so frames land exactly on schedule.
    let index = |k: u64| (k as f64 * rate_hz / imu_rate_hz).floor();
    index(k) != index(k - 1)
}

/// The device simulator: truth trajectory plus sensor models, advanced one IMU period per step.
#[derive(Debug, Clone)]
pub struct Simulator {
    imu_rate_hz: f64,
    trajectory: Trajectory,
    sensors: SensorModel,
    /// The sensors sampled slower than the IMU that the configuration fits.
    slow: Vec<Box<dyn SlowSensor>>,
    tick: u64,
    /// Per-frame-type sequence counters, in [`FrameType`] index order.
    seq: [u16; FrameType::COUNT],
}

impl Simulator {
    /// Validates `config` and the axes (3..=16 non-zero finite vectors each, normalised here) and
    /// builds the simulator. Equal seeds give identical output.
    pub fn new(
        config: &SimConfig,
        gyro_axes: &[[f64; 3]],
        accel_axes: &[[f64; 3]],
        seed: u64,
    ) -> Result<Self, SimError> {
        config.validate()?;
        let sensors = SensorModel::new(
            &config.sensor_model(),
            &config.environment(),
            gyro_axes,
            accel_axes,
            config.imu_rate_hz,
            seed,
        )?;
        Ok(Self {
            imu_rate_hz: config.imu_rate_hz,
            trajectory: Trajectory::new(config.scenario, config.trajectory_start()),
            sensors,
            slow: slow_sensors(config, seed),
            tick: 0,
            seq: [0; FrameType::COUNT],
        })
    }

    /// Number of steps taken so far (the next IMU sequence number, unwrapped).
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// Device time of the next step, s.
    pub fn time_s(&self) -> f64 {
        self.tick as f64 / self.imu_rate_hz
    }

    /// IMU period, s.
    pub fn imu_period_s(&self) -> f64 {
        1.0 / self.imu_rate_hz
    }

    /// The truth trajectory.
    pub fn trajectory(&self) -> &Trajectory {
        &self.trajectory
    }

    /// The sensor models (true channel errors, temperatures, faults).
    pub fn sensors(&self) -> &SensorModel {
        &self.sensors
    }

    /// Injects a fault into one inertial channel from the next step on.
    pub fn inject_fault(
        &mut self,
        sensor: InertialSensor,
        channel: usize,
        fault: ChannelFault,
    ) -> Result<(), SimError> {
        let now = self.time_s();
        self.sensors.set_fault(sensor, channel, Some(fault), now)
    }

    /// Clears the fault of one inertial channel.
    pub fn clear_fault(&mut self, sensor: InertialSensor, channel: usize) -> Result<(), SimError> {
        let now = self.time_s();
        self.sensors.set_fault(sensor, channel, None, now)
    }

    /// Advances one IMU period and fills `out`; allocation-free.
    pub fn step(&mut self, out: &mut TickOutput) {
        let t = self.time_s();
        // Exact for integer rates; µs since start never exceeds 2^53 in practice.
        let time_us = (self.tick as f64 * 1e6 / self.imu_rate_hz).round() as u64;
        let device_time_us = time_us as u32; // wraps on the wire by design
        let truth = self.trajectory.sample(t);

        let mut imu = ImuFrame::default();
        self.sensors.imu(&truth, &mut imu);
        out.imu = Frame {
            seq: next(&mut self.seq[FrameType::Imu.index()]),
            device_time_us,
            payload: Payload::Imu(imu),
        };

        out.slow = [None; FrameType::COUNT];
        let at = SampleAt {
            t_s: t,
            truth: &truth,
            trajectory: &self.trajectory,
        };
        for sensor in &mut self.slow {
            if !due(self.tick, sensor.rate_hz(), self.imu_rate_hz) {
                continue;
            }
            let payload = sensor.sample(&at, &mut self.sensors);
            let frame = payload.frame_type();
            // A slower sensor never sends the IMU's frame; were one to, it would not replace it.
            if frame != FrameType::Imu {
                out.slow[frame.index()] = Some(Frame {
                    seq: next(&mut self.seq[frame.index()]),
                    device_time_us,
                    payload,
                });
            }
        }

        let q = truth.attitude.quaternion();
        out.truth = TruthSample {
            device_time_us: time_us,
            imu_seq: self.tick,
            quaternion: [q.w, q.i, q.j, q.k],
            velocity_ned_mps: truth.velocity_n.into(),
            latitude_rad: truth.latitude_rad,
            longitude_rad: truth.longitude_rad,
            altitude_m: truth.altitude_m,
        };
        self.tick += 1;
    }
}
