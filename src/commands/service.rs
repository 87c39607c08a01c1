//! `rins service NAME`: run one service in this process until SIGINT/SIGTERM.

use std::path::Path;

use anyhow::{Result, anyhow};
use rins_runtime::ipc::IpcSettings;
use rins_runtime::shutdown::Shutdown;

use crate::cli::ServiceName;
use crate::config;

pub fn run(name: ServiceName, config_path: Option<&Path>, port: Option<String>) -> Result<()> {
    let process = name.kind().name();
    rins_runtime::logging::init(process);
    let mut cfg = config::load(config_path)?;
    if let Some(port) = port {
        cfg.acquisition.port = Some(port);
    }
    let shutdown = Shutdown::install()?;
    let settings = IpcSettings::from_env();
    tracing::info!(service = %process, pid = std::process::id(), prefix = %settings.prefix, "starting");
    let result = match name {
        ServiceName::Acquisition => {
            rins_acquisition::service::run(&cfg.acquisition, &settings, &shutdown)
        }
        ServiceName::Fusion => {
            let fuser = rins_fusion::ImuFuser::new(
                &cfg.fusion,
                cfg.device.gyro_lsb_rps(),
                cfg.device.accel_lsb_mps2(),
            )
            .map_err(|e| anyhow!("{}", e.within("fusion")))?;
            let deadline = rins_fusion::service::input_deadline(cfg.fusion.sample_rate_hz);
            rins_fusion::service::run(fuser, deadline, &settings, &shutdown)
        }
        ServiceName::Altimeter => {
            let estimator = rins_altimeter::AltitudeEstimator::new(cfg.altimeter.clone())
                .map_err(|e| anyhow!("{}", e.within("altimeter")))?;
            rins_altimeter::service::run(estimator, &settings, &shutdown)
        }
        ServiceName::Navigator | ServiceName::NavigatorStandby => {
            let lane = u8::from(name == ServiceName::NavigatorStandby);
            rins_navigator::service::run(
                &cfg.navigator,
                &settings,
                &shutdown,
                lane,
                cfg.deployment.navigator_lanes,
            )
        }
    };
    tracing::info!(service = %process, ok = result.is_ok(), "stopped");
    result
}
