//! `rins service NAME`: run one service in this process until SIGINT/SIGTERM.

use std::path::Path;

use anyhow::Result;
use rins_runtime::ipc::IpcSettings;
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::shutdown::Shutdown;

use crate::cli::ServiceName;
use crate::config;

/// Runs service `name` with the configuration at `config_path` (the built-in one when none) and,
/// for acquisition (or the gnss service), the serial device `port`; for the MAVLink output, the
/// endpoint `mavlink`; with `gnss`, a GNSS receiver fitted; `imu_rate` the block's sample rate; `realtime` turns `[realtime]` on.
pub fn run(
    name: ServiceName,
    config_path: Option<&Path>,
    port: Option<String>,
    mavlink: Option<String>,
    gnss: bool,
    imu_rate: Option<f64>,
    realtime: bool,
) -> Result<()> {
    let process = name.kind().name();
    rins_runtime::logging::init(process);
    let mut cfg = config::load(config_path)?;
    if gnss {
        cfg.enable_gnss();
    }
    if let Some(hz) = imu_rate {
        cfg.set_imu_rate(hz)?;
    }
    if realtime {
        cfg.realtime.enabled = true;
    }
    // Before any thread or port exists: threads started later inherit the scheduling.
    rins::realtime_config::apply_for(&cfg.realtime, process);
    match (name, port) {
        (ServiceName::Gnss, Some(port)) => cfg.gnss.port = Some(port),
        (_, Some(port)) => cfg.acquisition.port = Some(port),
        (_, None) => {}
    }
    if let Some(endpoint) = mavlink {
        cfg.mavlink.endpoints = vec![endpoint];
        cfg.validate()
            .map_err(|e| anyhow::anyhow!("--mavlink: {e}"))?;
    }
    if name == ServiceName::Acquisition {
        // The serial protocol carries 12-bit counts.
        cfg.device.check_serial_link()?;
    }
    let built = cfg.build_services()?;
    let shutdown = Shutdown::install()?;
    let settings = IpcSettings::from_env();
    tracing::info!(service = %process, pid = std::process::id(), prefix = %settings.prefix, "starting");
    let mut ctx = ServiceContext::new(settings, shutdown);
    ctx.wait = cfg.wait.for_service(process);
    let result = match name {
        ServiceName::Acquisition => rins_acquisition::service::AcquisitionService {
            config: cfg.acquisition,
        }
        .run(ctx),
        ServiceName::Fusion => rins_fusion::service::FusionService {
            fuser: built.fuser,
            input_deadline: built.fusion_input_deadline,
            readmit_probation_samples: built.readmit_probation_samples,
        }
        .run(ctx),
        ServiceName::Altimeter => rins_altimeter::service::AltimeterService {
            estimator: built.altimeter,
        }
        .run(ctx),
        ServiceName::Navigator | ServiceName::NavigatorStandby => {
            rins_navigator::service::NavigatorService {
                navigator: built.navigator,
                lane: u8::from(name == ServiceName::NavigatorStandby),
                lanes: cfg.deployment.navigator_lanes,
            }
            .run(ctx)
        }
        ServiceName::Mavlink => rins_mavlink::service::MavlinkService {
            config: cfg.mavlink,
        }
        .run(ctx),
        ServiceName::Gnss => rins_gnss::service::GnssService { config: cfg.gnss }.run(ctx),
    };
    tracing::info!(service = %process, ok = result.is_ok(), "stopped");
    result
}
