//! `rins up`: the watchdog. Starts every service (and the simulator unless a real port is given) as
//! child processes, restarts children that exit, prints a status line per second, and on shutdown
//! stops everything and removes the deployment's shared memory. While it runs, the deployment's
//! iceoryx2 configuration is in the run directory (`iceoryx2.toml`), for programs that are not rins
//! (a Python consumer) to join with.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use ipc_types::ServiceKind;
use rins_runtime::ipc::{IpcSettings, create_node};
use rins_runtime::root_lock::RootLock;
use rins_runtime::shm_cleanup;
use rins_runtime::shutdown::Shutdown;
use rins_watchdog::deployment_checks::{ensure_no_live_deployment, refuse_foreign_entries};
use rins_watchdog::health_publisher::HealthPublisher;
use rins_watchdog::link::no_valid_frame;
use rins_watchdog::monitor::Monitor;
use rins_watchdog::process_graph::{Optional, pipeline_services};
use rins_watchdog::restart_timing::RestartTiming;
use rins_watchdog::run_summary::summarise;
use rins_watchdog::sim_start::wait_for_path;
use rins_watchdog::summary::Summary;
use rins_watchdog::summary_text::summary_text;
use rins_watchdog::supervision_loop::{Supervision, Watch, supervise};
use rins_watchdog::supervisor::{ChildSpec, Supervisor};

use crate::cli::UpArgs;
use crate::commands::fault_args;
use crate::commands::record;
use crate::commands::up_recording::{self, RecordingOutcome};
use crate::config::{self, RinsConfig};
use rins::deploy_profile::{self, RequestedProfile};
use rins::deploy_profile_file::{self, ProfileRecord};

