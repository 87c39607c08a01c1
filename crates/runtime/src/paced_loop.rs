//! The loop of a process that a clock drives rather than an input (the simulator): tick `k` is due
//! at `start + k·period` on CLOCK_MONOTONIC. The loop sleeps until a tick is due, lets the source
//! take in what arrived between ticks (commands), runs the tick, keeps the counters, sends the
//! heartbeat and stops when asked or after the configured number of ticks.
//!
//! A tick that comes late is never skipped: a sample source's time counts in ticks, so each one
//! runs, in a burst until the loop is back on schedule. A tick that runs a whole period or more
//! behind its time (the next one was already due) is counted in [`Health::late`]. The schedule
//! is fixed to the start: a late wake-up does not shift the ticks after it.
//!
//! Per tick the loop adds no allocation, no log and no lock: clock reads, a sleep, the source's
//! hooks and the heartbeat check.

use ipc_types::{Health, ServiceKind};

use crate::clock::{monotonic_ns, sleep_until};
use crate::ipc::{IpcError, IpcNode};
use crate::service_loop::ServiceLoop;
use crate::shutdown::Shutdown;

/// What a clock-paced process does, called by [`PacedLoop::run`]. Only [`PacedSource::tick`] is
/// required.
pub trait PacedSource {
    /// When tick `tick` is due, before it runs: what must take effect from this tick on (commands
    /// received, scheduled events). Runs every tick; it may log what it applies (rare events),
    /// never on its idle path.
    fn between_ticks(&mut self, tick: u64, counters: &mut Health) -> Result<(), IpcError> {
        let _ = (tick, counters);
        Ok(())
    }

    /// Tick `tick` (0, 1, 2, … without gaps): make and send its sample. No allocation, no log, no
    /// lock.
    fn tick(&mut self, tick: u64, counters: &mut Health) -> Result<(), IpcError>;
}

/// What the loop does for the next tick at a given time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pace {
    /// Not due yet: sleep until this CLOCK_MONOTONIC time, ns.
    SleepUntil(u64),
    /// Due, less than a period behind its time.
    OnTime,
    /// A period or more behind its time (the next tick is due too): run it now, counted late.
    CatchUp,
}

/// When each tick is due. Pure: the caller reads the clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pacer {
    start_ns: u64,
    period_ns: u64,
    next: u64,
}

impl Pacer {
    /// Tick 0 is due at `start_ns`, each next one `period_ns` later (at least 1 ns).
    pub fn new(start_ns: u64, period_ns: u64) -> Self {
        Self {
            start_ns,
            period_ns: period_ns.max(1),
            next: 0,
        }
    }

    /// The tick that runs next (the number of ticks run so far).
    pub fn next_tick(&self) -> u64 {
        self.next
    }

    /// When the next tick is due, CLOCK_MONOTONIC ns.
    pub fn due_ns(&self) -> u64 {
        self.start_ns
            .saturating_add(self.next.saturating_mul(self.period_ns))
    }

    /// What to do for the next tick at `now_ns`.
    pub fn pace(&self, now_ns: u64) -> Pace {
        let due = self.due_ns();
        if now_ns < due {
            Pace::SleepUntil(due)
        } else if now_ns - due >= self.period_ns {
            Pace::CatchUp
        } else {
            Pace::OnTime
        }
    }

    /// The next tick ran.
    pub fn advance(&mut self) {
        self.next += 1;
    }
}

/// How a paced process runs: its period and how many ticks it runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pacing {
    /// The process: its heartbeat says so.
    pub kind: ServiceKind,
    /// Time between ticks, ns.
    pub period_ns: u64,
    /// Stop after this many ticks; `None`: run until a stop is requested.
    pub ticks: Option<u64>,
}

/// The schedule and the service loop of one clock-paced process.
pub struct PacedLoop {
    service: ServiceLoop,
    pacing: Pacing,
}

impl PacedLoop {
    /// The loop of the process `pacing` describes on `node`; it ends when `shutdown` is requested.
    pub fn new(node: &IpcNode, pacing: Pacing, shutdown: &Shutdown) -> Result<Self, IpcError> {
        Ok(Self {
            service: ServiceLoop::new(node, pacing.kind, shutdown)?,
            pacing,
        })
    }

