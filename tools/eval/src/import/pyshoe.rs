//! A foot-mounted pyshoe walk: one triad, the Vicon foot position as truth.
//!
//! The samples are the loader's (rows repeating a time dropped, a unit mounted upside down turned
//! over), in the product's body convention. Device time is [`device_us`] of the time since the
//! first sample: the walk starts at 1 s of device time, as the quadrotor flights do near it.
//!
//! Vicon's frame is x, y horizontal, z up, with no known heading: it is taken as east, north, up
//! (a proper rotation into NED: north = y, east = x, down = −z), about the walk's first position,
//! which is placed at the navigator's configured origin. The loader has no attitude: the truth's
//! quaternion is NaN (unknown), its velocity the central difference of the positions.

use anyhow::{Result, anyhow};
use ipc_types::{Header, RawImu, Truth};
use rins_earth::LocalOrigin;

use super::counts::{BlockQuantiser, Scales, largest_abs};
use super::fragment::{Axes, Fragment, NoiseDensity, render};
use super::quadrotor::Profile;
use super::{ImportedRun, RepairCount, central_difference};
use crate::datasets::FootTrial;
use crate::quadrotor_ahrs::run::device_us;

/// Channel noise of the unit: the MicroStrain 3DM-GX5-25's datasheet class.
pub const NOISE: NoiseDensity = NoiseDensity {
    gyro_dps_rthz: 0.005,
    accel_ug_rthz: 100.0,
    source: "MicroStrain 3DM-GX5-25 datasheet (gyro 0.005 °/s/√Hz, accelerometer 100 µg/√Hz)",
};

/// Vicon x, y, z (z up) relative to `first` as north, east, down.
fn vicon_ned(p: &[f64; 3], first: &[f64; 3]) -> [f64; 3] {
    [p[1] - first[1], p[0] - first[0], -(p[2] - first[2])]
}

/// The sample rate written to the configuration: the median rate rounded to 0.001 Hz.
fn written_rate(rate_hz: f64) -> f64 {
    (rate_hz * 1000.0).round() / 1000.0
}

