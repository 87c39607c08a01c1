//! Temperature-compensated calibration: recovery of the true value from counts produced by the
//! forward model, defaults, configuration parsing and validation.

use proptest::prelude::*;
use rins_fusion::calibration::{MAX_TEMPERATURE_C, MIN_TEMPERATURE_C};
use rins_fusion::geometry::MAX_CHANNELS;
use rins_fusion::{Calibration, ChannelCalibration, FusionConfig};

const LSB: f64 = 0.0025;

/// Four gyro channels with realistic MEMS coefficients: a few mrad/s of bias drifting by
/// ~0.1 mrad/s/°C, scale errors of a percent drifting by a few hundred ppm/°C, two channels on
/// each of two temperature sensors.
fn four_channels() -> ChannelCalibration {
    ChannelCalibration {
        bias: vec![0.004, -0.010, 0.002, 0.007],
        scale: vec![1.01, 0.985, 1.0, 1.02],
        bias_per_c: vec![1.5e-4, -0.8e-4, 0.0, 2.0e-4],
        scale_ppm_per_c: vec![300.0, -150.0, 80.0, 0.0],
        reference_temperature_c: 20.0,
        temperature_sensor: vec![0, 0, 1, 1],
    }
}

/// The forward model: counts that a channel with calibration `cal` outputs for the true value
/// `truth` at temperature `t`, rounded to the ADC step.
fn counts_for(cal: &ChannelCalibration, i: usize, truth: f64, t: f64) -> i16 {
    let dt = t - cal.reference_temperature_c;
    let bias = cal.bias[i] + cal.bias_per_c[i] * dt;
    let scale = cal.scale[i] * (1.0 + cal.scale_ppm_per_c[i] * 1e-6 * dt);
    ((scale * truth + bias) / LSB).round() as i16
}

/// Half an ADC step referred to the input: the only error the inverse model may leave.
fn rounding_bound(cal: &ChannelCalibration, i: usize, t: f64) -> f64 {
    let dt = t - cal.reference_temperature_c;
    0.5 * LSB / (cal.scale[i] * (1.0 + cal.scale_ppm_per_c[i] * 1e-6 * dt)) + 1e-12
}

#[test]
fn known_coefficients_recover_the_true_value_at_several_temperatures() {
    let cfg = four_channels();
    let cal = Calibration::new(&cfg, 4, LSB).unwrap();
    let truth = [0.5, -1.2, 0.03, 2.0];
    let mut out = [0.0; MAX_CHANNELS];
    for (t0, t1) in [(-40.0, 85.0), (-10.0, 0.0), (20.0, 20.0), (45.0, 60.0)] {
        let temps = [t0 as f32, t1 as f32, 99.0, -99.0];
        let t_of = |i: usize| if i < 2 { t0 } else { t1 };
        let counts: Vec<i16> = (0..4)
            .map(|i| counts_for(&cfg, i, truth[i], t_of(i)))
            .collect();
        cal.apply_all_with_temperature(&counts, &temps, &mut out);
        for i in 0..4 {
            let err = (out[i] - truth[i]).abs();
            assert!(
                err <= rounding_bound(&cfg, i, t_of(i)),
                "channel {i} at {} °C: {} vs {}",
                t_of(i),
                out[i],
                truth[i]
            );
            let single = cal.apply_with_temperature(i, counts[i], t_of(i));
            assert_eq!(single, out[i]);
        }
        // Ignoring the temperature leaves the drift: far beyond rounding away from T_ref.
        if (t0 - 20.0f64).abs() > 50.0 {
            let uncompensated = cal.apply(0, counts[0]);
            assert!((uncompensated - truth[0]).abs() > 10.0 * rounding_bound(&cfg, 0, t0));
        }
    }
}

