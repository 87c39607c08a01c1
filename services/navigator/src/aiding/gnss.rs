//! The GNSS receiver as an aiding source; its updates are in [`crate::gnss_updates`].

use crate::aiding::source::AidingSensor;
use crate::ekf::AidingSource;
use crate::gnss_config::GnssAidingConfig;

impl AidingSensor for GnssAidingConfig {
    fn source(&self) -> AidingSource {
        AidingSource::Gnss
    }

    fn enabled(&self) -> bool {
        self.enabled
    }

    fn watched_for_staleness(&self) -> bool {
        true
    }
}
