//! A simulated sensor block for the fault-detection tests: one sensor type, N channels with white
//! noise, 12-bit quantisation and injectable faults, driving a `SensorMonitor` directly.
#![allow(dead_code)]

use ipc_types::SensorType;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rins_fusion::fdi::channel_health::{COUNT_MAX, COUNT_MIN};
use rins_fusion::fdi::{
    ChannelEvents, FdiConfig, MonitorInput, SensorEstimate, SensorMonitor, SensorStatus,
};
use rins_fusion::geometry::MAX_CHANNELS;
use rins_fusion::{Geometry, GeometryConfig};

/// Gyro converter step at the default ±300 °/s full scale, rad/s.
pub const GYRO_LSB: f64 = 300.0 * std::f64::consts::PI / 180.0 / 2048.0;
/// Accelerometer converter step at the default ±8 g full scale, m/s².
pub const ACCEL_LSB: f64 = 8.0 * 9.80665 / 2048.0;
/// Default gyro channel σ, rad/s (≈ 2.2 lsb).
pub const GYRO_SIGMA: f64 = 0.005519;
/// Default accelerometer channel σ, m/s² (≈ 1.2 lsb).
pub const ACCEL_SIGMA: f64 = 0.046517;

/// A fault injected into one channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fault {
    None,
    /// Adds a constant, SI units.
    Bias(f64),
    /// Repeats the count it had when the fault started.
    Stuck,
    /// Reads the upper rail.
    Rail,
    /// Multiplies the noise.
    Noise(f64),
    /// Flagged invalid.
    Dead,
    /// Scale-factor error: reads (1 + k) times the true projection.
    Scale(f64),
}

pub struct Rig {
    pub monitor: SensorMonitor,
    pub geometry: Geometry,
    pub sigma: [f64; MAX_CHANNELS],
    pub lsb: f64,
    /// Feed quantised values (counts · lsb) as z; otherwise the exact noisy value.
    pub quantize: bool,
    pub faults: [Fault; MAX_CHANNELS],
    held: [i16; MAX_CHANNELS],
    last_counts: [i16; MAX_CHANNELS],
    /// Samples into the current stationary block.
    block: u32,
    pub rng: ChaCha8Rng,
    pub events: ChannelEvents,
}

pub fn build(kind: &GeometryConfig) -> Geometry {
    kind.build().unwrap()
}

pub fn pyramid4() -> Geometry {
    build(&GeometryConfig::seed_pyramid())
}

pub fn dodecahedron() -> Geometry {
    build(&GeometryConfig::Dodecahedron {})
}

/// Two triads, the second turned so that no parity columns are parallel.
pub fn stacked_two() -> Geometry {
    build(&GeometryConfig::Stacked {
        count: 2,
        rotations_deg: vec![[0.0, 0.0, 0.0], [45.0, 35.26, 30.0]],
    })
}

/// Builds a [`Rig`]: the four-axis pyramid, the sensor type's default σ and converter step,
/// quantised values, the default fault-detection settings and seed 0, unless told otherwise.
pub struct RigBuilder {
    sensor: SensorType,
    geometry: Option<Geometry>,
    sigma: Option<f64>,
    lsb: Option<f64>,
    quantize: bool,
    config: FdiConfig,
    seed: u64,
}

impl RigBuilder {
    /// The channels' sensitive axes.
    pub fn geometry(mut self, geometry: Geometry) -> Self {
        self.geometry = Some(geometry);
        self
    }

    /// One σ for every channel, SI units.
    pub fn sigma(mut self, sigma: f64) -> Self {
        self.sigma = Some(sigma);
        self
    }

    /// The converter step, SI units.
    pub fn lsb(mut self, lsb: f64) -> Self {
        self.lsb = Some(lsb);
        self
    }

    /// Feed the exact noisy values instead of counts · lsb (and no quantisation noise).
    pub fn exact(mut self) -> Self {
        self.quantize = false;
        self
    }

    /// The fault-detection settings.
    pub fn config(mut self, config: &FdiConfig) -> Self {
        self.config = config.clone();
        self
    }

