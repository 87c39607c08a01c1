//! The raw sensor samples of a recording, in the order the sensor block produced them.

use std::path::Path;

use anyhow::{Context, Result};
use ipc_types::{NavState, RawAux, RawBaro, RawImu, RawMag, names};
use rins_recording::{RecordedMessage, Recording, read_file};

/// One raw sample of a recording.
#[derive(Debug, Clone, Copy)]
pub enum RawSample {
    /// An IMU frame.
    Imu(RawImu),
    /// A barometer sample.
    Baro(RawBaro),
    /// A magnetometer sample.
    Mag(RawMag),
    /// An auxiliary sample (temperatures, foot pressure).
    Aux(RawAux),
}

impl RawSample {
    /// The order the samples reached the computer: the serial receive time of their frames (each
    /// frame type counts its own sequence numbers, so those do not order samples across types).
    fn order(&self) -> u64 {
        self.rx_ns()
    }

    /// The frame's serial receive time, ns (CLOCK_MONOTONIC of the recording).
    pub fn rx_ns(&self) -> u64 {
        match self {
            Self::Imu(s) => s.header.origin_rx_ns,
            Self::Baro(s) => s.header.origin_rx_ns,
            Self::Mag(s) => s.header.origin_rx_ns,
            Self::Aux(s) => s.header.origin_rx_ns,
        }
    }
}

/// What a recording holds for a replay: its raw samples in frame order, and the navigation
/// output of each lane as recorded.
#[derive(Debug, Default)]
pub struct ReplayInput {
    /// Raw samples, in frame order.
    pub raw: Vec<RawSample>,
    /// The recorded navigation output of lane 0 and lane 1.
    pub nav: [Vec<NavState>; 2],
    /// Messages of the file that could not be decoded (skipped, counted).
    pub undecodable: u64,
    /// Messages the reader skipped (wrong length, version), and where the file was cut short.
    pub skipped: u64,
    /// The reader's note on a damaged file, if any.
    pub damage: Option<String>,
}

impl ReplayInput {
    /// Reads `path`.
    pub fn read(path: &Path) -> Result<Self> {
        let recording =
            read_file(path).with_context(|| format!("cannot read {}", path.display()))?;
        Ok(Self::from_recording(recording))
    }

    /// Sorts a recording's messages into raw samples and recorded navigation output.
    pub fn from_recording(recording: Recording) -> Self {
        let mut input = Self {
            skipped: recording.skipped_count,
            damage: recording.damage.clone(),
            ..Self::default()
        };
        for m in &recording.messages {
            if input.take(m).is_err() {
                input.undecodable += 1;
            }
        }
        // Stable: samples received at the same instant keep their recorded order.
        input.raw.sort_by_key(RawSample::order);
        input
    }

    fn take(&mut self, m: &RecordedMessage) -> Result<(), rins_recording::DecodeError> {
        match &*m.topic {
            names::RAW_IMU => self.raw.push(RawSample::Imu(m.decode()?)),
            names::RAW_BARO => self.raw.push(RawSample::Baro(m.decode()?)),
            names::RAW_MAG => self.raw.push(RawSample::Mag(m.decode()?)),
            names::RAW_AUX => self.raw.push(RawSample::Aux(m.decode()?)),
            t if t == names::NAV_LANES[0] => self.nav[0].push(m.decode()?),
            t if t == names::NAV_LANES[1] => self.nav[1].push(m.decode()?),
            _ => {}
        }
        Ok(())
    }

    /// Raw IMU frames in the recording.
    pub fn imu_frames(&self) -> usize {
        self.raw
            .iter()
            .filter(|s| matches!(s, RawSample::Imu(_)))
            .count()
    }
}
