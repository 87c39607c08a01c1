//! What the navigator keeps between GNSS fixes: the state history the fixes are compared with,
//! the receiver's consistency monitor and the displacement test.

/// What the navigator keeps for its GNSS aiding.
#[derive(Debug, Clone)]
pub(crate) struct GnssAidingState {
    /// Recent states, for fixes measured before the IMU stream's present.
    pub(crate) history: crate::state_history::StateHistory,
    /// Whether the receiver is believed.
    pub(crate) monitor: crate::gnss_monitor::GnssMonitor,
    /// The receiver time of the last fix taken, µs.
    pub(crate) last_receiver_time_us: Option<u64>,
    /// The horizontal distance of the fixes from the solution when the receiver was rejected, m.
    pub(crate) jump_offset_m: Option<f64>,
    /// The receiver's displacement against the inertial velocity (the gain-free drift test).
    pub(crate) displacement: crate::gnss_displacement::DisplacementTest,
}

impl GnssAidingState {
    pub(crate) fn new(config: crate::gnss_config::GnssAidingConfig) -> Self {
        Self {
            history: crate::state_history::StateHistory::default(),
            monitor: crate::gnss_monitor::GnssMonitor::new(config),
            last_receiver_time_us: None,
            jump_offset_m: None,
            displacement: crate::gnss_displacement::DisplacementTest::default(),
        }
    }

    /// Forgets everything for a new solution, keeping the history's storage (no allocation on
    /// the sample that starts navigation).
    pub(crate) fn reset(&mut self, config: crate::gnss_config::GnssAidingConfig) {
        self.history.clear();
        self.monitor = crate::gnss_monitor::GnssMonitor::new(config);
        self.last_receiver_time_us = None;
        self.jump_offset_m = None;
        self.displacement.reset();
    }
}
