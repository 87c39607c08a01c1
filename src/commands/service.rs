//! `rins service NAME`: run one service in this process until SIGINT/SIGTERM.

use anyhow::Result;
use rins_runtime::ipc::IpcSettings;
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::shutdown::Shutdown;

use crate::cli::{ServiceArgs, ServiceName};
use crate::config::{self, RinsConfig};

/// The configuration service `args.name` runs with: a deployment's resolved configuration as it
/// is, or (run by hand) the file given (the built-in one when none) with the command line's
/// overrides: for acquisition (or the gnss service) the serial device, for the MAVLink output the
/// endpoint, a GNSS receiver fitted, the block's sample rate and `[realtime]` on.
fn configuration(args: &ServiceArgs) -> Result<RinsConfig> {
    if let Some(path) = &args.resolved_config {
        return config::resolved::load(path);
    }
    let mut cfg = config::load(args.config.as_deref())?;
    if args.gnss {
        cfg.enable_gnss();
    }
    if let Some(hz) = args.imu_rate {
        cfg.set_imu_rate(hz)?;
    }
    if args.realtime {
        cfg.realtime.enabled = true;
    }
    match (args.name, &args.port) {
        (ServiceName::Gnss, Some(port)) => cfg.gnss.port = Some(port.clone()),
        (_, Some(port)) => cfg.acquisition.port = Some(port.clone()),
        (_, None) => {}
    }
    if let Some(endpoint) = &args.mavlink {
        cfg.mavlink.endpoints = vec![endpoint.clone()];
        cfg.validate()
            .map_err(|e| anyhow::anyhow!("--mavlink: {e}"))?;
    }
    Ok(cfg)
}

/// Runs service `args.name` with the configuration [`configuration`] gives.
pub fn run(args: &ServiceArgs) -> Result<()> {
    let name = args.name;
    let process = name.kind().name();
    rins_runtime::logging::init(process);
    let cfg = configuration(args)?;
    // Before any thread or port exists: threads started later inherit the scheduling.
    rins::realtime_config::apply_for(&cfg.realtime, process);
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
                imu_rate_hz: cfg.device.imu_rate_hz,
            }
            .run(ctx)
        }
        ServiceName::Mavlink => rins_mavlink::service::MavlinkService {
            config: cfg.mavlink,
        }
        .run(ctx),
        ServiceName::Gnss => rins_gnss::service::GnssService { config: cfg.gnss }.run(ctx),
        ServiceName::Bridge => rins_bridge::service::BridgeService { config: cfg.zenoh }.run(ctx),
    };
    tracing::info!(service = %process, ok = result.is_ok(), "stopped");
    result
}
