//! The bridge process: the merged navigation stream, the fused IMU and the watchdog's report in
//! over iceoryx2; copies of the samples due handed to the network thread ([`Network`]), which puts
//! them on Zenoh as ROS 2 messages. The loop only copies fixed-size samples into a queue whose
//! slots exist from the start: it neither allocates per sample nor waits for the network.

use std::time::Duration;

use anyhow::Result;
use ipc_types::{FusedImu, HealthReport, ServiceKind, names};
use rins_navigator::lanes::NavSubscriber;
use rins_runtime::ipc::TopicSubscriber;
use rins_runtime::payload::OtherVersionWarning;
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::service_loop::ServiceLoop;

use crate::config::ZenohConfig;
use crate::network::Network;
use crate::outbox::Outbox;
use crate::session_config::session_config;

/// The longest sleep waiting for a solution: how often the heartbeat and the stop flag are served
/// when none comes.
const WAIT: Duration = Duration::from_millis(20);

/// The bridge process, built from `[zenoh]`.
pub struct BridgeService {
    /// The validated configuration.
    pub config: ZenohConfig,
}

impl Service for BridgeService {
    fn run(self, ctx: ServiceContext) -> Result<()> {
        let config = self.config;
        config.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
        // A file that cannot be used stops the start, naming it.
        let zenoh_config = session_config(&config, rins_runtime::user::effective_uid())?;
        let node = ctx.create_node(ServiceKind::Bridge)?;
        let mut lp = ServiceLoop::new(&node, ServiceKind::Bridge, &ctx.shutdown)?;
        let mut nav = NavSubscriber::new(&node)?;
        let fused = TopicSubscriber::<FusedImu>::new(&node, names::FUSED_IMU)?;
        let health = TopicSubscriber::<HealthReport>::new(&node, names::HEALTH)?;
        let network = Network::start(&config, zenoh_config)?;
        tracing::info!(
            connect = %config.connect.join(","),
            listen = %config.listen.join(","),
            mode = %config.mode,
            domain = config.domain_id,
            namespace = %config.namespace,
            "bridging to Zenoh"
        );
        let mut outbox = Outbox::new(&config.rates);
        let mut version_warning = OtherVersionWarning::new();
        let other_version =
            |nav: &NavSubscriber| nav.rejected() + fused.rejected() + health.rejected();
        let counters = network.counters.clone();
        let copy = |lp: &mut ServiceLoop, network: &Network| {
            use std::sync::atomic::Ordering::Relaxed;
            lp.counters.published = counters.published.load(Relaxed);
            lp.counters.lost = network.lost();
        };
        while lp.running() {
            nav.wait(WAIT)?;
            let mut send = |m| network.send(m);
            while let Some(f) = fused.receive()? {
                lp.counters.received += 1;
                outbox.on_fused(&f, &mut send);
            }
            while let Some(n) = nav.receive()? {
                lp.counters.received += 1;
                outbox.on_nav(&n, &mut send);
            }
            while let Some(h) = health.receive()? {
                outbox.on_health(&h, &mut send);
            }
            copy(&mut lp, &network);
            let refused = other_version(&nav);
            lp.counters.rejected = refused;
            version_warning.check("bridge", refused);
            lp.beat()?;
        }
        copy(&mut lp, &network);
        let c = &network.counters;
        use std::sync::atomic::Ordering::Relaxed;
        tracing::info!(
            queued = c.queued.load(Relaxed),
            published = c.published.load(Relaxed),
            dropped_full = c.dropped_full.load(Relaxed),
            dropped_offline = c.dropped_offline.load(Relaxed),
            put_errors = c.put_errors.load(Relaxed),
            withheld = c.withheld.load(Relaxed),
            open_failures = c.open_failures.load(Relaxed),
            sessions = c.sessions.load(Relaxed),
            "Zenoh bridge stopped"
        );
        Ok(())
    }
}