#[test]
fn apply_all_is_the_reference_temperature() {
    let cfg = four_channels();
    let cal = Calibration::new(&cfg, 4, LSB).unwrap();
    let counts = [123, -456, 789, -1011];
    let mut at_ref = [0.0; MAX_CHANNELS];
    let mut plain = [0.0; MAX_CHANNELS];
    cal.apply_all_with_temperature(&counts, &[20.0, 20.0], &mut at_ref);
    cal.apply_all(&counts, &mut plain);
    for i in 0..4 {
        assert!((at_ref[i] - plain[i]).abs() < 1e-15, "{i}");
    }
}

#[test]
fn default_config_is_identity_at_any_temperature() {
    let cfg = ChannelCalibration::default();
    assert_eq!(cfg.reference_temperature_c, 25.0);
    let cal = Calibration::new(&cfg, 5, 0.5).unwrap();
    let mut out = [7.0; MAX_CHANNELS];
    cal.apply_all_with_temperature(&[2, -4, 6, 8, -10], &[-40.0, 90.0, 3.0, 4.0], &mut out);
    assert_eq!(&out[..5], &[1.0, -2.0, 3.0, 4.0, -5.0]);
    // Entries beyond N are left alone.
    assert_eq!(out[5], 7.0);
    // The TOML default is the same as Default.
    let parsed: ChannelCalibration = toml::from_str("").unwrap();
    assert_eq!(parsed, cfg);
}

#[test]
fn missing_or_bad_temperatures_fall_back_to_reference_and_extremes_are_clamped() {
    let cfg = four_channels();
    let cal = Calibration::new(&cfg, 4, LSB).unwrap();
    let counts = [400i16, 400, 400, 400];
    let mut reference = [0.0; MAX_CHANNELS];
    cal.apply_all(&counts, &mut reference);
    let mut out = [0.0; MAX_CHANNELS];
    // Sensor 1 missing from the slice, sensor 0 NaN.
    cal.apply_all_with_temperature(&counts, &[f32::NAN], &mut out);
    assert_eq!(&out[..4], &reference[..4]);
    // Beyond the calibrated range the model is held at the range end.
    let mut hot = [0.0; MAX_CHANNELS];
    let mut at_max = [0.0; MAX_CHANNELS];
    cal.apply_all_with_temperature(&counts, &[400.0, f32::INFINITY], &mut hot);
    // +∞ is not finite: reference, like NaN.
    assert_eq!(hot[2], reference[2]);
    cal.apply_all_with_temperature(&counts, &[MAX_TEMPERATURE_C as f32, 0.0], &mut at_max);
    assert_eq!(hot[0], at_max[0]);
    assert_eq!(
        cal.apply_with_temperature(1, 400, -300.0),
        cal.apply_with_temperature(1, 400, MIN_TEMPERATURE_C)
    );
    // Missing counts are NaN, a channel beyond N is NaN.
    cal.apply_all_with_temperature(&counts[..2], &[20.0, 20.0], &mut out);
    assert!(out[2].is_nan() && out[3].is_nan());
    assert!(cal.apply_with_temperature(4, 1, 20.0).is_nan());
    assert_eq!(cal.temperature_sensor(2), 1);
}

#[test]
fn parses_old_and_new_keys() {
    let old: ChannelCalibration = toml::from_str("bias = [0.1, 0.2]\nscale = [1.0, 1.1]").unwrap();
    assert_eq!(old.bias, vec![0.1, 0.2]);
    assert!(old.bias_per_c.is_empty() && old.temperature_sensor.is_empty());
    let cfg: FusionConfig = toml::from_str(
        "[calibration.gyro]\n\
         bias = [0.004, -0.010, 0.002, 0.007]\n\
         scale = [1.01, 0.985, 1.0, 1.02]\n\
         bias_per_c = [1.5e-4, -0.8e-4, 0.0, 2.0e-4]\n\
         scale_ppm_per_c = [300, -150, 80, 0]\n\
         reference_temperature_c = 20\n\
         temperature_sensor = [0, 0, 1, 1]\n",
    )
    .unwrap();
    assert_eq!(cfg.calibration.gyro, four_channels());
    cfg.validate().unwrap();
    assert!(toml::from_str::<ChannelCalibration>("bias_per_degree = [1]").is_err());
}

