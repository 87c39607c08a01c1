//! A bank of single-axis inertial channels (all gyros, or all accelerometers) with their errors and
//! 12-bit ADC.
//!
//! Channel i measures `(1 + s_i)·(h_i · x) + b0_i + b_gm,i(t) + k_i·ΔT + w`, where h_i is the true
//! sensing axis (the nominal axis, optionally misaligned), s_i the scale error, b0_i the turn-on
//! bias, b_gm,i a first-order Gauss–Markov bias, k_i the bias temperature coefficient, ΔT the module
//! temperature minus the reference and w white noise; then `counts = round(value / lsb)` clipped to
//! -2048..=2047.

use ipc_types::MAX_CHANNELS;
use nalgebra::Vector3;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

use super::config::{ADC_MAX, ADC_MIN};
use super::fault::{ActiveFault, ChannelFault};
use super::temperature::TEMPERATURE_SLOTS;

/// Parameters shared by every channel of a bank, in SI units.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BankParams {
    pub lsb: f64,
    pub white_sigma: f64,
    pub turn_on_sigma: f64,
    pub gm_sigma: f64,
    pub gm_tau_s: f64,
    pub scale_sigma: f64,
    pub temp_coeff_sigma: f64,
    pub misalignment_sigma_rad: f64,
    pub sample_period_s: f64,
    pub temperature_sensors: usize,
}

/// The true errors of one channel, in its SI unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelErrors {
    /// True sensing axis (unit vector, body frame).
    pub axis: [f64; 3],
    /// Scale-factor error (fraction).
    pub scale_error: f64,
    /// Constant bias drawn at turn-on.
    pub turn_on_bias: f64,
    /// Current Gauss–Markov bias (the value used by the next sample).
    pub gauss_markov_bias: f64,
    /// Bias temperature coefficient, per °C.
    pub temp_coeff_per_c: f64,
    /// Index of the module temperature sensor this channel follows.
    pub temperature_sensor: usize,
}

impl ChannelErrors {
    /// Total additive bias at a module temperature `delta_c` above the reference.
    pub fn bias_at(&self, delta_c: f64) -> f64 {
        self.turn_on_bias + self.gauss_markov_bias + self.temp_coeff_per_c * delta_c
    }
}

/// Result of sampling a bank once.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct BankOutput {
    /// Bit i set: channel i delivered data.
    pub valid: u16,
    /// Some channel clipped at the ADC limits.
    pub saturated: bool,
}

#[derive(Debug, Clone)]
pub(crate) struct InertialBank {
    count: usize,
    errors: [ChannelErrors; MAX_CHANNELS],
    lsb: f64,
    white_sigma: f64,
    gm_phi: f64,
    gm_drive: f64,
    faults: [Option<ActiveFault>; MAX_CHANNELS],
    last_counts: [i16; MAX_CHANNELS],
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample::<f64, _>(StandardNormal)
}

impl InertialBank {
    /// `axes` are already validated unit vectors (at most [`MAX_CHANNELS`]); the per-channel errors
    /// are drawn from `rng`.
    pub fn new(axes: &[Vector3<f64>], params: &BankParams, rng: &mut ChaCha8Rng) -> Self {
        let blank = ChannelErrors {
            axis: [0.0; 3],
            scale_error: 0.0,
            turn_on_bias: 0.0,
            gauss_markov_bias: 0.0,
            temp_coeff_per_c: 0.0,
            temperature_sensor: 0,
        };
        let mut errors = [blank; MAX_CHANNELS];
        for (i, (axis, e)) in axes.iter().zip(errors.iter_mut()).enumerate() {
            // Always draw the same number of values per channel so that changing one σ does not
            // reshuffle the others.
            let tilt =
                Vector3::new(normal(rng), normal(rng), normal(rng)) * params.misalignment_sigma_rad;
            let true_axis = (axis + tilt).normalize();
            e.axis = [true_axis.x, true_axis.y, true_axis.z];
            e.scale_error = params.scale_sigma * normal(rng);
            e.turn_on_bias = params.turn_on_sigma * normal(rng);
            e.gauss_markov_bias = params.gm_sigma * normal(rng);
            e.temp_coeff_per_c = params.temp_coeff_sigma * normal(rng);
            e.temperature_sensor = i % params.temperature_sensors.max(1);
        }
        let gm_phi = (-params.sample_period_s / params.gm_tau_s).exp();
        Self {
            count: axes.len(),
            errors,
            lsb: params.lsb,
            white_sigma: params.white_sigma,
            gm_phi,
            gm_drive: params.gm_sigma * (1.0 - gm_phi * gm_phi).max(0.0).sqrt(),
            faults: [None; MAX_CHANNELS],
            last_counts: [0; MAX_CHANNELS],
        }
    }

