//! CPU time, peak memory and wake-ups of every process of the deployment, read from `/proc` for
//! the run's summary: `utime + stime` of `/proc/PID/stat`, `VmHWM` of `/proc/PID/status` and the
//! context switches of each of its threads (`/proc/PID/task/TID/status`), sampled about
//! once a second while the children run and once more just before they are stopped. A child that
//! was restarted counts every incarnation, each up to its last sample (at most a second of CPU
//! of an incarnation that died is not seen).

use std::time::{Duration, Instant};

use serde::Serialize;

/// How often the children are sampled.
pub const SAMPLE_PERIOD: Duration = Duration::from_secs(1);

/// One process's figures over the run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProcessUsage {
    /// The service (`watchdog` for `rins up` itself).
    pub name: String,
    /// User + system CPU time over every incarnation, s.
    pub cpu_s: f64,
    /// `cpu_s` as a percentage of one core over the run's duration.
    pub cpu_pct: f64,
    /// Largest resident set of any incarnation (`VmHWM`), KiB.
    pub peak_rss_kib: u64,
    /// Processes counted (1 + restarts seen).
    pub incarnations: u32,
    /// Times a thread of the process gave up the CPU to wait (`voluntary_ctxt_switches`, every
    /// thread, every incarnation): one per sleep, so one per wake-up.
    pub wakeups: u64,
    /// Times a thread was taken off the CPU while it could still run
    /// (`nonvoluntary_ctxt_switches`): preemptions.
    pub preemptions: u64,
}

/// Context switches of one thread or a sum over threads.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ContextSwitches {
    /// `voluntary_ctxt_switches`.
    pub voluntary: u64,
    /// `nonvoluntary_ctxt_switches`.
    pub involuntary: u64,
}

impl ContextSwitches {
    fn max(self, o: Self) -> Self {
        Self {
            voluntary: self.voluntary.max(o.voluntary),
            involuntary: self.involuntary.max(o.involuntary),
        }
    }
}

/// The context switches in the text of `/proc/PID/task/TID/status`.
pub fn context_switches(status: &str) -> Option<ContextSwitches> {
    let field = |key: &str| -> Option<u64> {
        let line = status.lines().find(|l| l.starts_with(key))?;
        line[key.len()..].trim().parse().ok()
    };
    Some(ContextSwitches {
        voluntary: field("voluntary_ctxt_switches:")?,
        involuntary: field("nonvoluntary_ctxt_switches:")?,
    })
}

/// The context switches of every thread of process `pid` (threads that ended are not counted).
fn process_switches(pid: u32) -> Option<ContextSwitches> {
    let mut total = ContextSwitches::default();
    for task in std::fs::read_dir(format!("/proc/{pid}/task"))
        .ok()?
        .flatten()
    {
        let Ok(text) = std::fs::read_to_string(task.path().join("status")) else {
            continue;
        };
        if let Some(c) = context_switches(&text) {
            total.voluntary += c.voluntary;
            total.involuntary += c.involuntary;
        }
    }
    Some(total)
}

/// `utime + stime` in clock ticks from the text of `/proc/PID/stat`. The command name (field 2)
/// is in parentheses and may itself hold spaces or parentheses: fields are counted after the
/// last `)`.
pub fn cpu_ticks(stat: &str) -> Option<u64> {
    let rest = &stat[stat.rfind(')')? + 1..];
    let mut fields = rest.split_ascii_whitespace();
    // After the name: state (3), ppid (4), …, utime (14), stime (15).
    let utime: u64 = fields.nth(11)?.parse().ok()?;
    let stime: u64 = fields.next()?.parse().ok()?;
    Some(utime + stime)
}

/// `VmHWM` in KiB from the text of `/proc/PID/status`.
pub fn peak_rss_kib(status: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let mut parts = line["VmHWM:".len()..].split_ascii_whitespace();
    let value: u64 = parts.next()?.parse().ok()?;
    match parts.next() {
        Some("kB") | None => Some(value),
        Some(_) => None,
    }
}

