//! What an aiding source sees of the inertial core while it handles a reading: the filter (once
//! navigating) or the aligner (before), the IMU stream's time, stance and specific force, and the
//! records and integrity monitor its updates are booked in. The core lends it for one reading;
//! the source changes nothing of the core beyond what this offers.

use nalgebra::Vector3;

use crate::aiding::records::SourceRecords;
use crate::alignment::StaticAligner;
use crate::ekf::{AidingSource, ErrorStateEkf, UpdateOutcome};
use crate::integrity::IntegrityMonitor;

/// Where the core is: aligning or navigating.
pub(crate) enum CorePhase<'a> {
    /// Filling the alignment window.
    Aligning(&'a mut StaticAligner),
    /// The filter runs.
    Navigating(&'a mut ErrorStateEkf),
}

/// The IMU stream as of the last sample propagated.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ImuNow {
    /// Device time of the last IMU sample, µs.
    pub(crate) time_us: Option<u64>,
    /// The stance detector fired on it.
    pub(crate) in_stance: bool,
    /// Its bias-corrected specific force, m/s².
    pub(crate) force: Vector3<f64>,
}

/// The inertial core as lent to one aiding source for one reading.
pub(crate) struct AidingContext<'a> {
    phase: CorePhase<'a>,
    imu: ImuNow,
    records: &'a mut SourceRecords,
    integrity: &'a mut IntegrityMonitor,
}

impl<'a> AidingContext<'a> {
    pub(crate) fn new(
        phase: CorePhase<'a>,
        imu: ImuNow,
        records: &'a mut SourceRecords,
        integrity: &'a mut IntegrityMonitor,
    ) -> Self {
        Self {
            phase,
            imu,
            records,
            integrity,
        }
    }

    /// The filter, once navigating.
    pub(crate) fn filter(&self) -> Option<&ErrorStateEkf> {
        match &self.phase {
            CorePhase::Navigating(ekf) => Some(ekf),
            CorePhase::Aligning(_) => None,
        }
    }

    /// The filter to update, once navigating.
    pub(crate) fn filter_mut(&mut self) -> Option<&mut ErrorStateEkf> {
        match &mut self.phase {
            CorePhase::Navigating(ekf) => Some(ekf),
            CorePhase::Aligning(_) => None,
        }
    }

    /// The aligner, while aligning.
    pub(crate) fn aligner_mut(&mut self) -> Option<&mut StaticAligner> {
        match &mut self.phase {
            CorePhase::Aligning(aligner) => Some(aligner),
            CorePhase::Navigating(_) => None,
        }
    }

    /// Device time of the last IMU sample, µs.
    pub(crate) fn time_us(&self) -> Option<u64> {
        self.imu.time_us
    }

    /// The stance detector fired on the last IMU sample.
    pub(crate) fn in_stance(&self) -> bool {
        self.imu.in_stance
    }

    /// Bias-corrected specific force of the last IMU sample, m/s².
    pub(crate) fn force(&self) -> Vector3<f64> {
        self.imu.force
    }

    /// `source` is in use but has gone quiet (see [`SourceRecords::is_stale`]).
    pub(crate) fn is_stale(&self, source: AidingSource) -> bool {
        self.records.is_stale(source, self.imu.time_us)
    }

    /// Device time of the last accepted update from `source`, µs.
    pub(crate) fn last_accepted_us(&self, source: AidingSource) -> Option<u64> {
        self.records.last_accepted_us(source)
    }

    /// A valid reading of `source` at `t_us`.
    pub(crate) fn note_reading(&mut self, source: AidingSource, t_us: u64) {
        self.records.note_reading(source, t_us);
    }

    /// An update of `source` at `t_us` the filter took, not judged by the integrity monitor.
    pub(crate) fn note_accepted(&mut self, source: AidingSource, t_us: u64) {
        self.records.note_accepted(source, t_us);
    }

    /// Books one update of `source` at `t_us` that measured `dof` components.
    pub(crate) fn book_update(
        &mut self,
        source: AidingSource,
        t_us: u64,
        result: UpdateOutcome,
        dof: u32,
    ) {
        self.records
            .book_update(self.integrity, source, t_us, result, dof);
    }

    /// Books a reset of the filter from `source` at `t_us`.
    pub(crate) fn book_reset(&mut self, source: AidingSource, t_us: u64) {
        self.records.book_reset(self.integrity, source, t_us);
    }

    /// The integrity monitor asks for the state `source` measures to be re-set from it (see
    /// [`crate::integrity`]).
    pub(crate) fn wants_reset(&self, source: AidingSource, t_us: u64) -> bool {
        self.integrity.wants_reset(source, t_us)
    }

    /// Whether the horizontal position is unknown (no configured origin, no absolute fix yet).
    pub(crate) fn position_unknown(&self) -> bool {
        self.integrity.position_unknown()
    }

    /// An absolute fix has set the horizontal position.
    pub(crate) fn set_position_known(&mut self) {
        self.integrity.set_position_unknown(false);
    }
}