    pub fn count(&self) -> usize {
        self.count
    }

    pub fn errors(&self, channel: usize) -> Option<&ChannelErrors> {
        self.errors[..self.count].get(channel)
    }

    pub fn fault(&self, channel: usize) -> Option<ChannelFault> {
        self.faults[..self.count]
            .get(channel)
            .copied()
            .flatten()
            .map(|f| f.fault)
    }

    /// Sets (or with `None` clears) the fault of an existing channel from time `now_s`.
    pub fn set_fault(&mut self, channel: usize, fault: Option<ChannelFault>, now_s: f64) {
        self.faults[channel] = fault.map(|fault| ActiveFault {
            fault,
            start_s: now_s,
            frozen_counts: self.last_counts[channel],
        });
    }

    /// Samples every channel for the truth vector `x` at time `t_s`; `delta_c` are the module
    /// temperatures minus the reference. The fault RNG is used only by noise-burst faults, so
    /// injecting a fault never changes the noise of the other channels.
    pub fn sample(
        &mut self,
        x: &Vector3<f64>,
        t_s: f64,
        delta_c: &[f64; TEMPERATURE_SLOTS],
        rng: &mut ChaCha8Rng,
        fault_rng: &mut ChaCha8Rng,
        counts: &mut [i16; MAX_CHANNELS],
    ) -> BankOutput {
        let mut out = BankOutput::default();
        for (i, count) in counts.iter_mut().enumerate().take(self.count) {
            let e = &mut self.errors[i];
            let projected = e.axis[0] * x.x + e.axis[1] * x.y + e.axis[2] * x.z;
            let mut value = (1.0 + e.scale_error) * projected
                + e.bias_at(delta_c[e.temperature_sensor])
                + self.white_sigma * normal(rng);
            e.gauss_markov_bias = self.gm_phi * e.gauss_markov_bias + self.gm_drive * normal(rng);

            let fault = self.faults[i];
            if let Some(f) = fault {
                match f.fault {
                    ChannelFault::BiasStep { bias } => value += bias,
                    ChannelFault::Ramp { rate_per_s } => value += rate_per_s * (t_s - f.start_s),
                    ChannelFault::NoiseBurst { sigma } => value += sigma * normal(fault_rng),
                    _ => {}
                }
            }
            let (mut c, mut clipped) = quantize(value / self.lsb);
            let mut valid = true;
            if let Some(f) = fault {
                match f.fault {
                    ChannelFault::Dead => valid = false,
                    ChannelFault::Stuck => (c, clipped) = (f.frozen_counts, false),
                    ChannelFault::Saturated => (c, clipped) = (ADC_MAX, true),
                    ChannelFault::Intermittent {
                        period_s,
                        dropout_s,
                    } => {
                        valid = !in_dropout(t_s - f.start_s, period_s, dropout_s);
                    }
                    _ => {}
                }
            }
            if valid {
                *count = c;
                out.valid |= 1 << i;
                out.saturated |= clipped;
                self.last_counts[i] = c;
            } else {
                *count = 0;
            }
        }
        counts[self.count..].fill(0);
        out
    }
}

/// Whether `elapsed_s` after injection falls in the dead part of an intermittent cycle. Sample times
/// are k/rate, so cycle boundaries land on them only up to round-off: a nanosecond of slack puts a
/// sample that is nominally on a boundary into the cycle that starts there.
fn in_dropout(elapsed_s: f64, period_s: f64, dropout_s: f64) -> bool {
    const SLACK_S: f64 = 1e-9;
    let cycles = ((elapsed_s + SLACK_S) / period_s).floor();
    elapsed_s - cycles * period_s < dropout_s - SLACK_S
}

/// Rounds to the nearest count and clips to the 12-bit range; reports clipping.
pub(crate) fn quantize(counts: f64) -> (i16, bool) {
    let r = counts.round();
    if r > f64::from(ADC_MAX) {
        (ADC_MAX, true)
    } else if r < f64::from(ADC_MIN) {
        (ADC_MIN, true)
    } else if r.is_nan() {
        (0, true)
    } else {
        // In range, so the cast is exact.
        (r as i16, false)
    }
}