    /// Seed of the noise.
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// The rig: with `quantize`, counts · lsb are the values and the monitor is told about the
    /// quantisation noise lsb²/12.
    pub fn build(self) -> Rig {
        let (default_sigma, default_lsb) = match self.sensor {
            SensorType::Gyro => (GYRO_SIGMA, GYRO_LSB),
            SensorType::Accel => (ACCEL_SIGMA, ACCEL_LSB),
        };
        let geometry = self.geometry.unwrap_or_else(pyramid4);
        let sigma = self.sigma.unwrap_or(default_sigma);
        let lsb = self.lsb.unwrap_or(default_lsb);
        let quantize = self.quantize;
        let n = geometry.n();
        let mut sig = [0.0; MAX_CHANNELS];
        sig[..n].fill(sigma);
        let quantisation = if quantize { lsb * lsb / 12.0 } else { 0.0 };
        let variances = sig.map(|s| if s > 0.0 { s * s + quantisation } else { 0.0 });
        let rails =
            std::array::from_fn(|_| [f64::from(COUNT_MIN) * lsb, f64::from(COUNT_MAX) * lsb]);
        let monitor = SensorMonitor::new(
            self.sensor,
            geometry,
            variances,
            rails,
            self.config.settings().unwrap(),
        );
        Rig {
            monitor,
            geometry,
            sigma: sig,
            lsb,
            quantize,
            faults: [Fault::None; MAX_CHANNELS],
            held: [0; MAX_CHANNELS],
            last_counts: [0; MAX_CHANNELS],
            block: 0,
            rng: ChaCha8Rng::seed_from_u64(self.seed),
            events: ChannelEvents::EMPTY,
        }
    }
}

impl Rig {
    /// A rig of one sensor type, with the defaults of [`RigBuilder`].
    pub fn builder(sensor: SensorType) -> RigBuilder {
        RigBuilder {
            sensor,
            geometry: None,
            sigma: None,
            lsb: None,
            quantize: true,
            config: FdiConfig::default(),
            seed: 0,
        }
    }

    pub fn n(&self) -> usize {
        self.geometry.n()
    }

    /// Sets a fault (Stuck repeats the channel's last count, as the simulator does).
    pub fn inject(&mut self, channel: usize, fault: Fault) {
        self.faults[channel] = fault;
        self.held[channel] = self.last_counts[channel];
    }

    /// One noisy sample of the true vector `x`: (z, counts, valid mask).
    pub fn sample(&mut self, x: [f64; 3]) -> ([f64; MAX_CHANNELS], [i16; MAX_CHANNELS], u32) {
        let mut z = [f64::NAN; MAX_CHANNELS];
        let mut counts = [0i16; MAX_CHANNELS];
        let mut valid = 0u32;
        for (i, h) in self.geometry.axes().iter().enumerate() {
            let noise: f64 = StandardNormal.sample(&mut self.rng);
            let mut sigma = self.sigma[i];
            let mut value = h[0] * x[0] + h[1] * x[1] + h[2] * x[2];
            match self.faults[i] {
                Fault::Bias(b) => value += b,
                Fault::Noise(k) => sigma *= k,
                Fault::Scale(k) => value *= 1.0 + k,
                _ => {}
            }
            value += sigma * noise;
            let mut c = (value / self.lsb)
                .round()
                .clamp(f64::from(COUNT_MIN), f64::from(COUNT_MAX)) as i16;
            match self.faults[i] {
                Fault::Stuck => {
                    c = self.held[i];
                    value = f64::from(c) * self.lsb;
                }
                Fault::Rail => {
                    c = COUNT_MAX;
                    value = f64::from(c) * self.lsb;
                }
                _ => {}
            }
            counts[i] = c;
            self.last_counts[i] = c;
            z[i] = if self.quantize {
                f64::from(c) * self.lsb
            } else {
                value
            };
            if self.faults[i] != Fault::Dead {
                valid |= 1 << i;
            }
        }
        (z, counts, valid)
    }

    /// Runs the learning phase (parity offset, adaptive noise) on the true vector `x` and checks
    /// that it raised nothing.
    pub fn learn(&mut self, x: [f64; 3], stationary: bool) {
        for _ in 0..self.monitor.settings().learning_samples {
            let (_, st) = self.step(x, stationary);
            assert!(!st.detected_not_isolated);
        }
    }

    /// One monitor step on the true vector `x`.
    pub fn step(&mut self, x: [f64; 3], stationary: bool) -> (SensorEstimate, SensorStatus) {
        let (z, counts, valid) = self.sample(x);
        self.step_with(&z, &counts, valid, stationary)
    }

    pub fn step_with(
        &mut self,
        z: &[f64; MAX_CHANNELS],
        counts: &[i16; MAX_CHANNELS],
        valid: u32,
        stationary: bool,
    ) -> (SensorEstimate, SensorStatus) {
        self.events = ChannelEvents::EMPTY;
        let input = MonitorInput {
            counts: &counts[..self.geometry.n()],
            z,
            valid,
            device_error: false,
            temperature_suspect: 0,
        };
        let out = self.monitor.step(&input, stationary, &mut self.events);
        // Close stationary blocks as the fuser's detector would, with `stationary` as the verdict.
        self.block += 1;
        if self.block == self.monitor.settings().stationary.window {
            self.block = 0;
            self.monitor.end_block(stationary);
        }
        out
    }
}

/// Unit vector of a random direction scaled to `norm`.
pub fn random_vector(rng: &mut ChaCha8Rng, norm: f64) -> [f64; 3] {
    let v: [f64; 3] = std::array::from_fn(|_| StandardNormal.sample(rng));
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|c| c / l * norm)
}
