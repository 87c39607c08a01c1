//! The acquisition process: read the serial port, decode frames, publish raw samples. A device that
//! is missing at start-up or vanishes later (unplugged, re-enumerated) is waited for with
//! exponential backoff ([`rins_serial_reader::backoff`]); the process never exits because of it.

use std::time::Duration;

use anyhow::{Result, anyhow};
use ipc_types::{Health, ServiceKind, Stage};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{IpcNode, IpcSettings, create_node};
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::service_loop::ServiceLoop;
use rins_runtime::shutdown::Shutdown;
use rins_runtime::stage_io::StagePublisher;

use crate::config::AcquisitionConfig;
use crate::line_watch::LineWatch;
use crate::resume_file;
use crate::resume_saver::ResumeSaver;
use crate::to_ipc;
use rins_protocol::{
    DecodedFrame, Decoder, DecoderStats, FrameType, Payload, SensorFrame, frames, link_error,
};
use rins_serial_reader::presence::{Opened, Presence, Retry};
use rins_serial_reader::reconnecting::{LineEvents, read_reconnecting};

/// Generates [`Publishers`] from the protocol's list of frame types
/// ([`rins_protocol::for_each_frame!`], whose grammar this matches): one publisher per frame type,
/// a field named by the type's module, carrying its `SensorFrame::Ipc` payload on its
/// `SensorFrame::TOPIC`; a new frame type needs no line here.
macro_rules! raw_topics {
    ($($(#[$doc:meta])* $variant:ident = $byte:literal => $module:ident :: $frame:ident,)+) => {
        /// The topics acquisition publishes, one per frame type; each sample leaves stamped with
        /// the acquisition's publish time.
        struct Publishers {
            $($module: StagePublisher<<frames::$module::$frame as SensorFrame>::Ipc>,)+
        }

        impl Publishers {
            fn new(node: &IpcNode) -> Result<Self> {
                let stage = Stage::Acquisition;
                Ok(Self {
                    $($module: StagePublisher::new(
                        node,
                        <frames::$module::$frame as SensorFrame>::TOPIC,
                        stage,
                    )?,)+
                })
            }

            /// Publishes `frame` on its topic; allocation-free (the payload is built in place).
            fn publish(&self, frame: &DecodedFrame, rx_ns: u64) -> Result<()> {
                let header = to_ipc::origin_header(frame, rx_ns);
                match &frame.payload {
                    $(Payload::$variant(f) => {
                        self.$module.publish(f.to_ipc(header))?;
                    })+
                }
                Ok(())
            }
        }
    };
}

rins_protocol::for_each_frame!(raw_topics);

fn millis(d: Duration) -> u64 {
    u64::try_from(d.as_millis()).unwrap_or(u64::MAX)
}

/// The acquisition process: reads the configured serial device until a stop is requested.
pub struct AcquisitionService {
    /// `[acquisition]` of the configuration, with the device to read.
    pub config: AcquisitionConfig,
}

impl Service for AcquisitionService {
    fn run(self, ctx: ServiceContext) -> Result<()> {
        run(&self.config, &ctx.settings, &ctx.shutdown)
    }
}

/// Reads the serial device of `config` and publishes its frames until `shutdown` is requested.
pub fn run(config: &AcquisitionConfig, settings: &IpcSettings, shutdown: &Shutdown) -> Result<()> {
    let path = config.port.clone().ok_or_else(|| {
        anyhow!(
            "acquisition.port is not set: name the serial device (rins up sets it to the simulator)"
        )
    })?;
    let node = create_node(ServiceKind::Acquisition.name(), settings)?;
    let publishers = Publishers::new(&node)?;
    let service = ServiceLoop::new(&node, ServiceKind::Acquisition, shutdown)?;
    let mut decoder = Decoder::new();
    // Continue the numbering of the run this one replaces (see `resume_file`), from the verified
    // run directory only.
    settings.ensure_run_dir()?;
    let resume_path = resume_file::path_for(settings);
    match resume_file::load(&resume_path) {
        resume_file::Loaded::Point(point) => match decoder.resume_from(&point) {
            Ok(()) => tracing::info!(
                imu_seq = point.seq[FrameType::Imu.index()],
                time_us = point.time_us,
                "continuing the sequence numbers of the previous run"
            ),
            Err(e) => tracing::warn!(
                path = %resume_path.display(),
                error = %e,
                "resume point out of bounds: ignored, numbering starts from the device's values"
            ),
        },
        resume_file::Loaded::Missing => {}
        resume_file::Loaded::Ignored(why) => {
            tracing::warn!("resume point ignored, numbering starts afresh: {why}");
        }
    }
    // The first frames judge the rest of the point: a part that does not fit them is counted.
    let resume_rejected = decoder.stats().resume_rejected;
    let resume_saver = ResumeSaver::start(resume_path.clone())?;
    let mut reader = Reader {
        path: &path,
        simulator_link: settings.in_run_dir(std::path::Path::new(&path)),
        publishers,
        line: LineWatch::new(monotonic_ns(), &decoder.stats()),
        decoder,
        resume_saver,
        next_save_ns: 0,
        resume_rejected,
    };
    let mut buf = [0u8; 4096];
    let counters = read_reconnecting(&path, &config.line(), service, &mut buf, &mut reader)?;
    reader.resume_saver.finish(reader.decoder.resume_point());
    tracing::info!(frames = counters.received, "acquisition stopped");
    Ok(())
}

/// The loop's state between events of the line.
struct Reader<'a> {
    path: &'a str,
    /// The port is the simulator's link under `rins up`, which appears moments after this
    /// service starts: waiting for it is expected, not worth a warning.
    simulator_link: bool,
    publishers: Publishers,
    decoder: Decoder,
    line: LineWatch,
    resume_saver: ResumeSaver,
    next_save_ns: u64,
    /// Resume-point parts the device's first frames refused, as last reported.
    resume_rejected: u64,
}

impl LineEvents for Reader<'_> {
    fn open_failed(&mut self, e: &anyhow::Error, retry: &Retry, presence: &Presence) {
        let path = self.path;
        if retry.first && self.simulator_link {
            tracing::debug!(port = %path, error = %e, "waiting for the simulator's link");
        } else if retry.first {
            let backoff = presence.backoff();
            tracing::warn!(
                port = %path,
                error = %e,
                first_retry_ms = millis(backoff.initial()),
                max_retry_ms = millis(backoff.max()),
                "waiting for serial device {path}: retrying with backoff"
            );
        } else {
            tracing::debug!(
                port = %path,
                error = %e,
                retry_ms = millis(retry.delay),
                "serial device still unavailable"
            );
        }
    }

    fn opened(&mut self, opened: Opened, presence: &Presence) {
        let path = self.path;
        match opened {
            Opened::First { waited, attempts } => {
                tracing::info!(
                    port = %path,
                    waited_ms = millis(waited),
                    attempts,
                    "serial device open"
                );
            }
            Opened::Reconnected { away, attempts } => {
                tracing::info!(
                    port = %path,
                    away_ms = millis(away),
                    attempts,
                    reconnects = presence.reconnects(),
                    "serial device back: resynchronising"
                );
            }
        }
        // Bytes of a frame cut by the disconnect must not be glued to the next stream.
        self.decoder.reset();
        self.line.opened(monotonic_ns(), &self.decoder.stats());
    }

    fn bytes(&mut self, bytes: &[u8], counters: &mut Health) {
        // One receive time for every frame this read completed: the moment we had them whole.
        let rx_ns = monotonic_ns();
        if rx_ns >= self.next_save_ns {
            self.next_save_ns = rx_ns + resume_file::SAVE_PERIOD_NS;
            self.resume_saver.offer(self.decoder.resume_point());
        }
        let mut failed = None;
        let publishers = &self.publishers;
        self.decoder.push(bytes, rx_ns, |frame| {
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

    fn after_read(&mut self, counters: &mut Health) {
        let stats = self.decoder.stats();
        if stats.resume_rejected != self.resume_rejected {
            self.resume_rejected = stats.resume_rejected;
            warn_resume_ignored(&self.decoder, self.resume_rejected);
        }
        if let Some(warning) = self.line.observe(monotonic_ns(), &stats) {
            tracing::warn!(port = %self.path, "{}", warning.message(self.path));
        }
        fill_counters(counters, &stats);
    }

    fn lost(&mut self, e: &std::io::Error, delay: Duration, presence: &Presence) {
        tracing::warn!(
            port = %self.path,
            error = %e,
            first_retry_ms = millis(delay),
            max_retry_ms = millis(presence.backoff().max()),
            "serial device lost: reopening with backoff"
        );
    }
}

/// The decoder's counters in the heartbeat.
fn fill_counters(counters: &mut Health, stats: &DecoderStats) {
    counters.received = stats.frames;
    counters.crc_errors = stats.crc_errors;
    counters.malformed = stats.malformed;
    counters.lost = stats.lost_frames;
    counters.duplicates = stats.duplicates;
    counters.late = stats.late;
    counters.seq_jumps = stats.seq_jumps;
    counters.time_rebases = stats.time_rebases;
    counters.resync_bytes = stats.resync_bytes;
    counters.bytes_received = stats.bytes;
    counters.valid_frames = stats.valid_frames();
    counters.last_decode_error = link_error(stats.last_error.as_ref()) as u8;
}

/// A part of the resume point did not fit the device's first frames (a device restarted, or a
/// point from another deployment): that numbering started from the device's values. Once per
/// part, off the per-frame path.
fn warn_resume_ignored(decoder: &Decoder, rejected: u64) {
    let now = decoder.resume_point();
    tracing::warn!(
        rejected,
        imu_seq = now.seq[FrameType::Imu.index()],
        time_us = now.time_us,
        "resume point far from the device's actual time: ignored"
    );
}
