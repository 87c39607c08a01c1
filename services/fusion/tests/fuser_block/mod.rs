//! A simulated sensor block feeding an `ImuFuser` end to end: seed pyramids, default channel
//! noise, 12-bit converters at the default full scales, optional per-channel gyro biases.
#![allow(dead_code)]

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rins_fusion::config::{default_accel_sigma_mps2, default_gyro_sigma_rps};
use rins_fusion::{Fused, FusionConfig, Geometry, ImuFuser};

/// Gyro converter step at ±300 °/s over 12 bits, rad/s.
pub const GYRO_LSB: f64 = 300.0 * std::f64::consts::PI / 180.0 / 2048.0;
/// Accelerometer converter step at ±8 g over 12 bits, m/s².
pub const ACCEL_LSB: f64 = 8.0 * 9.80665 / 2048.0;
/// Every channel of both pyramids valid.
pub const ALL_VALID: u32 = 0x000F_000F;
/// Specific force at rest, level, FRD, m/s².
pub const AT_REST_FORCE: [f64; 3] = [0.0, 0.0, -9.80665];

pub struct Block {
    pub fuser: ImuFuser,
    pub gyro: Geometry,
    pub accel: Geometry,
    /// Per-channel gyro bias, rad/s.
    pub gyro_bias: [f64; 4],
    rng: ChaCha8Rng,
}

impl Block {
    pub fn new(cfg: &FusionConfig, seed: u64) -> Self {
        let fuser = ImuFuser::new(cfg, GYRO_LSB, ACCEL_LSB).unwrap();
        Self {
            gyro: *fuser.gyro_geometry(),
            accel: *fuser.accel_geometry(),
            fuser,
            gyro_bias: [0.0; 4],
            rng: ChaCha8Rng::seed_from_u64(seed),
        }
    }

    fn counts(
        &mut self,
        g: Geometry,
        x: [f64; 3],
        sigma: f64,
        lsb: f64,
        bias: [f64; 4],
    ) -> [i16; 4] {
        std::array::from_fn(|i| {
            let h = g.axes()[i];
            let n: f64 = StandardNormal.sample(&mut self.rng);
            let v = h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + bias[i] + sigma * n;
            (v / lsb).round().clamp(-2048.0, 2047.0) as i16
        })
    }

    /// One frame of true body rate `rate` and specific force `force`, with the valid mask `valid`.
    pub fn step(&mut self, rate: [f64; 3], force: [f64; 3], valid: u32) -> Fused {
        let (g, a, b) = (self.gyro, self.accel, self.gyro_bias);
        let gc = self.counts(g, rate, default_gyro_sigma_rps(), GYRO_LSB, b);
        let ac = self.counts(a, force, default_accel_sigma_mps2(), ACCEL_LSB, [0.0; 4]);
        self.fuser.fuse(&gc, &ac, valid)
    }
}

/// Mean of `rate` over a run of frames.
pub fn mean_rate(frames: &[Fused]) -> [f64; 3] {
    let n = frames.len() as f64;
    std::array::from_fn(|k| frames.iter().map(|f| f.rate[k]).sum::<f64>() / n)
}
