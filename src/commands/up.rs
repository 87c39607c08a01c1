//! `rins up`: the watchdog. Starts every service (and the simulator unless a real port is given) as
//! child processes, restarts children that exit, prints a status line per second, and on shutdown
//! stops everything and removes the deployment's shared memory.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use ipc_types::ServiceKind;
use rins_runtime::ipc::{IpcSettings, create_node};
use rins_runtime::shm_cleanup;
use rins_runtime::shutdown::Shutdown;
use rins_watchdog::health_publisher::HealthPublisher;
use rins_watchdog::monitor::{COUNTED, Monitor};
use rins_watchdog::output_deadline::OutputDeadline;
use rins_watchdog::restart_policy::GiveUp;
use rins_watchdog::restart_timing::RestartTiming;
use rins_watchdog::status::status_line;
use rins_watchdog::summary::Summary;
use rins_watchdog::supervisor::{ChildEvent, ChildSpec, Supervisor};

use crate::cli::UpArgs;
use crate::commands::fault_args;
use crate::config::{self, RinsConfig};

/// Services in start order: consumers first, so that no sample is published before its subscriber
/// exists. The hot-standby navigator lane runs when the deployment asks for two lanes.
fn services(cfg: &RinsConfig) -> Vec<&'static str> {
    let mut names = vec!["navigator"];
    if cfg.deployment.navigator_lanes == 2 {
        names.push("navigator-standby");
    }
    names.extend(["altimeter", "fusion", "acquisition"]);
    names
}

/// How long the simulator may take to create its pseudo-terminal.
const SIM_START_TIMEOUT: Duration = Duration::from_secs(10);

/// Period of the supervision loop: topics drained and children checked this often.
const LOOP_PERIOD: Duration = Duration::from_millis(1);

/// Refuses to start while another user's files are on the prefix in /dev/shm: they are never
/// opened, never removed.
fn refuse_foreign_entries(settings: &IpcSettings) -> Result<()> {
    let foreign = shm_cleanup::foreign_entries(settings, settings.owner);
    if !foreign.is_empty() {
        bail!(
            "IPC prefix {:?} is in use by someone else: {}. Another user runs a deployment on this \
             prefix or planted these files; they are left alone. Set {} to a prefix of your own \
             (the default is per user), or have their owner remove them",
            settings.prefix,
            shm_cleanup::describe_entries(&foreign),
            rins_runtime::ipc::PREFIX_ENV
        );
    }
    Ok(())
}

/// Refuses to start while another deployment runs on the prefix; otherwise removes what a dead run
/// of ours left.
fn ensure_no_live_deployment(settings: &IpcSettings) -> Result<()> {
    let config = settings.iceoryx_config()?;
    let (mut alive, mut tools) = (0, 0);
    iceoryx2::prelude::Node::<iceoryx2::prelude::ipc::Service>::list(&config, |state| {
        // Only the pipeline's own processes make a deployment; a tool (`rins echo`, `status`,
        // `soak`, …) waiting on the prefix for the pipeline to start does not.
        if let iceoryx2::prelude::NodeState::Alive(view) = &state {
            use iceoryx2::node::NodeView;
            let service = view
                .details()
                .as_ref()
                .is_some_and(|d| ipc_types::ServiceKind::from_name(d.name().as_str()).is_some());
            if service {
                alive += 1;
            } else {
                tools += 1;
            }
        }
        iceoryx2::prelude::CallbackProgression::Continue
    })
    .map_err(|e| anyhow::anyhow!("cannot list iceoryx2 nodes: {e:?}"))?;
    if alive > 0 {
        bail!(
            "another rins deployment is running on IPC prefix {:?} ({alive} live processes): stop it or set {} to another prefix",
            settings.prefix,
            rins_runtime::ipc::PREFIX_ENV
        );
    }
    // No pipeline alive: whatever is left belongs to a deployment that died; start clean. While a
    // tool is already waiting on the prefix its shared memory must stay, so only the resources of
    // dead nodes go then.
    if tools == 0 {
        let removed = shm_cleanup::remove_all(settings, false);
        if removed > 0 {
            tracing::info!(removed, "removed shared memory left by an earlier run");
        }
    } else {
        let removed = rins_runtime::ipc::remove_dead_nodes(settings)?;
        if removed > 0 {
            tracing::info!(
                removed,
                "removed the resources of dead nodes left by an earlier run"
            );
        }
    }
    Ok(())
}