/// Clock ticks per second of `/proc/PID/stat`.
pub fn ticks_per_second() -> f64 {
    // SAFETY: sysconf reads a constant of the system; no memory is passed.
    let t = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
    if t > 0 { t as f64 } else { 100.0 }
}

/// The last sample of one process.
#[derive(Debug, Clone, PartialEq)]
struct Seen {
    name: String,
    pid: u32,
    ticks: u64,
    peak_rss_kib: u64,
    switches: ContextSwitches,
}

/// The samples of every process seen.
#[derive(Debug, Default)]
pub struct UsageTracker {
    seen: Vec<Seen>,
    last: Option<Instant>,
}

impl UsageTracker {
    /// An empty tracker.
    pub fn new() -> Self {
        Self::default()
    }

    /// Samples `processes` (name, pid) when [`SAMPLE_PERIOD`] has passed since the last sample.
    pub fn sample_if_due<'a>(
        &mut self,
        now: Instant,
        processes: impl Iterator<Item = (&'a str, u32)>,
    ) {
        if self
            .last
            .is_none_or(|t| now.duration_since(t) >= SAMPLE_PERIOD)
        {
            self.sample(processes);
            self.last = Some(now);
        }
    }

    /// Samples `processes` now. A process whose files cannot be read (it just exited) keeps its
    /// previous sample.
    pub fn sample<'a>(&mut self, processes: impl Iterator<Item = (&'a str, u32)>) {
        for (name, pid) in processes {
            let stat = std::fs::read_to_string(format!("/proc/{pid}/stat"));
            let status = std::fs::read_to_string(format!("/proc/{pid}/status"));
            let (Some(ticks), Some(rss)) = (
                stat.ok().as_deref().and_then(cpu_ticks),
                status.ok().as_deref().and_then(peak_rss_kib),
            ) else {
                continue;
            };
            let switches = process_switches(pid).unwrap_or_default();
            self.record(name, pid, ticks, rss, switches);
        }
    }

    /// Records one reading of a process.
    pub fn record(
        &mut self,
        name: &str,
        pid: u32,
        ticks: u64,
        peak_rss_kib: u64,
        switches: ContextSwitches,
    ) {
        match self
            .seen
            .iter_mut()
            .find(|s| s.pid == pid && s.name == name)
        {
            Some(s) => {
                s.ticks = s.ticks.max(ticks);
                s.peak_rss_kib = s.peak_rss_kib.max(peak_rss_kib);
                s.switches = s.switches.max(switches);
            }
            None => self.seen.push(Seen {
                name: name.to_string(),
                pid,
                ticks,
                peak_rss_kib,
                switches,
            }),
        }
    }

    /// Per name, in the order first seen: CPU over every incarnation, the largest peak.
    pub fn totals(&self, ticks_per_s: f64, elapsed: Duration) -> Vec<ProcessUsage> {
        let mut out: Vec<ProcessUsage> = Vec::new();
        for s in &self.seen {
            let cpu = s.ticks as f64 / ticks_per_s;
            match out.iter_mut().find(|u| u.name == s.name) {
                Some(u) => {
                    u.cpu_s += cpu;
                    u.peak_rss_kib = u.peak_rss_kib.max(s.peak_rss_kib);
                    u.incarnations += 1;
                    u.wakeups += s.switches.voluntary;
                    u.preemptions += s.switches.involuntary;
                }
                None => out.push(ProcessUsage {
                    name: s.name.clone(),
                    cpu_s: cpu,
                    cpu_pct: 0.0,
                    peak_rss_kib: s.peak_rss_kib,
                    incarnations: 1,
                    wakeups: s.switches.voluntary,
                    preemptions: s.switches.involuntary,
                }),
            }
        }
        let seconds = elapsed.as_secs_f64();
        for u in &mut out {
            u.cpu_pct = if seconds > 0.0 {
                100.0 * u.cpu_s / seconds
            } else {
                0.0
            };
        }
        out
    }
}

