//! Placing receiver fixes on the device time base, at a fixed place in the IMU stream.
//!
//! The receiver does not know the sensor block's clock; what both share is the receive clock
//! (CLOCK_MONOTONIC) their bytes were stamped with. A fix is held (see [`crate::aiding::hold`])
//! until an IMU sample received [`HOLD_NS`] after it comes through; that sample's device and
//! receive times put the fix's receive instant on the device time base, and the receiver's
//! configured latency goes back from there to the instant it measured. The same sample is chosen
//! whatever the scheduling of the processes, so two navigator lanes apply the fix to the same
//! state.

use ipc_types::GnssFix;

use crate::aiding::hold::{HOLD_US, Held, Hold};

/// How much later than a fix an IMU sample must have been received to release it, ns: as for the
/// other aiding readings, well beyond the hops' scheduling delays.
pub const HOLD_NS: u64 = HOLD_US * 1_000;

/// Fixes held at most (at 5–20 Hz, a second's worth); beyond it the oldest is dropped, counted.
const CAPACITY: usize = 32;

impl Held for GnssFix {
    /// The receive time, ns.
    fn place(&self) -> (u64, u8) {
        (self.header.origin_rx_ns, 0)
    }
}

/// Fixes waiting for the IMU stream.
#[derive(Debug, Clone)]
pub struct GnssHold {
    held: Hold<GnssFix>,
    delay_us: u64,
}

impl GnssHold {
    /// An empty hold for a receiver whose output lags its measurement by `delay_s`.
    pub fn new(delay_s: f64) -> Self {
        Self {
            held: Hold::new(HOLD_NS, CAPACITY),
            delay_us: (delay_s.max(0.0) * 1e6).round() as u64,
        }
    }

    /// Holds `fix` (in receive order); a full hold drops its oldest.
    pub fn push(&mut self, fix: GnssFix) {
        let _dropped = self.held.push(fix);
    }

    /// Hands `apply` every fix the IMU sample of device time `imu_t_us`, received at
    /// `imu_rx_ns`, releases, with the device time its receiver measured at.
    pub fn release(&mut self, imu_t_us: u64, imu_rx_ns: u64, mut apply: impl FnMut(&GnssFix, u64)) {
        let delay_us = self.delay_us;
        self.held.release(imu_rx_ns, |fix| {
            let before_us = (imu_rx_ns - fix.header.origin_rx_ns) / 1_000;
            let t_us = imu_t_us.saturating_sub(before_us).saturating_sub(delay_us);
            apply(&fix, t_us);
        });
    }

    /// Fixes dropped because the IMU stream stopped while fixes went on arriving.
    pub fn dropped(&self) -> u64 {
        self.held.displaced()
    }

    /// Fixes that arrived after the IMU sample that should have placed them.
    pub fn late(&self) -> u64 {
        self.held.late()
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    fn fix(rx_ns: u64, seq: u64) -> GnssFix {
        let mut f = GnssFix::default();
        f.header.origin_rx_ns = rx_ns;
        f.header.origin_seq = seq;
        f
    }

    #[test]
    fn a_fix_is_placed_by_the_first_imu_sample_received_a_hold_after_it() {
        let mut hold = GnssHold::new(0.08);
        // IMU sample i at device time 1 ms·i, received at 5 s + 1 ms·i + 0.3 ms of transit.
        let rx = |t_us: u64| 5_000_000_000 + t_us * 1_000 + 300_000;
        hold.push(fix(rx(200_000) + 1_000_000, 1));
        let mut applied = Vec::new();
        for i in 0..400u64 {
            let t = i * 1_000;
            hold.release(t, rx(t), |f, t_us| {
                applied.push((i, f.header.origin_seq, t_us))
            });
        }
        // Received 1 ms after the sample of 200 ms: released by the sample 10 ms later (211 ms,
        // the first whose receive time is >= fix + 10 ms), placed at 201 ms, measured 80 ms before.
        assert_eq!(applied, [(211, 1, 121_000)]);
    }

    #[test]
    fn fixes_arriving_out_of_order_are_released_in_receive_order() {
        let mut hold = GnssHold::new(0.0);
        hold.push(fix(3_000_000_000, 2));
        hold.push(fix(2_000_000_000, 1));
        let mut seqs = Vec::new();
        hold.release(10_000_000, 4_000_000_000, |f, _| {
            seqs.push(f.header.origin_seq)
        });
        assert_eq!(seqs, [1, 2]);
    }

    #[test]
    fn a_full_hold_drops_its_oldest_and_counts_it() {
        let mut hold = GnssHold::new(0.0);
        for i in 0..(CAPACITY as u64 + 3) {
            hold.push(fix(i, i));
        }
        assert_eq!(hold.dropped(), 3);
    }
}
