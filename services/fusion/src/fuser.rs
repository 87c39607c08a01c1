//! The gyro and accelerometer sides together: counts → SI → weighted least squares over the
//! channels currently valid.
//!
//! Each side keeps the solver of its full channel set and one solver for the most recent reduced
//! set, rebuilt only when the valid mask changes (rare). Fault detection (parity, χ²) belongs in
//! `RedundantSensor::fuse`, between calibration and the solve, where the calibrated channel
//! vector and the active solver are both at hand.

use crate::calibration::{Calibration, ChannelCalibration};
use crate::error::ConfigError;
use crate::geometry::{Geometry, GeometryConfig, MAX_CHANNELS, channel_mask};
use crate::wls::WlsSolver;
use serde::Deserialize;

/// Bit of the first accelerometer channel in the raw valid mask (bit i gyro i, bit 16 + i accel i).
pub const ACCEL_MASK_SHIFT: u32 = 16;

/// Default gyro channel noise σ: 0.01 °/s/√Hz over a 1 kHz bandwidth, in rad/s.
pub fn default_gyro_sigma_rps() -> f64 {
    0.01_f64.to_radians() * 1000_f64.sqrt()
}

/// Default accelerometer channel noise σ: 150 µg/√Hz over a 1 kHz bandwidth, in m/s².
pub fn default_accel_sigma_mps2() -> f64 {
    150e-6 * 9.80665 * 1000_f64.sqrt()
}

/// One value per sensor type.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PerSensor<T> {
    pub gyro: T,
    pub accel: T,
}

/// White-noise standard deviation of each channel at the sample rate, SI units.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum ChannelNoise {
    /// The same σ for every channel.
    Uniform(f64),
    /// One σ per channel (N entries).
    PerChannel(Vec<f64>),
}

impl ChannelNoise {
    /// Per-channel variances σ_i² for `n` channels. Errors name `[i]` or the whole field.
    pub fn variances(&self, n: usize) -> Result<[f64; MAX_CHANNELS], ConfigError> {
        let check = |field: String, s: f64| {
            if s.is_finite() && s > 0.0 {
                Ok(s * s)
            } else {
                Err(ConfigError::new(field, s, "must be finite and > 0"))
            }
        };
        let mut out = [0.0; MAX_CHANNELS];
        match self {
            ChannelNoise::Uniform(s) => {
                let v = check(String::new(), *s)?;
                out.iter_mut().take(n).for_each(|o| *o = v);
            }
            ChannelNoise::PerChannel(list) => {
                if list.len() != n {
                    return Err(ConfigError::new(
                        "",
                        format!("{} entries", list.len()),
                        format!("must be one number or have {n} entries (one per channel)"),
                    ));
                }
                for (i, (o, s)) in out.iter_mut().zip(list).enumerate() {
                    *o = check(format!("[{i}]"), *s)?;
                }
            }
        }
        Ok(out)
    }
}

/// Channel noise of both sensor types.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseConfig {
    /// Gyro channel σ, rad/s.
    pub gyro_sigma_rps: ChannelNoise,
    /// Accelerometer channel σ, m/s².
    pub accel_sigma_mps2: ChannelNoise,
}

impl Default for NoiseConfig {
    fn default() -> Self {
        Self {
            gyro_sigma_rps: ChannelNoise::Uniform(default_gyro_sigma_rps()),
            accel_sigma_mps2: ChannelNoise::Uniform(default_accel_sigma_mps2()),
        }
    }
}

/// Fusion configuration. Defaults: the seed pyramid (n = 4, α = 28.7°, β0 = 45°) for both types,
/// the default channel noise, identity calibration.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FusionConfig {
    pub geometry: PerSensor<GeometryConfig>,
    pub noise: NoiseConfig,
    pub calibration: PerSensor<ChannelCalibration>,
}

#[derive(Debug, Clone, Copy)]
enum Side {
    Gyro,
    Accel,
}

impl Side {
    fn name(self) -> &'static str {
        match self {
            Side::Gyro => "gyro",
            Side::Accel => "accel",
        }
    }
}

impl FusionConfig {
    /// Checks every field; errors name the field path (e.g. `geometry.gyro.alpha_deg`) and value.
    pub fn validate(&self) -> Result<(), ConfigError> {
        for side in [Side::Gyro, Side::Accel] {
            self.side_parts(side)?;
        }
        Ok(())
    }

    fn side_parts(
        &self,
        side: Side,
    ) -> Result<(Geometry, [f64; MAX_CHANNELS], &ChannelCalibration), ConfigError> {
        let (geometry, noise, noise_field, calibration) = match side {
            Side::Gyro => (
                &self.geometry.gyro,
                &self.noise.gyro_sigma_rps,
                "noise.gyro_sigma_rps",
                &self.calibration.gyro,
            ),
            Side::Accel => (
                &self.geometry.accel,
                &self.noise.accel_sigma_mps2,
                "noise.accel_sigma_mps2",
                &self.calibration.accel,
            ),
        };
        let geometry = geometry
            .build()
            .map_err(|e| e.within(side.name()).within("geometry"))?;
        let variances = noise
            .variances(geometry.n())
            .map_err(|e| e.within(noise_field))?;
        calibration
            .validate(geometry.n())
            .map_err(|e| e.within(side.name()).within("calibration"))?;
        Ok((geometry, variances, calibration))
    }
}

