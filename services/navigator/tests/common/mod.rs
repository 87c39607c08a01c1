//! Shared helpers for the navigator tests: true sensor outputs and seeded noise.
#![allow(dead_code)]

use nalgebra::{UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Seeded Gaussian noise source.
pub struct Noise {
    rng: ChaCha8Rng,
    unit: Normal<f64>,
}

impl Noise {
    pub fn new(seed: u64) -> Self {
        Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
            unit: Normal::new(0.0, 1.0).unwrap(),
        }
    }

    pub fn scalar(&mut self, sigma: f64) -> f64 {
        sigma * self.unit.sample(&mut self.rng)
    }

    pub fn vector(&mut self, sigma: f64) -> Vector3<f64> {
        Vector3::new(self.scalar(sigma), self.scalar(sigma), self.scalar(sigma))
    }
}

/// Specific force felt at rest in attitude `q` (body→NED): `C_nbᵀ [0, 0, −g]`.
pub fn specific_force_at_rest(q: &UnitQuaternion<f64>, g: f64) -> Vector3<f64> {
    q.inverse() * Vector3::new(0.0, 0.0, -g)
}

/// Earth field in NED for horizontal intensity `horizontal`, downward component `down` and declination
/// `declination` (rad, positive east), µT.
pub fn earth_field_ned(horizontal: f64, down: f64, declination: f64) -> Vector3<f64> {
    Vector3::new(
        horizontal * declination.cos(),
        horizontal * declination.sin(),
        down,
    )
}

/// Difference of two angles wrapped to (−π, π].
pub fn angle_diff(a: f64, b: f64) -> f64 {
    rins_navigator::attitude::wrap_pi(a - b)
}
