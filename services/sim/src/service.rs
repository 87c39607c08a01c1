//! The simulator process: a pseudo-terminal that behaves like the sensor block's serial line, fed in
//! real time by the runtime's paced loop (one tick per IMU period: the commands that arrived, then
//! one step of the device), plus the truth topic for accuracy checks. The line can be unplugged
//! for a while on command ([`SimCommand::Disconnect`]).
//!
//! [`SimCommand::Disconnect`]: crate::sim_command::SimCommand::Disconnect

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use ipc_types::ServiceKind;
use rins_runtime::paced_loop::{PacedLoop, Pacing};
use rins_runtime::service::{Service, ServiceContext};

use crate::device::{Device, GnssDevice};
use crate::fault_command::WhiteNoise;
use crate::fault_schedule::ScheduledFault;
use crate::gnss_receiver::GnssReceiver;
use crate::serial_line::SerialLine;
use crate::simulator::Simulator;
use crate::streaming::Streaming;

pub use crate::streaming::truth_message;

/// How the simulator process runs, beside the simulated device itself.
pub struct SimOptions {
    /// Also expose the pseudo-terminal under this path (a stable name for acquisition).
    pub link: Option<PathBuf>,
    /// Stop after this many seconds of device time.
    pub duration_s: Option<f64>,
    /// Faults to apply at given device times.
    pub faults: Vec<ScheduledFault>,
    /// Configured white noise, the unit of noise-factor faults.
    pub noise: WhiteNoise,
    /// The simulated GNSS receiver on its own terminal, when one is fitted.
    pub gnss: Option<GnssOptions>,
}

/// The simulated GNSS receiver's settings and its terminal's stable name.
pub struct GnssOptions {
    /// `[sim.gnss]`.
    pub config: crate::gnss_config::GnssReceiverConfig,
    /// Also expose the receiver's pseudo-terminal under this path.
    pub link: Option<PathBuf>,
    /// Seed of its noise (mixed with a salt of its own).
    pub seed: u64,
}

/// The simulator process: the simulated device and how it runs, ready to stream.
pub struct SimService {
    /// The simulated sensor block.
    pub sim: Simulator,
    /// Link, duration, scheduled faults, noise unit.
    pub options: SimOptions,
}

impl Service for SimService {
    fn run(self, ctx: ServiceContext) -> Result<()> {
        run(self.sim, &self.options, &ctx)
    }
}

/// Streams the device in real time until `ctx.shutdown` or the configured duration.
fn run(sim: Simulator, options: &SimOptions, ctx: &ServiceContext) -> Result<()> {
    let line = SerialLine::open(options.link.clone())?;
    let tty = line.tty().unwrap_or_default();
    // Without a link the path is how a person finds the device to read it; with one (under
    // `rins up`) the link is the device's name and the log line below carries the path.
    if options.link.is_none() {
        println!("{tty}");
        let _ = std::io::stdout().flush();
    }
    tracing::info!(port = %tty, link = ?options.link, "simulated sensor block streaming");

    let node = ctx.create_node(ServiceKind::Simulator)?;
    let gnss = match &options.gnss {
        Some(g) => {
            let line = SerialLine::open(g.link.clone())?;
            tracing::info!(port = line.tty().unwrap_or_default(), link = ?g.link, "simulated GNSS receiver streaming");
            Some(GnssDevice::new(GnssReceiver::new(g.config, g.seed), line))
        }
        None => None,
    };
    let period_s = sim.imu_period_s();
    let pacing = Pacing {
        kind: ServiceKind::Simulator,
        period_ns: (period_s * 1e9).round() as u64,
        ticks: options.duration_s.map(|d| (d / period_s).ceil() as u64),
    };
    let device = Device::new(line, 1.0 / period_s, gnss);
    let mut streaming = Streaming::new(sim, device, &options.faults, &options.noise, &node)?;
    PacedLoop::new(&node, pacing, &ctx.shutdown)?.run(&mut streaming)?;
    // Dropping the line removes the link.
    drop(streaming);
    Ok(())
}
