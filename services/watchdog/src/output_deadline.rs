//! The output deadline: a hung stage is seen long before its heartbeat is overdue. A stage whose
//! input keeps arriving while its own output stays silent for the deadline is not working (it is
//! stopped, spinning or blocked); the watchdog kills it and restarts it like any exit. A stage whose
//! input is quiet is not judged (it has nothing to do: the stall is upstream), nor one that has not
//! published since it started (its start-up is the heartbeat's to judge).

use std::time::{Duration, Instant};

use ipc_types::ServiceKind;

const KINDS: usize = ServiceKind::ALL.len();

/// Input samples that must have arrived, unanswered, before a silent output counts as missed.
pub const MIN_UNANSWERED_INPUT: u64 = 5;

#[derive(Debug, Clone, Copy)]
struct Track {
    pid: u32,
    /// Output and input counts when the output last moved (or when this pid was first seen).
    output: u64,
    input: u64,
    /// When the first input after that arrived: the deadline runs from there (after an outage
    /// upstream the input returns long after the last output, and the stage needs its moment).
    unanswered_since: Option<Instant>,
    /// The output has moved under this pid, and no miss has been reported since.
    armed: bool,
}

/// The output deadline of each stage: input arriving, output silent for longer is a hung stage.
#[derive(Debug, Clone)]
pub struct OutputDeadline {
    deadline: Duration,
    tracks: [Option<Track>; KINDS],
}

impl OutputDeadline {
    /// Deadlines of `deadline`.
    pub fn new(deadline: Duration) -> Self {
        Self {
            deadline,
            tracks: [None; KINDS],
        }
    }

    /// One look at `kind`, running as `pid`, with its input and output counts now. True once per
    /// stall when the output has missed its deadline.
    pub fn observe(
        &mut self,
        kind: ServiceKind,
        pid: u32,
        input: u64,
        output: u64,
        now: Instant,
    ) -> bool {
        let slot = &mut self.tracks[kind as usize];
        let fresh = Track {
            pid,
            output,
            input,
            unanswered_since: None,
            armed: false,
        };
        let Some(track) = slot.as_mut().filter(|t| t.pid == pid) else {
            *slot = Some(fresh);
            return false;
        };
        if output != track.output {
            *track = Track {
                armed: true,
                ..fresh
            };
            return false;
        }
        if input > track.input && track.unanswered_since.is_none() {
            track.unanswered_since = Some(now);
        }
        let missed = track.armed
            && input >= track.input + MIN_UNANSWERED_INPUT
            && track
                .unanswered_since
                .is_some_and(|t| now.saturating_duration_since(t) >= self.deadline);
        if missed {
            track.armed = false;
        }
        missed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FUSION: ServiceKind = ServiceKind::Fusion;

    fn ms(t0: Instant, ms: u64) -> Instant {
        t0 + Duration::from_millis(ms)
    }

    #[test]
    fn a_stage_that_stops_answering_its_input_misses_its_deadline_once() {
        let t0 = Instant::now();
        let mut d = OutputDeadline::new(Duration::from_millis(500));
        // 1 kHz in, 1 kHz out for 100 ms.
        for t in 0..=100 {
            assert!(!d.observe(FUSION, 7, t, t, ms(t0, t)));
        }
        // Hung at 100 ms: input goes on, output stays at 100.
        let missed: Vec<u64> = (101..=800)
            .filter(|&t| d.observe(FUSION, 7, t, 100, ms(t0, t)))
            .collect();
        // The first unanswered input came at 101 ms.
        assert_eq!(missed, vec![601]);
    }

    #[test]
    fn an_input_back_after_an_outage_gets_the_whole_deadline() {
        let t0 = Instant::now();
        let mut d = OutputDeadline::new(Duration::from_millis(500));
        for t in 0..=100 {
            d.observe(FUSION, 7, t, t, ms(t0, t));
        }
        // Nothing arrives for 1.3 s (the serial device unplugged), then the input is back and
        // the stage answers 3 ms later: no miss.
        assert!((101..1_400).all(|t| !d.observe(FUSION, 7, 100, 100, ms(t0, t))));
        assert!((1_400..1_403).all(|t| !d.observe(FUSION, 7, 100 + t - 1_399, 100, ms(t0, t))));
        assert!(!d.observe(FUSION, 7, 104, 104, ms(t0, 1_403)));
        // Back, but unanswered: missed 500 ms after the first new input.
        let missed: Vec<u64> = (1_404..=2_500)
            .filter(|&t| d.observe(FUSION, 7, 104 + t - 1_403, 104, ms(t0, t)))
            .collect();
        assert_eq!(missed, vec![1_904]);
    }

    #[test]
    fn a_quiet_input_is_no_reason() {
        let t0 = Instant::now();
        let mut d = OutputDeadline::new(Duration::from_millis(500));
        d.observe(FUSION, 7, 0, 0, t0);
        d.observe(FUSION, 7, 10, 10, ms(t0, 10));
        // Acquisition stops: fusion's input and output both stop, for seconds.
        assert!((11..5_000).all(|t| !d.observe(
            FUSION,
            7,
            10 + MIN_UNANSWERED_INPUT - 1,
            10,
            ms(t0, t)
        )));
    }

    #[test]
    fn a_new_process_is_judged_only_after_its_first_output() {
        let t0 = Instant::now();
        let mut d = OutputDeadline::new(Duration::from_millis(500));
        d.observe(FUSION, 7, 0, 0, t0);
        d.observe(FUSION, 7, 5, 5, ms(t0, 5));
        // Restarted as pid 8: still setting up for 2 s while input flows, output unchanged.
        assert!((6..2_000).all(|t| !d.observe(FUSION, 8, t, 5, ms(t0, t))));
        // First output at 2 s; hung again right after: missed 500 ms later.
        assert!(!d.observe(FUSION, 8, 2_000, 6, ms(t0, 2_000)));
        let missed: Vec<u64> = (2_001..=3_000)
            .filter(|&t| d.observe(FUSION, 8, t, 6, ms(t0, t)))
            .collect();
        assert_eq!(missed, vec![2_501]);
    }

    #[test]
    fn kinds_are_judged_apart() {
        let t0 = Instant::now();
        let mut d = OutputDeadline::new(Duration::from_millis(100));
        for t in 0..=10 {
            d.observe(FUSION, 7, t, t, ms(t0, t));
            d.observe(ServiceKind::Altimeter, 9, t, t, ms(t0, t));
        }
        // Only the altimeter stalls.
        let mut missed = Vec::new();
        for t in 11..=200 {
            if d.observe(FUSION, 7, t, t, ms(t0, t)) {
                missed.push((FUSION, t));
            }
            if d.observe(ServiceKind::Altimeter, 9, t, 10, ms(t0, t)) {
                missed.push((ServiceKind::Altimeter, t));
            }
        }
        assert_eq!(missed, vec![(ServiceKind::Altimeter, 111)]);
    }
}
