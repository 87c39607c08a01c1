//! Settings of the Monte Carlo comparison and their validation.

use rins_altimeter::AltimeterConfig;
use rins_fusion::config::ImuBlock;
use rins_fusion::{ConfigError, FusionConfig, Geometry, GeometryConfig, NoiseConfig, PerSensor};
use rins_navigator::NavigatorConfig;
use rins_sim::{Scenario, SimConfig, SimError, Trajectory};
use thiserror::Error;

/// Runs of the default comparison. Measured in a release build on a 2-vCPU VM: one run (both
/// blocks, full 615 s flight, kill fork at 300 s) takes 2.2–2.5 s of one core (36 runs on 2
/// threads: 40–45 s), so 48 runs take about a minute.
pub const DEFAULT_RUNS: usize = 48;
/// Default time of the channel kill, s of device time.
pub const DEFAULT_KILL_AT_S: f64 = 300.0;
/// Most worker threads accepted.
pub const MAX_THREADS: usize = 64;

/// The body x, y and z axes.
pub const TRIAD_AXES: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Why a Monte Carlo comparison could not run.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum McError {
    /// A setting of the comparison, fusion, navigator or altimeter is out of range.
    #[error("{0}")]
    Config(#[from] ConfigError),
    /// The simulator rejected its configuration or a fault.
    #[error("{0}")]
    Sim(#[from] SimError),
}

/// One sensor block under test: its gyro and accelerometer axes (the same for both).
#[derive(Debug, Clone, PartialEq)]
pub struct SystemSpec {
    /// Short name used in the report, e.g. `skewed 4 (pyramid α 28.7°, β0 45°)`.
    pub label: String,
    /// Axes of the gyros and of the accelerometers.
    pub geometry: GeometryConfig,
}

impl SystemSpec {
    /// The redundant block of \[R1\]: 4 skewed axes on a pyramid, α = 28.7°, β0 = 45°.
    pub fn skewed_pyramid() -> Self {
        Self {
            label: "skewed 4 (pyramid α 28.7°, β0 45°)".into(),
            geometry: GeometryConfig::Pyramid {
                n: 4,
                alpha_deg: 28.7,
                beta0_deg: 45.0,
            },
        }
    }

    /// The conventional block: an orthogonal triad along the body axes.
    pub fn orthogonal_triad() -> Self {
        Self {
            label: "orthogonal triad (3 axes)".into(),
            geometry: GeometryConfig::Axes {
                axes: TRIAD_AXES.to_vec(),
            },
        }
    }
}

/// Monte Carlo settings. Both systems fly the same trajectory with the same per-channel error
/// model; run `k` uses seed `first_seed + k` for both.
#[derive(Debug, Clone, PartialEq)]
pub struct McConfig {
    /// Number of runs (≥ 1; the 2σ needs ≥ 2).
    pub runs: usize,
    /// Seed of run 0.
    pub first_seed: u64,
    /// Flight time simulated, s; `None` flies the whole trajectory of `sim.scenario` (for the UAV
    /// profile: take-off to stop, about 615 s with the default 2 s parked start).
    pub duration_s: Option<f64>,
    /// Time of the channel kill, s; `None` skips the kill experiment. Ignored (no kill) when at or
    /// after the end of the flight.
    pub kill_at_s: Option<f64>,
    /// Gyro channel killed (a `Dead` fault: no data from then on) in both systems.
    pub kill_channel: usize,
    /// Worker threads.
    pub threads: usize,
    /// Redundant block.
    pub redundant: SystemSpec,
    /// Reference block.
    pub orthogonal: SystemSpec,
    /// Simulator: scenario, rates, origin, error model. The converter full scale
    /// (`sensors.gyro_full_scale_dps`, `sensors.accel_full_scale_g`) must be the device's.
    pub sim: SimConfig,
    /// Navigator settings; its initial position and declination are replaced by the simulator's
    /// origin and Earth field (the navigator is told where it starts).
    pub navigator: NavigatorConfig,
    /// Altimeter settings; `qnh_pa` is replaced by the simulator's (the altimeter is told QNH).
    pub altimeter: AltimeterConfig,
    /// Measure each gyro channel's bias in the fuser at rest (its `rest_bias_s` window, as the
    /// product does; default) instead of leaving the whole bias to the navigator, which estimates
    /// it on the fused body axes. The two are equivalent while every channel works; after a
    /// reconfiguration the navigator's body-axis bias no longer matches the new channel set, the
    /// per-channel one still does. Needs the vehicle parked for the window.
    pub calibrate_gyro_channels_at_rest: bool,
}

impl Default for McConfig {
    fn default() -> Self {
        Self {
            runs: DEFAULT_RUNS,
            first_seed: 1,
            duration_s: None,
            kill_at_s: Some(DEFAULT_KILL_AT_S),
            kill_channel: 0,
            threads: 2,
            redundant: SystemSpec::skewed_pyramid(),
            orthogonal: SystemSpec::orthogonal_triad(),
            sim: SimConfig {
                scenario: Scenario::Uav,
                ..SimConfig::default()
            },
            navigator: NavigatorConfig::default(),
            altimeter: AltimeterConfig::default(),
            calibrate_gyro_channels_at_rest: true,
        }
    }
}

/// Everything a run needs, validated and derived once.
#[derive(Debug, Clone)]
pub(crate) struct Prepared {
    pub sim: SimConfig,
    pub navigator: NavigatorConfig,
    pub altimeter: AltimeterConfig,
    pub systems: [PreparedSystem; 2],
    pub ticks: u64,
    pub duration_s: f64,
    pub kill_tick: Option<u64>,
    pub kill_channel: usize,
    /// Ticks of the static window the per-channel gyro bias is averaged over, when enabled.
    pub gyro_channel_bias_ticks: Option<u64>,
}

/// One system with its built geometry and fusion settings.
#[derive(Debug, Clone)]
pub(crate) struct PreparedSystem {
    pub label: String,
    pub geometry: Geometry,
    pub fusion: FusionConfig,
}

fn invalid(field: &str, value: impl std::fmt::Display, reason: &str) -> McError {
    ConfigError::new(field, value, reason).within("mc").into()
}

impl McConfig {
    /// Checks every setting and derives what the runs share.
    pub(crate) fn prepare(&self) -> Result<Prepared, McError> {
        if self.runs == 0 {
            return Err(invalid("runs", self.runs, "must be >= 1"));
        }
        if !(1..=MAX_THREADS).contains(&self.threads) {
            return Err(invalid("threads", self.threads, "must be in 1..=64"));
        }
        self.sim.validate()?;
        let full_flight_s = match self.sim.scenario {
            Scenario::Uav | Scenario::Walk | Scenario::Multirotor => {
                Trajectory::new(self.sim.scenario, self.sim.trajectory_start()).end_s()
            }
            // Neither ever stops: ten minutes, as long as one uav flight.
            Scenario::Static | Scenario::Calibrate => 600.0,
        };
        let duration_s = self.duration_s.unwrap_or(full_flight_s);
        if !(duration_s.is_finite() && duration_s > 0.0 && duration_s <= 86_400.0) {
            return Err(invalid("duration_s", duration_s, "must be in (0, 86400] s"));
        }
        if let Some(k) = self.kill_at_s
            && !(k.is_finite() && k >= 0.0)
        {
            return Err(invalid("kill_at_s", k, "must be finite and >= 0 s"));
        }
        let rate = self.sim.imu_rate_hz;
        let ticks = (duration_s * rate).round() as u64;
        let kill_tick = self
            .kill_at_s
            .map(|k| (k * rate).round() as u64)
            .filter(|&k| k < ticks);

        let mut navigator = self.navigator.clone();
        navigator.initial_latitude_deg = Some(self.sim.origin_latitude_deg);
        navigator.initial_longitude_deg = Some(self.sim.origin_longitude_deg);
        navigator.initial_altitude_m = self.sim.origin_altitude_m;
        navigator.declination_deg = self.sim.earth_field.declination_deg;
        navigator.validate()?;
        let altimeter = AltimeterConfig {
            qnh_pa: self.sim.qnh_pa,
            ..self.altimeter.clone()
        };
        rins_altimeter::AltitudeEstimator::new(altimeter.clone())
            .map_err(|e| McError::from(e.within("altimeter")))?;

        let gyro_channel_bias_ticks = if self.calibrate_gyro_channels_at_rest {
            let parked_s = match self.sim.scenario {
                Scenario::Uav | Scenario::Walk | Scenario::Calibrate | Scenario::Multirotor => {
                    self.sim.static_s
                }
                Scenario::Static => f64::INFINITY,
            };
            if parked_s < navigator.align_s {
                return Err(invalid(
                    "calibrate_gyro_channels_at_rest",
                    true,
                    &format!(
                        "needs the vehicle parked for the alignment window: sim.static_s = {} < navigator.align_s = {}",
                        self.sim.static_s, navigator.align_s
                    ),
                ));
            }
            Some((navigator.align_s * rate).round() as u64)
        } else {
            None
        };
        let redundant = self.prepare_system(&self.redundant, "redundant")?;
        let orthogonal = self.prepare_system(&self.orthogonal, "orthogonal")?;
        for system in [&redundant, &orthogonal] {
            if self.kill_at_s.is_some() && self.kill_channel >= system.geometry.n() {
                return Err(invalid(
                    "kill_channel",
                    self.kill_channel,
                    &format!("{} has {} gyro channels", system.label, system.geometry.n()),
                ));
            }
        }
        Ok(Prepared {
            sim: self.sim.clone(),
            navigator,
            altimeter,
            systems: [redundant, orthogonal],
            ticks,
            duration_s,
            kill_tick,
            kill_channel: self.kill_channel,
            gyro_channel_bias_ticks,
        })
    }

    /// The fusion settings of one system: its axes for both sensor types and the channel noise
    /// of the simulated error model (white noise density times √rate), identity calibration.
    fn prepare_system(&self, spec: &SystemSpec, field: &str) -> Result<PreparedSystem, McError> {
        let geometry = spec
            .geometry
            .build()
            .map_err(|e| e.within(field).within("mc"))?;
        let s = &self.sim.sensors;
        let sqrt_rate = self.sim.imu_rate_hz.sqrt();
        let gyro_sigma = s.gyro_noise_density_dps_rthz.to_radians() * sqrt_rate;
        let accel_sigma =
            s.accel_noise_density_ug_rthz * 1e-6 * rins_earth::STANDARD_GRAVITY * sqrt_rate;
        // A noiseless model still needs a positive weight; equal weights give plain least squares.
        let positive = |sigma: f64| if sigma > 0.0 { sigma } else { 1.0 };
        let fusion = FusionConfig {
            geometry: PerSensor {
                gyro: spec.geometry.clone(),
                accel: spec.geometry.clone(),
            },
            noise: NoiseConfig::from_per_sample_sigma(
                positive(gyro_sigma),
                positive(accel_sigma),
                self.sim.imu_rate_hz,
            ),
            block: ImuBlock {
                imu_rate_hz: self.sim.imu_rate_hz,
                ..ImuBlock::default()
            },
            ..FusionConfig::default()
        };
        fusion
            .validate()
            .map_err(|e| e.within(field).within("mc"))?;
        Ok(PreparedSystem {
            label: spec.label.clone(),
            geometry,
            fusion,
        })
    }
}
