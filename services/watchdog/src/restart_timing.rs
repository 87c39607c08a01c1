//! How long a killed process takes to publish again: from the moment its exit is seen to the first
//! sample of its output topic after that. Includes the restart backoff, the process start, its
//! iceoryx2 set-up and its first input.

use std::time::{Duration, Instant};

use ipc_types::ServiceKind;

const KINDS: usize = ServiceKind::ALL.len();

/// Restart-to-publish times: from a child's exit to its first output after the restart.
#[derive(Debug, Clone, Default)]
pub struct RestartTiming {
    /// Per kind: when its exit was seen and its output count then.
    pending: [Option<(Instant, u64)>; KINDS],
    /// Completed measurements per kind: count and the longest.
    count: [u64; KINDS],
    worst: [Duration; KINDS],
}

impl RestartTiming {
    /// A process of `kind` exited at `at`, when its output count was `output`.
    pub fn on_exit(&mut self, kind: ServiceKind, at: Instant, output: u64) {
        self.pending[kind as usize] = Some((at, output));
    }

    /// Output counts now: a kind whose count moved since its exit has published again.
    pub fn observe(&mut self, now: Instant, output: impl Fn(ServiceKind) -> Option<u64>) {
        for kind in ServiceKind::ALL {
            let i = kind as usize;
            let Some((at, before)) = self.pending[i] else {
                continue;
            };
            if output(kind).is_some_and(|n| n > before) {
                self.pending[i] = None;
                self.count[i] += 1;
                self.worst[i] = self.worst[i].max(now.saturating_duration_since(at));
            }
        }
    }

    /// Longest exit-to-publish time over every kind, and the number of measurements.
    pub fn worst(&self) -> (Duration, u64) {
        (
            self.worst.iter().copied().max().unwrap_or_default(),
            self.count.iter().sum(),
        )
    }

    /// Longest exit-to-publish time and measurements of each kind that was restarted.
    pub fn by_kind(&self) -> Vec<(ServiceKind, Duration, u64)> {
        ServiceKind::ALL
            .into_iter()
            .filter(|&k| self.count[k as usize] > 0)
            .map(|k| (k, self.worst[k as usize], self.count[k as usize]))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn measures_from_exit_to_the_first_new_sample() {
        let t0 = Instant::now();
        let ms = |n| t0 + Duration::from_millis(n);
        let mut t = RestartTiming::default();
        let mut fused = 100;
        t.on_exit(ServiceKind::Fusion, ms(0), fused);
        t.observe(ms(10), |k| (k == ServiceKind::Fusion).then_some(fused));
        assert_eq!(t.worst(), (Duration::ZERO, 0));
        fused += 1;
        t.observe(ms(42), |k| (k == ServiceKind::Fusion).then_some(fused));
        t.observe(ms(90), |k| (k == ServiceKind::Fusion).then_some(fused + 5));
        assert_eq!(t.worst(), (Duration::from_millis(42), 1));
        t.on_exit(ServiceKind::Navigator, ms(100), 7);
        t.observe(ms(130), |_| Some(8));
        assert_eq!(
            t.by_kind(),
            vec![
                (ServiceKind::Fusion, Duration::from_millis(42), 1),
                (ServiceKind::Navigator, Duration::from_millis(30), 1),
            ]
        );
    }
}
