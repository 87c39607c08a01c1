//! Configuration: defaults, TOML parsing, validation messages, axis checks.

mod common;

use rins_earth::STANDARD_GRAVITY;
use rins_sim::{Scenario, SensorModelConfig, SimConfig, SimError, Simulator};
use rins_test_support::pyramid::optimal_pyramid_axes;

#[test]
fn defaults_are_the_documented_mems_block() {
    let c = SimConfig::default();
    c.validate().unwrap();
    assert_eq!(c.scenario, Scenario::Uav);
    assert_eq!(
        (c.imu_rate_hz, c.baro_rate_hz, c.mag_rate_hz, c.aux_rate_hz),
        (1000.0, 50.0, 100.0, 100.0)
    );
    assert_eq!(c.qnh_pa, 101_325.0);
    assert!((c.gyro_lsb_rps() - 300f64.to_radians() / 2048.0).abs() < 1e-18);
    assert!((c.accel_lsb_mps2() - 8.0 * STANDARD_GRAVITY / 2048.0).abs() < 1e-15);
    assert_eq!(
        (c.earth_field.intensity_ut, c.earth_field.inclination_deg),
        (50.0, 60.0)
    );
}

#[test]
fn converter_range_is_the_device_s_not_a_simulator_key() {
    let err = toml::from_str::<SimConfig>("[sensors]\ngyro_full_scale_dps = 500.0\n").unwrap_err();
    assert!(err.to_string().contains("gyro_full_scale_dps"), "{err}");
}

#[test]
fn toml_section_parses_with_defaults_for_missing_fields() {
    let text = r#"
        scenario = "uav"
        origin_latitude_deg = 51.5
        [earth_field]
        declination_deg = -1.5
        [sensors]
        mag_soft_iron = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.1]]
    "#;
    let mut c: SimConfig = toml::from_str(text).unwrap();
    assert_eq!(
        c.imu_rate_hz, 1000.0,
        "the rate is the device's, set by the deployment"
    );
    c.imu_rate_hz = 8000.0;
    c.validate().unwrap();
    assert_eq!(c.scenario, Scenario::Uav);
    // Not a [sim] key.
    assert!(toml::from_str::<SimConfig>("imu_rate_hz = 8000.0").is_err());
    assert_eq!(c.baro_rate_hz, 50.0);
    assert_eq!(c.earth_field.declination_deg, -1.5);
    assert_eq!(c.earth_field.intensity_ut, 50.0);
    assert_eq!(c.sensors.gyro_full_scale_dps, 300.0);
    assert_eq!(c.sensors.mag_soft_iron[2][2], 1.1);
    assert_eq!(
        c.sensors.accel_full_scale_g,
        SensorModelConfig::default().accel_full_scale_g
    );
}

#[test]
fn toml_rejects_unknown_fields_and_scenarios() {
    assert!(toml::from_str::<SimConfig>("imu_rate = 1000.0").is_err());
    assert!(toml::from_str::<SimConfig>("[sensors]\ngyro_noise = 1.0").is_err());
    assert!(toml::from_str::<SimConfig>("[earth_field]\ndip = 60.0").is_err());
    assert!(toml::from_str::<SimConfig>("scenario = \"Uav\"").is_err());
    assert!(toml::from_str::<SimConfig>("scenario = \"Walk\"").is_err());
    assert!(toml::from_str::<SimConfig>("scenario = \"run\"").is_err());
}

fn error_of(mutate: impl FnOnce(&mut SimConfig)) -> String {
    let mut c = SimConfig::default();
    mutate(&mut c);
    c.validate().unwrap_err().to_string()
}

