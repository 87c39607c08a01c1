//! `rins replay FILE`: the raw sensor topics of a recording fed through a fresh deployment —
//! fusion, the altimeter and the navigator lanes run live, as `rins up` starts them — and its
//! navigation output compared with the recorded one, sample for sample. `--offline` runs the same
//! library code in this process instead.

use std::collections::HashSet;
use std::process::{Child, Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use std::collections::VecDeque;

use ipc_types::{Altitude, Health, NavState, RawAux, RawBaro, RawImu, RawMag, ServiceKind, names};
use rins::replay::compare::{NavComparison, compare};
use rins::replay::input::{RawSample, ReplayInput};
use rins::replay::offline::OfflinePipeline;
use rins_navigator::aiding_queue::HOLD_US;
use rins_runtime::ipc::{SUBSCRIBER_BUFFER, TopicPublisher, TopicSubscriber};
use rins_runtime::shutdown::Shutdown;
use rins_runtime::tool_node::ToolNode;
use serde::Serialize;

use crate::cli::ReplayArgs;
use crate::commands::progress::Progress;
use crate::config;

/// Raw frames the replay may run ahead of the slower navigator lane: well inside a subscriber's
/// buffer, so that no sample is ever overwritten before it is taken.
const AHEAD: u64 = (SUBSCRIBER_BUFFER / 4) as u64;
/// How long the fresh deployment may take to start every service.
const START_TIMEOUT: Duration = Duration::from_secs(30);
/// How long the pipeline may make no progress before the replay gives up.
const STALL_TIMEOUT: Duration = Duration::from_secs(10);

/// What `rins replay --json` prints last.
#[derive(Debug, Serialize)]
struct ReplayReport {
    file: String,
    mode: &'static str,
    raw_samples: u64,
    imu_frames: u64,
    seconds: f64,
    /// Recorded time over replay time.
    speed_achieved: f64,
    #[serde(flatten)]
    comparison: NavComparison,
    /// Aiding readings the recorded navigator lanes applied after their place in the IMU stream
    /// (a burst of frames after a serial stall); the replay applies them in their place, so the
    /// samples after the first cannot match.
    recorded_late_aiding: u64,
    /// Messages of the file that were skipped or not decodable.
    file_messages_skipped: u64,
    /// Chunks of the file skipped as damaged (their messages are lost, and not counted above).
    file_chunks_damaged: u64,
    file_damage: Option<String>,
}

pub fn run(args: &ReplayArgs) -> Result<ExitCode> {
    let speed = match (args.speed, args.as_fast_as_possible) {
        (Some(s), _) if !(s.is_finite() && s > 0.0) => {
            bail!("--speed {s}: must be a positive multiple of the recorded pace")
        }
        (Some(s), _) => Some(s),
        (None, true) => None,
        (None, false) => Some(1.0),
    };
    let cfg = config::load(args.config.as_deref())?;
    let input = ReplayInput::read(&args.file)?;
    if input.raw.is_empty() {
        bail!(
            "{}: no raw sensor samples to replay (record with the raw topics: rins record FILE)",
            args.file.display()
        );
    }
    let started = Instant::now();
    let (mode, replayed) = if args.offline {
        let built = cfg.build_services()?;
        let pipeline = OfflinePipeline::new(
            built.fuser,
            built.altimeter,
            built.navigator,
            cfg.deployment.navigator_lanes,
        );
        let mut progress = Progress::new("replaying offline");
        let out = pipeline.run(&input, |share| {
            progress.set((share * 1000.0) as usize, 1000)
        });
        progress.finish();
        ("offline", out)
    } else {
        (
            "live",
            replay_live(args, &input, speed, cfg.deployment.navigator_lanes)?,
        )
    };
    let seconds = started.elapsed().as_secs_f64();
    let span_s = recorded_span_s(&input);
    let report = ReplayReport {
        file: args.file.display().to_string(),
        mode,
        raw_samples: input.raw.len() as u64,
        imu_frames: input.imu_frames() as u64,
        seconds,
        speed_achieved: if seconds > 0.0 { span_s / seconds } else { 0.0 },
        comparison: compare(&input.nav, &replayed),
        recorded_late_aiding: input.recorded_late_aiding.iter().sum(),
        file_messages_skipped: input.skipped + input.undecodable,
        file_chunks_damaged: input.damaged_chunks,
        file_damage: input.damage.clone(),
    };
    let c = &report.comparison;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        println!(
            "{}: {} raw samples replayed {} in {:.1} s ({:.1}× the recorded pace); navigation: {} \
             samples compared, {} different, {} missing",
            report.file,
            report.raw_samples,
            mode,
            seconds,
            report.speed_achieved,
            c.nav_samples_compared,
            c.nav_samples_different,
            c.nav_samples_missing
        );
        if report.file_chunks_damaged > 0 || report.file_messages_skipped > 0 {
            println!(
                "{}: {} damaged chunks and {} damaged messages skipped",
                report.file, report.file_chunks_damaged, report.file_messages_skipped
            );
        }
        if let Some(damage) = &report.file_damage {
            println!("{}: reading stopped early: {damage}", report.file);
        }
        if report.recorded_late_aiding > 0 && c.nav_samples_different > 0 {
            println!(
                "the recording's navigator applied {} aiding readings after their place in the IMU \
                 stream (a burst of frames after a serial stall); the replay applies them in their \
                 place, so the samples after the first of them differ",
                report.recorded_late_aiding
            );
        }
    }
    // Not identical is a finding a script must see.
    Ok(
        if c.nav_samples_different == 0 && c.nav_samples_compared > 0 {
            ExitCode::SUCCESS
        } else {
            ExitCode::FAILURE
        },
    )
}

