//! One fix per receiver epoch when a receiver sends both UBX and NMEA.
//!
//! A u-blox receiver may be set to send its solution both ways, each message once per
//! navigation epoch: publishing both would hand the navigator every measurement twice, as if
//! independent. The rule: UBX is preferred (finer resolution, the receiver's own accuracies and
//! a vertical velocity). Once a UBX epoch has been published, NMEA epochs are counted as
//! superseded, not published (their sentences still count as used), until
//! [`NMEA_EPOCHS_TO_TAKE_OVER`] NMEA epochs in a row have passed without a UBX epoch: the
//! receiver stopped sending UBX navigation, and NMEA is published again. NMEA and UBX times
//! cannot be matched directly (UTC time of day against GPS time of week), which is why the rule
//! goes by arrival; it assumes both at one rate, which is how a u-blox receiver sends them.

/// NMEA epochs in a row without a UBX epoch after which NMEA is published again: the NMEA
/// epoch that completes just after the receiver's last UBX epoch is one of its own, so one
/// would not do; two do.
pub const NMEA_EPOCHS_TO_TAKE_OVER: u8 = 2;

/// Which protocol's epochs are published; see the module documentation for the rule.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EpochSource {
    ubx_seen: bool,
    nmea_since_ubx: u8,
}

impl EpochSource {
    /// A UBX epoch was published.
    pub fn ubx_published(&mut self) {
        self.ubx_seen = true;
        self.nmea_since_ubx = 0;
    }

    /// An NMEA epoch is complete: whether to publish it.
    pub fn publish_nmea(&mut self) -> bool {
        self.nmea_since_ubx = self.nmea_since_ubx.saturating_add(1);
        if self.ubx_seen && self.nmea_since_ubx <= NMEA_EPOCHS_TO_TAKE_OVER {
            return false;
        }
        self.ubx_seen = false;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nmea_alone_is_always_published() {
        let mut s = EpochSource::default();
        assert!((0..300).all(|_| s.publish_nmea()));
    }

    #[test]
    fn nmea_gives_way_while_ubx_epochs_come_and_takes_over_when_they_stop() {
        let mut s = EpochSource::default();
        // Both at one rate, in either order within the epoch, and with the NMEA epoch decided
        // only after the next epoch's UBX message.
        for _ in 0..3 {
            s.ubx_published();
            assert!(!s.publish_nmea());
        }
        s.ubx_published();
        assert!(!s.publish_nmea());
        assert!(!s.publish_nmea());
        // UBX stopped two NMEA epochs ago.
        assert!(s.publish_nmea());
        assert!(s.publish_nmea());
        // And comes back.
        s.ubx_published();
        assert!(!s.publish_nmea());
    }
}
