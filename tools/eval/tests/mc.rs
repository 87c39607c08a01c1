//! Monte Carlo comparison: determinism, the fault experiment, geometry figures, report rendering.

use rins_eval::mc::{McConfig, McError, McReport, run_monte_carlo};

fn short(runs: usize, duration_s: f64, kill_at_s: Option<f64>) -> McConfig {
    McConfig {
        runs,
        duration_s: Some(duration_s),
        kill_at_s,
        ..McConfig::default()
    }
}

#[test]
fn equal_seeds_give_equal_reports_whatever_the_thread_count() {
    let one = McConfig {
        threads: 1,
        ..short(3, 8.0, Some(5.0))
    };
    let two = McConfig {
        threads: 2,
        ..one.clone()
    };
    let mut calls = Vec::new();
    let a = run_monte_carlo(&one, |d, t| calls.push((d, t))).unwrap();
    let b = run_monte_carlo(&two, |_, _| {}).unwrap();
    // NaN-free in full (every run aligns), but compare the printed form: NaN ≠ NaN would make an
    // empty statistic unequal to itself.
    assert_eq!(format!("{a:?}"), format!("{b:?}"));
    assert_eq!(calls, vec![(0, 3), (1, 3), (2, 3), (3, 3)]);
    assert_eq!(
        a.records.iter().map(|r| r.seed).collect::<Vec<_>>(),
        [1, 2, 3]
    );
}

#[test]
fn dead_gyro_stops_the_triad_and_not_the_pyramid() {
    let duration_s = 12.0;
    let kill_at_s = 6.0;
    let report = run_monte_carlo(&short(2, duration_s, Some(kill_at_s)), |_, _| {}).unwrap();
    let r = report.redundant.kill.expect("redundant kill experiment");
    let o = report.orthogonal.kill.expect("orthogonal kill experiment");
    // The pyramid keeps a solution on every tick; the triad has none from the kill to the end.
    assert_eq!(r.faulted.unsolved_s.max, 0.0);
    assert_eq!(r.lost_runs, 0);
    assert_eq!(o.lost_runs, 2);
    let lost = duration_s - kill_at_s;
    assert!(
        (o.faulted.unsolved_s.mean - lost).abs() < 1.5e-3,
        "{:?}",
        o.faulted.unsolved_s
    );
    assert_eq!(o.nominal.unsolved_s.max, 0.0);
    // Three skewed axes remain: the amplification of the remaining set is larger on every axis.
    let before = report.redundant.noise_amplification;
    let after = report.redundant.noise_amplification_after_kill.unwrap();
    assert!(
        after.iter().zip(before).all(|(a, b)| *a > b),
        "{before:?} {after:?}"
    );
    assert_eq!(report.orthogonal.noise_amplification_after_kill, None);
    // Before the kill both copies are the same flight, so the fault-free window of the fork has
    // exactly the errors of the nominal flight at the end.
    for rec in &report.records {
        let k = rec.redundant.kill.unwrap();
        assert_eq!(
            k.nominal.final_errors,
            rec.redundant.nominal.unwrap().final_errors
        );
    }
}

#[test]
fn geometry_figures_are_the_seed_values() {
    let report = run_monte_carlo(&short(1, 3.0, None), |_, _| {}).unwrap();
    // α = 28.7°: variance factors 0.65 (x, y) and 1.084 (z); the triad's are 1.
    let [x, y, z] = report.redundant.noise_amplification.map(|a| a * a);
    assert!(
        (x - 0.650).abs() < 1e-3 && (y - 0.650).abs() < 1e-3,
        "{x} {y}"
    );
    assert!((z - 1.084).abs() < 1e-3, "{z}");
    assert_eq!(report.orthogonal.noise_amplification, [1.0, 1.0, 1.0]);
    assert!(report.redundant.kill.is_none());
}

#[test]
fn alignment_completes_after_the_window_and_errors_stay_small_at_first() {
    let report = run_monte_carlo(&short(2, 6.0, None), |_, _| {}).unwrap();
    for rec in &report.records {
        for run in [&rec.redundant, &rec.orthogonal] {
            // Of the 3 s parked start, fusion measures the per-channel gyro biases over the first
            // second, then the navigator aligns over the next.
            let t = run.aligned_at_s.unwrap();
            assert!((t - 2.0).abs() < 2e-3, "{t}");
            let e = run.nominal.unwrap().final_errors.unwrap();
            // 5 s after alignment: tilt from a 1 s averaged gravity vector (accelerometer turn-on
            // bias 5 mg ≈ 0.3° at 1σ) and heading from the magnetometer stay well below 2°.
            assert!(e.roll_deg.abs() < 2.0 && e.pitch_deg.abs() < 2.0, "{e:?}");
            assert!(e.heading_deg.abs() < 2.0, "{e:?}");
            assert!(e.altitude_m.abs() < 5.0, "{e:?}");
        }
    }
}

