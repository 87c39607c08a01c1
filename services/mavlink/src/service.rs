//! The MAVLink process: the merged navigation stream, the fused IMU and the watchdog's report in;
//! MAVLink 2 over UDP and serial ports out through the [`Link`]'s threads; the pipeline's CPU
//! measured for SYS_STATUS on a thread of its own; re-admission commands from the link carried to
//! fusion and acknowledged with fusion's answer, no faster than the configured acknowledgement
//! rate.

use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use ipc_types::{FusedImu, FusionControl, FusionReply, HealthReport, ServiceKind, names};
use rins_navigator::lanes::NavSubscriber;
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{TopicPublisher, TopicSubscriber};
use rins_runtime::payload::OtherVersionWarning;
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::service_loop::ServiceLoop;

use crate::command::{Decision, ack, decide, result_of};
use crate::command_gate::{AckLimiter, CommandGate};
use crate::config::MavlinkConfig;
use crate::dialect::{MavCmd, MavMessage, MavResult};
use crate::endpoint::Endpoint;
use crate::link::{InboundCommand, Link, LinkCounters, LinkSecurity};
use crate::stream::MavlinkStream;

/// The longest sleep waiting for a solution: how often the heartbeat, the commands and the stop
/// flag are served when none comes.
const WAIT: Duration = Duration::from_millis(20);
/// How long a re-admission may take before it is acknowledged as failed: the probation (about a
/// second at the block's rate) and the way there, with a wide margin.
const COMMAND_TIMEOUT: Duration = Duration::from_secs(10);
/// Re-admissions waiting for fusion's answer at once; more are answered "temporarily rejected".
const MAX_PENDING: usize = 8;
/// Request ids of this service have the top bit set: `rins readmit` uses its process id.
const REQUEST_ID_BASE: u32 = 1 << 31;

/// The MAVLink process, built from `[mavlink]`.
pub struct MavlinkService {
    /// The validated configuration.
    pub config: MavlinkConfig,
}

/// A re-admission sent to fusion, waiting for its answer.
#[derive(Debug, Clone, Copy)]
struct Pending {
    request: FusionControl,
    peer: (u8, u8),
    command: MavCmd,
    deadline: Instant,
}

/// The commands from the link and the re-admissions they started.
struct Commands {
    control: TopicPublisher<FusionControl>,
    replies: TopicSubscriber<FusionReply>,
    pending: Vec<Pending>,
    next_id: u32,
    own: (u8, u8),
    accept: bool,
    acks: AckLimiter,
}

/// Queues `ack` of `command` to `peer` if the limiter lets it go; counts it dropped otherwise.
fn send_ack(
    link: &Link,
    limiter: &mut AckLimiter,
    command: MavCmd,
    result: MavResult,
    peer: (u8, u8),
) {
    if limiter.allow(monotonic_ns()) {
        link.queue(MavMessage::COMMAND_ACK(ack(command, result, peer)));
    } else {
        link.counters
            .acks_dropped
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }
}

impl Commands {
    /// Takes one command from the link: answered at once, or sent to fusion.
    fn on_command(&mut self, c: &InboundCommand, link: &Link) -> Result<()> {
        let id = REQUEST_ID_BASE | (self.next_id & !REQUEST_ID_BASE);
        self.next_id = self.next_id.wrapping_add(1);
        let acks = &mut self.acks;
        let mut answer = |result| send_ack(link, acks, c.command.command, result, c.from);
        match decide(&c.command, self.own, self.accept, id) {
            Decision::Ignore => {}
            Decision::Answer(result) => answer(result),
            Decision::Readmit(_) if self.pending.len() >= MAX_PENDING => {
                answer(MavResult::MAV_RESULT_TEMPORARILY_REJECTED);
            }
            Decision::Readmit(request) => {
                self.control.publish(request)?;
                tracing::info!(
                    sensor = request.sensor,
                    channel = request.channel,
                    from_system = c.from.0,
                    "re-admission requested over MAVLink"
                );
                self.pending.push(Pending {
                    request,
                    peer: c.from,
                    command: c.command.command,
                    deadline: Instant::now() + COMMAND_TIMEOUT,
                });
                answer(MavResult::MAV_RESULT_IN_PROGRESS);
            }
        }
        Ok(())
    }

