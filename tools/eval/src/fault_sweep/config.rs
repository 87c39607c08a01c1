//! Settings of the fault sweep: the configured chain, the faults, the channels and the times.

use rins_altimeter::AltimeterConfig;
use rins_fusion::{ConfigError, FusionConfig};
use rins_navigator::NavigatorConfig;
use rins_sim::fault_command::WhiteNoise;
use rins_sim::{ChannelFault, InertialSensor, Scenario, SimConfig};
use serde::Serialize;

use crate::mc::McError;

/// Default injection times, s of device time: 8 s is on the ground roll, just after the
/// alignment (as `rins up --inject gyro2:bias=0.02@8s`); 120 s is the first turn of the `uav`
/// flight at full bank (it starts at 117 s and rolls in over 3 s).
pub const DEFAULT_INJECT_AT_S: [f64; 2] = [8.0, 120.0];
/// Default flight after each injection, s: long enough for the turns' rate changes to show a
/// rate error in the attitude, and for the aiding to work off what the fault left.
pub const DEFAULT_WINDOW_S: f64 = 45.0;
/// Longest flight after an injection accepted, s.
pub const MAX_WINDOW_S: f64 = 3600.0;
/// Most worker threads accepted.
pub const MAX_THREADS: usize = 64;
/// Target of the sweep: the attitude error of any sample the integrity called ok, degrees. The
/// same degree as `[navigator.integrity] fault_attitude_sigma_deg`, the σ below which the
/// navigator calls the attitude ok again after a fault.
pub const TARGET_ATT_ERR_DEG: f64 = 1.0;

/// One fault of the sweep, sized in the channel's white-noise σ per sample (the σ fault detection
/// weighs the channel with, `[fusion.noise]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SweepFault {
    /// A constant bias of `sigmas` σ from the injection on.
    Bias {
        /// Size of the step, σ.
        sigmas: f64,
    },
    /// A bias growing from zero to `sigmas` σ over `over_s` seconds, and on at the same rate.
    Ramp {
        /// Size reached after `over_s`, σ.
        sigmas: f64,
        /// Time to reach it, s.
        over_s: f64,
    },
    /// The channel's white noise multiplied by `factor` (as `rins inject CHANNEL noise FACTOR`).
    Noise {
        /// Total noise over the configured noise (≥ 1).
        factor: f64,
    },
}

impl SweepFault {
    /// The default list: bias steps of 2, 5, 10 and 20 σ, a ramp reaching 20 σ in 10 s, the
    /// noise multiplied by 10.
    pub fn defaults() -> Vec<Self> {
        let mut faults: Vec<Self> = [2.0, 5.0, 10.0, 20.0]
            .into_iter()
            .map(|sigmas| Self::Bias { sigmas })
            .collect();
        faults.push(Self::Ramp {
            sigmas: 20.0,
            over_s: 10.0,
        });
        faults.push(Self::Noise { factor: 10.0 });
        faults
    }

    /// `bias`, `ramp` or `noise`, as `rins inject` names them.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Bias { .. } => "bias",
            Self::Ramp { .. } => "ramp",
            Self::Noise { .. } => "noise",
        }
    }

    /// Short description for the table: `bias 20σ`, `ramp 20σ/10s`, `noise ×10`.
    pub fn label(&self) -> String {
        match *self {
            Self::Bias { sigmas } => format!("bias {sigmas}σ"),
            Self::Ramp { sigmas, over_s } => format!("ramp {sigmas}σ/{over_s}s"),
            Self::Noise { factor } => format!("noise ×{factor}"),
        }
    }

    fn validate(&self) -> Result<(), ConfigError> {
        let bad = |field: &str, value: f64, reason: &str| {
            Err(ConfigError::new(field, value, reason).within("sweep.faults"))
        };
        match *self {
            Self::Bias { sigmas } if !(sigmas.is_finite() && sigmas != 0.0) => {
                bad("bias.sigmas", sigmas, "must be finite and not 0")
            }
            Self::Ramp { sigmas, .. } if !(sigmas.is_finite() && sigmas != 0.0) => {
                bad("ramp.sigmas", sigmas, "must be finite and not 0")
            }
            Self::Ramp { over_s, .. } if !(over_s.is_finite() && over_s > 0.0) => bad(
                "ramp.over_s",
                over_s,
                "must be a positive number of seconds",
            ),
            Self::Noise { factor } if !(factor.is_finite() && factor >= 1.0) => {
                bad("noise.factor", factor, "must be finite and >= 1")
            }
            _ => Ok(()),
        }
    }

    /// The simulator's fault for a channel of per-sample σ `fdi_sigma` (bias and ramp) and
    /// simulated white noise `sim_sigma` (the noise factor scales what the simulator draws: the
    /// added noise is σ·√(F² − 1), as `rins inject` does).
    pub(crate) fn channel_fault(&self, fdi_sigma: f64, sim_sigma: f64) -> ChannelFault {
        match *self {
            Self::Bias { sigmas } => ChannelFault::BiasStep {
                bias: sigmas * fdi_sigma,
            },
            Self::Ramp { sigmas, over_s } => ChannelFault::Ramp {
                rate_per_s: sigmas * fdi_sigma / over_s,
            },
            Self::Noise { factor } => ChannelFault::NoiseBurst {
                sigma: sim_sigma * (factor * factor - 1.0).max(0.0).sqrt(),
            },
        }
    }

    /// The fault's parameter in SI units (rad/s, m/s², per second for a ramp, the added noise σ).
    pub(crate) fn param(&self, fdi_sigma: f64, sim_sigma: f64) -> f64 {
        match self.channel_fault(fdi_sigma, sim_sigma) {
            ChannelFault::BiasStep { bias } => bias,
            ChannelFault::Ramp { rate_per_s } => rate_per_s,
            ChannelFault::NoiseBurst { sigma } => sigma,
            // The sweep builds only the three kinds above.
            _ => f64::NAN,
        }
    }
}

