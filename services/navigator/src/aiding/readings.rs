//! The barometric heights, magnetometer samples and airspeeds on their way to the navigator: held
//! on their device time until the IMU stream is [`HOLD_US`] past it (see
//! [`crate::aiding::hold`]), then applied in device-time order, baro before mag before airspeed at
//! the same time.

use ipc_types::{Altitude, RawAirspeed, RawMag};

use crate::aiding::hold::{HOLD_US, Held, Hold};

/// Readings held at most; beyond it the oldest is applied at once (the IMU stream stopped while
/// aiding went on).
const CAPACITY: usize = 256;

/// One aiding reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reading {
    /// A barometric height: device time µs, height m, variance m², valid.
    Baro {
        /// Device time, µs.
        t_us: u64,
        /// Height above mean sea level, m.
        height_m: f64,
        /// Its variance, m².
        variance_m2: f64,
        /// The altimeter's validity flag.
        valid: bool,
    },
    /// A magnetometer sample: device time µs, field µT (body FRD, raw).
    Mag {
        /// Device time, µs.
        t_us: u64,
        /// Raw field, µT.
        field_ut: [f64; 3],
    },
    /// A pitot differential pressure: device time µs, Pa.
    Airspeed {
        /// Device time, µs.
        t_us: u64,
        /// Differential pressure, Pa.
        diff_pressure_pa: f64,
    },
}

impl Reading {
    /// The altimeter's height.
    pub fn from_altitude(alt: &Altitude) -> Self {
        Self::Baro {
            t_us: alt.header.origin_device_time_us,
            height_m: alt.height_m,
            variance_m2: alt.height_var,
            valid: alt.valid != 0,
        }
    }

    /// A raw magnetometer sample.
    pub fn from_mag(mag: &RawMag) -> Self {
        Self::Mag {
            t_us: mag.header.origin_device_time_us,
            field_ut: mag.field_ut.map(f64::from),
        }
    }

    /// A raw airspeed sample.
    pub fn from_airspeed(airspeed: &RawAirspeed) -> Self {
        Self::Airspeed {
            t_us: airspeed.header.origin_device_time_us,
            diff_pressure_pa: f64::from(airspeed.diff_pressure_pa),
        }
    }

    /// Device time, µs.
    pub fn t_us(&self) -> u64 {
        match self {
            Self::Baro { t_us, .. } | Self::Mag { t_us, .. } | Self::Airspeed { t_us, .. } => *t_us,
        }
    }
}

impl Held for Reading {
    /// Device time; at the same time, baro before mag before airspeed (the airspeed's density
    /// is taken at the altitude the baro just corrected).
    fn place(&self) -> (u64, u8) {
        let rank = match self {
            Self::Baro { .. } => 0,
            Self::Mag { .. } => 1,
            Self::Airspeed { .. } => 2,
        };
        (self.t_us(), rank)
    }
}

/// What the held readings are applied to (the navigator).
pub trait ReadingSink {
    /// Applies one reading now.
    fn take(&mut self, r: Reading);
}

/// The baro, magnetometer and airspeed readings waiting for the IMU stream to pass them.
pub type AidingQueue = Hold<Reading>;

impl Default for AidingQueue {
    fn default() -> Self {
        Hold::new(HOLD_US, CAPACITY)
    }
}

impl AidingQueue {
    /// Holds `r` for the navigator `nav` (a full queue applies its oldest to it at once).
    pub fn hold(&mut self, r: Reading, nav: &mut impl ReadingSink) {
        if let Some(oldest) = self.push(r) {
            nav.take(oldest);
        }
    }

    /// Applies to the navigator `nav`, before its IMU sample at `imu_t_us`, every reading that
    /// sample releases.
    pub fn release_to(&mut self, imu_t_us: u64, nav: &mut impl ReadingSink) {
        self.release(imu_t_us, |r| nav.take(r));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn baro_goes_before_mag_of_the_same_time() {
        let baro = Reading::Baro {
            t_us: 3_000,
            height_m: 1.0,
            variance_m2: 1.0,
            valid: true,
        };
        let mag = Reading::Mag {
            t_us: 3_000,
            field_ut: [1.0, 0.0, 0.0],
        };
        let mut q = AidingQueue::default();
        assert_eq!(q.push(mag), None);
        assert_eq!(q.push(baro), None);
        let mut applied = Vec::new();
        q.release(3_000 + HOLD_US, |r| applied.push(r));
        assert_eq!(applied, [baro, mag]);
    }
}
