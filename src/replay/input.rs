//! The raw sensor samples of a recording, in the order the sensor block produced them.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{Context, Result};
use ipc_types::{
    GnssFix, Health, NavState, RawAirspeed, RawAux, RawBaro, RawImu, RawMag, ServiceKind, names,
};
use rins_navigator::aiding::readings::{HeldPayload, Reading};
use rins_recording::{RecordedMessage, Recording, read_file};

/// The raw topics a replay feeds, one line per topic: `Variant(Payload) = TOPIC,` makes the
/// [`RawSample`] variant `Variant` of the `ipc_types::names` topic `TOPIC`. The lines under `held`
/// are payloads the navigator holds as they come (see `rins_navigator::aiding::readings`); those
/// under `stages` feed a stage (fusion, the altimeter), the navigator's own receiver hold (GNSS),
/// or none.
macro_rules! raw_samples {
    (
        stages { $($(#[$sdoc:meta])* $stage:ident($stage_payload:ty) = $stage_topic:ident,)+ }
        held { $($(#[$hdoc:meta])* $held:ident($held_payload:ty) = $held_topic:ident,)+ }
    ) => {
        /// One raw sample of a recording.
        #[derive(Debug, Clone, Copy)]
        pub enum RawSample {
            $($(#[$sdoc])* $stage($stage_payload),)+
            $($(#[$hdoc])* $held($held_payload),)+
        }

        impl RawSample {
            /// The frame's header.
            pub fn header(&self) -> &ipc_types::Header {
                match self {
                    $(Self::$stage(s) => &s.header,)+
                    $(Self::$held(s) => &s.header,)+
                }
            }

            /// The payload's layout version.
            pub fn version(&self) -> u16 {
                match self {
                    $(Self::$stage(s) => s.version,)+
                    $(Self::$held(s) => s.version,)+
                }
            }

            /// The aiding reading the navigator holds, for a payload it takes as it comes.
            pub fn held_reading(&self) -> Option<Reading> {
                match self {
                    $(Self::$held(s) => Some(s.reading()),)+
                    _ => None,
                }
            }

            /// The raw sample of message `m`, when its topic is one a replay feeds.
            fn decode(
                m: &RecordedMessage,
            ) -> Option<Result<Self, rins_recording::DecodeError>> {
                match &*m.topic {
                    $(names::$stage_topic => Some(m.decode().map(Self::$stage)),)+
                    $(names::$held_topic => Some(m.decode().map(Self::$held)),)+
                    _ => None,
                }
            }
        }
    };
}

raw_samples! {
    stages {
        /// An IMU frame.
        Imu(RawImu) = RAW_IMU,
        /// A barometer sample (through the altimeter).
        Baro(RawBaro) = RAW_BARO,
        /// An auxiliary sample (temperatures, foot pressure).
        Aux(RawAux) = RAW_AUX,
        /// A receiver fix (the navigator lanes place it by its receive time).
        Gnss(GnssFix) = GNSS,
    }
    held {
        /// A magnetometer sample.
        Mag(RawMag) = RAW_MAG,
        /// A pitot airspeed sample.
        Airspeed(RawAirspeed) = RAW_AIRSPEED,
    }
}

impl RawSample {
    /// The order the samples reached the computer: the serial receive time of their frames (each
    /// frame type counts its own sequence numbers, so those do not order samples across types),
    /// then the device time. One read of the serial port after a stall hands out many frames with
    /// one receive time; the wire carries them in device-time order, while the recorder wrote
    /// them topic by topic. Ordered by receive time alone, a barometer sample would be fed after
    /// IMU frames it preceded on the wire, and meet the navigator later than it did when recorded.
    fn order(&self) -> (u64, u64) {
        (self.rx_ns(), self.device_time_us())
    }

    /// The frame's device time, µs.
    pub fn device_time_us(&self) -> u64 {
        self.header().origin_device_time_us
    }

    /// The frame's serial receive time, ns (CLOCK_MONOTONIC of the recording).
    pub fn rx_ns(&self) -> u64 {
        self.header().origin_rx_ns
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
    /// Aiding readings each recorded navigator lane applied after their place in the IMU stream
    /// (from its last recorded heartbeat). A serial stall hands the pipeline a burst of frames at
    /// once, and an altitude can then reach a lane after the IMU frames it had to precede; a
    /// replay applies it in its place, so the samples after it cannot match the recording.
    pub recorded_late_aiding: [u64; 2],
    /// Messages of the file that could not be decoded (skipped, counted).
    pub undecodable: u64,
    /// Messages the reader skipped (wrong length, version), and where the file was cut short.
    pub skipped: u64,
    /// Chunks of the file the reader skipped as damaged (their messages are lost).
    pub damaged_chunks: u64,
    /// The reader's note on a damaged file, if any.
    pub damage: Option<String>,
}

impl ReplayInput {
    /// Reads `path` (a regular file: anything else is refused at once, see
    /// [`rins_recording::read_file_bytes`]).
    pub fn read(path: &Path) -> Result<Self> {
        let recording =
            read_file(path).with_context(|| format!("cannot read {}", path.display()))?;
        Ok(Self::from_recording(recording))
    }

    /// Sorts a recording's messages into raw samples and recorded navigation output.
    pub fn from_recording(recording: Recording) -> Self {
        let mut input = Self {
            skipped: recording.skipped_count,
            damaged_chunks: recording.damaged_chunk_count,
            damage: recording.damage.clone(),
            ..Self::default()
        };
        let mut late_by_process = HashMap::new();
        for m in &recording.messages {
            if input.take(m, &mut late_by_process).is_err() {
                input.undecodable += 1;
            }
        }
        for ((lane, _pid), late) in late_by_process {
            input.recorded_late_aiding[lane] += late;
        }
        // Stable: samples of one frame (same receive and device time) keep their recorded order.
        input.raw.sort_by_key(RawSample::order);
        input
    }

    fn take(
        &mut self,
        m: &RecordedMessage,
        late_by_process: &mut HashMap<(usize, u32), u64>,
    ) -> Result<(), rins_recording::DecodeError> {
        if let Some(sample) = RawSample::decode(m) {
            self.raw.push(sample?);
            return Ok(());
        }
        match &*m.topic {
            t if t == names::NAV_LANES[0] => self.nav[0].push(m.decode()?),
            t if t == names::NAV_LANES[1] => self.nav[1].push(m.decode()?),
            names::HEARTBEAT => {
                let beat: Health = m.decode()?;
                let lane = ServiceKind::NAVIGATOR_LANES
                    .iter()
                    .position(|k| *k as u8 == beat.service);
                if let Some(lane) = lane {
                    // Counters count since the process started: the newest of each process.
                    let late = late_by_process.entry((lane, beat.pid)).or_insert(0);
                    *late = (*late).max(beat.late);
                }
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn header(rx_ns: u64, t_us: u64) -> ipc_types::Header {
        ipc_types::Header {
            origin_rx_ns: rx_ns,
            origin_device_time_us: t_us,
            ..ipc_types::Header::default()
        }
    }

    /// A recording of `n` raw IMU frames in small chunks, its bytes.
    fn raw_recording(path: &Path, n: u64) -> Vec<u8> {
        let options = rins_recording::RecordOptions {
            chunk_size: 4096,
            ..Default::default()
        };
        let mut rec = rins_recording::Recorder::create(path, &options).unwrap();
        let ch = rec.channel_for::<RawImu>(names::RAW_IMU).unwrap();
        for i in 0..n {
            let imu = RawImu {
                header: header(1_000_000 + i * 1_000_000, 1000 + i * 1000),
                ..RawImu::default()
            };
            rec.write_payload(ch, i, i, &imu).unwrap();
        }
        rec.finish().unwrap();
        std::fs::read(path).unwrap()
    }

    #[test]
    fn a_damaged_chunk_is_counted_and_the_rest_replayed() {
        let dir = std::env::temp_dir().join(format!("rins-replay-input-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("run.mcap");
        let mut bytes = raw_recording(&path, 300);
        // The chunk records (opcode 6) of the file, outside any chunk.
        let mut chunks = Vec::new();
        let mut pos = 8;
        while pos + 9 <= bytes.len() && bytes[pos] != 0x0F {
            let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().unwrap()) as usize;
            if bytes[pos] == 0x06 {
                chunks.push((pos, len));
            }
            pos += 9 + len;
        }
        assert!(chunks.len() >= 3, "{} chunks", chunks.len());
        let (start, len) = chunks[1];
        for i in 0..16 {
            bytes[start + 9 + len / 2 + i] ^= 1 << (i % 8);
        }
        std::fs::write(&path, &bytes).unwrap();
        let input = ReplayInput::read(&path).unwrap();
        assert_eq!(input.damaged_chunks, 1);
        assert_eq!(input.skipped, 0);
        assert_eq!(input.damage, None);
        // The frames after the damaged chunk are there.
        assert_eq!(
            input.raw.last().map(RawSample::device_time_us),
            Some(300_000)
        );
        assert!(
            input.raw.len() < 300 && input.raw.len() > 150,
            "{}",
            input.raw.len()
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_fifo_is_refused_without_waiting_for_a_writer() {
        let dir = std::env::temp_dir().join(format!("rins-replay-fifo-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("run.mcap");
        let c = std::ffi::CString::new(fifo.to_string_lossy().as_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let (tx, rx) = std::sync::mpsc::channel();
        let path = fifo.clone();
        std::thread::spawn(move || {
            let _ = tx.send(ReplayInput::read(&path).map(|i| i.raw.len()));
        });
        let result = rx
            .recv_timeout(std::time::Duration::from_secs(5))
            .expect("reading a FIFO did not end within 5 s");
        let text = format!("{:#}", result.unwrap_err());
        assert!(
            text.ends_with(&format!("{} is a FIFO, not a regular file", fifo.display())),
            "{text}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_navigator_holds_magnetometer_and_airspeed_samples_as_they_come() {
        let airspeed = RawSample::Airspeed(RawAirspeed {
            header: header(10, 1000),
            diff_pressure_pa: 250.0,
            ..RawAirspeed::default()
        });
        match airspeed.held_reading() {
            Some(Reading::Airspeed(r)) => {
                assert_eq!((r.t_us, r.diff_pressure_pa), (1000, 250.0));
            }
            other => panic!("{other:?}"),
        }
        let mag = RawSample::Mag(RawMag {
            header: header(10, 1000),
            ..RawMag::default()
        });
        assert!(matches!(mag.held_reading(), Some(Reading::Mag(_))));
        // The barometer goes through the altimeter first.
        let baro = RawSample::Baro(RawBaro {
            header: header(10, 1000),
            ..RawBaro::default()
        });
        assert_eq!(baro.held_reading(), None);
    }

    #[test]
    fn frames_of_one_serial_read_keep_their_wire_order_across_topics() {
        let imu = |rx, t| {
            RawSample::Imu(RawImu {
                header: header(rx, t),
                ..RawImu::default()
            })
        };
        let baro = |rx, t| {
            RawSample::Baro(RawBaro {
                header: header(rx, t),
                ..RawBaro::default()
            })
        };
        // The recorder wrote the IMU topic first; a stall made the read at 50 ns hand out the
        // frames of 2000..2030 µs at once.
        let mut raw = [
            imu(10, 1000),
            imu(50, 2000),
            imu(50, 2010),
            imu(50, 2030),
            baro(10, 1000),
            baro(50, 2020),
        ];
        raw.sort_by_key(RawSample::order);
        let order: Vec<(bool, u64)> = raw
            .iter()
            .map(|s| (matches!(s, RawSample::Baro(_)), s.device_time_us()))
            .collect();
        assert_eq!(
            order,
            [
                (false, 1000),
                (true, 1000),
                (false, 2000),
                (false, 2010),
                (true, 2020),
                (false, 2030)
            ]
        );
    }
}
