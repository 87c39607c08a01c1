//! Settings of the aided inertial core, built from the `[navigator]` section
//! ([`crate::NavigatorConfig::aided_config`]): plain values, copied into each run of the
//! evaluations' parameter searches.

use crate::aiding::airspeed::AirspeedAidingConfig;
use crate::aiding::baro::BaroAidingConfig;
use crate::aiding::gnss::config::GnssAidingConfig;
use crate::aiding::mag_heading::MagAidingConfig;
use crate::aiding::source::{AidingSensor, Bucket};
use crate::aiding::tilt::TiltAidingConfig;
use crate::aiding::zupt::ZuptConfig;
use crate::alignment::AlignConfig;
use crate::ekf::{AidingSource, EkfNoise};
use crate::integrity::IntegrityConfig;
use crate::mag_calibration::MagCalibration;
use crate::mechanisation::StrapdownConfig;
use crate::stance::StanceConfig;

/// Settings of the inertial core.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AidedConfig {
    /// Static alignment window and its limits.
    pub align: AlignConfig,
    /// Strapdown mechanisation options (largest step, coning correction).
    pub strapdown: StrapdownConfig,
    /// Filter noise and initial uncertainties.
    pub noise: EkfNoise,
    /// Zero-velocity updates.
    pub zupt: ZuptConfig,
    /// The stance detector that gates zero-velocity and stance heading updates.
    pub stance: StanceConfig,
    /// Barometric height updates.
    pub baro: BaroAidingConfig,
    /// Magnetometer heading updates.
    pub mag: MagAidingConfig,
    /// Tilt updates from the specific force (AHRS).
    pub tilt: TiltAidingConfig,
    /// GNSS position and velocity updates.
    pub gnss: GnssAidingConfig,
    /// Pitot airspeed updates.
    pub airspeed: AirspeedAidingConfig,
    /// Applied to every magnetometer sample before use.
    pub mag_calibration: MagCalibration,
    /// An aiding source whose last reading is older than this is stale: the filter coasts on the
    /// inertial solution and re-admits the source, without its innovation gate, when it returns, s.
    pub stale_after_s: f64,
    /// Declination, rad, positive east.
    pub declination_rad: f64,
    /// Position where navigation starts: latitude, longitude (rad), altitude (m).
    pub origin: [f64; 3],
    /// The origin's latitude and longitude were configured; otherwise they are placeholders and
    /// the horizontal position is unknown until an absolute fix sets it.
    pub origin_known: bool,
    /// The integrity monitor and its recovery policies (`[navigator.integrity]`).
    pub integrity: IntegrityConfig,
    /// How long the unit's gyro channel lags its accelerometer's, s: each rate sample is paired
    /// with the specific force of this long before (see [`crate::force_delay`]).
    pub gyro_lag_s: f64,
}

impl AidedConfig {
    /// The aiding sources this profile uses whose verdicts the integrity monitor weighs, indexed
    /// by [`AidingSource`].
    pub fn configured_sources(&self) -> [bool; AidingSource::COUNT] {
        self.sources_where(|sensor| sensor.judged_by_integrity())
    }

    /// The aiding sources this profile uses whose silence is an outage, indexed by
    /// [`AidingSource`].
    pub(crate) fn watched_sources(&self) -> [bool; AidingSource::COUNT] {
        self.sources_where(|sensor| sensor.watched_for_staleness())
    }

    fn sources_where(
        &self,
        pick: impl Fn(&dyn AidingSensor) -> bool,
    ) -> [bool; AidingSource::COUNT] {
        let mut on = [false; AidingSource::COUNT];
        for sensor in self.sensors() {
            if sensor.enabled() && pick(sensor) {
                on[sensor.source() as usize] = true;
            }
        }
        on
    }

    /// Each bucket's integrity reason when its innovations are inconsistent, indexed by
    /// [`AidingSource`].
    pub(crate) fn inconsistency_reasons(&self) -> [u32; AidingSource::COUNT] {
        self.per_bucket(|bucket| bucket.inconsistent)
    }

    fn per_bucket(&self, pick: impl Fn(&Bucket) -> u32) -> [u32; AidingSource::COUNT] {
        let mut bits = [0; AidingSource::COUNT];
        for sensor in self.sensors() {
            for bucket in sensor.buckets() {
                bits[bucket.source as usize] = pick(bucket);
            }
        }
        bits
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NavigatorConfig;

    #[test]
    fn every_bucket_is_declared_by_exactly_one_source() {
        let config = NavigatorConfig::default().aided_config();
        let mut declared = [0; AidingSource::COUNT];
        for sensor in config.sensors() {
            for bucket in sensor.buckets() {
                declared[bucket.source as usize] += 1;
            }
            // The bucket its settings book under is one it declares.
            assert!(sensor.buckets().iter().any(|b| b.source == sensor.source()));
        }
        assert_eq!(declared, [1; AidingSource::COUNT]);
    }
}