#[test]
fn validation_names_field_and_value() {
    let check = |edit: fn(&mut ChannelCalibration)| {
        let mut c = four_channels();
        edit(&mut c);
        c.validate(4).unwrap_err().to_string()
    };
    assert_eq!(
        check(|c| c.bias_per_c = vec![0.0; 3]),
        "bias_per_c = 3 entries: must have 4 entries (one per channel) or be empty"
    );
    assert_eq!(
        check(|c| c.scale_ppm_per_c = vec![0.0; 5]),
        "scale_ppm_per_c = 5 entries: must have 4 entries (one per channel) or be empty"
    );
    assert_eq!(
        check(|c| c.temperature_sensor = vec![0]),
        "temperature_sensor = 1 entries: must have 4 entries (one per channel) or be empty"
    );
    assert_eq!(
        check(|c| c.bias_per_c[2] = f64::NAN),
        "bias_per_c[2] = NaN: must be finite"
    );
    assert_eq!(
        check(|c| c.temperature_sensor[3] = 4),
        "temperature_sensor[3] = 4: must be < 4 (module temperature sensors)"
    );
    assert_eq!(
        check(|c| c.reference_temperature_c = 130.0),
        "reference_temperature_c = 130: must be in -55..=125 °C"
    );
    // With T_ref = 20 °C, −10000 ppm/°C drives the scale factor through zero at 120 °C, and
    // +20000 ppm/°C at −30 °C; −9000 ppm/°C still leaves 5.5 % of it at 125 °C.
    assert_eq!(
        check(|c| c.scale_ppm_per_c[1] = 20000.0),
        "scale_ppm_per_c[1] = 20000: must be finite and keep the scale factor > 0 over -55..=125 °C"
    );
    assert!(check(|c| c.scale_ppm_per_c[0] = -10000.0).starts_with("scale_ppm_per_c[0]"));
    let mut edge = four_channels();
    edge.scale_ppm_per_c[0] = -9000.0;
    edge.validate(4).unwrap();
    // The full path through the fusion configuration.
    let mut cfg = FusionConfig::default();
    cfg.calibration.accel.temperature_sensor = vec![0, 1, 2, 7];
    assert_eq!(
        cfg.validate().unwrap_err().field,
        "calibration.accel.temperature_sensor[3]"
    );
}

proptest! {
    #[test]
    fn inverse_of_the_forward_model(
        truth in -3.0..3.0f64,
        bias in -0.05..0.05f64,
        scale in 0.9..1.1f64,
        bias_per_c in -1e-3..1e-3f64,
        ppm in -1000.0..1000.0f64,
        t_ref in -20.0..60.0f64,
        t in MIN_TEMPERATURE_C..MAX_TEMPERATURE_C,
    ) {
        let cfg = ChannelCalibration {
            bias: vec![bias],
            scale: vec![scale],
            bias_per_c: vec![bias_per_c],
            scale_ppm_per_c: vec![ppm],
            reference_temperature_c: t_ref,
            temperature_sensor: vec![2],
        };
        let cal = Calibration::new(&cfg, 1, LSB).unwrap();
        let counts = counts_for(&cfg, 0, truth, t);
        let mut temps = [0.0f32; 4];
        temps[2] = t as f32;
        let mut out = [0.0; MAX_CHANNELS];
        cal.apply_all_with_temperature(&[counts], &temps, &mut out);
        // f32 temperature: its rounding (≤ 125·2⁻²⁴ °C) moves the result by far less than 1e-9.
        prop_assert!((out[0] - truth).abs() <= rounding_bound(&cfg, 0, t) + 1e-9,
            "{} vs {truth}", out[0]);
    }
}
