//! When an unplugged serial line comes back, counted in IMU ticks so that the outage is exact in
//! device time whatever the load on the machine. Pure bookkeeping for the service loop.

/// Whether the simulated serial line is unplugged, and the IMU tick at which it is due back.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Outage {
    /// First tick at which the line is plugged in again; `None` while it is up.
    back_at: Option<u64>,
}

impl Outage {
    /// Starts an outage of `ticks` samples at `tick` (that sample is the first lost), or extends
    /// the current one when it would end later. Returns whether the line must be unplugged now,
    /// i.e. it was up.
    pub fn begin(&mut self, tick: u64, ticks: u64) -> bool {
        let end = tick.saturating_add(ticks);
        match self.back_at {
            Some(back) => {
                self.back_at = Some(back.max(end));
                false
            }
            None => {
                self.back_at = Some(end);
                true
            }
        }
    }

    /// Whether the line is down and due back at `tick`.
    pub fn due(&self, tick: u64) -> bool {
        self.back_at.is_some_and(|back| tick >= back)
    }

    /// Whether the line is unplugged (due back or not).
    pub fn is_down(&self) -> bool {
        self.back_at.is_some()
    }

    /// The line is plugged in again.
    pub fn end(&mut self) {
        self.back_at = None;
    }

    /// Plugging in failed: try again at `tick`.
    pub fn retry_at(&mut self, tick: u64) {
        if self.back_at.is_some() {
            self.back_at = Some(tick);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_outage_loses_exactly_its_ticks_and_a_second_one_extends_it() {
        let mut o = Outage::default();
        assert!(!o.is_down() && !o.due(0));
        assert!(o.begin(100, 50));
        assert!(o.is_down());
        // Samples 100..150 are lost; the line is back before sample 150.
        assert!((100..150).all(|t| !o.due(t)));
        assert!(o.due(150));
        // A shorter command during the outage does not cut it short; a longer one extends it.
        assert!(!o.begin(120, 10));
        assert!(!o.due(149) && o.due(150));
        assert!(!o.begin(140, 30));
        assert!(!o.due(169) && o.due(170));
        o.retry_at(180);
        assert!(!o.due(179) && o.due(180));
        o.end();
        assert!(!o.is_down() && !o.due(u64::MAX));
        o.retry_at(5);
        assert!(!o.is_down(), "a retry while up does nothing");
        assert!(o.begin(u64::MAX - 1, 10));
        assert!(o.due(u64::MAX));
    }
}
