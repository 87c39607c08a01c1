//! The simulated GNSS receiver: epochs measured from the trajectory's truth at the configured
//! rate, with white noise, written to the line `latency_s` later, and the receiver faults a
//! flight test injects (outage, jump, freeze, drift).

use std::collections::VecDeque;

use ipc_types::{GnssFix, GnssFixType, PAYLOAD_VERSION, SimFault};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rins_earth::LocalOrigin;
use rins_gnss_protocol::encode::{write_nav_pvt, write_nmea_epoch};

use crate::gnss_config::{GnssReceiverConfig, ReceiverProtocol};
use crate::simulator::TruthSample;

/// The receiver's clock reads the device time plus this (12:00 UTC, or noon of the GPS week's
/// first day, at device time zero): an arbitrary epoch far from midnight.
pub const RECEIVER_CLOCK_OFFSET_US: u64 = 12 * 3_600_000_000;

/// Epochs in flight between measurement and output at most.
const QUEUE: usize = 64;

/// Salt of the receiver's random stream, so that its noise is not the sensor block's.
const SEED_SALT: u64 = 0x6e55_5f72_6563_7672;

/// The faults of the receiver in effect.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Faults {
    /// No fix until this device time (µs), or until cleared.
    outage_until_us: Option<Option<u64>>,
    /// The epoch repeated verbatim until this device time, or until cleared.
    freeze_until_us: Option<Option<u64>>,
    /// Position offset north, m.
    jump_north_m: f64,
    /// Drift north, m/s, and the device time it started (µs).
    drift: Option<(f64, u64)>,
}

/// The simulated receiver.
#[derive(Debug, Clone)]
pub struct GnssReceiver {
    config: GnssReceiverConfig,
    rng: ChaCha8Rng,
    period_us: u64,
    latency_us: u64,
    next_epoch_us: u64,
    /// Measured epochs waiting for their output time (µs).
    queue: VecDeque<(u64, GnssFix)>,
    last: Option<GnssFix>,
    faults: Faults,
}

impl GnssReceiver {
    /// A receiver with `config`, its noise drawn from `seed`.
    pub fn new(config: GnssReceiverConfig, seed: u64) -> Self {
        Self {
            config,
            rng: ChaCha8Rng::seed_from_u64(seed ^ SEED_SALT),
            period_us: (1e6 / config.rate_hz).round().max(1.0) as u64,
            latency_us: (config.latency_s * 1e6).round() as u64,
            next_epoch_us: 0,
            queue: VecDeque::with_capacity(QUEUE),
            last: None,
            faults: Faults::default(),
        }
    }

    /// One simulator tick with its truth: measures an epoch when one is due, and appends to
    /// `out` the bytes of every epoch whose output time has come.
    pub fn tick(&mut self, truth: &TruthSample, out: &mut Vec<u8>) {
        let t = truth.device_time_us;
        if t >= self.next_epoch_us {
            self.next_epoch_us = t - t % self.period_us + self.period_us;
            let epoch = self.measure(truth);
            if self.queue.len() == QUEUE {
                self.queue.pop_front();
            }
            self.queue.push_back((t + self.latency_us, epoch));
        }
        while let Some(&(due, epoch)) = self.queue.front() {
            if due > t {
                break;
            }
            self.queue.pop_front();
            match self.config.protocol {
                ReceiverProtocol::Nmea => write_nmea_epoch(&epoch, out),
                ReceiverProtocol::Ubx => write_nav_pvt(&epoch, out),
            }
        }
    }