/// Waits for the simulator's terminal link; returns false when a stop was requested meanwhile (a
/// clean stop, not a failure).
fn wait_for_path(path: &Path, supervisor: &mut Supervisor, shutdown: &Shutdown) -> Result<bool> {
    let deadline = Instant::now() + SIM_START_TIMEOUT;
    let mut events = Vec::new();
    while !path.exists() {
        if shutdown.requested() {
            return Ok(false);
        }
        supervisor.poll(&mut events);
        // A child given up (a restart limit of 0) stops the start-up too rather than being lost.
        if let Some(
            ChildEvent::Exited { name, status, .. } | ChildEvent::GaveUp { name, status, .. },
        ) = events.first()
        {
            bail!(
                "{name} exited ({status}) before creating {}",
                path.display()
            );
        }
        if Instant::now() >= deadline {
            bail!(
                "simulator did not create {} in {:?}",
                path.display(),
                SIM_START_TIMEOUT
            );
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    Ok(true)
}

fn apply_overrides(cfg: &mut RinsConfig, args: &UpArgs) -> Result<()> {
    if let Some(scenario) = args.scenario {
        cfg.set_scenario(scenario);
    }
    if let Some(seed) = args.seed {
        cfg.sim.seed = seed;
    }
    if let Some(duration) = args.duration
        && !(duration.is_finite() && duration > 0.0)
    {
        bail!("--duration {duration}: must be a positive number of seconds");
    }
    if let Some(port) = &args.port {
        if !port.exists() {
            bail!(
                "serial device {} does not exist: check the cable and the device path",
                port.display()
            );
        }
        cfg.acquisition.port = Some(port.to_string_lossy().into_owned());
    }
    if !args.faults.is_empty() {
        if args.port.is_some() {
            bail!("--inject and --faults need the simulator: they cannot be used with --port");
        }
        // Checked here so that a bad fault stops the start-up before any child runs.
        let (n_gyro, n_accel) = fault_args::channel_counts(cfg)?;
        fault_args::schedule(&args.faults, n_gyro, n_accel)?;
    }
    Ok(())
}

pub fn run(args: &UpArgs) -> Result<std::process::ExitCode> {
    // First of all: a stop requested at any moment from here on is a clean stop, not a death by
    // signal that leaves children and shared memory behind.
    let shutdown = Shutdown::install()?;
    let mut cfg = config::load(args.config.as_deref())?;
    apply_overrides(&mut cfg, args)?;
    // Refused here, before any child runs, rather than by a child in a restart loop.
    cfg.build_services()?;
    if shutdown.requested() {
        return Ok(std::process::ExitCode::SUCCESS);
    }
    let settings = IpcSettings::from_env();
    refuse_foreign_entries(&settings)?;
    // Only a root this run created is removed at the end (and only when empty).
    let root_created = settings.ensure_root()?;
    let run_dir = ensure_no_live_deployment(&settings)
        .and_then(|()| Ok(settings.ensure_run_dir()?))
        .inspect_err(|_| {
            if root_created {
                let _ = std::fs::remove_dir(&settings.root);
            }
        })?;
    // A new deployment numbers its frames afresh: the last one's resume point does not apply.
    let _ = std::fs::remove_file(rins_acquisition::resume_file::path_for(&settings));
    let simulate = cfg.acquisition.port.is_none();
    let link = run_dir.join("sim-tty");
    if simulate {
        let _ = std::fs::remove_file(&link);
        cfg.acquisition.port = Some(link.to_string_lossy().into_owned());
    }
    // Children read the same file (or the built-in configuration); command-line overrides travel as
    // arguments.
    let config_args: Vec<String> = match &args.config {
        Some(path) => vec!["--config".into(), path.to_string_lossy().into_owned()],
        None => Vec::new(),
    };
    let port = cfg.acquisition.port.clone().unwrap_or_default();

    let exe = std::env::current_exe().context("cannot locate the rins executable")?;
    let node = create_node("watchdog", &settings)?;
    let mut monitor = Monitor::new(&node)?;
    let mut supervisor = Supervisor::new();
    let started = Instant::now();
    // With the check off, a silent process is still reported, after an hour.
    let silent_after = match cfg.watchdog.heartbeat_timeout_s {
        0.0 => Duration::from_secs(3600),
        s => Duration::from_secs_f64(s),
    };
    let mut health = HealthPublisher::new(&node, started, silent_after)?;
    let mut timing = RestartTiming::default();
    let outcome = (|| -> Result<()> {
        for name in services(&cfg) {
            if shutdown.requested() {
                return Ok(());
            }
            let mut child_args = vec!["service".to_string(), name.to_string()];
            child_args.extend(config_args.iter().cloned());
            if name == "acquisition" {
                child_args.extend(["--port".to_string(), port.clone()]);
            }
            supervisor.start(ChildSpec {
                name: name.to_string(),
                program: exe.clone(),
                args: child_args,
                policy: cfg.watchdog.policy_for(name),
            })?;
        }
        if simulate {
            supervisor.start(ChildSpec {
                name: "sim".into(),
                program: exe.clone(),
                args: sim_args(&cfg, &config_args, &link, args),
                policy: cfg.watchdog.policy_for("sim"),
            })?;
            if !wait_for_path(&link, &mut supervisor, &shutdown)? {
                return Ok(());
            }
        }
        supervise(
            &cfg,
            &settings,
            args,
            &shutdown,
            Watch {
                supervisor: &mut supervisor,
                monitor: &mut monitor,
                health: &mut health,
                timing: &mut timing,
            },
            started,
        )
    })();

    supervisor.stop_all(Duration::from_millis(cfg.watchdog.stop_grace_ms));
    // Drain what the children published while stopping, then release our own ports.
    let _ = monitor.drain();
    let summary = summarise(&monitor, &supervisor, &timing, started.elapsed(), simulate);
    drop(health);
    drop(monitor);
    drop(node);
    shm_cleanup::remove_all(&settings, root_created);
    // Ours only: another user's files on the prefix are not a leak of this deployment.
    let leaked = shm_cleanup::inspect(Path::new(shm_cleanup::SHM_DIR), &settings.prefix)
        .iter()
        .filter(|e| e.belongs_to(settings.owner))
        .count() as u64;
    outcome?;
    if args.json {
        let summary = Summary {
            shm_leaked: leaked,
            ..summary
        };
        println!("{}", serde_json::to_string(&summary)?);
    }
    Ok(std::process::ExitCode::SUCCESS)
}

fn sim_args(cfg: &RinsConfig, config_args: &[String], link: &Path, up: &UpArgs) -> Vec<String> {
    let mut args = vec!["sim".to_string()];
    args.extend(config_args.iter().cloned());
    args.extend([
        "--scenario".to_string(),
        cfg.scenario_name().to_string(),
        "--seed".to_string(),
        cfg.sim.seed.to_string(),
        "--link".to_string(),
        link.to_string_lossy().into_owned(),
    ]);
    // The simulator applies timed faults itself, exactly at their tick.
    for spec in &up.faults.inject {
        args.extend(["--inject".to_string(), spec.clone()]);
    }
    if let Some(file) = &up.faults.faults {
        args.extend(["--faults".to_string(), file.to_string_lossy().into_owned()]);
    }
    args
}

/// SIGKILL to every process the report calls silent (heartbeat overdue while it still runs: hung or
/// stopped); the supervisor restarts it like any process that exited.
fn kill_hung(report: &ipc_types::HealthReport, supervisor: &mut Supervisor) {
    let count = usize::from(report.count).min(report.services.len());
    for s in &report.services[..count] {
        let silent =
            ipc_types::ServiceState::from_u8(s.state) == Some(ipc_types::ServiceState::Silent);
        let own = s.pid == std::process::id();
        if silent && !own && supervisor.kill(s.pid) {
            tracing::warn!(
                service = ipc_types::ServiceKind::from_u8(s.service).map_or("?", |k| k.name()),
                pid = s.pid,
                heartbeat_age_ms = s.heartbeat_age_ms,
                "heartbeat overdue: killed, will be restarted"
            );
        }
    }
}

/// Stages judged by their output deadline: each reads a topic the monitor counts.
const DEADLINED: [ServiceKind; 4] = [
    ServiceKind::Fusion,
    ServiceKind::Altimeter,
    ServiceKind::Navigator,
    ServiceKind::NavigatorStandby,
];

/// A hung stage is seen sooner by its output than by its heartbeat: input arriving, output silent
/// for `[watchdog] output_deadline_s`. It is killed, so that it is reaped and restarted like any
/// exit.
fn kill_overdue_outputs(
    deadline: &mut OutputDeadline,
    monitor: &Monitor,
    supervisor: &mut Supervisor,
    now: Instant,
) {
    for kind in DEADLINED {
        let (Some(pid), Some(input), Some(output)) = (
            supervisor.running_pid(kind.name()),
            monitor.input_count(kind),
            monitor.output_count(kind),
        ) else {
            continue;
        };
        if deadline.observe(kind, pid, input, output, now) && supervisor.kill(pid) {
            tracing::warn!(
                service = kind.name(),
                pid,
                "output overdue while its input arrives: killed, will be restarted"
            );
        }
    }
}

/// Another way a death is seen, besides the child's exit, its heartbeat and its output deadline:
/// iceoryx2 finds its node dead. Every dead node's resources are freed; a child the supervisor still counts as
/// running under that pid is killed, so that it is reaped and restarted like any exit.
fn sweep_dead_nodes(settings: &IpcSettings, supervisor: &mut Supervisor) {
    let result = rins_runtime::ipc::for_each_dead_node(settings, |name, pid| {
        let child = pid.filter(|&p| supervisor.kill(p));
        match child {
            Some(pid) => {
                tracing::warn!(
                    node = name,
                    pid,
                    "iceoryx2 node dead: killed, will be restarted"
                )
            }
            None => tracing::info!(node = name, ?pid, "removed the resources of a dead node"),
        }
    });
    if let Err(e) = result {
        tracing::warn!(error = %e, "cannot sweep dead nodes");
    }
}

/// What the supervision loop drives.
struct Watch<'a> {
    supervisor: &'a mut Supervisor,
    monitor: &'a mut Monitor,
    health: &'a mut HealthPublisher,
    timing: &'a mut RestartTiming,
}

fn supervise(
    cfg: &RinsConfig,
    settings: &IpcSettings,
    args: &UpArgs,
    shutdown: &Shutdown,
    watch: Watch<'_>,
    started: Instant,
) -> Result<()> {
    let Watch {
        supervisor,
        monitor,
        health,
        timing,
    } = watch;
    let end = args.duration.map(|d| started + Duration::from_secs_f64(d));
    let mut deadline = (cfg.watchdog.output_deadline_s > 0.0)
        .then(|| OutputDeadline::new(Duration::from_secs_f64(cfg.watchdog.output_deadline_s)));
    let period = (cfg.watchdog.status_period_s > 0.0)
        .then(|| Duration::from_secs_f64(cfg.watchdog.status_period_s));
    let mut next_status = period.map(|p| Instant::now() + p);
    let mut last_totals = monitor.totals;
    let mut last_status_at = Instant::now();
    let mut events = Vec::new();
    while !shutdown.requested() && end.is_none_or(|e| Instant::now() < e) {
        monitor.drain()?;
        timing.observe(Instant::now(), |kind| monitor.output_count(kind));
        supervisor.poll(&mut events);
        if let Some(deadline) = deadline.as_mut() {
            kill_overdue_outputs(deadline, monitor, supervisor, Instant::now());
        }
        if let Some(report) = health.tick(supervisor, monitor)? {
            sweep_dead_nodes(settings, supervisor);
            if cfg.watchdog.heartbeat_timeout_s > 0.0 {
                kill_hung(&report, supervisor);
            }
        }
        for event in events.drain(..) {
            match event {
                ChildEvent::Exited {
                    name,
                    status,
                    restart_in,
                } => {
                    tracing::warn!(child = %name, %status, restart_in_ms = restart_in.as_millis() as u64, "child exited");
                    if let Some(kind) = ipc_types::ServiceKind::from_name(&name)
                        && let Some(count) = monitor.output_count(kind)
                    {
                        timing.on_exit(kind, Instant::now(), count);
                    }
                    // Its node is dead now: free its shared memory before the restart.
                    match rins_runtime::ipc::remove_dead_nodes(settings) {
                        Ok(n) if n > 0 => {
                            tracing::info!(child = %name, nodes = n, "removed the resources of dead nodes")
                        }
                        Ok(_) => {}
                        Err(e) => tracing::warn!(error = %e, "cannot clean up dead nodes"),
                    }
                }
                ChildEvent::Restarted { name, pid } => {
                    tracing::info!(child = %name, pid, "child restarted")
                }
                ChildEvent::GaveUp {
                    name,
                    status,
                    exits,
                    window,
                    action,
                } => {
                    let why = format!(
                        "{name} exited ({status}) {exits} times within {:.0} s, more than \
                         watchdog.max_restarts allows (watchdog.services.{name} may raise it)",
                        window.as_secs_f64()
                    );
                    if let Err(e) = rins_runtime::ipc::remove_dead_nodes(settings) {
                        tracing::warn!(error = %e, "cannot clean up dead nodes");
                    }
                    match action {
                        GiveUp::Shutdown => bail!("{why}: stopping the pipeline"),
                        GiveUp::LeaveDown => {
                            tracing::error!("{why}: left down, the other services go on")
                        }
                    }
                }
            }
        }
        if let (Some(due), Some(period)) = (next_status, period)
            && Instant::now() >= due
        {
            let dt = last_status_at.elapsed().as_secs_f64();
            let mut rates = [0.0; COUNTED.len()];
            for (i, rate) in rates.iter_mut().enumerate() {
                *rate = (monitor.totals[i] - last_totals[i]) as f64 / dt;
            }
            last_totals = monitor.totals;
            last_status_at = Instant::now();
            println!(
                "{}",
                status_line(
                    started.elapsed().as_secs_f64(),
                    &rates,
                    monitor.nav_gaps.missing,
                    &monitor.device_counters(),
                    monitor.last_nav.as_ref(),
                )
            );
            next_status = Some(due + period);
        }
        std::thread::sleep(LOOP_PERIOD);
    }
    Ok(())
}

fn summarise(
    monitor: &Monitor,
    supervisor: &Supervisor,
    timing: &RestartTiming,
    elapsed: Duration,
    simulate: bool,
) -> Summary {
    let (restart_worst, restart_measurements) = timing.worst();
    let device = monitor.device_counters();
    let acc = &monitor.accuracy;
    let sim = |v: Option<f64>| if simulate { v } else { None };
    Summary {
        duration_s: elapsed.as_secs_f64(),
        frames: monitor.totals[0],
        baro_frames: monitor.totals[1],
        mag_frames: monitor.totals[2],
        dropped: monitor.nav_gaps.missing,
        crc_errors: device.crc_errors,
        malformed_frames: device.malformed_frames,
        lost_frames: device.lost_frames,
        duplicate_frames: device.duplicate_frames,
        late_frames: device.late_frames,
        seq_jumps: device.seq_jumps,
        time_rebases: device.time_rebases,
        nav_samples: monitor.totals[5],
        restarts: supervisor.restarts(),
        restart_to_publish_ms_max: restart_worst.as_secs_f64() * 1e3,
        restart_measurements,
        restart_to_publish_ms_by_service: timing
            .by_kind()
            .into_iter()
            .map(|(kind, worst, n)| (kind.name().to_string(), worst.as_secs_f64() * 1e3, n))
            .collect(),
        nav_lane_samples: monitor.nav_lanes().lane_totals(),
        nav_lane_switches: monitor.nav_lanes().switches().0,
        nav_lane_filled: monitor.nav_lanes().filled(),
        nav_integrity_samples: monitor.integrity_samples.into(),
        att_err_deg_rms: sim(acc.attitude_deg.rms()),
        att_err_deg_max: sim(acc.attitude_deg.max()),
        alt_err_m_rms: sim(acc.altitude_m.rms()),
        alt_err_m_max: sim(acc.altitude_m.max()),
        shm_leaked: 0,
        faults: monitor.faults.records().to_vec(),
        false_alarms: monitor.faults.false_alarms(),
    }
}
