//! `rins sim`: the device simulator on a pseudo-terminal.

use anyhow::{Result, bail};
use rins_runtime::ipc::IpcSettings;
use rins_runtime::service::{Service, ServiceContext};
use rins_runtime::shutdown::Shutdown;
use rins_sim::Simulator;
use rins_sim::fault_command::WhiteNoise;
use rins_sim::service::{GnssOptions, SimOptions, SimService};

use crate::cli::SimArgs;
use crate::commands::fault_args;
use crate::config;

pub fn run(args: &SimArgs) -> Result<()> {
    let mut cfg = match &args.resolved_config {
        Some(path) => config::resolved::load(path)?,
        None => config::load(args.config.as_deref())?,
    };
    if let Some(scenario) = args.scenario {
        cfg.set_scenario(scenario);
    }
    if let Some(hz) = args.imu_rate {
        cfg.set_imu_rate(hz)?;
    }
    if let Some(seed) = args.seed {
        cfg.sim.seed = seed;
    }
    if let Some(d) = args.duration
        && !(d.is_finite() && d > 0.0)
    {
        bail!("--duration {d}: must be a positive number of seconds");
    }
    if let Some(flight_s) = args.flight_s.or(args.duration) {
        // Checked with the rest of the configuration when the simulator is built.
        cfg.sim.uav_flight_s = Some(flight_s);
    }
    // The simulated block carries the sensors the fusion geometry describes.
    let (gyro, accel) = cfg.geometries()?;
    let mut fitted = fault_args::fitted_sources(&cfg)?;
    fitted.gnss_receiver = cfg.sim.gnss.enabled || args.gnss_link.is_some();
    let faults = fault_args::schedule(&args.faults, &fitted)?;
    let sim = Simulator::new(&cfg.sim, gyro.axes(), accel.axes(), cfg.sim.seed)?;
    let shutdown = Shutdown::install()?;
    let gnss = (cfg.sim.gnss.enabled || args.gnss_link.is_some()).then(|| GnssOptions {
        config: cfg.sim.gnss,
        link: args.gnss_link.clone(),
        seed: cfg.sim.seed,
    });
    let options = SimOptions {
        gnss,
        link: args.link.clone(),
        duration_s: args.duration,
        faults,
        noise: WhiteNoise::from_config(&cfg.sim),
    };
    SimService { sim, options }.run(ServiceContext::new(IpcSettings::from_env(), shutdown))
}
