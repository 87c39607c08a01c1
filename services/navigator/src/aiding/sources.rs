//! The aiding sources of the inertial core, each with its settings and what it keeps between
//! readings, and what happens to them when navigation starts or is taken over.

use crate::aiding::airspeed::AirspeedAiding;
use crate::aiding::baro::BaroAiding;
use crate::aiding::gnss::GnssAiding;
use crate::aiding::mag::MagAiding;
use crate::aiding::tilt::TiltAiding;
use crate::aiding::zupt::ZuptAiding;
use crate::alignment::Alignment;

/// Every aiding source of the inertial core, built by
/// [`crate::aided_config::AidedConfig::sources`].
#[derive(Debug, Clone)]
pub(crate) struct AidingSources {
    /// Barometric height.
    pub(crate) baro: BaroAiding,
    /// Magnetometer heading (or the stance heading, HUPT).
    pub(crate) mag: MagAiding,
    /// Zero velocity in stance.
    pub(crate) zupt: ZuptAiding,
    /// Tilt from the specific force.
    pub(crate) tilt: TiltAiding,
    /// GNSS position and velocity.
    pub(crate) gnss: GnssAiding,
    /// Pitot airspeed as the body-x velocity.
    pub(crate) airspeed: AirspeedAiding,
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