/// Applies the command line's overrides to the configuration and checks them.
fn apply_overrides(cfg: &mut RinsConfig, args: &UpArgs) -> Result<()> {
    if let Some(scenario) = args.scenario {
        cfg.set_scenario(scenario);
    }
    if let Some(seed) = args.seed {
        cfg.sim.seed = seed;
    }
    if let Some(hz) = args.imu_rate {
        cfg.set_imu_rate(hz)?;
    }
    if let Some(duration) = args.duration
        && !(duration.is_finite() && duration > 0.0)
    {
        bail!("--duration {duration}: must be a positive number of seconds");
    }
    // A deployment reads the serial line (the simulator's or a device's), unless an external
    // source (a replay) publishes the raw samples.
    if !args.external_source {
        cfg.device.check_serial_link()?;
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
    if args.gnss {
        cfg.enable_gnss();
    }
    // The built-in simulator samples its gyros and accelerometers at the same instant: the lag a
    // profile sets for a real unit (its gyro channel behind its accelerometer's) is not its.
    if args.port.is_none() && !args.external_source && cfg.navigator.gyro_lag_s != 0.0 {
        eprintln!(
            "rins up: [navigator] gyro_lag_s = {} s is for a real unit; the simulated one has none (0 s used)",
            cfg.navigator.gyro_lag_s
        );
        cfg.navigator.gyro_lag_s = 0.0;
    }
    if args.realtime {
        cfg.realtime.enabled = true;
    }
    if cfg.gnss.enabled && args.port.is_some() && cfg.gnss.port.is_none() {
        bail!(
            "GNSS is on with a real device (--port) but gnss.port is not set: name the receiver's serial device in [gnss] port"
        );
    }
    if let Some(endpoint) = &args.mavlink {
        rins_mavlink::endpoint::Endpoint::parse(endpoint)
            .map_err(|why| anyhow::anyhow!("--mavlink {endpoint:?}: {why}"))?;
        cfg.mavlink.enabled = true;
        cfg.mavlink.endpoints = vec![endpoint.clone()];
    }
    if args.zenoh.is_some() || args.zenoh_listen.is_some() {
        for (flag, endpoint) in [
            ("--zenoh", &args.zenoh),
            ("--zenoh-listen", &args.zenoh_listen),
        ] {
            if let Some(e) = endpoint {
                rins_bridge::endpoint::Endpoint::parse(e)
                    .map_err(|why| anyhow::anyhow!("{flag} {e:?}: {why}"))?;
            }
        }
        cfg.zenoh.enabled = true;
        if let Some(e) = &args.zenoh {
            cfg.zenoh.connect = vec![e.clone()];
        }
        if let Some(e) = &args.zenoh_listen {
            cfg.zenoh.listen = vec![e.clone()];
        }
        cfg.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    if !args.faults.is_empty() {
        if args.port.is_some() {
            bail!("--inject and --faults need the simulator: they cannot be used with --port");
        }
        // Checked here so that a bad fault stops the start-up before any child runs.
        fault_args::schedule(&args.faults, &fault_args::fitted_sources(cfg)?)?;
    }
    Ok(())
}

/// Runs the deployment until a stop is requested, the `--duration` ends or a child is given up.
pub fn run(args: &UpArgs) -> Result<std::process::ExitCode> {
    // First of all: a stop requested at any moment from here on is a clean stop, not a death by
    // signal that leaves children and shared memory behind.
    let shutdown = Shutdown::install()?;
    let mut cfg = config::load(args.config.as_deref())?;
    apply_overrides(&mut cfg, args)?;
    // Planned on the configuration as the command line left it, and written over it before it is
    // resolved: every child, a restarted one too, starts with the profile's settings.
    let profile = deploy_profile::resolve(args.profile, &mut cfg).map_err(anyhow::Error::msg)?;
    if args.profile != RequestedProfile::Shared {
        eprintln!(
            "rins up: profile {} — {}",
            profile.profile.name(),
            profile.reason
        );
    }
    // The simulator and the recorder are started by this process and inherit its CPUs.
    if let Some(why) = deploy_profile::confine_this_process(&profile) {
        eprintln!("rins up: {why}; it runs on without it");
    }
    let profile = ProfileRecord::of(&profile);
    // A recording that cannot be made is refused before anything starts, naming the path.
    // `[record]` records into systemd's state directory when the unit gives one.
    let state_directory = std::env::var("STATE_DIRECTORY").ok();
    let record_target = record::Target::for_up(
        args.record.as_deref(),
        &cfg.record,
        state_directory.as_deref(),
        args.external_source,
    );
    if let Some(target) = &record_target {
        target.check()?;
    }
    // Refused here, before any child runs, rather than by a child in a restart loop.
    cfg.build_services()?;
    if cfg.mavlink.enabled {
        rins_mavlink::signing::key_for(&cfg.mavlink)?;
    }
    if cfg.zenoh.enabled {
        rins_bridge::session_config::session_config(
            &cfg.zenoh,
            rins_runtime::user::effective_uid(),
        )?;
    }
    if shutdown.requested() {
        return Ok(std::process::ExitCode::SUCCESS);
    }
    let settings = IpcSettings::from_env();
    settings.check_name_lengths()?;
    refuse_foreign_entries(&settings)?;
    // Only a root this run created is removed at the end (and only when empty).
    let root_created = settings.ensure_root()?;
    // Held until this deployment's first node exists: a tool arriving meanwhile either made its
    // node before the check below (and is seen) or makes it after the clean-up (and keeps it).
    let arrival_lock = RootLock::exclusive(&settings)?;
    // The configuration file lets programs that are not rins (a Python consumer) join this
    // deployment; it goes again at stop.
    let run_dir = ensure_no_live_deployment(&settings)
        .and_then(|()| Ok(settings.ensure_run_dir()?))
        .and_then(|dir| Ok(settings.write_iceoryx_config_file().map(|_| dir)?))
        .inspect_err(|_| {
            if root_created {
                let _ = std::fs::remove_dir(&settings.root);
            }
        })?;
    // A new deployment numbers its frames afresh: the last one's resume point does not apply.
    let _ = std::fs::remove_file(rins_acquisition::resume_file::path_for(&settings));
    let simulate = cfg.acquisition.port.is_none() && !args.external_source;
    let link = run_dir.join("sim-tty");
    let gnss_link = run_dir.join("sim-gnss-tty");
    if simulate {
        let _ = std::fs::remove_file(&link);
        cfg.acquisition.port = Some(link.to_string_lossy().into_owned());
        if cfg.gnss.enabled && cfg.gnss.port.is_none() {
            let _ = std::fs::remove_file(&gnss_link);
            cfg.gnss.port = Some(gnss_link.to_string_lossy().into_owned());
            cfg.sim.gnss.enabled = true;
        }
    }
    // Resolved once, here: every child reads this file as it is, with nothing applied on top.
    let resolved = config::resolved::write(&cfg, &run_dir)
        .inspect_err(|_| settings.remove_iceoryx_config_file())?;
    // Read by `rins status`: what runs, and why.
    deploy_profile_file::write(&run_dir, &profile).inspect_err(|_| {
        settings.remove_iceoryx_config_file();
        let _ = std::fs::remove_file(&resolved);
    })?;
    let resolved_args = [
        "--resolved-config".to_string(),
        resolved.to_string_lossy().into_owned(),
    ];
    let port = cfg.acquisition.port.clone().unwrap_or_default();

    let exe = std::env::current_exe().context("cannot locate the rins executable")?;
    let node = create_node("watchdog", &settings)?;
    drop(arrival_lock);
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
    let mut recorder: Option<std::process::Child> = None;
    let outcome = (|| -> Result<()> {
        let kinds = pipeline_services(
            cfg.deployment.navigator_lanes,
            Optional {
                mavlink: cfg.mavlink.enabled,
                gnss: cfg.gnss.enabled,
                bridge: cfg.zenoh.enabled,
            },
        );
        for kind in kinds {
            // An external source (a replay) publishes the raw topics and the receiver's fixes.
            if args.external_source && matches!(kind, ServiceKind::Acquisition | ServiceKind::Gnss)
            {
                continue;
            }
            if shutdown.requested() {
                return Ok(());
            }
            let name = kind.name();
            let mut child_args = vec!["service".to_string(), name.to_string()];
            child_args.extend(resolved_args.iter().cloned());
            supervisor.start(ChildSpec {
                name: name.to_string(),
                program: exe.clone(),
                args: child_args,
                policy: cfg.watchdog.policy_for(name),
                // The readers of a device stop first, the services downstream after them.
                stops_last: !matches!(kind, ServiceKind::Acquisition | ServiceKind::Gnss),
            })?;
        }
        if let Some(target) = &record_target {
            recorder = Some(start_recorder(&exe, target, &run_dir, &shutdown)?);
        }
        if simulate {
            supervisor.start(ChildSpec {
                name: ServiceKind::Simulator.name().into(),
                program: exe.clone(),
                args: sim_args(&cfg, &resolved_args, &link, &gnss_link, args),
                policy: cfg.watchdog.policy_for(ServiceKind::Simulator.name()),
                stops_last: true,
            })?;
            if !wait_for_path(&link, &mut supervisor, &shutdown)? {
                return Ok(());
            }
        }
        let run = Supervision {
            settings: &settings,
            config: &cfg.watchdog,
            shutdown: &shutdown,
            started,
            end: args.duration.map(|d| started + Duration::from_secs_f64(d)),
            status_on_stderr: args.json,
        };
        supervise(
            &run,
            Watch {
                supervisor: &mut supervisor,
                monitor: &mut monitor,
                health: &mut health,
                timing: &mut timing,
            },
        )
    })();

    supervisor.stop_all(Duration::from_millis(cfg.watchdog.stop_grace_ms));
    // The recorder last: it writes what the services published while stopping.
    let recording = recorder
        .zip(record_target.as_ref())
        .map(|(child, target)| stop_recorder(child, target.path()));
    settings.remove_iceoryx_config_file();
    let _ = std::fs::remove_file(&resolved);
    deploy_profile_file::remove(&run_dir);
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
    let summary = Summary {
        shm_leaked: leaked,
        profile: profile.profile,
        profile_reason: profile.profile_reason,
        ..summary
    };
    if args.json {
        println!(
            "{}",
            up_recording::summary_json(&summary, recording.as_ref())?
        );
    } else {
        // A run ends with what it measured, whether its duration ended or it was stopped by a
        // signal (Ctrl-C on an interactive run).
        print!("{}", summary_text(&summary));
        if let Some(r) = &recording {
            print!("{}", r.text());
        }
    }
    // A timed run that never saw a frame did not do what was asked: a bring-up script must see it.
    if args.duration.is_some()
        && !shutdown.requested()
        && let Some(why) = no_valid_frame(&port, &summary)
    {
        bail!("{why}");
    }
    // A timed run with a stage given up did not run the pipeline it was asked to: a script must
    // see it, whatever the rest of the summary says.
    if args.duration.is_some() && !shutdown.requested() && !summary.failed_services.is_empty() {
        bail!(
            "{} given up during the run (restarts kept failing): the pipeline was not whole at \
             its end",
            summary.failed_services.join(", ")
        );
    }
    // A recording asked for and not made whole is a failed run, however it was stopped.
    if let Some(why) = recording.as_ref().and_then(RecordingOutcome::failure) {
        bail!("{why}");
    }
    Ok(std::process::ExitCode::SUCCESS)
}

/// How long the recorder may take to subscribe to every topic (a loaded machine is slow to start
/// a process).
const RECORDER_START: Duration = Duration::from_secs(10);

/// Starts `rins record` (one file, or a directory's rotating files) on this deployment and waits
/// until it has subscribed to every topic, so that the recording starts with the first sample;
/// fails as soon as the recorder exits.
fn start_recorder(
    exe: &Path,
    target: &record::Target,
    run_dir: &Path,
    shutdown: &Shutdown,
) -> Result<std::process::Child> {
    let file = target.path();
    let ready = run_dir.join("recorder-ready");
    let _ = std::fs::remove_file(&ready);
    let mut child = std::process::Command::new(exe)
        .arg("record")
        .args(target.record_args())
        .args(["--json", "--ready-file"])
        .arg(&ready)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .with_context(|| format!("cannot start the recorder for {}", file.display()))?;
    let waited = up_recording::wait_until_ready(&mut child, &ready, file, shutdown, RECORDER_START);
    let _ = std::fs::remove_file(&ready);
    if let Err(e) = waited {
        let _ = child.kill();
        let _ = child.wait();
        return Err(e.context("the recorder did not start"));
    }
    Ok(child)
}

/// Stops the recorder (SIGINT: it finishes the file) and returns what it reported.
fn stop_recorder(child: std::process::Child, file: &Path) -> RecordingOutcome {
    if let Ok(pid) = i32::try_from(child.id()) {
        // SAFETY: kill(2) on our own child's pid with a valid signal number.
        unsafe { libc::kill(pid, libc::SIGINT) };
    }
    match child.wait_with_output() {
        Ok(out) => RecordingOutcome::from_recorder(file, out.status, &out.stdout),
        Err(e) => RecordingOutcome::lost(file, format!("cannot collect the recorder: {e}")),
    }
}

/// The simulator's command line: the run's resolved configuration (its scenario, seed and rate
/// included), the faults of this run, and its terminal links (the GNSS receiver's when one is
/// simulated).
fn sim_args(
    cfg: &RinsConfig,
    resolved_args: &[String],
    link: &Path,
    gnss_link: &Path,
    up: &UpArgs,
) -> Vec<String> {
    let mut args = vec!["sim".to_string()];
    args.extend(resolved_args.iter().cloned());
    args.extend(["--link".to_string(), link.to_string_lossy().into_owned()]);
    if cfg.sim.gnss.enabled {
        args.extend([
            "--gnss-link".to_string(),
            gnss_link.to_string_lossy().into_owned(),
        ]);
    }
    // A run of given length flies the uav circuits for all of it, unless the configuration says
    // how long the flight is.
    if let (Some(d), None) = (up.duration, cfg.sim.uav_flight_s) {
        args.extend(["--flight-s".to_string(), d.to_string()]);
    }
    // The simulator applies timed faults itself, exactly at their tick.
    for spec in &up.faults.inject {
        args.extend(["--inject".to_string(), spec.clone()]);
    }
    if let Some(file) = &up.faults.faults {
        args.extend(["--faults".to_string(), file.to_string_lossy().into_owned()]);
    }
    args
}