    /// The epoch the receiver reports for the instant of `truth`.
    pub fn measure(&mut self, truth: &TruthSample) -> GnssFix {
        let t = truth.device_time_us;
        let f = &mut self.faults;
        if f.outage_until_us.is_some_and(|u| u.is_some_and(|u| t >= u)) {
            f.outage_until_us = None;
        }
        if f.freeze_until_us.is_some_and(|u| u.is_some_and(|u| t >= u)) {
            f.freeze_until_us = None;
        }
        if f.freeze_until_us.is_some()
            && let Some(last) = self.last
        {
            return last;
        }
        let c = &self.config;
        let mut normal = || -> f64 { StandardNormal.sample(&mut self.rng) };
        let q = truth.quaternion;
        let attitude = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
        let arm = attitude * Vector3::from(c.lever_arm_m);
        let drift_m = f.drift.map_or(0.0, |(rate, since)| {
            rate * t.saturating_sub(since) as f64 * 1e-6
        });
        let north = arm.x + f.jump_north_m + drift_m + c.sigma_horizontal_m * normal();
        let east = arm.y + c.sigma_horizontal_m * normal();
        let down = arm.z + c.sigma_vertical_m * normal();
        let here = LocalOrigin::new(truth.latitude_rad, truth.longitude_rad, truth.altitude_m);
        let [latitude_rad, longitude_rad, altitude_m] = here.geodetic([north, east, down]);
        let v = truth.velocity_ned_mps;
        let outage = f.outage_until_us.is_some();
        let fix_type = if outage {
            GnssFixType::NoFix
        } else {
            GnssFixType::Fix3d
        };
        let epoch = GnssFix {
            version: PAYLOAD_VERSION,
            receiver_time_us: t + RECEIVER_CLOCK_OFFSET_US,
            fix_type: fix_type as u8,
            velocity_valid: 1,
            accuracy_reported: 1,
            satellites: if outage { 0 } else { 12 },
            latitude_rad,
            longitude_rad,
            altitude_m,
            velocity_ned_mps: [
                v[0] + c.sigma_velocity_mps * normal(),
                v[1] + c.sigma_velocity_mps * normal(),
                v[2] + c.sigma_velocity_mps * normal(),
            ],
            horizontal_accuracy_m: c.sigma_horizontal_m,
            vertical_accuracy_m: c.sigma_vertical_m,
            speed_accuracy_mps: c.sigma_velocity_mps,
            hdop: 0.8,
            ..GnssFix::default()
        };
        self.last = Some(epoch);
        epoch
    }