    /// Runs `source` from now until a stop is requested or the ticks are done; returns the final
    /// counters.
    pub fn run<S: PacedSource>(mut self, source: &mut S) -> Result<Health, IpcError> {
        precise_sleeps();
        let mut pacer = Pacer::new(monotonic_ns(), self.pacing.period_ns);
        let ticks = self.pacing.ticks;
        while self.service.running() && ticks.is_none_or(|n| pacer.next_tick() < n) {
            match pacer.pace(monotonic_ns()) {
                Pace::SleepUntil(due) => {
                    // A signal may end the sleep early: look at the stop flag and the clock again.
                    sleep_until(due);
                    continue;
                }
                Pace::OnTime => {}
                Pace::CatchUp => self.service.counters.late += 1,
            }
            let tick = pacer.next_tick();
            source.between_ticks(tick, &mut self.service.counters)?;
            source.tick(tick, &mut self.service.counters)?;
            pacer.advance();
            self.service.beat()?;
        }
        Ok(self.service.counters)
    }
}

/// Sleeps of this process end within a microsecond of their deadline: the default 50 µs timer
/// slack would show up as jitter of the ticks.
fn precise_sleeps() {
    // SAFETY: prctl on our own process with a plain integer argument; a refusal leaves the
    // default slack, which only widens the jitter.
    unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong) };
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    /// The loop's decisions for wake-ups at `wakes` (ns after the start), with the ticks run.
    fn run(pacer: &mut Pacer, wakes: &[u64]) -> Vec<(Pace, u64)> {
        wakes
            .iter()
            .map(|&now| {
                let pace = pacer.pace(now);
                let tick = pacer.next_tick();
                if !matches!(pace, Pace::SleepUntil(_)) {
                    pacer.advance();
                }
                (pace, tick)
            })
            .collect()
    }

    #[test]
    fn ticks_are_due_a_period_apart_from_the_start() {
        let mut p = Pacer::new(5 * MS, MS);
        assert_eq!(p.pace(0), Pace::SleepUntil(5 * MS));
        assert_eq!(p.pace(5 * MS), Pace::OnTime);
        p.advance();
        assert_eq!((p.next_tick(), p.due_ns()), (1, 6 * MS));
        // Woken just before its time (a signal): sleep again, to the same deadline.
        assert_eq!(p.pace(6 * MS - 1), Pace::SleepUntil(6 * MS));
        // Up to a period late is on time.
        assert_eq!(p.pace(7 * MS - 1), Pace::OnTime);
        assert_eq!(p.pace(7 * MS), Pace::CatchUp);
    }

    #[test]
    fn a_stall_is_caught_up_tick_by_tick_without_shifting_the_schedule() {
        let mut p = Pacer::new(0, MS);
        // Ticks 0 and 1 on time; then the process stalls until 4.5 ms: ticks 2 and 3 are a
        // period or more behind, tick 4 is half a period late, tick 5 is waited for again.
        let wakes = [
            0,
            MS,
            4 * MS + MS / 2,
            4 * MS + MS / 2,
            4 * MS + MS / 2,
            4 * MS + MS / 2,
        ];
        let decided = run(&mut p, &wakes);
        assert_eq!(
            decided,
            [
                (Pace::OnTime, 0),
                (Pace::OnTime, 1),
                (Pace::CatchUp, 2),
                (Pace::CatchUp, 3),
                (Pace::OnTime, 4),
                (Pace::SleepUntil(5 * MS), 5),
            ]
        );
        // Every tick ran once, none skipped, and the next is still due on the start's grid.
        assert_eq!((p.next_tick(), p.due_ns()), (5, 5 * MS));
    }

    #[test]
    fn a_zero_period_and_huge_tick_counts_do_not_overflow() {
        let mut p = Pacer::new(u64::MAX - 10, 0);
        assert_eq!(p.pace(u64::MAX - 10), Pace::OnTime);
        p.next = u64::MAX / 2;
        assert_eq!(p.due_ns(), u64::MAX);
        assert_eq!(p.pace(0), Pace::SleepUntil(u64::MAX));
    }
}