/// Wake-ups of every process but the simulator's per IMU frame acquisition published: how many
/// times the pipeline's processes are woken to carry one sample (0 without frames).
pub fn pipeline_wakeups_per_frame(usage: &[ProcessUsage], frames: u64) -> f64 {
    if frames == 0 {
        return 0.0;
    }
    let wakeups: u64 = usage
        .iter()
        .filter(|u| u.name != "sim")
        .map(|u| u.wakeups)
        .sum();
    wakeups as f64 / frames as f64
}

/// The sum of `cpu_pct` over every process but the simulator's (`sim`): what the pipeline costs
/// on the avionics computer, where the device is real.
pub fn pipeline_cpu_pct(usage: &[ProcessUsage]) -> f64 {
    usage
        .iter()
        .filter(|u| u.name != "sim")
        .map(|u| u.cpu_pct)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stat_and_status_are_read_past_an_awkward_name() {
        // A name with a space and a parenthesis; utime 1234, stime 56.
        let stat = "4242 (rins (x) y) S 1 4242 4242 0 -1 4194560 100 0 0 0 1234 56 0 0 20 0 3 0 99 1000 200";
        assert_eq!(cpu_ticks(stat), Some(1290));
        assert_eq!(cpu_ticks("garbage"), None);
        assert_eq!(cpu_ticks("1 (a) S 1 2"), None);
        let status = "Name:\trins\nVmPeak:\t  9000 kB\nVmHWM:\t    5120 kB\nVmRSS:\t 4000 kB\n";
        assert_eq!(peak_rss_kib(status), Some(5120));
        assert_eq!(peak_rss_kib("Name:\tx\n"), None);
        assert_eq!(peak_rss_kib("VmHWM:\t12 MB\n"), None);
    }

    #[test]
    fn incarnations_add_up_and_the_simulator_is_left_out_of_the_pipeline() {
        let cs = |voluntary, involuntary| ContextSwitches {
            voluntary,
            involuntary,
        };
        let mut t = UsageTracker::new();
        t.record("fusion", 10, 100, 4000, cs(1000, 5));
        t.record("fusion", 10, 250, 4100, cs(2500, 9));
        // Restarted under a new pid.
        t.record("fusion", 11, 50, 3900, cs(500, 1));
        t.record("sim", 12, 1000, 8000, cs(9000, 0));
        let u = t.totals(100.0, Duration::from_secs(10));
        assert_eq!(u.len(), 2);
        assert_eq!(u[0].name, "fusion");
        assert!((u[0].cpu_s - 3.0).abs() < 1e-12);
        assert!((u[0].cpu_pct - 30.0).abs() < 1e-9);
        assert_eq!((u[0].peak_rss_kib, u[0].incarnations), (4100, 2));
        assert!((pipeline_cpu_pct(&u) - 30.0).abs() < 1e-9);
        assert_eq!((u[0].wakeups, u[0].preemptions), (3000, 10));
        assert!((pipeline_wakeups_per_frame(&u, 1000) - 3.0).abs() < 1e-12);
        assert_eq!(pipeline_wakeups_per_frame(&u, 0), 0.0);
    }

    #[test]
    fn context_switches_are_read_from_a_task_status() {
        let status =
            "Name:\trins\nvoluntary_ctxt_switches:\t1234\nnonvoluntary_ctxt_switches:\t56\n";
        assert_eq!(
            context_switches(status),
            Some(ContextSwitches {
                voluntary: 1234,
                involuntary: 56
            })
        );
        assert_eq!(context_switches("Name:\tx\n"), None);
    }

    #[test]
    fn this_process_can_be_read() {
        let mut t = UsageTracker::new();
        t.sample(std::iter::once(("self", std::process::id())));
        let u = t.totals(ticks_per_second(), Duration::from_secs(1));
        assert_eq!(u.len(), 1);
        assert!(u[0].peak_rss_kib > 0, "{u:?}");
        // Every thread's counters are there to read.
        assert!(process_switches(std::process::id()).is_some());
    }
}