#[test]
fn validation_errors_name_field_and_value() {
    assert!(error_of(|c| c.imu_rate_hz = 0.0).starts_with("device.imu_rate_hz = 0: must be > 0"));
    assert!(error_of(|c| c.imu_rate_hz = f64::NAN).starts_with("device.imu_rate_hz = NaN"));
    assert!(error_of(|c| c.baro_rate_hz = -5.0).starts_with("sim.baro_rate_hz = -5: must be > 0"));
    assert!(error_of(|c| c.mag_rate_hz = 2000.0).contains("<= device.imu_rate_hz"));
    assert!(error_of(|c| c.aux_rate_hz = 0.0).starts_with("sim.aux_rate_hz = 0"));
    // A sensor that is not fitted still has its settings checked.
    assert!(error_of(|c| c.airspeed.rate_hz = 0.0).starts_with("sim.airspeed.rate_hz = 0"));
    assert!(error_of(|c| c.airspeed.noise_pa = -1.0).starts_with("sim.airspeed.noise_pa = -1"));
    assert!(error_of(|c| c.origin_latitude_deg = 89.0).starts_with("sim.origin_latitude_deg = 89"));
    assert!(
        error_of(|c| c.origin_longitude_deg = 181.0).starts_with("sim.origin_longitude_deg = 181")
    );
    assert!(
        error_of(|c| c.origin_altitude_m = 20_000.0).starts_with("sim.origin_altitude_m = 20000")
    );
    assert!(error_of(|c| c.static_s = -1.0).starts_with("sim.static_s = -1"));
    assert!(error_of(|c| c.qnh_pa = 0.0).starts_with("sim.qnh_pa = 0"));
    assert!(
        error_of(|c| c.earth_field.intensity_ut = 0.0)
            .starts_with("sim.earth_field.intensity_ut = 0")
    );
    assert!(
        error_of(|c| c.earth_field.inclination_deg = 95.0)
            .starts_with("sim.earth_field.inclination_deg = 95")
    );
    assert!(
        error_of(|c| c.sensors.gyro_full_scale_dps = 0.0)
            .starts_with("sim.sensors.gyro_full_scale_dps = 0")
    );
    assert!(
        error_of(|c| c.sensors.accel_noise_density_ug_rthz = -1.0)
            .starts_with("sim.sensors.accel_noise_density_ug_rthz = -1")
    );
    assert!(
        error_of(|c| c.sensors.gyro_bias_instability_tau_s = 0.0)
            .starts_with("sim.sensors.gyro_bias_instability_tau_s = 0")
    );
    assert!(
        error_of(|c| c.sensors.temperature_sensors = 5)
            .starts_with("sim.sensors.temperature_sensors = 5")
    );
    assert!(
        error_of(|c| c.sensors.mag_soft_iron[1][1] = f64::INFINITY)
            .starts_with("sim.sensors.mag_soft_iron = inf")
    );
}

#[test]
fn simulator_rejects_bad_config_and_axes() {
    let axes = optimal_pyramid_axes();
    let bad = SimConfig {
        imu_rate_hz: 0.0,
        ..SimConfig::default()
    };
    assert!(matches!(
        Simulator::new(&bad, &axes, &axes, 0),
        Err(SimError::Config {
            field: "device.imu_rate_hz",
            ..
        })
    ));
    let c = SimConfig::default();
    let two = &axes[..2];
    let err = Simulator::new(&c, two, &axes, 0).unwrap_err();
    assert_eq!(
        err.to_string(),
        "gyro axes: 2 channels given: must be 3..=16"
    );
    let seventeen = vec![[1.0, 0.0, 0.0]; 17];
    assert!(matches!(
        Simulator::new(&c, &axes, &seventeen, 0),
        Err(SimError::AxisCount {
            kind: "accel",
            count: 17
        })
    ));
    let mut zero = axes.clone();
    zero[2] = [0.0, 0.0, 0.0];
    let err = Simulator::new(&c, &axes, &zero, 0).unwrap_err();
    assert!(
        err.to_string()
            .starts_with("accel axis 2 = [0.0, 0.0, 0.0]: must not be a zero vector"),
        "{err}"
    );
    let mut nan = axes.clone();
    nan[0][1] = f64::NAN;
    assert!(matches!(
        Simulator::new(&c, &nan, &axes, 0),
        Err(SimError::Axis {
            kind: "gyro",
            index: 0,
            ..
        })
    ));
    // Non-unit axes are accepted and normalised; 16 channels (four stacked triads plus four) work.
    let mut many: Vec<[f64; 3]> = (0..4)
        .flat_map(|_| [[2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 0.5]])
        .collect();
    many.extend(optimal_pyramid_axes());
    let s = Simulator::new(&c, &many, &many, 0).unwrap();
    let e = s
        .sensors()
        .channel_errors(rins_sim::InertialSensor::Gyro, 1)
        .unwrap();
    assert_eq!(e.axis, [0.0, 1.0, 0.0]);
}