    /// Acknowledges the re-admissions fusion answered, and those it left unanswered too long.
    fn on_replies(&mut self, link: &Link) -> Result<()> {
        while let Some(reply) = self.replies.receive()? {
            let Some(i) = self.pending.iter().position(|p| {
                p.request.request_id == reply.request_id
                    && p.request.sensor == reply.sensor
                    && p.request.channel == reply.channel
            }) else {
                continue;
            };
            let p = self.pending.swap_remove(i);
            send_ack(link, &mut self.acks, p.command, result_of(&reply), p.peer);
        }
        let now = Instant::now();
        let acks = &mut self.acks;
        self.pending.retain(|p| {
            let waiting = now < p.deadline;
            if !waiting {
                send_ack(link, acks, p.command, MavResult::MAV_RESULT_FAILED, p.peer);
            }
            waiting
        });
        Ok(())
    }
}

/// The link's counters into the heartbeat's: messages queued are published, messages the queue
/// could not take or a serial port could not be given are lost, undecodable datagrams are
/// malformed, commands not carried out for the link's reasons (refused by the gate, or dropped for
/// a full queue) are rejected.
fn copy_counters(link: &LinkCounters, counters: &mut ipc_types::Health) {
    use std::sync::atomic::Ordering::Relaxed;
    counters.published = link.queued.load(Relaxed);
    counters.lost = link.dropped.load(Relaxed) + link.serial_dropped.load(Relaxed);
    counters.malformed = link.undecodable.load(Relaxed);
    counters.rejected = link.commands_dropped.load(Relaxed) + link.refused_total();
}

