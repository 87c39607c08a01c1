//! The one list of the sensors sampled slower than the IMU — barometer, magnetometer, auxiliary
//! (foot pressure), airspeed. A new sensor is its model (with `SlowSensor`, `slow_sensor.rs`,
//! implemented), one entry here and its settings field in `SimConfig`.
//!
//! This file names nothing of the crate: each entry's code is only read where the list is
//! expanded, by its three readers — the model modules (`sensor_model`), the fitted sensors
//! (`slow_sensors.rs`) and the settings checks (`config.rs`) — so the list depends on none of
//! them and none of them needs another to read it.

/// The slower sensors, one entry each, in the order they are sampled on a tick:
///
/// ```text
/// NAME [in mod MODULE]:
///     fitted |config, seed| BUILD,
///     checked |config| CHECK;
/// ```
///
/// - NAME: the sensor, as the reader knows it.
/// - `in mod MODULE`: the model has its own file, `sensor_model/MODULE.rs`; the entry declares
///   it there (`crate::sensor_model::MODULE`) and brings `MODULE` into scope for BUILD.
/// - BUILD: the sensor (`Option<impl SlowSensor>`) for `config: &SimConfig` and the run's
///   `seed`; `None` when the configuration does not fit it. Expanded in `slow_sensors.rs`, whose
///   names (`Baro`, …) it may use.
/// - CHECK: the check of its settings in `config` (`Result<(), SimError>`, the error naming the
///   field and its value), part of `SimConfig::validate`. Expanded in `config.rs`, whose names
///   (`check_rate`) it may use.
///
/// The list is handed to the macro named in the call (`slow_sensor_list!(model_modules)`), which
/// makes of it what it needs and ignores the rest.
macro_rules! slow_sensor_list {
    ($($then:ident)::+) => {
        $($then)::+! {
            baro:
                fitted |c, _| Some(Baro(c.baro_rate_hz)),
                checked |c| check_rate("sim.baro_rate_hz", c.baro_rate_hz, c);
            mag:
                fitted |c, _| Some(Mag(c.mag_rate_hz)),
                checked |c| check_rate("sim.mag_rate_hz", c.mag_rate_hz, c);
            aux:
                fitted |c, _| Some(Aux(c.aux_rate_hz)),
                checked |c| check_rate("sim.aux_rate_hz", c.aux_rate_hz, c);
            airspeed in mod airspeed:
                fitted |c, seed| c.airspeed.enabled
                    .then(|| airspeed::AirspeedModel::new(c.airspeed, c.qnh_pa, seed)),
                checked |c| c.airspeed.validate(c.imu_rate_hz);
        }
    };
}
pub(crate) use slow_sensor_list;