/// Imports one loaded walk under `profile` (the pedestrian profile). Errors name the trial.
pub fn import_trial(trial: &FootTrial, profile: &Profile<'_>) -> Result<ImportedRun> {
    let name = &trial.name;
    let t0 = trial
        .samples
        .first()
        .map(|s| s.t_s)
        .ok_or_else(|| anyhow!("{name}: no samples"))?;
    let rate_hz = written_rate(trial.rate_hz);
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(anyhow!("{name}: sample rate {} Hz", trial.rate_hz));
    }
    let scales = Scales::above(
        largest_abs(trial.samples.iter().flat_map(|s| s.gyro_rps)),
        largest_abs(trial.samples.iter().flat_map(|s| s.accel_mps2)),
    )
    .ok_or_else(|| anyhow!("{name}: no finite IMU value to scale the converter to"))?;
    let mut block = BlockQuantiser::new(&scales);
    let imu: Vec<RawImu> = trial
        .samples
        .iter()
        .enumerate()
        .map(|(j, s)| block.frame(j as u64, device_us(s.t_s - t0), &s.gyro_rps, &s.accel_mps2))
        .collect();

    let mut notes = Vec::new();
    let truth = match &trial.truth_m {
        Some(vicon) if !vicon.is_empty() => {
            let [lat, lon, alt] = profile.origin;
            let origin = LocalOrigin::new(lat, lon, alt);
            let first = vicon[0];
            let times: Vec<f64> = trial.samples.iter().map(|s| s.t_s).collect();
            let ned: Vec<[f64; 3]> = vicon.iter().map(|p| vicon_ned(p, &first)).collect();
            let velocity = central_difference(&times, &ned);
            imu.iter()
                .zip(&ned)
                .zip(velocity)
                .map(|((frame, p), v)| {
                    let [lat, lon, alt] = origin.geodetic(*p);
                    Truth {
                        header: Header {
                            origin_seq: frame.header.origin_seq,
                            origin_device_time_us: frame.header.origin_device_time_us,
                            ..Header::default()
                        },
                        quaternion: [f64::NAN; 4],
                        velocity_ned_mps: v,
                        latitude_rad: lat,
                        longitude_rad: lon,
                        altitude_m: alt,
                        ..Truth::default()
                    }
                })
                .collect()
        }
        _ => {
            notes.push("no Vicon position: no truth written".to_string());
            Vec::new()
        }
    };
    if trial.turned_over {
        notes.push("recorded z up: turned 180° about x into the z-down body axes".to_string());
    }
    let config_fragment = render(&Fragment {
        title: format!(
            "Foot-mounted walk {name} (pyshoe, Wagstaff, Peretroukhin & Kelly: MicroStrain \
             3DM-GX5-25 at {rate_hz} Hz), imported."
        ),
        profile: profile.text,
        profile_name: profile.name,
        scales,
        rate_hz,
        axes: Axes::Triad,
        axes_comment: "One triad in the body axes (z down); the walk starts at rest: static alignment.",
        noise: NOISE,
        fdi: None,
        start: None,
        origin_deg: [
            profile.origin[0].to_degrees(),
            profile.origin[1].to_degrees(),
            profile.origin[2],
        ],
    });
    let repairs = [
        ("repeated_timestamps_dropped", trial.dropped_duplicates),
        ("turned_over", usize::from(trial.turned_over)),
    ]
    .into_iter()
    .filter(|(_, n)| *n > 0)
    .map(|(kind, count)| RepairCount {
        kind: kind.into(),
        count,
    })
    .collect();
    Ok(ImportedRun {
        name: name.clone(),
        imu,
        truth,
        config_fragment,
        scales,
        rate_hz,
        quantisation: block.quantisation(),
        clock_offsets: Vec::new(),
        repairs,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::datasets::FootSample;

    /// 3 s at 200 Hz from t = 12.5 s, the foot walking along Vicon x and rising.
    fn walk() -> FootTrial {
        let samples: Vec<FootSample> = (0..600)
            .map(|j| {
                let t = 12.5 + j as f64 / 200.0;
                FootSample {
                    t_s: t,
                    gyro_rps: [0.3 * (5.0 * t).sin(), -2.0 * (3.0 * t).cos(), 0.01],
                    accel_mps2: [1.5 * t.sin(), 0.2, -9.8 + (4.0 * t).cos()],
                }
            })
            .collect();
        let truth = samples
            .iter()
            .map(|s| [1.0 + 0.5 * (s.t_s - 12.5), 2.0, 0.1 + 0.2 * (s.t_s - 12.5)])
            .collect();
        FootTrial {
            name: "2017-11-22-11-22-03".into(),
            path: "d/2017-11-22-11-22-03.csv".into(),
            samples,
            truth_m: Some(truth),
            peer: None,
            dropped_duplicates: 2,
            turned_over: false,
            rate_hz: 200.0,
        }
    }

    fn profile() -> Profile<'static> {
        Profile {
            text: "[navigator]\nalign_s = 0.2\n",
            name: "test profile",
            origin: [0.8, 0.15, 488.0],
        }
    }

    #[test]
    fn one_triad_in_counts_from_one_second_of_device_time() {
        let trial = walk();
        let run = import_trial(&trial, &profile()).unwrap();
        assert_eq!(run.imu.len(), 600);
        for (frame, s) in run.imu.iter().zip(&trial.samples) {
            assert_eq!((frame.n_gyro, frame.n_accel), (3, 3));
            assert_eq!(frame.valid_mask, 0x0007_0007);
            assert_eq!(frame.header.origin_device_time_us, device_us(s.t_s - 12.5));
            for i in 0..3 {
                let g = f64::from(frame.gyro_counts[i]) * run.scales.gyro_lsb_rps;
                let a = f64::from(frame.accel_counts[i]) * run.scales.accel_lsb_mps2;
                // Error feedback: one reading is off by up to one count.
                assert!((g - s.gyro_rps[i]).abs() <= run.scales.gyro_lsb_rps * (1.0 + 1e-9));
                assert!((a - s.accel_mps2[i]).abs() <= run.scales.accel_lsb_mps2 * (1.0 + 1e-9));
            }
        }
        assert_eq!(run.imu[0].header.origin_device_time_us, 1_000_000);
        assert_eq!(run.repairs[0].kind, "repeated_timestamps_dropped");

        let table: toml::Table = toml::from_str(&run.config_fragment).unwrap();
        assert_eq!(table["device"]["imu_rate_hz"].as_float(), Some(200.0));
        assert_eq!(
            table["fusion"]["geometry"]["gyro"]["kind"].as_str(),
            Some("triad")
        );
        assert!(
            table["navigator"].get("start").is_none(),
            "a walk starts at rest"
        );
        assert_eq!(
            table["fusion"]["noise"]["gyro_noise_density_dps_rthz"].as_float(),
            Some(0.005)
        );
    }

    #[test]
    fn vicon_x_y_up_is_east_north_up_about_the_origin() {
        let run = import_trial(&walk(), &profile()).unwrap();
        assert_eq!(run.truth.len(), 600);
        let origin = LocalOrigin::new(0.8, 0.15, 488.0);
        let first = &run.truth[0];
        let ned = origin.ned(first.latitude_rad, first.longitude_rad, first.altitude_m);
        assert!(ned.iter().all(|x| x.abs() < 1e-9), "{ned:?}");
        let last = &run.truth[599];
        let ned = origin.ned(last.latitude_rad, last.longitude_rad, last.altitude_m);
        let t = 599.0 / 200.0;
        assert!((ned[0]).abs() < 1e-6, "{ned:?}");
        assert!((ned[1] - 0.5 * t).abs() < 1e-6, "{ned:?}");
        assert!((ned[2] + 0.2 * t).abs() < 1e-6, "{ned:?}");
        let v = run.truth[300].velocity_ned_mps;
        assert!(
            (v[1] - 0.5).abs() < 1e-9 && (v[2] + 0.2).abs() < 1e-9,
            "{v:?}"
        );
        assert!(
            first.quaternion.iter().all(|q| q.is_nan()),
            "no attitude reference"
        );
        assert_eq!(
            first.header.origin_device_time_us,
            run.imu[0].header.origin_device_time_us
        );
    }
}
