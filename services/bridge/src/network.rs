//! The network side: a thread of its own holding the Zenoh session, fed by a bounded queue from the
//! IPC side. The IPC side never waits for it: a full queue drops the sample and counts it. The
//! thread opens the session with backoff (an unreachable router or a refused open is retried, 0.25
//! s doubling to 8 s), declares the node's and each publisher's liveliness tokens as rmw_zenoh
//! nodes do, encodes each message as CDR with rmw_zenoh's attachment, and puts it without
//! blocking (Zenoh's congestion control drops rather than waits).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering::Relaxed};
use std::time::Duration;

use anyhow::{Context, Result};
use crossbeam_channel::{Receiver, RecvTimeoutError, Sender, TrySendError};
use ipc_types::Stage;
use rins_navigator::consumer_origin::OriginTracker;
use rins_ros2_messages::from_rins::{self, FrameNames};
use rins_runtime::clock::monotonic_to_realtime_ns;
use zenoh::Wait;

use crate::attachment::{attachment, gid_of};
use crate::config::ZenohConfig;
use crate::diagnostics::diagnostic_array;
use crate::outbox::Outgoing;
use crate::ros_graph::{self, NodeIdentity, RosType};

/// The first wait after a failed open; doubled after each failure up to [`BACKOFF_MAX`].
const BACKOFF_START: Duration = Duration::from_millis(250);
/// The longest wait between two opens.
const BACKOFF_MAX: Duration = Duration::from_secs(8);
/// How often the thread looks at the stop flag while idle.
const POLL: Duration = Duration::from_millis(100);

/// What the network side did, for the heartbeat and the final log line.
#[derive(Debug, Default)]
pub struct NetworkCounters {
    /// Messages handed to the queue.
    pub queued: AtomicU64,
    /// Messages the full queue could not take.
    pub dropped_full: AtomicU64,
    /// Messages discarded while no session was open.
    pub dropped_offline: AtomicU64,
    /// Messages put on the network.
    pub published: AtomicU64,
    /// Odometry withheld because the solution was not usable (aligning, failed) or had no origin.
    pub withheld: AtomicU64,
    /// Puts (or encodings) that failed.
    pub put_errors: AtomicU64,
    /// Opens of the session that failed (each retried).
    pub open_failures: AtomicU64,
    /// Sessions opened.
    pub sessions: AtomicU64,
}

