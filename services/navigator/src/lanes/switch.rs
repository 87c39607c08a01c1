//! A change of the lane delivering: why the selector made it, how it reads in a log, and the
//! changes since start counted by cause.

use std::fmt;

use crate::lanes::trust::Distrust;

/// Why the selector changed lanes: what it saw when it did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SwitchReason {
    /// The selected lane delivered nothing for `silent_ns` (navigator publish times) while the
    /// other lane was `ahead` samples ahead of the output.
    Silent {
        /// How long the selected lane had been silent, ns.
        silent_ns: u64,
        /// Samples of the other lane pending ahead of the output.
        ahead: u32,
    },
    /// The selected lane delivered nothing while the other lane, whose samples carry no publish
    /// times, was `ahead` samples ahead: judged by the count alone.
    Behind {
        /// Samples of the other lane pending ahead of the output.
        ahead: u32,
    },
    /// The other lane's pending samples filled the ring (`ahead` of them) and the selected lane
    /// had been silent for `silent_ns` on the consumer's clock.
    RingFull {
        /// How long the selected lane had been silent, ns.
        silent_ns: u64,
        /// Samples of the other lane pending ahead of the output.
        ahead: u32,
    },
    /// The selected lane's next sample was not trusted and the other lane's was.
    Untrusted(Distrust),
}

impl SwitchReason {
    /// A name for the cause alone, for counts and structured logs.
    pub fn name(self) -> &'static str {
        match self {
            Self::Silent { .. } => "silent",
            Self::Behind { .. } => "behind",
            Self::RingFull { .. } => "ring-full",
            Self::Untrusted(_) => "untrusted",
        }
    }
}

/// A change of the lane delivering, and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Switch {
    /// The lane left.
    pub from: usize,
    /// The lane delivering from now on.
    pub to: usize,
    /// Why the selector switched.
    pub reason: SwitchReason,
    /// Sequence number of the first sample delivered from the new lane.
    pub at_seq: u64,
}

impl fmt::Display for Switch {
    /// `lane 0 → 1 at seq 1234: lane 0 silent 12.3 ms while lane 1 was 15 samples ahead`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (from, to) = (self.from, self.to);
        write!(f, "lane {from} → {to} at seq {}: ", self.at_seq)?;
        match self.reason {
            SwitchReason::Silent { silent_ns, ahead } => write!(
                f,
                "lane {from} silent {:.1} ms while lane {to} was {ahead} samples ahead",
                silent_ns as f64 * 1e-6
            ),
            SwitchReason::Behind { ahead } => write!(
                f,
                "lane {from} silent while lane {to} was {ahead} samples ahead (no publish times)"
            ),
            SwitchReason::RingFull { silent_ns, ahead } => write!(
                f,
                "lane {to}'s {ahead} pending samples filled the ring, lane {from} silent {:.1} ms",
                silent_ns as f64 * 1e-6
            ),
            SwitchReason::Untrusted(Distrust::Young { run }) => write!(
                f,
                "lane {from}'s solution too young ({run} samples), lane {to} trusted"
            ),
            SwitchReason::Untrusted(d) => {
                write!(f, "lane {from} {}, lane {to} trusted", d.name())
            }
        }
    }
}

/// Lane changes since start, by cause.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SwitchCounts {
    /// [`SwitchReason::Silent`].
    pub silent: u64,
    /// [`SwitchReason::Behind`].
    pub behind: u64,
    /// [`SwitchReason::RingFull`].
    pub ring_full: u64,
    /// [`SwitchReason::Untrusted`].
    pub untrusted: u64,
}

impl SwitchCounts {
    /// All of them.
    pub fn total(&self) -> u64 {
        self.silent + self.behind + self.ring_full + self.untrusted
    }

    /// One more switch of `reason`'s cause.
    pub(super) fn count(&mut self, reason: SwitchReason) {
        let slot = match reason {
            SwitchReason::Silent { .. } => &mut self.silent,
            SwitchReason::Behind { .. } => &mut self.behind,
            SwitchReason::RingFull { .. } => &mut self.ring_full,
            SwitchReason::Untrusted(_) => &mut self.untrusted,
        };
        *slot += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reasons_read_as_what_happened() {
        let switch = |reason| Switch {
            from: 1,
            to: 0,
            reason,
            at_seq: 42,
        };
        assert_eq!(
            switch(SwitchReason::Behind { ahead: 8 }).to_string(),
            "lane 1 → 0 at seq 42: lane 1 silent while lane 0 was 8 samples ahead (no publish times)"
        );
        assert_eq!(
            switch(SwitchReason::RingFull {
                silent_ns: 8_250_000,
                ahead: 512
            })
            .to_string(),
            "lane 1 → 0 at seq 42: lane 0's 512 pending samples filled the ring, lane 1 silent 8.2 ms"
        );
        assert_eq!(
            switch(SwitchReason::Untrusted(Distrust::Aligning)).to_string(),
            "lane 1 → 0 at seq 42: lane 1 aligning, lane 0 trusted"
        );
        let names = [
            SwitchReason::Silent {
                silent_ns: 0,
                ahead: 0,
            },
            SwitchReason::Behind { ahead: 0 },
            SwitchReason::RingFull {
                silent_ns: 0,
                ahead: 0,
            },
            SwitchReason::Untrusted(Distrust::Invalid),
        ]
        .map(SwitchReason::name);
        assert_eq!(names, ["silent", "behind", "ring-full", "untrusted"]);
    }
}
