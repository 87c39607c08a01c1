//! A standard GNSS receiver made from the reference trajectory: positions decimated to 5 Hz
//! (interpolated at 0.2 s steps), with seeded white noise of σ 1.5 m horizontal, 3 m vertical and
//! 0.1 m/s velocity per axis, measured at the reference's own time (no latency), which leads the
//! units' clock by the lead the evaluation fits ([`super::antenna`]).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use ipc_types::{GnssFix, GnssFixType, GnssProtocol, Header};
use rins_earth::LocalOrigin;

use crate::datasets::quadrotor::TruthRow;
use crate::import::rx_ns;
use crate::quadrotor_ahrs::run::device_us;

/// Epochs per second.
pub const RATE_HZ: f64 = 5.0;
/// Horizontal σ per axis, m.
pub const SIGMA_H_M: f64 = 1.5;
/// Vertical σ, m.
pub const SIGMA_V_M: f64 = 3.0;
/// Velocity σ per axis, m/s.
pub const SIGMA_VEL_MPS: f64 = 0.1;

/// One epoch in the reference's local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFix {
    /// Time on the trial's time base, s.
    pub t_s: f64,
    /// North, east, down from the first reference row, m.
    pub ned_m: [f64; 3],
    /// Velocity NED, m/s.
    pub velocity_ned_mps: [f64; 3],
}

/// The reference's north/east/down at `t_s`, linearly interpolated; `None` outside it.
pub fn truth_ned_at(truth: &[TruthRow], t_s: f64) -> Option<[f64; 3]> {
    let (first, last) = (truth.first()?, truth.last()?);
    if !(t_s >= first.t_s && t_s <= last.t_s) {
        return None;
    }
    let i = truth
        .partition_point(|r| r.t_s <= t_s)
        .clamp(1, truth.len() - 1);
    let (a, b) = (&truth[i - 1], &truth[i]);
    let span = b.t_s - a.t_s;
    let w = if span > 0.0 {
        (t_s - a.t_s) / span
    } else {
        0.0
    };
    let lerp = |x: f64, y: f64| x + w * (y - x);
    Some([
        lerp(a.north_m, b.north_m),
        lerp(a.east_m, b.east_m),
        lerp(a.down_m, b.down_m),
    ])
}

/// The receiver's epochs from `from_s` to `to_s` (inclusive), every 1/[`RATE_HZ`] s, the noise
/// drawn from `seed`. The velocity is the central difference of the reference over ±0.1 s. Each
/// epoch made from the reference at t is stamped `t + lead_s`: the reference position stamped t
/// is the antenna's at t + `lead_s` on the units' clock.
pub fn epochs(truth: &[TruthRow], from_s: f64, to_s: f64, lead_s: f64, seed: u64) -> Vec<LocalFix> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut normal = move || -> f64 { StandardNormal.sample(&mut rng) };
    let step = 1.0 / RATE_HZ;
    let mut out = Vec::new();
    let mut k = 0u32;
    loop {
        let t = from_s + f64::from(k) * step;
        if t > to_s {
            break;
        }
        k += 1;
        let (Some(p), Some(before), Some(after)) = (
            truth_ned_at(truth, t),
            truth_ned_at(truth, t - 0.1),
            truth_ned_at(truth, t + 0.1),
        ) else {
            continue;
        };
        let v = [0, 1, 2].map(|i| (after[i] - before[i]) / 0.2);
        out.push(LocalFix {
            t_s: t + lead_s,
            ned_m: [
                p[0] + SIGMA_H_M * normal(),
                p[1] + SIGMA_H_M * normal(),
                p[2] + SIGMA_V_M * normal(),
            ],
            velocity_ned_mps: v.map(|x| x + SIGMA_VEL_MPS * normal()),
        });
    }
    out
}

/// The receiver message of `fix`: a 3-D fix at the geodetic position of its local `ned_m` about
/// `origin`, its velocity and the receiver's σs, received at its device time (the trial's time
/// plus a second, as the import writes it), `seq` its sequence number.
pub fn gnss_fix(fix: &LocalFix, origin: &LocalOrigin, seq: u64) -> GnssFix {
    let [lat, lon, alt] = origin.geodetic(fix.ned_m);
    let t_us = device_us(fix.t_s);
    GnssFix {
        fix_type: GnssFixType::Fix3d as u8,
        satellites: 12,
        protocol: GnssProtocol::Ubx as u8,
        velocity_valid: 1,
        accuracy_reported: 1,
        header: Header {
            origin_seq: seq,
            origin_device_time_us: t_us,
            origin_rx_ns: rx_ns(t_us),
            ..Header::default()
        },
        receiver_time_us: t_us,
        latitude_rad: lat,
        longitude_rad: lon,
        altitude_m: alt,
        velocity_ned_mps: fix.velocity_ned_mps,
        horizontal_accuracy_m: SIGMA_H_M,
        vertical_accuracy_m: SIGMA_V_M,
        speed_accuracy_mps: SIGMA_VEL_MPS,
        ..GnssFix::default()
    }
}

/// A seed from a trial's name, so that each flight has its own noise and every run the same.
pub fn seed_of(name: &str) -> u64 {
    // FNV-1a: stable across runs and platforms.
    name.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(n: usize) -> Vec<TruthRow> {
        // 10 Hz rows, 3 m/s north, 4 m/s east.
        (0..n)
            .map(|i| {
                let t = i as f64 * 0.1;
                TruthRow {
                    t_s: t,
                    distance_m: 5.0 * t,
                    speed_mps: 5.0,
                    heading_rad: 0.0,
                    pitch_rad: 0.0,
                    roll_rad: 0.0,
                    height_m: 0.0,
                    north_m: 3.0 * t,
                    east_m: 4.0 * t,
                    down_m: 0.0,
                }
            })
            .collect()
    }

    #[test]
    fn five_epochs_a_second_with_the_configured_noise() {
        let truth = line(20_001);
        let fixes = epochs(&truth, 0.1, 1999.0, 0.0, 3);
        // 0.1 … 1998.9 s every 0.2 s, the last needing a row 0.1 s later.
        assert_eq!(fixes.len(), 9995);
        assert!((fixes[1].t_s - fixes[0].t_s - 0.2).abs() < 1e-9);
        let n = fixes.len() as f64;
        let rms = |f: &dyn Fn(&LocalFix) -> f64| {
            (fixes.iter().map(|x| f(x).powi(2)).sum::<f64>() / n).sqrt()
        };
        assert!((rms(&|x| x.ned_m[0] - 3.0 * x.t_s) - SIGMA_H_M).abs() < 0.05);
        assert!((rms(&|x| x.ned_m[2]) - SIGMA_V_M).abs() < 0.1);
        assert!((rms(&|x| x.velocity_ned_mps[1] - 4.0) - SIGMA_VEL_MPS).abs() < 0.004);
        assert_eq!(
            epochs(&truth, 0.1, 10.0, 0.0, 3),
            epochs(&truth, 0.1, 10.0, 0.0, 3)
        );
        assert_ne!(seed_of("Horizontal/path_1"), seed_of("Horizontal/path_2"));
    }
}