#[test]
fn bad_settings_are_rejected_with_the_field_named() {
    let err = run_monte_carlo(
        &McConfig {
            runs: 0,
            ..McConfig::default()
        },
        |_, _| {},
    )
    .unwrap_err();
    assert!(err.to_string().contains("mc.runs = 0"), "{err}");
    let err = run_monte_carlo(&short(1, -1.0, None), |_, _| {}).unwrap_err();
    assert!(err.to_string().contains("mc.duration_s = -1"), "{err}");
    let mut cfg = short(1, 5.0, Some(2.0));
    cfg.kill_channel = 3;
    let err = run_monte_carlo(&cfg, |_, _| {}).unwrap_err();
    assert!(err.to_string().contains("mc.kill_channel = 3"), "{err}");
    let mut cfg = short(1, 5.0, None);
    cfg.sim.imu_rate_hz = 0.0;
    assert!(matches!(
        run_monte_carlo(&cfg, |_, _| {}),
        Err(McError::Sim(_))
    ));
}

#[test]
fn report_serialises_and_renders_both_tables() {
    let report = run_monte_carlo(&short(2, 6.0, Some(4.0)), |_, _| {}).unwrap();
    let json = serde_json::to_value(&report).unwrap();
    assert_eq!(json["runs"], 2);
    assert!(json["redundant"]["nominal"]["final_errors"]["heading_deg"]["two_sigma"].is_number());
    let table = report.to_table();
    assert!(table.contains("| roll/pitch, ° (per axis) |"), "{table}");
    assert!(table.contains("±0.220 / ±0.380 = 0.579"), "{table}");
    assert!(table.contains("channel dead"), "{table}");
    assert!(table.contains("lost"), "{table}");
}

#[test]
fn the_heading_survives_the_kill_with_or_without_per_channel_calibration() {
    // A 60 s flight, a channel dead from 10 s. With the body-axis bias of the navigator only, the
    // four channels carry turn-on biases (σ 0.05 °/s each) the alignment saw only through the
    // four-channel solution; the part of them the full set hides (its parity part, ≈ 0.05 °/s)
    // would step into the three-channel solution and turn the heading by about 0.05 °/s × 50 s
    // ≈ 2.5° by the end. Fusion takes the mean parity out of the solve at the reconfiguration, so
    // the reduced set continues where the full one was: calibrating each channel at rest is then
    // no longer what keeps the heading. Magnetometer updates would pull the heading back and hide
    // the bias: inertial heading here.
    let mut base = McConfig {
        calibrate_gyro_channels_at_rest: false,
        ..short(4, 60.0, Some(10.0))
    };
    base.navigator.mag.enabled = false;
    let body = run_monte_carlo(&base, |_, _| {}).unwrap();
    let per_channel = McConfig {
        calibrate_gyro_channels_at_rest: true,
        ..base.clone()
    };
    let channel = run_monte_carlo(&per_channel, |_, _| {}).unwrap();
    assert!(channel.gyro_channels_calibrated_at_rest);
    // The kill's own effect: heading of the faulted flight minus that of the same flight without
    // the fault, at the end, RMS over runs.
    let kill_effect = |r: &McReport| {
        let d: Vec<f64> = r
            .records
            .iter()
            .map(|rec| {
                let k = rec.redundant.kill.unwrap();
                k.faulted.final_errors.unwrap().heading_deg
                    - k.nominal.final_errors.unwrap().heading_deg
            })
            .collect();
        rins_eval::stats::rms(&d).unwrap()
    };
    let (calibrated, uncalibrated) = (kill_effect(&channel), kill_effect(&body));
    // What is left is three channels' noise against four over 50 s: a few tenths of a degree at
    // most, an order of magnitude under the uncorrected step, and the same in both set-ups.
    assert!(
        uncalibrated < 0.3,
        "{uncalibrated}° without per-channel calibration"
    );
    assert!(calibrated < 0.3, "{calibrated}° with it");
    assert!(
        (calibrated - uncalibrated).abs() < 0.5 * uncalibrated.max(calibrated),
        "{calibrated} vs {uncalibrated}"
    );
    // Without a fault the two set-ups are the same estimator up to the window noise.
    let nominal = |r: &McReport| r.redundant.nominal.rms.heading_deg.rms;
    assert!((nominal(&channel) - nominal(&body)).abs() < 0.5 * nominal(&body).max(0.05));
}

#[test]
fn per_channel_calibration_needs_the_vehicle_parked() {
    let mut cfg = short(1, 5.0, None);
    cfg.calibrate_gyro_channels_at_rest = true;
    cfg.sim.static_s = 0.5;
    let err = run_monte_carlo(&cfg, |_, _| {}).unwrap_err();
    assert!(
        err.to_string()
            .contains("mc.calibrate_gyro_channels_at_rest"),
        "{err}"
    );
}
