//! The gnss process: read the receiver's serial line, decode its epochs, publish one fix per
//! epoch. A receiver that is missing at start-up or vanishes later is waited for with the same
//! exponential backoff as the sensor block's line; the process never exits because of it.

use std::io::Read;
use std::time::Duration;

use anyhow::{Result, anyhow};
use ipc_types::{GnssFix, Health, ServiceKind, Stage, names};
use rins_acquisition::backoff::Backoff;
use rins_acquisition::port;
use rins_acquisition::presence::{Opened, Presence};
use rins_acquisition::service::wait_for_retry;
use rins_gnss_protocol::decode::GnssDecoder;
use rins_runtime::clock::monotonic_ns;
use rins_runtime::heartbeat::Heartbeat;
use rins_runtime::ipc::create_node;
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::shutdown::Shutdown;
use rins_runtime::stage_io::StagePublisher;

use crate::config::GnssConfig;
use crate::counters;

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
        let heartbeat = Heartbeat::new(&node, ServiceKind::Gnss)?;
        Reader {
            config: &self.config,
            simulator_link: ctx.settings.in_run_dir(std::path::Path::new(&path)),
            path: &path,
            shutdown: &ctx.shutdown,
            publisher,
            heartbeat,
            counters: Health::default(),
            decoder: GnssDecoder::new(),
            published: 0,
        }
        .run()
    }
}

/// The loop's state.
struct Reader<'a> {
    config: &'a GnssConfig,
    /// The port is the simulator's link under `rins up`, which appears moments after this
    /// service starts: waiting for it is expected, not worth a warning.
    simulator_link: bool,
    path: &'a str,
    shutdown: &'a Shutdown,
    publisher: StagePublisher<GnssFix>,
    heartbeat: Heartbeat,
    counters: Health,
    decoder: GnssDecoder,
    published: u64,
}

impl Reader<'_> {
    fn run(mut self) -> Result<()> {
        let line = self.config.line();
        let mut presence = Presence::new(Backoff::new(
            Duration::from_millis(line.reconnect_initial_ms),
            Duration::from_millis(line.reconnect_max_ms),
        ));
        while !self.shutdown.requested() {
            let timeout = Duration::from_millis(line.read_timeout_ms);
            let port = match port::open(self.path, line.baud, timeout) {
                Ok(port) => port,
                Err(e) => {
                    let retry = presence.open_failed(monotonic_ns());
                    if retry.first && self.simulator_link {
                        tracing::debug!(port = %self.path, error = %e, "waiting for the simulator's link");
                    } else if retry.first {
                        tracing::warn!(port = %self.path, error = %e, "waiting for the GNSS receiver: retrying with backoff");
                    }
                    self.wait(retry.delay)?;
                    continue;
                }
            };
            match presence.opened(monotonic_ns()) {
                Opened::First { .. } => tracing::info!(port = %self.path, "GNSS receiver open"),
                Opened::Reconnected { away, .. } => {
                    self.counters.reconnects = presence.reconnects();
                    tracing::info!(port = %self.path, away_ms = away.as_millis() as u64, "GNSS receiver back");
                }
            }
            let lost = self.read_until_lost(port, &mut presence)?;
            if let Some(e) = lost
                && !self.shutdown.requested()
            {
                let delay = presence.lost(monotonic_ns());
                tracing::warn!(port = %self.path, error = %e, "GNSS receiver lost: reopening with backoff");
                self.wait(delay)?;
            }
        }
        tracing::info!(epochs = self.published, "gnss stopped");
        Ok(())
    }

    /// Reads `port` until it fails or a stop is requested; allocation-free per read.
    fn read_until_lost(
        &mut self,
        mut port: serialport::TTYPort,
        presence: &mut Presence,
    ) -> Result<Option<std::io::Error>> {
        let mut buf = [0u8; 1024];
        let stale_ns = u64::try_from(self.config.stale_after().as_nanos()).unwrap_or(u64::MAX);
        let mut last_byte_ns = monotonic_ns();
        while !self.shutdown.requested() {
            match port.read(&mut buf) {
                Ok(0) => return Ok(Some(std::io::ErrorKind::UnexpectedEof.into())),
                Ok(n) => {
                    presence.data_arrived();
                    let rx_ns = monotonic_ns();
                    last_byte_ns = rx_ns;
                    let (publisher, published, counters) =
                        (&self.publisher, &mut self.published, &mut self.counters);
                    self.decoder
                        .push(&buf[..n], rx_ns, |fix| match publisher.publish(fix) {
                            Ok(_) => *published += 1,
                            Err(_) => counters.rejected += 1,
                        });
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                    ) => {}
                Err(e) => return Ok(Some(e)),
            }
            let quiet = monotonic_ns().saturating_sub(last_byte_ns) > stale_ns;
            if quiet && self.counters.input_stale == 0 {
                self.counters.stale_input_episodes += 1;
                tracing::warn!(port = %self.path, "the GNSS receiver went quiet");
            }
            self.counters.input_stale = u8::from(quiet);
            counters::fill(&mut self.counters, &self.decoder.stats(), self.published);
            self.heartbeat.tick(&self.counters)?;
        }
        Ok(None)
    }

    /// Sleeps `total` between attempts to open the device, waking on shutdown and keeping the
    /// heartbeat going.
    fn wait(&mut self, total: Duration) -> Result<()> {
        wait_for_retry(total, self.shutdown, &mut self.heartbeat, &self.counters)
    }
}
