//! Pacing a stream by the measurement time: a message is due when its sample's time reaches the
//! next slot. Paced by the samples' own clock, a stream keeps its rate exactly however the
//! process is scheduled, and the messages of one slot carry the same sample's time.

/// One stream's pacing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RateGate {
    /// Slot length, ns; 0 = the stream is off.
    period_ns: u64,
    /// Start of the next slot, ns of the sample clock; `None` before the first sample.
    next_ns: Option<u64>,
}

impl RateGate {
    /// A gate letting `hz` messages a second through (0: none).
    pub fn new(hz: f64) -> Self {
        let period_ns = if hz > 0.0 && hz.is_finite() {
            (1e9 / hz).round().max(1.0) as u64
        } else {
            0
        };
        Self {
            period_ns,
            next_ns: None,
        }
    }

    /// Whether the sample at `t_ns` is sent. The first sample is; then one per slot. After a gap
    /// longer than a slot (no samples), the slots restart at the sample instead of bursting to
    /// catch up.
    pub fn due(&mut self, t_ns: u64) -> bool {
        if self.period_ns == 0 {
            return false;
        }
        match self.next_ns {
            Some(next) if t_ns < next => false,
            Some(next) => {
                let following = next + self.period_ns;
                self.next_ns = Some(if t_ns >= following {
                    t_ns + self.period_ns
                } else {
                    following
                });
                true
            }
            None => {
                self.next_ns = Some(t_ns + self.period_ns);
                true
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Messages let through from samples every `step_ns` for `seconds`.
    fn count(hz: f64, step_ns: u64, seconds: u64) -> usize {
        let mut gate = RateGate::new(hz);
        (0..seconds * 1_000_000_000 / step_ns)
            .filter(|i| gate.due(1_000 + i * step_ns))
            .count()
    }

    #[test]
    fn keeps_the_rate_from_a_faster_stream() {
        // 1 kHz samples: 50, 30, 1 and 0.5 Hz exactly over 10 s.
        assert_eq!(count(50.0, 1_000_000, 10), 500);
        assert_eq!(count(30.0, 1_000_000, 10), 300);
        assert_eq!(count(1.0, 1_000_000, 10), 10);
        assert_eq!(count(0.5, 1_000_000, 10), 5);
        // Jittered samples keep the average: a slot is never skipped for a late sample.
        let mut gate = RateGate::new(30.0);
        let sent = (0..10_000u64)
            .filter(|i| gate.due(i * 1_000_000 + (i % 2) * 600_000))
            .count();
        assert!((299..=301).contains(&sent), "{sent}");
    }

    #[test]
    fn off_and_gaps() {
        assert_eq!(count(0.0, 1_000_000, 10), 0);
        // A rate above the sample rate sends every sample, no more.
        assert_eq!(count(2000.0, 1_000_000, 1), 1000);
        // After a 5 s gap the next sample goes and the rate resumes, with no burst.
        let mut gate = RateGate::new(10.0);
        assert!(gate.due(0));
        assert!(!gate.due(50_000_000));
        assert!(gate.due(5_000_000_000));
        assert!(!gate.due(5_050_000_000));
        assert!(gate.due(5_100_000_000));
    }
}
