//! The aiding sources of the inertial core, each with its settings and what it keeps between
//! readings, and what happens to them when navigation starts or is taken over.
//!
//! The list below is the one place that names every source: from one line per source it makes
//! the source's field of [`AidingSources`], its place in [`AidedConfig::sensors`] (its settings,
//! the [`AidedConfig`] field of the same name) and its construction in [`AidedConfig::sources`].

use crate::aided_config::AidedConfig;
use crate::aiding::airspeed::AirspeedAiding;
use crate::aiding::baro::BaroAiding;
use crate::aiding::gnss::GnssAiding;
use crate::aiding::mag::MagAiding;
use crate::aiding::source::AidingSensor;
use crate::aiding::tilt::TiltAiding;
use crate::aiding::zupt::ZuptAiding;
use crate::alignment::Alignment;

/// `field: Type(args)`: the source `field` is a `Type`, built by `Type::new` from the
/// [`AidedConfig`] fields `args`, and its settings are the [`AidedConfig`] field `field`.
macro_rules! aiding_sources {
    ($($(#[$doc:meta])* $field:ident: $ty:ident($($arg:ident),+),)+) => {
        /// Every aiding source of the inertial core, built by [`AidedConfig::sources`].
        #[derive(Debug, Clone)]
        pub(crate) struct AidingSources {
            $($(#[$doc])* pub(crate) $field: $ty,)+
        }

        /// Number of aiding sources.
        const SOURCES: usize = [$(stringify!($field)),+].len();

        impl AidedConfig {
            /// The settings of every aiding source, in the order their settings are checked.
            pub(crate) fn sensors(&self) -> [&dyn AidingSensor; SOURCES] {
                [$(&self.$field),+]
            }

            /// Every aiding source, with its settings and nothing kept yet.
            pub(crate) fn sources(&self) -> AidingSources {
                AidingSources {
                    $($field: $ty::new($(self.$arg),+),)+
                }
            }
        }
    };
}

aiding_sources! {
    /// Zero velocity in stance.
    zupt: ZuptAiding(zupt),
    /// Barometric height.
    baro: BaroAiding(baro),
    /// Magnetometer heading (or the stance heading, HUPT).
    mag: MagAiding(mag, mag_calibration, declination_rad),
    /// GNSS position and velocity.
    gnss: GnssAiding(gnss),
    /// Pitot airspeed as the body-x velocity.
    airspeed: AirspeedAiding(airspeed),
    /// Tilt from the specific force.
    tilt: TiltAiding(tilt),
}

impl AidingSources {
    /// Navigation starts from the alignment `a`.
    pub(crate) fn on_aligned(&mut self, a: &Alignment) {
        self.mag.on_aligned(a);
        self.gnss.reset();
    }

    /// Navigation goes on from another filter's solution, at altitude `alt_m`.
    pub(crate) fn on_take_over(&mut self, alt_m: f64) {
        self.baro.on_take_over(alt_m);
        self.mag.on_take_over();
        self.tilt.reset();
        self.gnss.reset();
    }
}
