//! The acquisition process: read the serial port, decode frames, publish raw samples.

use std::io::Read;
use std::time::Duration;

use anyhow::{Result, anyhow};
use ipc_types::{Health, RawAux, RawBaro, RawImu, RawMag, ServiceKind, Stage, names};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::heartbeat::Heartbeat;
use rins_runtime::ipc::{IpcNode, IpcSettings, TopicPublisher, create_node};
use rins_runtime::shutdown::Shutdown;

use crate::config::AcquisitionConfig;
use crate::protocol::{DecodedFrame, Decoder, Payload};
use crate::to_ipc;

struct Publishers {
    imu: TopicPublisher<RawImu>,
    baro: TopicPublisher<RawBaro>,
    mag: TopicPublisher<RawMag>,
    aux: TopicPublisher<RawAux>,
}

impl Publishers {
    fn new(node: &IpcNode) -> Result<Self> {
        Ok(Self {
            imu: TopicPublisher::new(node, names::RAW_IMU)?,
            baro: TopicPublisher::new(node, names::RAW_BARO)?,
            mag: TopicPublisher::new(node, names::RAW_MAG)?,
            aux: TopicPublisher::new(node, names::RAW_AUX)?,
        })
    }

    fn publish(&self, frame: &DecodedFrame, rx_ns: u64) -> Result<()> {
        let mut header = to_ipc::origin_header(frame, rx_ns);
        header.stamp(Stage::Acquisition, monotonic_ns());
        match &frame.payload {
            Payload::Imu(f) => self.imu.publish(to_ipc::raw_imu(f, header)),
            Payload::Baro(f) => self.baro.publish(to_ipc::raw_baro(f, header)),
            Payload::Mag(f) => self.mag.publish(to_ipc::raw_mag(f, header)),
            Payload::Aux(f) => self.aux.publish(to_ipc::raw_aux(f, header)),
        }
    }
}

/// Sleeps `total`, waking early on shutdown.
fn sleep_unless_shutdown(total: Duration, shutdown: &Shutdown) {
    let step = Duration::from_millis(10);
    let mut left = total;
    while !left.is_zero() && !shutdown.requested() {
        let d = left.min(step);
        std::thread::sleep(d);
        left -= d;
    }
}

fn open_port(path: &str, config: &AcquisitionConfig) -> Result<serialport::TTYPort> {
    serialport::new(path, config.baud)
        .timeout(Duration::from_millis(config.read_timeout_ms))
        .open_native()
        .map_err(|e| anyhow!("cannot open serial device {path}: {e}"))
}

pub fn run(config: &AcquisitionConfig, settings: &IpcSettings, shutdown: &Shutdown) -> Result<()> {
    let path = config.port.clone().ok_or_else(|| {
        anyhow!(
            "acquisition.port is not set: name the serial device (rins up sets it to the simulator)"
        )
    })?;
    let node = create_node("acquisition", settings)?;
    let publishers = Publishers::new(&node)?;
    let mut heartbeat = Heartbeat::new(&node, ServiceKind::Acquisition)?;
    let mut decoder = Decoder::new();
    let mut counters = Health::default();
    let initial_backoff = Duration::from_millis(config.reconnect_initial_ms);
    let max_backoff = Duration::from_millis(config.reconnect_max_ms);
    let mut backoff = initial_backoff;
    let mut buf = [0u8; 4096];
    let mut opened_before = false;

    while !shutdown.requested() {
        let mut port = match open_port(&path, config) {
            Ok(port) => port,
            Err(e) => {
                tracing::warn!(error = %e, retry_ms = backoff.as_millis() as u64, "serial device unavailable");
                heartbeat.tick(&counters)?;
                sleep_unless_shutdown(backoff, shutdown);
                backoff = (backoff * 2).min(max_backoff);
                continue;
            }
        };
        if opened_before {
            counters.reconnects += 1;
        }
        opened_before = true;
        tracing::info!(port = %path, "serial device open");
        backoff = initial_backoff;
        // Bytes of a frame cut by the disconnect must not be glued to the next stream.
        decoder.reset();

        while !shutdown.requested() {
            match port.read(&mut buf) {
                Ok(0) => {
                    tracing::warn!(port = %path, "serial device closed");
                    break;
                }
                Ok(n) => {
                    // One receive time for every frame this read completed: the moment we had them whole.
                    let rx_ns = monotonic_ns();
                    let mut failed = None;
                    decoder.push(&buf[..n], |frame| {
                        if let Err(e) = publishers.publish(&frame, rx_ns) {
                            counters.rejected += 1;
                            failed.get_or_insert(e);
                        } else {
                            counters.published += 1;
                        }
                    });
                    if let Some(e) = failed {
                        tracing::error!(error = %e, "publishing a frame failed");
                    }
                }
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => {
                    tracing::warn!(port = %path, error = %e, "serial device lost");
                    break;
                }
            }
            let stats = decoder.stats();
            counters.received = stats.frames;
            counters.crc_errors = stats.crc_errors;
            counters.lost = stats.lost_frames;
            counters.resync_bytes = stats.resync_bytes;
            heartbeat.tick(&counters)?;
        }
        if !shutdown.requested() {
            sleep_unless_shutdown(backoff, shutdown);
        }
    }
    tracing::info!(frames = counters.received, "acquisition stopped");
    Ok(())
}
