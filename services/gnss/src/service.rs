//! The gnss process: read the receiver's serial line, decode its epochs, publish one fix per
//! epoch. A receiver that is missing at start-up or vanishes later is waited for with the same
//! exponential backoff as the sensor block's line; the process never exits because of it.

use std::time::Duration;

use anyhow::{Result, anyhow};
use ipc_types::{GnssFix, GnssLinkReport, Health, ServiceKind, Stage, names};
use rins_gnss_protocol::decode::GnssDecoder;
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{TopicPublisher, create_node};
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::service_loop::ServiceLoop;
use rins_runtime::stage_io::StagePublisher;
use rins_serial_reader::presence::{Opened, Presence, Retry};
use rins_serial_reader::reconnecting::{LineEvents, read_reconnecting};

use crate::config::GnssConfig;
use crate::counters;
use crate::link_report::{ServiceCounts, Silence, SilentLine, link_report};

/// How often the line report is published, ns: with the heartbeat.
const REPORT_PERIOD_NS: u64 = 1_000_000_000;

/// The gnss process: reads the configured receiver until a stop is requested.
pub struct GnssService {
    /// `[gnss]` of the configuration, with the receiver's device.
    pub config: GnssConfig,
}

impl Service for GnssService {
    fn run(self, ctx: ServiceContext) -> Result<()> {
        let path = self.config.port.clone().ok_or_else(|| {
            anyhow!("gnss.port is not set: name the receiver's serial device (rins up sets it to the simulated receiver)")
        })?;
        let node = create_node(ServiceKind::Gnss.name(), &ctx.settings)?;
        let publisher = StagePublisher::<GnssFix>::new(&node, names::GNSS, Stage::Acquisition)?;
        let link_publisher = TopicPublisher::<GnssLinkReport>::new(&node, names::GNSS_LINK)?;
        let service = ServiceLoop::new(&node, ServiceKind::Gnss, &ctx.shutdown)?;
        let mut reader = Reader {
            simulator_link: ctx.settings.in_run_dir(std::path::Path::new(&path)),
            path: &path,
            stale_ns: u64::try_from(self.config.stale_after().as_nanos()).unwrap_or(u64::MAX),
            last_byte_ns: monotonic_ns(),
            publisher,
            decoder: GnssDecoder::new(),
            counts: ServiceCounts::default(),
            link_publisher,
            silence: SilentLine::default(),
            next_report_ns: 0,
        };
        let mut buf = [0u8; 1024];
        read_reconnecting(&path, &self.config.line(), service, &mut buf, &mut reader)?;
        // The receiver's last epoch, complete or not, then the final counts, for whoever reads
        // the line's figures at the end of a run.
        let (publisher, counts) = (&reader.publisher, &mut reader.counts);
        let mut counters = Health::default();
        reader.decoder.flush(monotonic_ns(), |fix| {
            publish(publisher, fix, counts, &mut counters)
        });
        reader.report(monotonic_ns());
        tracing::info!(epochs = reader.counts.published, "gnss stopped");
        Ok(())
    }
}

/// The loop's state between events of the line.
struct Reader<'a> {
    /// The port is the simulator's link under `rins up`, which appears moments after this
    /// service starts: waiting for it is expected, not worth a warning.
    simulator_link: bool,
    path: &'a str,
    /// The line counts as quiet after this long without a byte, ns.
    stale_ns: u64,
    /// The last byte's arrival, or the opening of the port if none came since.
    last_byte_ns: u64,
    publisher: StagePublisher<GnssFix>,
    decoder: GnssDecoder,
    counts: ServiceCounts,
    link_publisher: TopicPublisher<GnssLinkReport>,
    silence: SilentLine,
    next_report_ns: u64,
}

impl Reader<'_> {
    /// Judges the line's silence and publishes the line report.
    fn report(&mut self, now_ns: u64) {
        let stats = self.decoder.stats();
        match self.silence.observe(&stats, now_ns) {
            Silence::Began => tracing::warn!(
                port = %self.path,
                bytes = stats.bytes,
                checksum_errors = stats.checksum_errors,
                unframed_bytes = stats.framing.unframed_bytes,
                "the GNSS line carries bytes but no usable sentence or frame: check the receiver's \
                 baud rate and protocol (rins probe --gnss listens to it)"
            ),
            Silence::Ended => tracing::info!(port = %self.path, "usable GNSS messages again"),
            Silence::Unchanged => {}
        }
        let report = link_report(&stats, &self.counts, &self.silence, now_ns);
        if self.link_publisher.publish(report).is_err() {
            self.counts.publish_failures += 1;
        }
    }
}

impl LineEvents for Reader<'_> {
    fn open_failed(&mut self, e: &anyhow::Error, retry: &Retry, _: &Presence) {
        if retry.first && self.simulator_link {
            tracing::debug!(port = %self.path, error = %e, "waiting for the simulator's link");
        } else if retry.first {
            tracing::warn!(port = %self.path, error = %e, "waiting for the GNSS receiver: retrying with backoff");
        }
    }

    fn opened(&mut self, opened: Opened, _: &Presence) {
        match opened {
            Opened::First { .. } => tracing::info!(port = %self.path, "GNSS receiver open"),
            Opened::Reconnected { away, .. } => {
                tracing::info!(port = %self.path, away_ms = away.as_millis() as u64, "GNSS receiver back");
            }
        }
        self.last_byte_ns = monotonic_ns();
    }

    fn bytes(&mut self, bytes: &[u8], counters: &mut Health) {
        let rx_ns = monotonic_ns();
        self.last_byte_ns = rx_ns;
        let (publisher, counts) = (&self.publisher, &mut self.counts);
        self.decoder.push(bytes, rx_ns, |fix| {
            publish(publisher, fix, counts, counters)
        });
    }

    fn after_read(&mut self, counters: &mut Health) {
        let now_ns = monotonic_ns();
        // An epoch a sentence of which was lost is not held until the receiver speaks again.
        let (publisher, counts) = (&self.publisher, &mut self.counts);
        self.decoder
            .close_quiet(now_ns, |fix| publish(publisher, fix, counts, counters));
        let quiet = now_ns.saturating_sub(self.last_byte_ns) > self.stale_ns;
        if quiet && counters.input_stale == 0 {
            counters.stale_input_episodes += 1;
            tracing::warn!(port = %self.path, "the GNSS receiver went quiet");
        }
        counters.input_stale = u8::from(quiet);
        counters::fill(counters, &self.decoder.stats(), self.counts.published);
        self.counts.quiet = quiet;
        self.counts.reconnects = counters.reconnects;
        if now_ns >= self.next_report_ns {
            self.next_report_ns = now_ns + REPORT_PERIOD_NS;
            self.report(now_ns);
        }
    }

    fn lost(&mut self, e: &std::io::Error, _: Duration, _: &Presence) {
        tracing::warn!(port = %self.path, error = %e, "GNSS receiver lost: reopening with backoff");
    }
}

/// Publishes one epoch, counting it, or counting its failure.
fn publish(
    publisher: &StagePublisher<GnssFix>,
    fix: GnssFix,
    counts: &mut ServiceCounts,
    counters: &mut Health,
) {
    match publisher.publish(fix) {
        Ok(_) => counts.published += 1,
        Err(_) => {
            counts.publish_failures += 1;
            counters.rejected += 1;
        }
    }
}
