//! Rotor vibration of the sensor block: a sinusoid at the blade-pass frequency added to the body
//! rate and the specific force before they are projected on the channels.
//!
//! The block is rigid, so every channel sees the projection of the same body vector: the
//! vibration lies in the range of the geometry and the parity residuals cancel it (up to each
//! channel's scale and misalignment error). It is evaluated at the sample instant with no
//! anti-alias filter, as a MEMS IMU sampled without one sees it: above half the IMU rate it
//! folds to |f − k·rate|.

use nalgebra::Vector3;

/// The rotors' contribution at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RotorState {
    /// Blade-pass phase, rad (not wrapped).
    pub blade_phase_rad: f64,
    /// Vibration amplitude on the accelerometers, m/s² (the largest body axis); 0: rotors stopped.
    pub accel_amplitude_mps2: f64,
    /// Vibration amplitude on the gyros, rad/s (the largest body axis).
    pub gyro_amplitude_rps: f64,
}

/// Share of the acceleration amplitude on body x and y: the thrust ripple along z dominates, the
/// rotor imbalance shakes the plane less.
const ACCEL_SHAPE: [f64; 3] = [0.4, 0.4, 1.0];
/// Share of the angular amplitude on body x, y and z: rocking about the arms more than yawing.
const GYRO_SHAPE: [f64; 3] = [1.0, 1.0, 0.3];
/// Phase of each body axis relative to the blade phase, rad: the axes do not swing together.
const ACCEL_PHASE: [f64; 3] = [0.0, 1.571, 0.5];
const GYRO_PHASE: [f64; 3] = [1.0, 2.571, 0.0];

/// Vibration body rate (rad/s) and specific force (m/s²) of `rotor`.
pub fn body_vibration(rotor: &RotorState) -> (Vector3<f64>, Vector3<f64>) {
    if rotor.accel_amplitude_mps2 == 0.0 && rotor.gyro_amplitude_rps == 0.0 {
        return (Vector3::zeros(), Vector3::zeros());
    }
    let wave = |amplitude: f64, shape: [f64; 3], phase: [f64; 3]| {
        Vector3::from_fn(|i, _| amplitude * shape[i] * (rotor.blade_phase_rad + phase[i]).sin())
    };
    (
        wave(rotor.gyro_amplitude_rps, GYRO_SHAPE, GYRO_PHASE),
        wave(rotor.accel_amplitude_mps2, ACCEL_SHAPE, ACCEL_PHASE),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// Amplitude of the component of `x` (sampled at `rate_hz`) at `hz`.
    fn amplitude_at(x: &[f64], rate_hz: f64, hz: f64) -> f64 {
        let (mut c, mut s) = (0.0, 0.0);
        for (k, v) in x.iter().enumerate() {
            let a = TAU * hz * k as f64 / rate_hz;
            c += v * a.cos();
            s += v * a.sin();
        }
        2.0 * (c * c + s * s).sqrt() / x.len() as f64
    }

    #[test]
    fn stopped_rotors_do_not_shake() {
        let (w, f) = body_vibration(&RotorState::default());
        assert_eq!((w, f), (Vector3::zeros(), Vector3::zeros()));
    }

    #[test]
    fn amplitude_and_shape_are_as_configured() {
        let rotor = |phase: f64| RotorState {
            blade_phase_rad: phase,
            accel_amplitude_mps2: 3.0,
            gyro_amplitude_rps: 0.01,
        };
        let peak = (0..3600)
            .map(|i| {
                body_vibration(&rotor(TAU * f64::from(i) / 3600.0))
                    .1
                    .z
                    .abs()
            })
            .fold(0.0, f64::max);
        assert!((peak - 3.0).abs() < 1e-5);
        let (w, f) = body_vibration(&rotor(0.3));
        assert!(f.x.abs() <= 0.4 * 3.0 && w.norm() <= 0.01 * 3f64.sqrt());
    }

    #[test]
    fn a_blade_pass_above_half_the_imu_rate_aliases() {
        // 200 Hz blade pass sampled at 250 Hz (Nyquist 125 Hz) appears at |200 − 250| = 50 Hz.
        let (blade_hz, rate_hz) = (200.0, 250.0);
        let z: Vec<f64> = (0..2500)
            .map(|k| {
                let t = k as f64 / rate_hz;
                let rotor = RotorState {
                    blade_phase_rad: TAU * blade_hz * t,
                    accel_amplitude_mps2: 3.0,
                    gyro_amplitude_rps: 0.0,
                };
                body_vibration(&rotor).1.z
            })
            .collect();
        assert!((amplitude_at(&z, rate_hz, 50.0) - 3.0).abs() < 1e-6);
        for other in [10.0, 25.0, 75.0, 100.0, 120.0] {
            assert!(amplitude_at(&z, rate_hz, other) < 1e-6, "{other} Hz");
        }
        // Sampled at 1 kHz it stays at 200 Hz.
        let z: Vec<f64> = (0..1000)
            .map(|k| {
                let rotor = RotorState {
                    blade_phase_rad: TAU * blade_hz * k as f64 / 1000.0,
                    accel_amplitude_mps2: 3.0,
                    gyro_amplitude_rps: 0.0,
                };
                body_vibration(&rotor).1.z
            })
            .collect();
        assert!((amplitude_at(&z, 1000.0, 200.0) - 3.0).abs() < 1e-6);
        assert!(amplitude_at(&z, 1000.0, 50.0) < 1e-6);
    }
}
