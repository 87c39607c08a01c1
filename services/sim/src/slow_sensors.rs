//! The sensors sampled slower than the IMU — barometer, magnetometer, auxiliary (foot pressure),
//! airspeed — each behind one small trait: its frame rate and one sample into its frame's payload.
//! [`slow_sensors`] is the one list of them that the simulator steps; a new sensor is its model
//! (with this trait implemented) and one line there.
//!
//! Each sensor draws from its own random stream, so the order of the list changes no sample: a
//! sensor that is not fitted draws nothing and leaves every other frame as it was.

use rins_protocol::{AuxFrame, BaroFrame, MagFrame, Payload};

use crate::config::SimConfig;
use crate::sensor_model::SensorModel;
use crate::sensor_model::airspeed::AirspeedModel;
use crate::slow_sensor::{SampleAt, SlowSensor};

/// Every slower sensor `config` fits, one line each; `seed` seeds the ones with their own stream.
pub(crate) fn slow_sensors(config: &SimConfig, seed: u64) -> Vec<Box<dyn SlowSensor>> {
    let fitted: Vec<Option<Box<dyn SlowSensor>>> = vec![
        Some(Box::new(Baro(config.baro_rate_hz))),
        Some(Box::new(Mag(config.mag_rate_hz))),
        Some(Box::new(Aux(config.aux_rate_hz))),
        config.airspeed.enabled.then(|| {
            Box::new(AirspeedModel::new(config.airspeed, config.qnh_pa, seed))
                as Box<dyn SlowSensor>
        }),
    ];
    fitted.into_iter().flatten().collect()
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
