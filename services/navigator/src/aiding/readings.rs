//! The aiding readings that arrive on topics of their own (barometric heights, magnetometer
//! samples, airspeeds) on their way to the navigator: held on their device time until the IMU
//! stream is [`HOLD_US`] past it (see [`crate::aiding::hold`]), then applied in device-time order,
//! ranked at the same time.
//!
//! `held_readings!` names every such source once; from it come the [`Reading`] enum, its time
//! and rank, its application to the source (`Reading::apply`), the payloads it is built from
//! ([`HeldPayload`]), whether the navigator subscribes to it ([`Reading::subscribed`]), and the
//! service's subscriptions (`crate::held_inputs`).

use crate::aiding::context::AidingContext;
use crate::aiding::hold::{HOLD_US, Held, Hold};
use crate::aiding::outcome::AidingOutcome;
use crate::aiding::sources::AidingSources;
use crate::config::NavigatorConfig;

/// Readings held at most; beyond it the oldest is applied at once (the IMU stream stopped while
/// aiding went on).
const CAPACITY: usize = 256;

/// The list of held aiding readings, one line per source, handed to the macro `$then`:
///
/// ```text
/// Variant(field: ReadingType) from TOPIC: Payload => build, rank N, subscribed if wanted;
/// ```
///
/// - `Variant`: its [`Reading`] variant, holding a `ReadingType` (with a `t_us` field, its device
///   time) of the source's module `crate::aiding::field`; `field`: that module, and the
///   [`AidingSources`] field whose `on_reading(&mut AidingContext, ReadingType) -> AidingOutcome`
///   applies it;
/// - `TOPIC`: the `ipc_types::names` topic it comes from, whose payload is `ipc_types::Payload`;
///   `build`: the `ReadingType::build(&Payload) -> ReadingType` that makes the reading of a payload;
/// - `N`: its rank among readings of the same device time (lower first);
/// - `wanted`: a `fn(&NavigatorConfig) -> bool`, whether the navigator subscribes to the topic.
macro_rules! held_readings {
    ($then:ident) => {
        $then! {
            /// A barometric height.
            Baro(baro: BaroReading) from ALTITUDE: Altitude => from_altitude,
                rank 0, subscribed if |_| true;
            /// A raw magnetometer sample.
            Mag(mag: MagReading) from RAW_MAG: RawMag => from_raw,
                rank 1, subscribed if |_| true;
            /// A pitot differential pressure (after the baro of the same time: its density is
            /// taken at the altitude the baro just corrected).
            Airspeed(airspeed: AirspeedReading) from RAW_AIRSPEED: RawAirspeed => from_raw,
                rank 2, subscribed if |c| c.airspeed.enabled;
        }
    };
}
pub(crate) use held_readings;

/// The [`Reading`] enum and what is made of it, from [`held_readings!`]'s list.
macro_rules! reading_enum {
    ($($(#[$doc:meta])* $variant:ident($field:ident: $reading:ident) from $topic:ident: $payload:ident
        => $build:ident, rank $rank:literal, subscribed if $wanted:expr;)+) => {
        /// One held aiding reading.
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum Reading {
            $($(#[$doc])* $variant(crate::aiding::$field::$reading),)+
        }

        impl Reading {
            /// Device time, µs.
            pub fn t_us(&self) -> u64 {
                match self {
                    $(Self::$variant(r) => r.t_us,)+
                }
            }

            /// Its place among readings of the same device time (lower first).
            fn rank(&self) -> u8 {
                match self {
                    $(Self::$variant(_) => $rank,)+
                }
            }

            /// Whether a navigator configured by `config` subscribes to its topic.
            pub fn subscribed(&self, config: &NavigatorConfig) -> bool {
                match self {
                    $(Self::$variant(_) => {
                        let wanted: fn(&NavigatorConfig) -> bool = $wanted;
                        wanted(config)
                    })+
                }
            }

            /// Applies it to its source.
            pub(crate) fn apply(
                self,
                ctx: &mut AidingContext<'_>,
                sources: &mut AidingSources,
            ) -> AidingOutcome {
                match self {
                    $(Self::$variant(r) => sources.$field.on_reading(ctx, r),)+
                }
            }
        }

        $(
            impl HeldPayload for ipc_types::$payload {
                fn reading(&self) -> Reading {
                    Reading::$variant(crate::aiding::$field::$reading::$build(self))
                }
            }
        )+
    };
}

/// An IPC payload that carries a held aiding reading.
pub trait HeldPayload {
    /// The reading it carries.
    fn reading(&self) -> Reading;
}

held_readings!(reading_enum);

impl Held for Reading {
    /// Device time, then the rank at the same time.
    fn place(&self) -> (u64, u8) {
        (self.t_us(), self.rank())
    }
}

/// What the held readings are applied to (the navigator).
pub trait ReadingSink {
    /// Applies one reading now.
    fn take(&mut self, r: Reading);
}

/// The held readings waiting for the IMU stream to pass them.
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
    use crate::aiding::airspeed::AirspeedReading;
    use crate::aiding::baro::BaroReading;
    use crate::aiding::mag::MagReading;

    #[test]
    fn baro_goes_before_mag_before_airspeed_of_the_same_time() {
        let baro = Reading::Baro(BaroReading {
            t_us: 3_000,
            height_m: 1.0,
            variance_m2: 1.0,
            valid: true,
        });
        let mag = Reading::Mag(MagReading {
            t_us: 3_000,
            field_ut: [1.0, 0.0, 0.0],
        });
        let airspeed = Reading::Airspeed(AirspeedReading {
            t_us: 3_000,
            diff_pressure_pa: 100.0,
        });
        let mut q = AidingQueue::default();
        assert_eq!(q.push(airspeed), None);
        assert_eq!(q.push(mag), None);
        assert_eq!(q.push(baro), None);
        let mut applied = Vec::new();
        q.release(3_000 + HOLD_US, |r| applied.push(r));
        assert_eq!(applied, [baro, mag, airspeed]);
    }

    #[test]
    fn airspeed_is_subscribed_only_when_enabled() {
        let airspeed = Reading::Airspeed(AirspeedReading {
            t_us: 0,
            diff_pressure_pa: 0.0,
        });
        let mut config = NavigatorConfig::default();
        assert!(!airspeed.subscribed(&config));
        config.airspeed.enabled = true;
        assert!(airspeed.subscribed(&config));
    }

    #[test]
    fn a_payload_gives_its_reading() {
        let mag = ipc_types::RawMag {
            header: ipc_types::Header {
                origin_device_time_us: 7,
                ..ipc_types::Header::default()
            },
            field_ut: [1.5, -2.0, 0.25],
            ..ipc_types::RawMag::default()
        };
        let r = mag.reading();
        assert_eq!(
            r,
            Reading::Mag(MagReading {
                t_us: 7,
                field_ut: [1.5, -2.0, 0.25]
            })
        );
        assert!(r.subscribed(&NavigatorConfig::default()));
    }
}
