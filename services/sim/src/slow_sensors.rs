//! The sensors sampled slower than the IMU — barometer, magnetometer, auxiliary (foot pressure),
//! airspeed — each behind one small trait ([`SlowSensor`]: its frame rate and one sample into its
//! frame's payload), fitted as the one list of them (`slow_sensor_list.rs`) says.
//!
//! Each sensor draws from its own random stream, so the order of the list changes no sample: a
//! sensor that is not fitted draws nothing and leaves every other frame as it was.

use rins_protocol::{AuxFrame, BaroFrame, MagFrame, Payload};

use crate::config::SimConfig;
use crate::sensor_model::SensorModel;
use crate::slow_sensor::{SampleAt, SlowSensor};
use crate::slow_sensor_list::slow_sensor_list;

/// [`slow_sensors`] of the listed sensors (their BUILD; their CHECK is read by `config.rs`).
macro_rules! fitted_sensors {
    ($($name:ident $(in mod $module:ident)?: fitted $build:expr, checked $check:expr;)*) => {
        $($(use crate::sensor_model::$module;)?)*

        /// Every slower sensor `config` fits, in list order; `seed` seeds the ones with their own
        /// stream.
        pub(crate) fn slow_sensors(config: &SimConfig, seed: u64) -> Vec<Box<dyn SlowSensor>> {
            let mut fitted: Vec<Box<dyn SlowSensor>> = Vec::new();
            $(
                if let Some(sensor) = build(config, seed, $build) {
                    fitted.push(Box::new(sensor));
                }
            )*
            fitted
        }
    };
}

slow_sensor_list!(fitted_sensors);

/// Runs one entry's BUILD (a function, so that its closure's argument types are known).
fn build<S: SlowSensor + 'static>(
    config: &SimConfig,
    seed: u64,
    build: impl FnOnce(&SimConfig, u64) -> Option<S>,
) -> Option<S> {
    build(config, seed)
}

/// The barometer at its rate, Hz, at the true altitude.
#[derive(Debug, Clone, Copy)]
struct Baro(f64);

impl SlowSensor for Baro {
    fn rate_hz(&self) -> f64 {
        self.0
    }

    fn sample(&mut self, at: &SampleAt<'_>, block: &mut SensorModel) -> Payload {
        let mut frame = BaroFrame::default();
        block.baro(at.truth.altitude_m, &mut frame);
        Payload::Baro(frame)
    }
}

/// The magnetometer at its rate, Hz, at the true attitude.
#[derive(Debug, Clone, Copy)]
struct Mag(f64);

impl SlowSensor for Mag {
    fn rate_hz(&self) -> f64 {
        self.0
    }

    fn sample(&mut self, at: &SampleAt<'_>, block: &mut SensorModel) -> Payload {
        let mut frame = MagFrame::default();
        block.mag(&at.truth.attitude, &mut frame);
        Payload::Mag(frame)
    }
}

/// The foot-pressure sensor at its rate, Hz, under the true load.
#[derive(Debug, Clone, Copy)]
struct Aux(f64);

impl SlowSensor for Aux {
    fn rate_hz(&self) -> f64 {
        self.0
    }

    fn sample(&mut self, at: &SampleAt<'_>, block: &mut SensorModel) -> Payload {
        let mut frame = AuxFrame::default();
        block.foot_pressure(at.truth.foot_load, &mut frame);
        Payload::Aux(frame)
    }
}