/// Recorded time from the first raw sample to the last, s.
fn recorded_span_s(input: &ReplayInput) -> f64 {
    let times = input.raw.iter().map(RawSample::rx_ns);
    let (lo, hi) = times.fold((u64::MAX, 0), |(lo, hi), t| (lo.min(t), hi.max(t)));
    hi.saturating_sub(lo) as f64 * 1e-9
}

/// The deployment the replay feeds: `rins up` without acquisition and simulator.
struct Deployment {
    child: Child,
}

impl Deployment {
    fn start(args: &ReplayArgs) -> Result<Self> {
        let exe = std::env::current_exe().context("cannot locate the rins executable")?;
        let mut cmd = Command::new(exe);
        cmd.args(["up", "--external-source", "--json"]);
        if let Some(config) = &args.config {
            cmd.arg("--config").arg(config);
        }
        let child = cmd
            .stdout(Stdio::null())
            .spawn()
            .context("cannot start the replaying deployment")?;
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
            bail!("the replaying deployment ended with {status}");
        }
        Ok(())
    }
}

/// The replaying deployment's navigation output, per lane, as it arrives, and how far the
/// altimeter got.
struct NavTap {
    lanes: [TopicSubscriber<NavState>; 2],
    out: [Vec<NavState>; 2],
    altitude: TopicSubscriber<Altitude>,
    /// Device time of the newest altitude, µs.
    altitude_t_us: Option<u64>,
}

impl NavTap {
    fn drain(&mut self) -> Result<bool> {
        let mut any = false;
        while let Some(a) = self.altitude.receive()? {
            self.altitude_t_us = Some(a.header.origin_device_time_us);
            any = true;
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

fn replay_live(
    args: &ReplayArgs,
    input: &ReplayInput,
    speed: Option<f64>,
    lanes: u8,
) -> Result<[Vec<NavState>; 2]> {
    let shutdown = Shutdown::install()?;
    // A replay into a running deployment would mix its samples with the live ones: refused, as
    // `rins up` refuses a second deployment on one prefix.
    let settings = rins_runtime::ipc::IpcSettings::from_env();
    rins_watchdog::deployment_checks::ensure_no_live_deployment(&settings)
        .context("rins replay starts a deployment of its own")?;
    let deployment = Deployment::start(args)?;
    let result = feed(input, speed, lanes, &shutdown);
    let stopped = deployment.stop();
    let out = result?;
    stopped?;
    Ok(out)
}

/// Waits for every service of the deployment to beat, then publishes the raw samples, paced, and
/// collects the navigation output.
fn feed(
    input: &ReplayInput,
    speed: Option<f64>,
    lanes: u8,
    shutdown: &Shutdown,
) -> Result<[Vec<NavState>; 2]> {
    let tool = ToolNode::join("replay")?;
    let node = tool.node();
    let heartbeats = TopicSubscriber::<Health>::new(node, names::HEARTBEAT)?;
    let mut expected: HashSet<u8> = [ServiceKind::Fusion, ServiceKind::Altimeter]
        .iter()
        .chain(&ServiceKind::NAVIGATOR_LANES[..usize::from(lanes.clamp(1, 2))])
        .map(|k| *k as u8)
        .collect();
    let deadline = Instant::now() + START_TIMEOUT;
    while !expected.is_empty() {
        if shutdown.requested() {
            bail!("stopped");
        }
        if Instant::now() > deadline {
            bail!(
                "the replaying deployment did not start within {} s (services missing: {:?})",
                START_TIMEOUT.as_secs(),
                expected
            );
        }
        heartbeats.wait(Duration::from_millis(50))?;
        while let Some(h) = heartbeats.receive()? {
            expected.remove(&h.service);
        }
    }
    let imu = TopicPublisher::<RawImu>::new(node, names::RAW_IMU)?;
    let baro = TopicPublisher::<RawBaro>::new(node, names::RAW_BARO)?;
    let mag = TopicPublisher::<RawMag>::new(node, names::RAW_MAG)?;
    let aux = TopicPublisher::<RawAux>::new(node, names::RAW_AUX)?;
    let mut tap = NavTap {
        lanes: [
            TopicSubscriber::new(node, names::NAV_LANES[0])?,
            TopicSubscriber::new(node, names::NAV_LANES[1])?,
        ],
        out: [Vec::new(), Vec::new()],
        altitude: TopicSubscriber::new(node, names::ALTITUDE)?,
        altitude_t_us: None,
    };
    // Barometer samples published whose altitude the navigator may not have yet.
    let mut baro_in_flight: VecDeque<u64> = VecDeque::new();
    let t0 = input.raw.first().map_or(0, RawSample::rx_ns);
    let started = Instant::now();
    let mut progress = Progress::new("replaying");
    let mut last_imu_seq = 0;
    for (i, sample) in input.raw.iter().enumerate() {
        if shutdown.requested() {
            bail!("stopped");
        }
        if let Some(speed) = speed {
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
        }
        tap.drain()?;
        if i % 1000 == 0 {
            progress.set(i, input.raw.len());
        }
    }
    progress.finish();
    wait_until(&mut tap, lanes, last_imu_seq, last_imu_seq)?;
    let out = std::mem::take(&mut tap.out);
    drop(tap);
    drop((imu, baro, mag, aux, heartbeats));
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
                    "the replaying altimeter delivered nothing for {} s (waiting for device time {t_us} µs)",
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
                "the replaying pipeline delivered nothing for {} s (navigation up to sequence {}, \
                 waiting for {seq})",
                STALL_TIMEOUT.as_secs(),
                tap.delivered(lanes)
            ));
        } else {
            tap.lanes[0].wait(Duration::from_millis(1))?;
        }
    }
    Ok(())
}
