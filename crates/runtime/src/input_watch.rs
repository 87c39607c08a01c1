//! Notices when a process's input goes quiet and when it comes back, so the process can say so
//! (log and heartbeat) instead of silently waiting.

use std::time::Duration;

/// What a call to [`InputWatch::input`] or [`InputWatch::idle`] changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputChange {
    /// Nothing new.
    None,
    /// No input for longer than the deadline: the input just became stale.
    WentStale,
    /// Input again after a stale period of this length.
    CameBack(Duration),
}

/// Deadline check on one input stream, on the caller's clock (ns). Allocation-free.
#[derive(Debug, Clone)]
pub struct InputWatch {
    deadline_ns: u64,
    last_input_ns: Option<u64>,
    stale: bool,
    /// Stale periods so far.
    pub episodes: u64,
}

impl InputWatch {
    /// A watch that calls the input stale after `deadline` without a sample.
    pub fn new(deadline: Duration) -> Self {
        Self {
            deadline_ns: u64::try_from(deadline.as_nanos()).unwrap_or(u64::MAX),
            last_input_ns: None,
            stale: false,
            episodes: 0,
        }
    }

    /// True while the input is stale.
    pub fn is_stale(&self) -> bool {
        self.stale
    }

    /// An input sample arrived at `now_ns`.
    pub fn input(&mut self, now_ns: u64) -> InputChange {
        let previous = self.last_input_ns.replace(now_ns);
        if !self.stale {
            return InputChange::None;
        }
        self.stale = false;
        InputChange::CameBack(Duration::from_nanos(
            now_ns.saturating_sub(previous.unwrap_or(now_ns)),
        ))
    }

    /// No input this time round; checks the deadline at `now_ns`. Before the first input the
    /// input is not stale: the source may still be starting.
    pub fn idle(&mut self, now_ns: u64) -> InputChange {
        match self.last_input_ns {
            Some(last) if !self.stale && now_ns.saturating_sub(last) > self.deadline_ns => {
                self.stale = true;
                self.episodes += 1;
                InputChange::WentStale
            }
            _ => InputChange::None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    #[test]
    fn goes_stale_once_after_the_deadline_and_reports_the_gap_when_back() {
        let mut w = InputWatch::new(Duration::from_millis(50));
        // Nothing before the first input.
        assert_eq!(w.idle(1000 * MS), InputChange::None);
        assert_eq!(w.input(0), InputChange::None);
        assert_eq!(w.idle(50 * MS), InputChange::None);
        assert_eq!(w.idle(51 * MS), InputChange::WentStale);
        assert!(w.is_stale());
        assert_eq!(w.idle(500 * MS), InputChange::None);
        assert_eq!(
            w.input(700 * MS),
            InputChange::CameBack(Duration::from_millis(700))
        );
        assert!(!w.is_stale());
        assert_eq!(w.input(701 * MS), InputChange::None);
        assert_eq!(w.episodes, 1);
    }
}
