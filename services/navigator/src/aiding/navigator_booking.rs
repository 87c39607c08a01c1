//! The navigator's booking of its aiding sources' updates, for the sources that update the
//! filter through the [`AidedNavigator`] (see [`crate::aiding::booking`]).

use crate::aiding::booking::{record_reset, record_update};
use crate::ekf::{AidingSource, UpdateOutcome};
use crate::inertial_core::AidedNavigator;

impl AidedNavigator {
    /// Books one update of `source` at `t_us` that measured `dof` components (see
    /// [`crate::aiding::booking`]).
    pub(crate) fn book_update(
        &mut self,
        source: AidingSource,
        t_us: u64,
        outcome: UpdateOutcome,
        dof: u32,
    ) {
        record_update(
            &mut self.last_accepted_us,
            &mut self.integrity,
            source,
            t_us,
            outcome,
            dof,
        );
    }

    /// Books a reset of the filter from `source` at `t_us`.
    pub(crate) fn book_reset(&mut self, source: AidingSource, t_us: u64) {
        record_reset(
            &mut self.last_accepted_us,
            &mut self.integrity,
            source,
            t_us,
        );
    }
}