impl Service for MavlinkService {
    fn run(self, ctx: ServiceContext) -> Result<()> {
        let config = self.config;
        let endpoints = config
            .endpoints
            .iter()
            .map(|e| {
                Endpoint::parse(e).map_err(|why| anyhow::anyhow!("mavlink endpoint {e:?}: {why}"))
            })
            .collect::<Result<Vec<_>>>()?;
        // Before anything else: a key that cannot be used stops the start, naming the file.
        let key = crate::signing::key_for(&config)?;
        let security = LinkSecurity {
            key,
            link_id: config.signing_link_id,
            gate: CommandGate::new(&config, key.is_some()),
        };
        let node = ctx.create_node(ServiceKind::Mavlink)?;
        let mut lp = ServiceLoop::new(&node, ServiceKind::Mavlink, &ctx.shutdown)?;
        let mut nav = NavSubscriber::new(&node)?;
        let fused = TopicSubscriber::<FusedImu>::new(&node, names::FUSED_IMU)?;
        let health = TopicSubscriber::<HealthReport>::new(&node, names::HEALTH)?;
        let own = (config.system_id, config.speaking_component());
        let mut commands = Commands {
            control: TopicPublisher::new(&node, names::FUSION_CONTROL)?,
            replies: TopicSubscriber::new(&node, names::FUSION_REPLY)?,
            pending: Vec::with_capacity(MAX_PENDING),
            next_id: 0,
            own,
            accept: config.accept_commands,
            acks: AckLimiter::new(config.command_ack_rate_hz, config.command_ack_burst),
        };
        let link = Link::start(&endpoints, own, config.queue_capacity, security)
            .context("cannot open the MAVLink endpoints")?;
        tracing::info!(
            endpoints = %config.endpoints.join(","),
            system = own.0,
            component = own.1,
            profile = %config.profile,
            autopilot = %config.autopilot,
            accept_commands = config.accept_commands,
            signed = key.is_some(),
            "streaming MAVLink 2"
        );
        let mut stream = MavlinkStream::new(&config);
        // The pipeline's CPU for SYS_STATUS, measured on its own thread: the loop only reads it.
        let load_stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let (load, load_thread) =
            crate::pipeline_cpu::start(config.rates.sys_status_hz, load_stop.clone());
        let mut version_warning = OtherVersionWarning::new();
        // Samples of another payload version the readers dropped count as rejected too.
        let other_version = |nav: &NavSubscriber, replies: &TopicSubscriber<FusionReply>| {
            nav.rejected() + fused.rejected() + health.rejected() + replies.rejected()
        };
        while lp.running() {
            nav.wait(WAIT)?;
            let mut emit = |m: MavMessage| link.queue(m);
            while let Some(f) = fused.receive()? {
                lp.counters.received += 1;
                stream.on_fused(&f, &mut emit);
            }
            while let Some(n) = nav.receive()? {
                lp.counters.received += 1;
                stream.on_nav(&n, nav.switches(), &mut emit);
            }
            while let Some(h) = health.receive()? {
                stream.on_health(&h, &mut emit);
            }
            stream.set_load_permille(load.permille());
            stream.on_clock(monotonic_ns(), &mut emit);
            while let Ok(c) = link.commands.try_recv() {
                commands.on_command(&c, &link)?;
            }
            commands.on_replies(&link)?;
            copy_counters(&link.counters, &mut lp.counters);
            let refused = other_version(&nav, &commands.replies);
            lp.counters.rejected += refused;
            version_warning.check("mavlink", refused);
            lp.beat()?;
        }
        copy_counters(&link.counters, &mut lp.counters);
        lp.counters.rejected += other_version(&nav, &commands.replies);
        load_stop.store(true, std::sync::atomic::Ordering::Relaxed);
        if let Some(t) = load_thread {
            let _ = t.join();
        }
        let c = &link.counters;
        use std::sync::atomic::Ordering::Relaxed;
        tracing::info!(
            queued = c.queued.load(Relaxed),
            dropped = c.dropped.load(Relaxed),
            sent = c.sent.load(Relaxed),
            send_errors = c.send_errors.load(Relaxed),
            undecodable = c.undecodable.load(Relaxed),
            timesync_answered = c.timesync_answered.load(Relaxed),
            commands_dropped = c.commands_dropped.load(Relaxed),
            unsigned_refused = c.unsigned_refused.load(Relaxed),
            bad_signature_refused = c.bad_signature_refused.load(Relaxed),
            replay_refused = c.replay_refused.load(Relaxed),
            sender_refused = c.sender_refused.load(Relaxed),
            address_refused = c.address_refused.load(Relaxed),
            acks_dropped = c.acks_dropped.load(Relaxed),
            serial_dropped = c.serial_dropped.load(Relaxed),
            serial_lost = c.serial_lost.load(Relaxed),
            serial_reopened = c.serial_reopened.load(Relaxed),
            load_unreadable = load.unreadable.load(Relaxed),
            other_version = other_version(&nav, &commands.replies),
            "MAVLink output stopped"
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command_gate::CommandGate;
    use std::sync::atomic::Ordering::Relaxed;

    #[test]
    fn a_flood_of_acknowledgements_keeps_to_the_limit_and_is_counted() {
        let sink = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
        let endpoint = Endpoint::UdpOut {
            host: "127.0.0.1".into(),
            port: sink.local_addr().unwrap().port(),
        };
        let config = MavlinkConfig::default();
        let link = Link::start(
            &[endpoint],
            (1, 197),
            1024,
            LinkSecurity {
                key: None,
                link_id: 0,
                gate: CommandGate::new(&config, false),
            },
        )
        .unwrap();
        // A burst of 3 and one a second: 1000 acknowledgements asked for within far less than a
        // second let the burst through, at most one more.
        let mut limiter = AckLimiter::new(1.0, 3);
        for _ in 0..1000 {
            send_ack(
                &link,
                &mut limiter,
                MavCmd::MAV_CMD_USER_1,
                MavResult::MAV_RESULT_DENIED,
                (255, 190),
            );
        }
        let queued = link.counters.queued.load(Relaxed);
        assert!((3..=4).contains(&queued), "{queued}");
        assert_eq!(link.counters.acks_dropped.load(Relaxed), 1000 - queued);
    }
}
