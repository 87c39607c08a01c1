//! Raw sensor samples through a deployment of the running processes: `rins up
//! --external-source` (fusion, the altimeter and the navigator lanes, no acquisition) started with
//! a given configuration — on the environment's IPC prefix, or on a private root of its own — fed
//! the samples at their recorded pace or as fast as the pipeline takes them, its output collected,
//! and stopped. `rins replay` and the live evaluations share it.

use std::collections::{HashSet, VecDeque};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use ipc_types::{
    Altitude, ChannelState, FusedImu, GnssFix, Health, NavState, RawAirspeed, RawAux, RawBaro,
    RawImu, RawMag, ServiceKind, names,
};
use rins_navigator::aiding::hold::HOLD_US;
use rins_runtime::ipc::{
    IpcSettings, PREFIX_ENV, ROOT_ENV, SUBSCRIBER_BUFFER, TopicPublisher, TopicSubscriber,
};
use rins_runtime::shutdown::Shutdown;
use rins_runtime::tool_node::ToolNode;

use super::input::RawSample;

/// Raw frames the feed may run ahead of the slower navigator lane: well inside a subscriber's
/// buffer, so that no sample is ever overwritten before it is taken.
const AHEAD: u64 = (SUBSCRIBER_BUFFER / 4) as u64;
/// How long the fresh deployment may take to start every service.
const START_TIMEOUT: Duration = Duration::from_secs(30);
/// How long the pipeline may make no progress before the feed gives up.
const STALL_TIMEOUT: Duration = Duration::from_secs(10);

/// How to run the deployment.
#[derive(Debug, Clone, Default)]
pub struct LiveOptions {
    /// The rins executable that runs the deployment (`None`: this process's own).
    pub exe: Option<PathBuf>,
    /// The configuration file the deployment runs (`None`: the built-in one).
    pub config: Option<PathBuf>,
    /// Navigator lanes the configuration runs (1 or 2).
    pub lanes: u8,
    /// Multiple of the recorded pace (`None`: as fast as the pipeline takes the samples).
    pub speed: Option<f64>,
    /// A private deployment on these settings (its root and shared memory removed afterwards);
    /// `None`: the environment's prefix, refused while another deployment runs on it.
    pub private: Option<IpcSettings>,
    /// Where the deployment's log goes (`None`: this process's standard error).
    pub log: Option<PathBuf>,
    /// The navigator aids with the receiver fixes the feed publishes (`rins up --gnss`; no
    /// receiver service is started).
    pub gnss: bool,
}

/// What the deployment published while it was fed.
#[derive(Debug, Default)]
pub struct LiveOutput {
    /// Each navigator lane's states, in order (lane 1 empty with one lane).
    pub nav: [Vec<NavState>; 2],
    /// The last heartbeat of each service that beat.
    pub health: Vec<Health>,
    /// Fusion's channel state changes seen (a channel turning suspect, excluded, or back).
    pub channel_events: u64,
    /// Channels fusion excluded at some time (`gyro 2`, `accel 0`, ...), in order of first
    /// exclusion.
    pub excluded_channels: Vec<String>,
    /// Fused samples missed by the tap (gaps in their sequence numbers): their channel states
    /// were not seen.
    pub fused_missed: u64,
}

/// Settings of a private deployment: a new root (mode 0700) under the temporary directory and a
/// prefix of this process's own.
pub fn private_settings(tag: &str) -> Result<IpcSettings> {
    use std::os::unix::fs::DirBuilderExt;
    use std::sync::atomic::{AtomicU32, Ordering};
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let pid = std::process::id();
    let root = std::env::temp_dir().join(format!("rins-{tag}-{pid}-{n}"));
    std::fs::DirBuilder::new()
        .mode(0o700)
        .create(&root)
        .with_context(|| format!("cannot create the private IPC root {}", root.display()))?;
    Ok(IpcSettings::new(
        format!("{tag}{pid}x{n}_"),
        root.display().to_string(),
    ))
}