/// One inertial channel: its sensor type and 0-based index.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SweepChannel {
    /// Gyro or accelerometer.
    pub sensor: InertialSensor,
    /// 0-based channel index.
    pub index: usize,
}

impl SweepChannel {
    /// `gyro2`, `accel0`, as `rins inject` spells channels.
    pub fn name(&self) -> String {
        let kind = match self.sensor {
            InertialSensor::Gyro => "gyro",
            InertialSensor::Accel => "accel",
        };
        format!("{kind}{}", self.index)
    }

    /// Parses `gyro2`, `accel0`; `None` for anything else.
    pub fn parse(text: &str) -> Option<Self> {
        let text = text.trim();
        let (sensor, digits) = if let Some(d) = text.strip_prefix("gyro") {
            (InertialSensor::Gyro, d)
        } else if let Some(d) = text.strip_prefix("accel") {
            (InertialSensor::Accel, d)
        } else {
            return None;
        };
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        digits.parse().ok().map(|index| Self { sensor, index })
    }
}

/// Sweep settings: the chain as configured, and what to inject when.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepConfig {
    /// Simulator; the sweep flies the `uav` scenario whatever this names.
    pub sim: SimConfig,
    /// Fusion as configured (geometries, noise, FDI, rest-bias window).
    pub fusion: FusionConfig,
    /// Altimeter as configured.
    pub altimeter: AltimeterConfig,
    /// Navigator as configured.
    pub navigator: NavigatorConfig,
    /// Simulator seed of every run (the clean run included).
    pub seed: u64,
    /// Device times of the injections, s; each fault is injected once at each.
    pub inject_at_s: Vec<f64>,
    /// Flight after each injection, s.
    pub window_s: f64,
    /// Channels that get each fault; empty: every gyro and accelerometer channel.
    pub channels: Vec<SweepChannel>,
    /// Faults injected.
    pub faults: Vec<SweepFault>,
    /// Worker threads.
    pub threads: usize,
}

impl SweepConfig {
    /// The default sweep of a configured chain: every channel, [`SweepFault::defaults`], at
    /// [`DEFAULT_INJECT_AT_S`] for [`DEFAULT_WINDOW_S`], with the simulator's configured seed.
    pub fn new(
        sim: SimConfig,
        fusion: FusionConfig,
        altimeter: AltimeterConfig,
        navigator: NavigatorConfig,
    ) -> Self {
        let seed = sim.seed;
        Self {
            sim,
            fusion,
            altimeter,
            navigator,
            seed,
            inject_at_s: DEFAULT_INJECT_AT_S.to_vec(),
            window_s: DEFAULT_WINDOW_S,
            channels: Vec::new(),
            faults: SweepFault::defaults(),
            threads: 2,
        }
    }
}

/// Everything the runs share, validated once.
#[derive(Debug, Clone)]
pub(crate) struct Prepared {
    pub sim: SimConfig,
    pub fusion: FusionConfig,
    pub altimeter: AltimeterConfig,
    pub navigator: NavigatorConfig,
    pub seed: u64,
    pub tick_s: f64,
    /// Injection ticks, one per injection time.
    pub inject_ticks: Vec<u64>,
    pub window_ticks: u64,
    pub channels: Vec<SweepChannel>,
    pub faults: Vec<SweepFault>,
    /// Per-sample σ fault detection uses, per gyro and accelerometer channel.
    pub fdi_sigma: [Vec<f64>; 2],
    /// The simulator's white noise per sample.
    pub sim_noise: WhiteNoise,
}

fn invalid(field: &str, value: impl std::fmt::Display, reason: &str) -> McError {
    ConfigError::new(field, value, reason)
        .within("sweep")
        .into()
}

pub(crate) fn sensor_index(sensor: InertialSensor) -> usize {
    match sensor {
        InertialSensor::Gyro => 0,
        InertialSensor::Accel => 1,
    }
}

