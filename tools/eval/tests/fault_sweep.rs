//! Fault sweep: a short sweep on the built-in configuration detects a large gyro bias at once, its
//! figures are consistent, and bad settings are refused by name.

use rins_altimeter::AltimeterConfig;
use rins_eval::fault_sweep::{SweepChannel, SweepConfig, SweepFault, run_fault_sweep};
use rins_fusion::FusionConfig;
use rins_navigator::NavigatorConfig;
use rins_sim::{InertialSensor, SimConfig};
use serde::Deserialize;

/// The tables of the built-in configuration file the chain is built from.
#[derive(Deserialize)]
struct BuiltIn {
    device: Device,
    sim: SimConfig,
    fusion: FusionConfig,
    altimeter: AltimeterConfig,
    navigator: NavigatorConfig,
}

#[derive(Deserialize)]
struct Device {
    gyro_full_scale_dps: f64,
    accel_full_scale_g: f64,
}

/// The sweep of the configuration `rins up` runs by default (the loader gives the simulated block
/// the device's converters, so this does too).
fn built_in_sweep() -> SweepConfig {
    let text = include_str!("../../../config/rins.toml");
    let mut cfg: BuiltIn = toml::from_str(text).expect("the built-in configuration parses");
    cfg.sim.sensors.gyro_full_scale_dps = cfg.device.gyro_full_scale_dps;
    cfg.sim.sensors.accel_full_scale_g = cfg.device.accel_full_scale_g;
    SweepConfig::new(cfg.sim, cfg.fusion, cfg.altimeter, cfg.navigator)
}

fn gyro(index: usize) -> SweepChannel {
    SweepChannel {
        sensor: InertialSensor::Gyro,
        index,
    }
}

#[test]
fn a_twenty_sigma_gyro_bias_is_detected_at_once_and_the_figures_agree() {
    // On the ground roll and in the first turn.
    let config = SweepConfig {
        inject_at_s: vec![8.0, 120.0],
        window_s: 5.0,
        channels: vec![gyro(2)],
        faults: vec![SweepFault::Bias { sigmas: 20.0 }],
        ..built_in_sweep()
    };
    let mut calls = Vec::new();
    let report = run_fault_sweep(&config, |done, total| calls.push((done, total))).unwrap();
    // The clean run, and per injection time the reference of the window and the faulted run.
    assert_eq!(calls.first(), Some(&(0, 5)));
    assert_eq!(calls.last(), Some(&(5, 5)));
    assert_eq!(report.runs.len(), 4);

    for (pair, at) in report.runs.chunks(2).zip([8.0, 120.0]) {
        let [reference, run] = pair else {
            panic!("{pair:?}");
        };
        assert_eq!((reference.channel.as_str(), reference.kind), ("-", "none"));
        assert_eq!(reference.inject_at_s, at);
        assert_eq!(reference.detected_after_s, None);
        assert_eq!(reference.isolated_after_s, None);
        assert_eq!(reference.wrongly_excluded, None);
        assert_eq!(reference.unisolated_share, 0.0);

        assert_eq!((run.channel.as_str(), run.kind), ("gyro2", "bias"));
        assert_eq!(run.inject_at_s, at);
        let sigma = run.sigma.unwrap();
        assert!((sigma - 0.005519).abs() < 1e-6, "{sigma}");
        assert!((run.param.unwrap() - 20.0 * sigma).abs() < 1e-12);
        // 20 σ is far beyond the per-sample parity threshold: the k-of-n persistence (3 of 5)
        // is all it waits for.
        let detected = run.detected_after_s.expect("a 20σ bias is detected");
        assert!(detected <= 0.01, "detected after {detected} s at {at} s");
        match run.isolated_after_s {
            Some(isolated) => {
                assert!(detected <= isolated, "{detected} > {isolated}");
                assert!(run.reason.is_some(), "{run:?}");
            }
            None => assert_eq!(run.reason, None),
        }
        // Detected and not yet isolated: the navigator says so.
        if run.isolated_after_s.is_none_or(|i| i > detected + 0.1) {
            assert!(run.unisolated_share > 0.0, "{run:?}");
            assert!(run.ok_share < 1.0, "{run:?}");
        }
        for r in [reference, run] {
            let all = r.att_err_deg_max.expect("a solution after the injection");
            if let Some(ok) = r.att_err_deg_max_while_ok {
                assert!(ok <= all, "{ok} > {all}");
                assert!(r.horiz_err_m_max_while_ok.is_some());
            } else {
                assert_eq!(r.ok_share, 0.0);
            }
            assert!((0.0..=1.0).contains(&r.ok_share), "{}", r.ok_share);
            assert!(r.ok_share + r.unisolated_share <= 1.0 + 1e-12, "{r:?}");
        }
    }
    // The clean run flies to the end of the latest window without a false alarm.
    assert!((report.clean.duration_s - 125.0).abs() < 1e-9);
    assert_eq!(report.clean.false_alarms, 0, "{:?}", report.clean);
    assert_eq!(report.summary.false_alarms, 0);
    assert_eq!(report.summary.undetected, 0);
    let worst = report.summary.worst_att_err_deg_max_while_ok.unwrap();
    let largest_ok = report
        .runs
        .iter()
        .filter_map(|r| r.att_err_deg_max_while_ok)
        .fold(0.0f64, f64::max);
    assert_eq!(worst, largest_ok);
    assert_eq!(report.summary.target_met, worst <= 1.0);
    let not_isolated = report.runs[1..]
        .iter()
        .step_by(2)
        .filter(|r| r.isolated_after_s.is_none())
        .count();
    assert_eq!(report.summary.not_isolated, not_isolated);

    let table = report.to_table();
    assert!(
        table.contains("gyro2") && table.contains("bias 20σ"),
        "{table}"
    );
    assert!(
        table.contains("summary: worst att_err_deg_max_while_ok"),
        "{table}"
    );
    let json = serde_json::to_value(&report).unwrap();
    assert_eq!(json["runs"][1]["kind"], "bias");
    assert!(json["runs"][0]["detected_after_s"].is_null());
}

#[test]
fn bad_settings_are_refused_by_name() {
    let message =
        |config: SweepConfig| run_fault_sweep(&config, |_, _| {}).unwrap_err().to_string();
    let m = message(SweepConfig {
        window_s: -1.0,
        ..built_in_sweep()
    });
    assert!(m.contains("sweep.window_s") && m.contains("-1"), "{m}");
    let m = message(SweepConfig {
        channels: vec![gyro(7)],
        ..built_in_sweep()
    });
    assert!(m.contains("gyro7") && m.contains("4 channels"), "{m}");
    let m = message(SweepConfig {
        threads: 0,
        ..built_in_sweep()
    });
    assert!(m.contains("sweep.threads"), "{m}");
    let m = message(SweepConfig {
        faults: vec![SweepFault::Noise { factor: 0.5 }],
        ..built_in_sweep()
    });
    assert!(m.contains("noise.factor") && m.contains("0.5"), "{m}");
    // Still aligning (the navigator aligns over 1 s after the 1 s rest-bias window).
    let m = message(SweepConfig {
        inject_at_s: vec![0.5],
        window_s: 1.0,
        channels: vec![gyro(0)],
        faults: vec![SweepFault::Bias { sigmas: 5.0 }],
        ..built_in_sweep()
    });
    assert!(
        m.contains("sweep.inject_at_s") && m.contains("aligning"),
        "{m}"
    );
}