/// The network side as the IPC side holds it.
pub struct Network {
    queue: Sender<Outgoing>,
    /// Its counters.
    pub counters: Arc<NetworkCounters>,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Network {
    /// Starts the thread; `zenoh_config` is the session's configuration, `config` the bridge's.
    pub fn start(config: &ZenohConfig, zenoh_config: zenoh::Config) -> Result<Self> {
        let (queue, rx) = crossbeam_channel::bounded(config.queue_capacity);
        let counters = Arc::new(NetworkCounters::default());
        let stop = Arc::new(AtomicBool::new(false));
        let side = Side {
            config: config.clone(),
            counters: counters.clone(),
            stop: stop.clone(),
        };
        let thread = std::thread::Builder::new()
            .name("zenoh-out".into())
            .spawn(move || side.run(zenoh_config, &rx))
            .context("cannot start the bridge's network thread")?;
        Ok(Self {
            queue,
            counters,
            stop,
            thread: Some(thread),
        })
    }

    /// Hands `m` over, or drops and counts it when the queue is full. Never waits.
    pub fn send(&self, m: Outgoing) {
        match self.queue.try_send(m) {
            Ok(()) => self.counters.queued.fetch_add(1, Relaxed),
            Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => {
                self.counters.dropped_full.fetch_add(1, Relaxed)
            }
        };
    }

    /// Messages lost on the way: dropped at the full queue or while offline, or failed to put.
    pub fn lost(&self) -> u64 {
        let c = &self.counters;
        c.dropped_full.load(Relaxed) + c.dropped_offline.load(Relaxed) + c.put_errors.load(Relaxed)
    }
}

impl Drop for Network {
    fn drop(&mut self) {
        self.stop.store(true, Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// One topic's publisher with what its attachment needs.
struct Topic {
    publisher: zenoh::pubsub::Publisher<'static>,
    gid: [u8; 16],
    sequence: i64,
    _token: zenoh::liveliness::LivelinessToken,
}

/// The published topics (`None`: off).
struct Topics {
    odometry: Option<Topic>,
    imu: Option<Topic>,
    nav_sat_fix: Option<Topic>,
    diagnostics: Option<Topic>,
    _node: zenoh::liveliness::LivelinessToken,
}

/// The thread's state.
struct Side {
    config: ZenohConfig,
    counters: Arc<NetworkCounters>,
    stop: Arc<AtomicBool>,
}

impl Side {
    fn stopped(&self) -> bool {
        self.stop.load(Relaxed)
    }

    /// Sleeps `d` in slices, draining (and counting) what arrives meanwhile.
    fn wait_offline(&self, d: Duration, rx: &Receiver<Outgoing>) {
        let end = std::time::Instant::now() + d;
        while !self.stopped() && std::time::Instant::now() < end {
            std::thread::sleep(POLL.min(d));
            let n = rx.try_iter().count() as u64;
            self.counters.dropped_offline.fetch_add(n, Relaxed);
        }
    }

    fn run(self, zenoh_config: zenoh::Config, rx: &Receiver<Outgoing>) {
        let mut backoff = BACKOFF_START;
        while !self.stopped() {
            match zenoh::open(zenoh_config.clone()).wait() {
                Ok(session) => {
                    self.counters.sessions.fetch_add(1, Relaxed);
                    tracing::info!(zid = %session.zid(), "Zenoh session open");
                    match self.declare(&session) {
                        Ok(topics) => self.serve(topics, rx),
                        Err(e) => {
                            tracing::error!(error = %format!("{e:#}"), "cannot declare the bridge's publishers")
                        }
                    }
                    let _ = session.close().wait();
                    if self.stopped() {
                        return;
                    }
                }
                Err(e) => {
                    let failures = self.counters.open_failures.fetch_add(1, Relaxed) + 1;
                    // The first failure and every tenth: a router away for hours is not a log flood.
                    if failures == 1 || failures.is_multiple_of(10) {
                        tracing::warn!(error = %e, failures, retry_in_ms = backoff.as_millis() as u64, "cannot open the Zenoh session; retrying");
                    }
                }
            }
            self.wait_offline(backoff, rx);
            backoff = (backoff * 2).min(BACKOFF_MAX);
        }
    }

    fn declare(&self, session: &zenoh::Session) -> Result<Topics> {
        let c = &self.config;
        let me = NodeIdentity {
            domain: c.domain_id,
            zid: session.zid().to_string(),
            node_id: 0,
            namespace: c.namespace.clone(),
            name: c.node_name.clone(),
        };
        let token = |key: String| {
            session
                .liveliness()
                .declare_token(key.clone())
                .wait()
                .map_err(|e| anyhow::anyhow!("liveliness token {key}: {e}"))
        };
        let node = token(me.node_token())?;
        let mut entity = 0;
        let mut topic = |hz: f64, name: &str, ty: RosType| -> Result<Option<Topic>> {
            if hz <= 0.0 {
                return Ok(None);
            }
            entity += 1;
            let full = ros_graph::topic_name(&c.namespace, name);
            let key = ros_graph::topic_key(c.domain_id, &full, ty);
            let live = me.publisher_token(entity, &full, ty);
            let publisher = session
                .declare_publisher(key.clone())
                .wait()
                .map_err(|e| anyhow::anyhow!("publisher {key}: {e}"))?;
            tracing::info!(topic = %full, key = %key, "publishing");
            Ok(Some(Topic {
                publisher,
                gid: gid_of(&live),
                sequence: 0,
                _token: token(live)?,
            }))
        };
        let r = &c.rates;
        Ok(Topics {
            odometry: topic(r.odometry_hz, "odom", ros_graph::ODOMETRY)?,
            imu: topic(r.imu_hz, "imu", ros_graph::IMU)?,
            nav_sat_fix: topic(r.nav_sat_fix_hz, "fix", ros_graph::NAV_SAT_FIX)?,
            diagnostics: topic(
                r.diagnostics_hz,
                "/diagnostics",
                ros_graph::DIAGNOSTIC_ARRAY,
            )?,
            _node: node,
        })
    }

    fn serve(&self, mut topics: Topics, rx: &Receiver<Outgoing>) {
        let frames = FrameNames {
            world: &self.config.world_frame,
            body: &self.config.body_frame,
        };
        let mut origin = OriginTracker::default();
        let mut buffer = Vec::with_capacity(1024);
        loop {
            let m = match rx.recv_timeout(POLL) {
                Ok(m) => m,
                Err(RecvTimeoutError::Timeout) if !self.stopped() => continue,
                Err(_) => return,
            };
            let real = monotonic_to_realtime_ns;
            // The measurement's time for the header; when rins published the sample for the
            // attachment's source timestamp, so that a receiver sees the way from rins to it.
            let sent = match m {
                Outgoing::Odometry { nav, imu } => {
                    let usable = nav.is_shown();
                    origin.observe(&nav, usable);
                    match (origin.origin(), topics.odometry.as_mut()) {
                        (Some(o), Some(t)) if usable => {
                            let msg = from_rins::odometry(
                                &nav,
                                &imu,
                                o,
                                frames,
                                real(nav.header.origin_rx_ns),
                            );
                            put(t, &msg, &mut buffer, nav.header.stage_ns(Stage::Navigator))
                        }
                        _ => {
                            self.counters.withheld.fetch_add(1, Relaxed);
                            continue;
                        }
                    }
                }
                Outgoing::Imu { fused, nav } => {
                    let Some(t) = topics.imu.as_mut() else {
                        continue;
                    };
                    let msg = from_rins::imu(
                        &fused,
                        nav.as_ref(),
                        frames.body,
                        real(fused.header.origin_rx_ns),
                    );
                    put(t, &msg, &mut buffer, fused.header.stage_ns(Stage::Fusion))
                }
                Outgoing::NavSatFix(nav) => {
                    let Some(t) = topics.nav_sat_fix.as_mut() else {
                        continue;
                    };
                    let msg =
                        from_rins::nav_sat_fix(&nav, frames.body, real(nav.header.origin_rx_ns));
                    put(t, &msg, &mut buffer, nav.header.stage_ns(Stage::Navigator))
                }
                Outgoing::Diagnostics(report) => {
                    let Some(t) = topics.diagnostics.as_mut() else {
                        continue;
                    };
                    let msg = diagnostic_array(&report, real(report.now_ns));
                    put(t, &msg, &mut buffer, report.now_ns)
                }
            };
            let counter = if sent {
                &self.counters.published
            } else {
                &self.counters.put_errors
            };
            counter.fetch_add(1, Relaxed);
        }
    }
}

/// Encodes `msg` and puts it on `topic` with rmw_zenoh's attachment, its source time
/// `source_monotonic_ns` on the system clock. Whether it went out.
fn put<T: serde::Serialize>(
    topic: &mut Topic,
    msg: &T,
    buffer: &mut Vec<u8>,
    source_monotonic_ns: u64,
) -> bool {
    if rins_ros2_messages::encode(msg, buffer).is_err() {
        return false;
    }
    topic.sequence += 1;
    let stamp = i64::try_from(monotonic_to_realtime_ns(source_monotonic_ns)).unwrap_or(i64::MAX);
    let extra = attachment(topic.sequence, stamp, &topic.gid);
    topic
        .publisher
        .put(buffer.as_slice())
        .attachment(extra.as_slice())
        .wait()
        .is_ok()
}