    /// Applies a receiver fault from device time `t_us` on: `param` as [`SimFault`] describes it.
    /// `Err` with the reason for a fault that is not the receiver's or a parameter out of range.
    pub fn apply(&mut self, fault: SimFault, param: f64, t_us: u64) -> Result<(), &'static str> {
        let until = |param: f64| (param > 0.0).then(|| t_us + (param * 1e6).round() as u64);
        let f = &mut self.faults;
        match fault {
            SimFault::Clear => *f = Faults::default(),
            SimFault::GnssOutage if param.is_finite() && param >= 0.0 => {
                f.outage_until_us = Some(until(param));
            }
            SimFault::GnssFreeze if param.is_finite() && param >= 0.0 => {
                f.freeze_until_us = Some(until(param));
            }
            SimFault::GnssJump if param.is_finite() => f.jump_north_m = param,
            SimFault::GnssDrift if param.is_finite() => f.drift = Some((param, t_us)),
            SimFault::GnssOutage | SimFault::GnssFreeze => {
                return Err("must be a duration >= 0 s (0: until cleared)");
            }
            SimFault::GnssJump | SimFault::GnssDrift => return Err("must be a finite number"),
            _ => return Err("not a fault of the GNSS receiver"),
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rins_gnss_protocol::decode::GnssDecoder;

    const LAT: f64 = 0.7;

    fn truth(t_us: u64) -> TruthSample {
        TruthSample {
            device_time_us: t_us,
            latitude_rad: LAT,
            altitude_m: 100.0,
            velocity_ned_mps: [2.0, 0.0, 0.0],
            ..TruthSample::default()
        }
    }

    fn quiet() -> GnssReceiverConfig {
        GnssReceiverConfig {
            sigma_horizontal_m: 0.0,
            sigma_vertical_m: 0.0,
            sigma_velocity_mps: 0.0,
            ..GnssReceiverConfig::default()
        }
    }

    fn north_m(e: &GnssFix) -> f64 {
        LocalOrigin::new(LAT, 0.0, 100.0).ned(e.latitude_rad, e.longitude_rad, 100.0)[0]
    }

    #[test]
    fn five_epochs_a_second_each_on_the_line_after_the_latency() {
        let mut rx = GnssReceiver::new(quiet(), 1);
        let mut decoder = GnssDecoder::new();
        let mut seen = Vec::new();
        for ms in 0..=2_000u64 {
            let mut out = Vec::new();
            rx.tick(&truth(ms * 1_000), &mut out);
            decoder.push(&out, ms, |f| seen.push((ms, f.receiver_time_us)));
        }
        // Measured at 0, 200, …, 1800 ms; on the line 80 ms later, and decoded then (the very
        // first when the second starts: the decoder learns which sentences come per epoch).
        assert_eq!(seen.len(), 10, "{seen:?}");
        for (k, (out_ms, time_us)) in seen.iter().enumerate() {
            let measured_ms = k as u64 * 200;
            let decoded_ms = if k == 0 { 280 } else { measured_ms + 80 };
            assert_eq!(*out_ms, decoded_ms);
            assert_eq!(*time_us, measured_ms * 1_000 + RECEIVER_CLOCK_OFFSET_US);
        }
    }

    #[test]
    fn faults_do_what_they_say() {
        let mut rx = GnssReceiver::new(quiet(), 1);
        assert!(north_m(&rx.measure(&truth(0))).abs() < 1e-9);
        rx.apply(SimFault::GnssJump, 50.0, 1_000_000).unwrap();
        assert!((north_m(&rx.measure(&truth(1_000_000))) - 50.0).abs() < 1e-6);
        rx.apply(SimFault::Clear, 0.0, 2_000_000).unwrap();
        rx.apply(SimFault::GnssDrift, 0.5, 2_000_000).unwrap();
        assert!((north_m(&rx.measure(&truth(12_000_000))) - 5.0).abs() < 1e-6);
        rx.apply(SimFault::Clear, 0.0, 13_000_000).unwrap();
        rx.apply(SimFault::GnssOutage, 2.0, 13_000_000).unwrap();
        assert_eq!(
            rx.measure(&truth(13_000_000)).fix_type,
            GnssFixType::NoFix as u8
        );
        assert_eq!(
            rx.measure(&truth(15_000_000)).fix_type,
            GnssFixType::Fix3d as u8
        );
        let before = rx.measure(&truth(16_000_000));
        rx.apply(SimFault::GnssFreeze, 0.0, 16_000_000).unwrap();
        assert_eq!(rx.measure(&truth(20_000_000)), before);
        rx.apply(SimFault::Clear, 0.0, 21_000_000).unwrap();
        assert_ne!(
            rx.measure(&truth(21_000_000)).receiver_time_us,
            before.receiver_time_us
        );
        assert!(rx.apply(SimFault::Dead, 0.0, 0).is_err());
        assert!(rx.apply(SimFault::GnssOutage, -1.0, 0).is_err());
    }

    #[test]
    fn the_noise_has_the_configured_sigma() {
        let mut rx = GnssReceiver::new(GnssReceiverConfig::default(), 7);
        let n = 4000;
        let (mut sn, mut sd, mut sv) = (0.0, 0.0, 0.0);
        for k in 0..n {
            let e = rx.measure(&truth(k * 200_000));
            sn += north_m(&e).powi(2);
            sd += (e.altitude_m - 100.0).powi(2);
            sv += (e.velocity_ned_mps[0] - 2.0).powi(2);
        }
        let rms = |s: f64| (s / n as f64).sqrt();
        assert!((rms(sn) - 1.5).abs() < 0.15, "{}", rms(sn));
        assert!((rms(sd) - 3.0).abs() < 0.3, "{}", rms(sd));
        assert!((rms(sv) - 0.1).abs() < 0.01, "{}", rms(sv));
    }

    #[test]
    fn the_antenna_is_the_lever_arm_away_turned_with_the_attitude() {
        let config = GnssReceiverConfig {
            lever_arm_m: [1.0, 0.0, 0.0],
            ..quiet()
        };
        let mut rx = GnssReceiver::new(config, 1);
        // Heading north: the antenna 1 m forward is 1 m north.
        assert!((north_m(&rx.measure(&truth(0))) - 1.0).abs() < 1e-6);
    }
}
