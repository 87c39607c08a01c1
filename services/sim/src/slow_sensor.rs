//! What the simulator asks of a sensor sampled slower than the IMU: its frame rate and one sample
//! into its frame's payload. The list of such sensors is in `slow_sensor_list.rs`; each model
//! implements this trait beside its own code.

use rins_protocol::Payload;

use crate::sensor_model::SensorModel;
use crate::trajectory::{Trajectory, TruthState};

/// What a sensor may read at its sample time.
pub(crate) struct SampleAt<'a> {
    /// Device time of the sample, s.
    pub t_s: f64,
    /// The truth at that time.
    pub truth: &'a TruthState,
    /// The trajectory, for what the truth does not carry (the wind).
    pub trajectory: &'a Trajectory,
}

/// A sensor sampled on the ticks where its rate falls due.
pub(crate) trait SlowSensor: CloneSlowSensor + std::fmt::Debug + Send + Sync {
    /// Frame rate, Hz (validated at most the IMU rate).
    fn rate_hz(&self) -> f64;

    /// One sample at `at` as its frame's payload; `block` holds the models (and random streams)
    /// of the sensor block's built-in sensors. Allocation-free.
    fn sample(&mut self, at: &SampleAt<'_>, block: &mut SensorModel) -> Payload;
}

/// Copies a listed sensor (the simulator is `Clone`: a copy continues exactly as the original).
pub(crate) trait CloneSlowSensor {
    fn clone_boxed(&self) -> Box<dyn SlowSensor>;
}

impl<T: SlowSensor + Clone + 'static> CloneSlowSensor for T {
    fn clone_boxed(&self) -> Box<dyn SlowSensor> {
        Box::new(self.clone())
    }
}

impl Clone for Box<dyn SlowSensor> {
    fn clone(&self) -> Self {
        self.clone_boxed()
    }
}