impl SweepConfig {
    pub(crate) fn prepare(&self) -> Result<Prepared, McError> {
        if !(1..=MAX_THREADS).contains(&self.threads) {
            return Err(invalid("threads", self.threads, "must be in 1..=64"));
        }
        if !(self.window_s.is_finite() && self.window_s > 0.0 && self.window_s <= MAX_WINDOW_S) {
            return Err(invalid("window_s", self.window_s, "must be in (0, 3600] s"));
        }
        if self.inject_at_s.is_empty() {
            return Err(invalid("inject_at_s", "[]", "needs at least one time"));
        }
        if self.faults.is_empty() {
            return Err(invalid("faults", "[]", "needs at least one fault"));
        }
        for f in &self.faults {
            f.validate()?;
        }
        let sim = SimConfig {
            scenario: Scenario::Uav,
            ..self.sim.clone()
        };
        sim.validate()?;
        self.fusion.validate().map_err(|e| e.within("fusion"))?;
        self.navigator.validate()?;
        let rate = sim.imu_rate_hz;
        let tick_s = 1.0 / rate;
        let mut inject_ticks = Vec::with_capacity(self.inject_at_s.len());
        for &t in &self.inject_at_s {
            if !(t.is_finite() && t > 0.0 && t <= 86_400.0) {
                return Err(invalid("inject_at_s", t, "must be in (0, 86400] s"));
            }
            inject_ticks.push((t * rate).round() as u64);
        }
        let window_ticks = ((self.window_s * rate).round() as u64).max(1);

        let gyro = self
            .fusion
            .geometry
            .gyro
            .build()
            .map_err(|e| e.within("fusion.geometry.gyro"))?;
        let accel = self
            .fusion
            .geometry
            .accel
            .build()
            .map_err(|e| e.within("fusion.geometry.accel"))?;
        let counts = [gyro.n(), accel.n()];
        // The parity test's per-sample σ at the simulated rate.
        let mut fusion = self.fusion.clone();
        fusion.block.imu_rate_hz = rate;
        let sigmas = |sensor| {
            fusion
                .channel_sigmas(sensor)
                .map_err(|e| e.within("fusion"))
        };
        let fdi_sigma = [
            sigmas(ipc_types::SensorType::Gyro)?,
            sigmas(ipc_types::SensorType::Accel)?,
        ];
        let channels = if self.channels.is_empty() {
            let all = |sensor, n| (0..n).map(move |index| SweepChannel { sensor, index });
            all(InertialSensor::Gyro, counts[0])
                .chain(all(InertialSensor::Accel, counts[1]))
                .collect()
        } else {
            for c in &self.channels {
                let n = counts[sensor_index(c.sensor)];
                if c.index >= n {
                    return Err(invalid(
                        "channels",
                        c.name(),
                        &format!("the block has {n} channels of this type"),
                    ));
                }
            }
            self.channels.clone()
        };
        Ok(Prepared {
            sim_noise: WhiteNoise::from_config(&sim),
            sim,
            fusion: self.fusion.clone(),
            altimeter: self.altimeter.clone(),
            navigator: self.navigator.clone(),
            seed: self.seed,
            tick_s,
            inject_ticks,
            window_ticks,
            channels,
            faults: self.faults.clone(),
            fdi_sigma,
        })
    }
}

impl Prepared {
    /// Per-sample σ of a channel as fault detection weighs it, and as the simulator draws it.
    pub fn sigmas(&self, channel: SweepChannel) -> (f64, f64) {
        let fdi = self.fdi_sigma[sensor_index(channel.sensor)][channel.index];
        let sim = match channel.sensor {
            InertialSensor::Gyro => self.sim_noise.gyro_rps,
            InertialSensor::Accel => self.sim_noise.accel_mps2,
        };
        (fdi, sim)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_names_round_trip_and_junk_is_refused() {
        for text in ["gyro0", "gyro3", "accel2", "gyro15"] {
            let c = SweepChannel::parse(text).unwrap();
            assert_eq!(c.name(), text);
        }
        for bad in ["gyro", "gyrox", "mag0", "accel-1", "", "gyro+1"] {
            assert_eq!(SweepChannel::parse(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn faults_scale_with_sigma() {
        let ramp = SweepFault::Ramp {
            sigmas: 20.0,
            over_s: 10.0,
        };
        assert_eq!(
            ramp.channel_fault(0.5, 9.0),
            ChannelFault::Ramp { rate_per_s: 1.0 }
        );
        assert_eq!(
            SweepFault::Bias { sigmas: 5.0 }.channel_fault(0.5, 9.0),
            ChannelFault::BiasStep { bias: 2.5 }
        );
        // Noise ×10: σ√99 added to σ gives 10σ in total.
        let ChannelFault::NoiseBurst { sigma } =
            SweepFault::Noise { factor: 10.0 }.channel_fault(9.0, 0.5)
        else {
            panic!("not a noise fault");
        };
        assert!((0.25 + sigma * sigma - 25.0).abs() < 1e-9, "{sigma}");
        assert_eq!(SweepFault::defaults().len(), 6);
        assert_eq!(ramp.label(), "ramp 20σ/10s");
    }
}