/// Fused body rate and specific force of one IMU frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Fused {
    /// Body rate, FRD, rad/s (zeros when `!gyro_ok`).
    pub rate: [f64; 3],
    /// Specific force, FRD, m/s² (zeros when `!accel_ok`).
    pub specific_force: [f64; 3],
    /// Variance of each rate axis, (rad/s)².
    pub rate_var: [f64; 3],
    /// Variance of each specific-force axis, (m/s²)².
    pub specific_force_var: [f64; 3],
    /// At least three valid, well-conditioned gyro channels.
    pub gyro_ok: bool,
    /// At least three valid, well-conditioned accelerometer channels.
    pub accel_ok: bool,
    /// Gyro channels that entered the solution (bit i = channel i).
    pub gyro_mask: u32,
    /// Accelerometer channels that entered the solution (bit i = channel i).
    pub accel_mask: u32,
}

/// Combines the redundant gyro and accelerometer channels into body rate and specific force.
#[derive(Debug, Clone)]
pub struct ImuFuser {
    gyro: RedundantSensor,
    accel: RedundantSensor,
}

impl ImuFuser {
    /// Builds the fuser. `gyro_lsb` (rad/s per count) and `accel_lsb` (m/s² per count) come from
    /// the ADC full scale of the sensor block.
    pub fn new(config: &FusionConfig, gyro_lsb: f64, accel_lsb: f64) -> Result<Self, ConfigError> {
        Ok(Self {
            gyro: RedundantSensor::new(config, Side::Gyro, gyro_lsb)?,
            accel: RedundantSensor::new(config, Side::Accel, accel_lsb)?,
        })
    }

    /// Fuses one frame. `valid_mask`: bit i gyro channel i, bit 16 + i accel channel i; invalid
    /// channels and channels beyond the end of a counts slice are excluded.
    pub fn fuse(&mut self, gyro_counts: &[i16], accel_counts: &[i16], valid_mask: u32) -> Fused {
        let g = self.gyro.fuse(gyro_counts, valid_mask);
        let a = self
            .accel
            .fuse(accel_counts, valid_mask >> ACCEL_MASK_SHIFT);
        Fused {
            rate: g.x,
            specific_force: a.x,
            rate_var: g.var,
            specific_force_var: a.var,
            gyro_ok: g.ok,
            accel_ok: a.ok,
            gyro_mask: g.mask,
            accel_mask: a.mask,
        }
    }

    /// Gyro axes.
    pub fn gyro_geometry(&self) -> &Geometry {
        &self.gyro.geometry
    }

    /// Accelerometer axes.
    pub fn accel_geometry(&self) -> &Geometry {
        &self.accel.geometry
    }
}

/// Result of one sensor type for one frame.
#[derive(Debug, Clone, Copy)]
struct SideEstimate {
    x: [f64; 3],
    var: [f64; 3],
    ok: bool,
    mask: u32,
}

/// Solver for a reduced channel set; `solver` is `None` when that set cannot be solved.
#[derive(Debug, Clone, Copy)]
struct ReducedSet {
    mask: u32,
    solver: Option<WlsSolver>,
}

/// One sensor type: geometry, calibration and the solvers of its channel sets.
#[derive(Debug, Clone)]
struct RedundantSensor {
    geometry: Geometry,
    calibration: Calibration,
    variances: [f64; MAX_CHANNELS],
    full: WlsSolver,
    reduced: Option<ReducedSet>,
}

impl RedundantSensor {
    fn new(config: &FusionConfig, side: Side, lsb: f64) -> Result<Self, ConfigError> {
        let lsb_field = match side {
            Side::Gyro => "gyro_lsb",
            Side::Accel => "accel_lsb",
        };
        if !(lsb.is_finite() && lsb > 0.0) {
            return Err(ConfigError::new(lsb_field, lsb, "must be finite and > 0"));
        }
        let (geometry, variances, calibration) = config.side_parts(side)?;
        let n = geometry.n();
        let calibration = Calibration::new(calibration, n, lsb)
            .map_err(|e| e.within(side.name()).within("calibration"))?;
        // The full geometry passed the conditioning check, so this only fails on a logic error.
        let full =
            WlsSolver::new(&geometry, geometry.full_mask(), &variances[..n]).map_err(|e| {
                ConfigError::new(
                    format!("geometry.{}", side.name()),
                    format!("{n} axes"),
                    e.to_string(),
                )
            })?;
        Ok(Self {
            geometry,
            calibration,
            variances,
            full,
            reduced: None,
        })
    }

    fn fuse(&mut self, counts: &[i16], valid: u32) -> SideEstimate {
        let n = self.geometry.n();
        let mask = valid & channel_mask(n.min(counts.len()));
        let mut z = [f64::NAN; MAX_CHANNELS];
        self.calibration.apply_all(counts, &mut z);
        match self.solver_for(mask) {
            Some(solver) => {
                let (x, var) = solver.solve(&z);
                SideEstimate {
                    x,
                    var,
                    ok: true,
                    mask,
                }
            }
            None => SideEstimate {
                x: [0.0; 3],
                var: [0.0; 3],
                ok: false,
                mask,
            },
        }
    }

    fn solver_for(&mut self, mask: u32) -> Option<&WlsSolver> {
        if mask == self.full.mask() {
            return Some(&self.full);
        }
        if self.reduced.is_none_or(|r| r.mask != mask) {
            let n = self.geometry.n();
            self.reduced = Some(ReducedSet {
                mask,
                solver: WlsSolver::new(&self.geometry, mask, &self.variances[..n]).ok(),
            });
        }
        self.reduced.as_ref().and_then(|r| r.solver.as_ref())
    }
}
