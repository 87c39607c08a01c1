//! Magnetometer: the Earth field rotated into the body frame by the true attitude, distorted by
//! soft and hard iron, plus white noise; output in nanotesla.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rins_protocol::MagFrame;

/// The local Earth magnetic field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EarthField {
    /// Total intensity, nT.
    pub intensity_nt: f64,
    /// Inclination (dip), positive down, rad.
    pub inclination_rad: f64,
    /// Declination, positive east of true north, rad.
    pub declination_rad: f64,
}

impl EarthField {
    /// The field in NED: `B [cos I cos D, cos I sin D, sin I]`, nT.
    pub fn ned_nt(&self) -> Vector3<f64> {
        let (si, ci) = self.inclination_rad.sin_cos();
        let (sd, cd) = self.declination_rad.sin_cos();
        self.intensity_nt * Vector3::new(ci * cd, ci * sd, si)
    }
}

#[derive(Debug, Clone)]
pub(crate) struct MagModel {
    pub field_ned_nt: Vector3<f64>,
    pub soft_iron: Matrix3<f64>,
    pub hard_iron_nt: Vector3<f64>,
    pub noise_nt: f64,
}

impl MagModel {
    pub fn sample(&self, attitude: &UnitQuaternion<f64>, rng: &mut ChaCha8Rng, out: &mut MagFrame) {
        let body = self.soft_iron * attitude.inverse_transform_vector(&self.field_ned_nt)
            + self.hard_iron_nt;
        for (o, b) in out.field_nt.iter_mut().zip(body.iter()) {
            let v = b + self.noise_nt * rng.sample::<f64, _>(StandardNormal);
            // `as` saturates; the configured field and iron terms keep this far inside i32.
            *o = v.round() as i32;
        }
    }
}
