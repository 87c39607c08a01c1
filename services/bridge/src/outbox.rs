//! What the IPC side hands to the network side: copies of the samples due, each topic decimated to
//! its rate by the samples' measurement time ([`RateGate`]), so that a topic keeps its rate exactly
//! whatever the process's scheduling. Pure; the service moves the samples.

use ipc_types::{FusedImu, HealthReport, NavState};
use rins_runtime::rate_gate::RateGate;

use crate::config::ZenohRates;

/// One message to publish, carried by value (the queue between the sides holds its slots from the
/// start: no allocation per sample).
#[derive(Debug, Clone, Copy)]
pub enum Outgoing {
    /// `nav_msgs/msg/Odometry` of `nav`, the body rate from `imu`.
    Odometry {
        /// The navigation state.
        nav: NavState,
        /// The latest fused sample at the time.
        imu: FusedImu,
    },
    /// `sensor_msgs/msg/Imu` of `fused`, oriented by `nav` when it is usable.
    Imu {
        /// The fused sample.
        fused: FusedImu,
        /// The latest navigation state at the time.
        nav: Option<NavState>,
    },
    /// `sensor_msgs/msg/NavSatFix` of the navigation's position.
    NavSatFix(NavState),
    /// `diagnostic_msgs/msg/DiagnosticArray` of the watchdog's report.
    Diagnostics(HealthReport),
}

/// The latest samples and each topic's pacing.
#[derive(Debug, Clone)]
pub struct Outbox {
    odometry: RateGate,
    imu: RateGate,
    nav_sat_fix: RateGate,
    diagnostics: RateGate,
    fused: Option<FusedImu>,
    nav: Option<NavState>,
}

impl Outbox {
    /// Paced by `rates` (a rate of 0 keeps the topic off).
    pub fn new(rates: &ZenohRates) -> Self {
        Self {
            odometry: RateGate::new(rates.odometry_hz),
            imu: RateGate::new(rates.imu_hz),
            nav_sat_fix: RateGate::new(rates.nav_sat_fix_hz),
            diagnostics: RateGate::new(rates.diagnostics_hz),
            fused: None,
            nav: None,
        }
    }

    /// A fused sample: the Imu message when due.
    pub fn on_fused(&mut self, f: &FusedImu, send: &mut impl FnMut(Outgoing)) {
        self.fused = Some(*f);
        if self.imu.due(f.header.origin_rx_ns) {
            send(Outgoing::Imu {
                fused: *f,
                nav: self.nav,
            });
        }
    }

    /// A navigation state: Odometry (once a fused sample gives the body rate) and NavSatFix when
    /// due.
    pub fn on_nav(&mut self, n: &NavState, send: &mut impl FnMut(Outgoing)) {
        self.nav = Some(*n);
        let t = n.header.origin_rx_ns;
        if let Some(imu) = self.fused
            && self.odometry.due(t)
        {
            send(Outgoing::Odometry { nav: *n, imu });
        }
        if self.nav_sat_fix.due(t) {
            send(Outgoing::NavSatFix(*n));
        }
    }

    /// The watchdog's report: DiagnosticArray when due.
    pub fn on_health(&mut self, h: &HealthReport, send: &mut impl FnMut(Outgoing)) {
        if self.diagnostics.due(h.now_ns) {
            send(Outgoing::Diagnostics(*h));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_topic_keeps_its_rate_by_measurement_time() {
        let mut outbox = Outbox::new(&ZenohRates {
            odometry_hz: 50.0,
            imu_hz: 100.0,
            nav_sat_fix_hz: 0.0,
            diagnostics_hz: 1.0,
        });
        let (mut odometry, mut imu, mut fix) = (0, 0, 0);
        let mut count = |m: Outgoing| match m {
            Outgoing::Odometry { .. } => odometry += 1,
            Outgoing::Imu { .. } => imu += 1,
            Outgoing::NavSatFix(_) => fix += 1,
            Outgoing::Diagnostics(_) => {}
        };
        // 10 s at 1 kHz.
        for k in 0..10_000u64 {
            let mut f = FusedImu::default();
            f.header.origin_rx_ns = k * 1_000_000;
            let n = NavState {
                header: f.header,
                ..NavState::default()
            };
            outbox.on_fused(&f, &mut count);
            outbox.on_nav(&n, &mut count);
        }
        assert_eq!((odometry, imu, fix), (500, 1000, 0));
    }
}