/// Runs `raw` (in frame order) through a fresh deployment with `options`; `progress(done,
/// total)` now and then.
pub fn run(
    raw: &[RawSample],
    options: &LiveOptions,
    shutdown: &Shutdown,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<LiveOutput> {
    let settings = match &options.private {
        Some(s) => s.clone(),
        None => {
            // A feed into a running deployment would mix its samples with the live ones: refused,
            // as `rins up` refuses a second deployment on one prefix.
            let settings = IpcSettings::from_env();
            rins_watchdog::deployment_checks::ensure_no_live_deployment(&settings)
                .context("a live replay starts a deployment of its own")?;
            settings
        }
    };
    let deployment = Deployment::start(options)?;
    let result = feed(raw, options, &settings, shutdown, progress);
    let stopped = deployment.stop();
    if options.private.is_some() {
        rins_runtime::shm_cleanup::remove_all(&settings, true);
    }
    let out = result.with_context(|| match &options.log {
        Some(log) => format!("the deployment's log: {}", log.display()),
        None => "the live replay".to_string(),
    })?;
    stopped?;
    Ok(out)
}

/// The deployment fed: `rins up` without acquisition and simulator.
struct Deployment {
    child: Child,
}

impl Deployment {
    fn start(options: &LiveOptions) -> Result<Self> {
        let exe = match &options.exe {
            Some(exe) => exe.clone(),
            None => std::env::current_exe().context("cannot locate the rins executable")?,
        };
        let mut cmd = Command::new(exe);
        cmd.args(["up", "--external-source", "--json"]);
        if let Some(config) = &options.config {
            cmd.arg("--config").arg(config);
        }
        if options.gnss {
            cmd.arg("--gnss");
        }
        if let Some(s) = &options.private {
            cmd.env(ROOT_ENV, &s.root).env(PREFIX_ENV, &s.prefix);
        }
        if let Some(log) = &options.log {
            let file = std::fs::File::create(log)
                .with_context(|| format!("cannot create {}", log.display()))?;
            cmd.stderr(file);
        }
        let child = cmd
            .stdout(Stdio::null())
            .spawn()
            .context("cannot start the deployment")?;
        Ok(Self { child })
    }

    /// Stops the deployment (SIGINT: a clean stop) and waits for it.
    fn stop(mut self) -> Result<()> {
        if let Ok(pid) = i32::try_from(self.child.id()) {
            // SAFETY: kill(2) on our own, not yet reaped, child.
            unsafe { libc::kill(pid, libc::SIGINT) };
        }
        let status = self.child.wait()?;
        if !status.success() {
            bail!("the deployment ended with {status}");
        }
        Ok(())
    }
}

/// Fusion's channel states as they change.
#[derive(Default)]
struct ChannelWatch {
    last: Option<([u8; ipc_types::MAX_CHANNELS], [u8; ipc_types::MAX_CHANNELS])>,
    last_seq: u64,
    events: u64,
    excluded: Vec<String>,
    missed: u64,
}

impl ChannelWatch {
    fn push(&mut self, imu: &FusedImu) {
        let seq = imu.header.origin_seq;
        if self.last_seq != 0 && seq > self.last_seq + 1 {
            self.missed += seq - self.last_seq - 1;
        }
        self.last_seq = seq;
        let now = (imu.gyro_state, imu.accel_state);
        let kinds = [
            ("gyro", &now.0, usize::from(imu.n_gyro)),
            ("accel", &now.1, usize::from(imu.n_accel)),
        ];
        for (k, (kind, states, n)) in kinds.into_iter().enumerate() {
            for (i, &state) in states.iter().enumerate().take(n) {
                let before = self.last.map(|l| if k == 0 { l.0[i] } else { l.1[i] });
                if before.is_some_and(|b| b != state) {
                    self.events += 1;
                }
                if state == ChannelState::Excluded as u8 {
                    let name = format!("{kind} {i}");
                    if !self.excluded.contains(&name) {
                        self.excluded.push(name);
                    }
                }
            }
        }
        self.last = Some(now);
    }
}

/// The deployment's output, per lane, as it arrives, and how far the altimeter got.
struct NavTap {
    lanes: [TopicSubscriber<NavState>; 2],
    out: [Vec<NavState>; 2],
    altitude: TopicSubscriber<Altitude>,
    /// Device time of the newest altitude, µs.
    altitude_t_us: Option<u64>,
    fused: TopicSubscriber<FusedImu>,
    channels: ChannelWatch,
    heartbeats: TopicSubscriber<Health>,
    health: Vec<Health>,
}

impl NavTap {
    fn drain(&mut self) -> Result<bool> {
        let mut any = false;
        while let Some(a) = self.altitude.receive()? {
            self.altitude_t_us = Some(a.header.origin_device_time_us);
            any = true;
        }
        while let Some(f) = self.fused.receive()? {
            self.channels.push(&f);
        }
        while let Some(h) = self.heartbeats.receive()? {
            match self.health.iter_mut().find(|k| k.service == h.service) {
                Some(k) => *k = h,
                None => self.health.push(h),
            }
        }
        for (sub, out) in self.lanes.iter().zip(&mut self.out) {
            while let Some(n) = sub.receive()? {
                out.push(n);
                any = true;
            }
        }
        Ok(any)
    }

    /// The sequence number every running lane has delivered up to.
    fn delivered(&self, lanes: u8) -> u64 {
        self.out[..usize::from(lanes.clamp(1, 2))]
            .iter()
            .map(|o| o.last().map_or(0, |n| n.header.origin_seq))
            .min()
            .unwrap_or(0)
    }
}

/// Waits for every service of the deployment to beat, then publishes the raw samples, paced, and
/// collects the output.
fn feed(
    raw: &[RawSample],
    options: &LiveOptions,
    settings: &IpcSettings,
    shutdown: &Shutdown,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<LiveOutput> {
    let lanes = options.lanes;
    let tool = match options.private {
        Some(_) => ToolNode::join_settings("replay", settings.clone())?,
        None => ToolNode::join("replay")?,
    };
    let node = tool.node();
    let heartbeats = TopicSubscriber::<Health>::new(node, names::HEARTBEAT)?;
    let mut expected: HashSet<u8> = [ServiceKind::Fusion, ServiceKind::Altimeter]
        .iter()
        .chain(&ServiceKind::NAVIGATOR_LANES[..usize::from(lanes.clamp(1, 2))])
        .map(|k| *k as u8)
        .collect();
    let mut health = Vec::new();
    let deadline = Instant::now() + START_TIMEOUT;
    while !expected.is_empty() {
        if shutdown.requested() {
            bail!("stopped");
        }
        if Instant::now() > deadline {
            bail!(
                "the deployment did not start within {} s (services missing: {:?})",
                START_TIMEOUT.as_secs(),
                expected
            );
        }
        heartbeats.wait(Duration::from_millis(50))?;
        while let Some(h) = heartbeats.receive()? {
            expected.remove(&h.service);
            health.push(h);
        }
    }
    let imu = TopicPublisher::<RawImu>::new(node, names::RAW_IMU)?;
    let baro = TopicPublisher::<RawBaro>::new(node, names::RAW_BARO)?;
    let mag = TopicPublisher::<RawMag>::new(node, names::RAW_MAG)?;
    let aux = TopicPublisher::<RawAux>::new(node, names::RAW_AUX)?;
    let airspeed = TopicPublisher::<RawAirspeed>::new(node, names::RAW_AIRSPEED)?;
    let gnss = TopicPublisher::<GnssFix>::new(node, names::GNSS)?;
    let mut tap = NavTap {
        lanes: [
            TopicSubscriber::new(node, names::NAV_LANES[0])?,
            TopicSubscriber::new(node, names::NAV_LANES[1])?,
        ],
        out: [Vec::new(), Vec::new()],
        altitude: TopicSubscriber::new(node, names::ALTITUDE)?,
        altitude_t_us: None,
        fused: TopicSubscriber::new(node, names::FUSED_IMU)?,
        channels: ChannelWatch::default(),
        heartbeats,
        health: Vec::new(),
    };
    // Barometer samples published whose altitude the navigator may not have yet.
    let mut baro_in_flight: VecDeque<u64> = VecDeque::new();
    let t0 = raw.first().map_or(0, RawSample::rx_ns);
    let started = Instant::now();
    let mut last_imu_seq = 0;
    for (i, sample) in raw.iter().enumerate() {
        if shutdown.requested() {
            bail!("stopped");
        }
        if let Some(speed) = options.speed {
            let due =
                Duration::from_secs_f64(sample.rx_ns().saturating_sub(t0) as f64 * 1e-9 / speed);
            if let Some(wait) = due.checked_sub(started.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        if let RawSample::Imu(raw) = sample {
            // Never further ahead of the navigator than its buffers hold.
            wait_until(
                &mut tap,
                lanes,
                raw.header.origin_seq.saturating_sub(AHEAD),
                last_imu_seq,
            )?;
            last_imu_seq = raw.header.origin_seq;
            // The navigator applies an altitude where the IMU stream passes its time: the
            // altimeter must have delivered it before an IMU frame that far on is published, as
            // it had, with time to spare, when the recording was made. (Magnetometer samples go
            // straight to the navigator, published before the later IMU frames.)
            let t = raw.header.origin_device_time_us;
            while let Some(&b) = baro_in_flight.front() {
                if b.saturating_add(HOLD_US) > t {
                    break;
                }
                wait_for_altitude(&mut tap, b)?;
                baro_in_flight.pop_front();
            }
        }
        if let RawSample::Baro(raw) = sample {
            baro_in_flight.push_back(raw.header.origin_device_time_us);
        }
        match sample {
            RawSample::Imu(s) => imu.publish(*s)?,
            RawSample::Baro(s) => baro.publish(*s)?,
            RawSample::Mag(s) => mag.publish(*s)?,
            RawSample::Aux(s) => aux.publish(*s)?,
            RawSample::Airspeed(s) => airspeed.publish(*s)?,
            RawSample::Gnss(s) => gnss.publish(*s)?,
        }
        tap.drain()?;
        if i % 1000 == 0 {
            progress(i, raw.len());
        }
    }
    wait_until(&mut tap, lanes, last_imu_seq, last_imu_seq)?;
    progress(raw.len(), raw.len());
    let mut out = LiveOutput {
        nav: std::mem::take(&mut tap.out),
        health,
        channel_events: tap.channels.events,
        excluded_channels: std::mem::take(&mut tap.channels.excluded),
        fused_missed: tap.channels.missed,
    };
    for h in std::mem::take(&mut tap.health) {
        match out.health.iter_mut().find(|k| k.service == h.service) {
            Some(k) => *k = h,
            None => out.health.push(h),
        }
    }
    drop(tap);
    drop((imu, baro, mag, aux, airspeed, gnss));
    drop(tool);
    Ok(out)
}

/// Drains the topics until the altimeter delivered the altitude of device time `t_us`.
fn wait_for_altitude(tap: &mut NavTap, t_us: u64) -> Result<()> {
    let started = Instant::now();
    while tap.altitude_t_us.is_none_or(|a| a < t_us) {
        if !tap.drain()? {
            if started.elapsed() > STALL_TIMEOUT {
                bail!(
                    "the altimeter delivered nothing for {} s (waiting for device time {t_us} µs)",
                    STALL_TIMEOUT.as_secs()
                );
            }
            tap.altitude.wait(Duration::from_millis(1))?;
        }
    }
    Ok(())
}

/// Drains the navigation output until every lane delivered `seq` (none before the first frame);
/// an error when nothing comes for [`STALL_TIMEOUT`].
fn wait_until(tap: &mut NavTap, lanes: u8, seq: u64, published_up_to: u64) -> Result<()> {
    if published_up_to == 0 {
        return Ok(());
    }
    let mut last_progress = Instant::now();
    while tap.delivered(lanes) < seq {
        if tap.drain()? {
            last_progress = Instant::now();
        } else if last_progress.elapsed() > STALL_TIMEOUT {
            return Err(anyhow!(
                "the pipeline delivered nothing for {} s (navigation up to sequence {}, waiting \
                 for {seq})",
                STALL_TIMEOUT.as_secs(),
                tap.delivered(lanes)
            ));
        } else {
            tap.lanes[0].wait(Duration::from_millis(1))?;
        }
    }
    Ok(())
}
