//! SYS_STATUS `load`: the CPU the pipeline used over the last interval, in ‰ of the CPU it may
//! use.
//!
//! The pipeline is this process and its siblings: the processes with the same parent and the same
//! command name (what `rins up` started, or the rins services a service manager started). Their
//! CPU time is the sum of `utime` and `stime` of `/proc/<pid>/stat`, in clock ticks
//! (`sysconf(_SC_CLK_TCK)`). The load is that time's growth over the interval as a share of the
//! interval times the processors this process may run on (its affinity and the cgroup's quota:
//! [`std::thread::available_parallelism`]), ×1000, at most 1000. A share of all usable processors
//! rather than of one: the pipeline is several processes, and it is short of CPU only when it
//! uses all there is, which is what MAVLink's "should always be below 1000" asks a ground station
//! to warn about. CPU of a sibling that ended during the interval is not seen.
//!
//! The arithmetic is pure ([`parse_stat`], [`ticks_grown`], [`load_permille`]); the [`Sampler`]
//! reads `/proc` on its own thread, once per SYS_STATUS period at most, never in the navigation
//! loop, which only reads the latest figure ([`LoadGauge`]). When `/proc` cannot be read, the load
//! is 0 (not measured), each such sample is counted and the first one logged with its reason.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU16, AtomicU64, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The shortest interval the load is measured over: a share measured in 10 ms clock ticks over
/// less would jump by whole ticks.
const SHORTEST_INTERVAL: Duration = Duration::from_millis(250);

/// What one `/proc/<pid>/stat` line says about its process, as far as the load needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProcStat<'a> {
    /// The command name, between the parentheses.
    pub comm: &'a str,
    /// The parent's process id.
    pub ppid: u32,
    /// CPU time in user and kernel mode, clock ticks.
    pub cpu_ticks: u64,
}

/// Parses a `/proc/<pid>/stat` line: `pid (comm) state ppid ...`, utime and stime the 14th and
/// 15th fields. The command name may hold spaces and parentheses: it ends at the last `)`.
pub fn parse_stat(text: &str) -> Option<ProcStat<'_>> {
    let open = text.find('(')?;
    let close = text.rfind(')')?;
    let comm = text.get(open + 1..close)?;
    // Fields from the 3rd (state) on.
    let mut fields = text.get(close + 1..)?.split_ascii_whitespace();
    let ppid = fields.nth(1)?.parse().ok()?;
    // utime is the 14th field: 10 after ppid (the 4th).
    let utime: u64 = fields.nth(9)?.parse().ok()?;
    let stime: u64 = fields.next()?.parse().ok()?;
    Some(ProcStat {
        comm,
        ppid,
        cpu_ticks: utime.saturating_add(stime),
    })
}

/// The CPU ticks the processes of `now` used since `before` (both `(pid, ticks)`, sorted by
/// pid): a process in both adds its growth, a new one all its time (it started within the
/// interval, or was not seen before); a pid reused by a younger process adds nothing for the
/// interval it was replaced in.
pub fn ticks_grown(before: &[(u32, u64)], now: &[(u32, u64)]) -> u64 {
    now.iter()
        .map(
            |&(pid, ticks)| match before.binary_search_by_key(&pid, |&(p, _)| p) {
                Ok(i) => ticks.saturating_sub(before[i].1),
                Err(_) => ticks,
            },
        )
        .fold(0u64, u64::saturating_add)
}

/// `ticks` of CPU time (at `ticks_per_s`) over `interval` on `cpus` processors, in ‰ of all of
/// them, rounded, at most 1000; 0 when any of them is 0.
pub fn load_permille(ticks: u64, ticks_per_s: u64, interval: Duration, cpus: usize) -> u16 {
    let available_s = interval.as_secs_f64() * cpus as f64;
    if ticks_per_s == 0 || available_s <= 0.0 {
        return 0;
    }
    let used_s = ticks as f64 / ticks_per_s as f64;
    (used_s / available_s * 1000.0).round().clamp(0.0, 1000.0) as u16
}

/// The latest load, for the navigation loop to read, and how often it could not be measured.
#[derive(Debug, Default)]
pub struct LoadGauge {
    permille: AtomicU16,
    /// Samples in which `/proc` could not be read (the load then reads 0).
    pub unreadable: AtomicU64,
    /// Samples taken.
    pub samples: AtomicU64,
}

impl LoadGauge {
    /// The pipeline's load over the last interval, ‰ (0: not measured, or not yet).
    pub fn permille(&self) -> u16 {
        self.permille.load(Ordering::Relaxed)
    }
}

/// Reads the pipeline's CPU time from `/proc` and turns it into the load.
pub struct Sampler {
    proc_root: std::path::PathBuf,
    ticks_per_s: u64,
    cpus: usize,
    /// This process's command name: the siblings that are the pipeline share it.
    comm: String,
    previous: Vec<(u32, u64)>,
    current: Vec<(u32, u64)>,
    previous_at: Option<Instant>,
    text: String,
}

impl Sampler {
    /// A sampler of the processes under `proc_root` (`/proc`); the error says what could not be
    /// read.
    pub fn new(proc_root: impl Into<std::path::PathBuf>) -> Result<Self, String> {
        let proc_root = proc_root.into();
        // SAFETY: sysconf only reads a system constant.
        let ticks = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
        let ticks_per_s =
            u64::try_from(ticks).map_err(|_| format!("sysconf(_SC_CLK_TCK) gave {ticks}"))?;
        let own = proc_root.join(std::process::id().to_string()).join("stat");
        let text = std::fs::read_to_string(&own)
            .map_err(|e| format!("cannot read {}: {e}", own.display()))?;
        let comm = parse_stat(&text)
            .ok_or_else(|| format!("{}: not a process status line", own.display()))?
            .comm
            .to_string();
        Ok(Self {
            proc_root,
            ticks_per_s,
            cpus: std::thread::available_parallelism().map_or(1, usize::from),
            comm,
            previous: Vec::new(),
            current: Vec::new(),
            previous_at: None,
            text,
        })
    }

    /// The siblings' `(pid, ticks)` now, sorted by pid, into `self.current`.
    fn read_siblings(&mut self) -> Result<(), String> {
        // SAFETY: getppid has no preconditions. Read each time: a parent that ended makes this
        // process another's child.
        let parent = u32::try_from(unsafe { libc::getppid() }).unwrap_or(0);
        self.current.clear();
        let dir = std::fs::read_dir(&self.proc_root)
            .map_err(|e| format!("cannot list {}: {e}", self.proc_root.display()))?;
        for entry in dir.flatten() {
            let Some(pid) = entry
                .file_name()
                .to_str()
                .and_then(|n| n.parse::<u32>().ok())
            else {
                continue;
            };
            self.text.clear();
            // A process that ended since the listing has no status any more: it is skipped.
            let Ok(mut file) = std::fs::File::open(entry.path().join("stat")) else {
                continue;
            };
            if std::io::Read::read_to_string(&mut file, &mut self.text).is_err() {
                continue;
            }
            if let Some(stat) = parse_stat(&self.text)
                && stat.ppid == parent
                && stat.comm == self.comm
            {
                self.current.push((pid, stat.cpu_ticks));
            }
        }
        self.current.sort_unstable_by_key(|&(pid, _)| pid);
        if self.current.is_empty() {
            return Err(format!(
                "no process {:?} of parent {parent} in {} (not even this one)",
                self.comm,
                self.proc_root.display()
            ));
        }
        Ok(())
    }

    /// Reads the siblings at `now`; the load since the previous sample (`None` for the first).
    pub fn sample(&mut self, now: Instant) -> Result<Option<u16>, String> {
        let read = self.read_siblings();
        if read.is_err() {
            // The next readable sample starts a new interval.
            self.previous_at = None;
        }
        read?;
        let load = self.previous_at.map(|at| {
            let grown = ticks_grown(&self.previous, &self.current);
            load_permille(grown, self.ticks_per_s, now - at, self.cpus)
        });
        std::mem::swap(&mut self.previous, &mut self.current);
        self.previous_at = Some(now);
        Ok(load)
    }
}

/// Starts the thread that measures the load every `1 / sys_status_hz` (at least
/// [`SHORTEST_INTERVAL`]) into the gauge it returns, until `stop` is set; no thread when the rate
/// is 0 (SYS_STATUS off), and none, the load reading 0, when `/proc` cannot be read at all.
pub fn start(
    sys_status_hz: f64,
    stop: Arc<AtomicBool>,
) -> (Arc<LoadGauge>, Option<JoinHandle<()>>) {
    let gauge = Arc::new(LoadGauge::default());
    if !(sys_status_hz > 0.0 && sys_status_hz.is_finite()) {
        return (gauge, None);
    }
    let interval = Duration::from_secs_f64(1.0 / sys_status_hz).max(SHORTEST_INTERVAL);
    let mut sampler = match Sampler::new("/proc") {
        Ok(s) => s,
        Err(why) => {
            gauge.unreadable.fetch_add(1, Ordering::Relaxed);
            tracing::warn!("SYS_STATUS load not measured (reads 0): {why}");
            return (gauge, None);
        }
    };
    let shared = Arc::clone(&gauge);
    let thread = std::thread::Builder::new()
        .name("mavlink-load".into())
        .spawn(move || {
            let mut logged = false;
            while !stop.load(Ordering::Relaxed) {
                shared.samples.fetch_add(1, Ordering::Relaxed);
                match sampler.sample(Instant::now()) {
                    Ok(Some(load)) => shared.permille.store(load, Ordering::Relaxed),
                    Ok(None) => {}
                    Err(why) => {
                        shared.permille.store(0, Ordering::Relaxed);
                        shared.unreadable.fetch_add(1, Ordering::Relaxed);
                        if !logged {
                            logged = true;
                            tracing::warn!(
                                "SYS_STATUS load not measured (reads 0): {why} (further \
                                 failures are only counted)"
                            );
                        }
                    }
                }
                let mut left = interval;
                while !left.is_zero() && !stop.load(Ordering::Relaxed) {
                    let step = left.min(Duration::from_millis(100));
                    std::thread::sleep(step);
                    left -= step;
                }
            }
        })
        .ok();
    if thread.is_none() {
        gauge.unreadable.fetch_add(1, Ordering::Relaxed);
        tracing::warn!("SYS_STATUS load not measured (reads 0): cannot start its thread");
    }
    (gauge, thread)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stat line as the kernel writes it, with `comm`, `ppid`, `utime`, `stime`.
    fn stat_line(pid: u32, comm: &str, ppid: u32, utime: u64, stime: u64) -> String {
        format!(
            "{pid} ({comm}) S {ppid} {pid} {pid} 0 -1 4194560 1261 0 0 0 {utime} {stime} 0 0 20 \
             0 4 0 123456 12345678 2048 18446744073709551615 1 1 0 0 0 0 0 4096 0 0 0 0 17 1 0 \
             0 0 0 0"
        )
    }

    #[test]
    fn parses_the_fields_even_behind_a_command_name_with_spaces_and_parentheses() {
        let line = stat_line(4242, "rins", 4200, 1234, 56);
        assert_eq!(
            parse_stat(&line),
            Some(ProcStat {
                comm: "rins",
                ppid: 4200,
                cpu_ticks: 1290
            })
        );
        let odd = stat_line(7, "a) (b c", 1, 10, 5);
        assert_eq!(
            parse_stat(&odd),
            Some(ProcStat {
                comm: "a) (b c",
                ppid: 1,
                cpu_ticks: 15
            })
        );
        for bad in ["", "12 rins S 1", "12 (rins) S x 1", "12 (rins) S 1 2 3"] {
            assert_eq!(parse_stat(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn growth_counts_survivors_and_newcomers_never_a_shrink() {
        let before = [(10, 100), (11, 50), (12, 7)];
        // 10 grew by 30, 11 ended, 12 was replaced by a younger process with less time, 13 is
        // new (a restarted service).
        let now = [(10, 130), (12, 3), (13, 20)];
        // 30 from pid 10, nothing from the replaced 12, 20 from the new 13.
        assert_eq!(ticks_grown(&before, &now), 50);
        assert_eq!(ticks_grown(&[], &now), 153);
        assert_eq!(ticks_grown(&before, &[]), 0);
    }

    #[test]
    fn load_is_the_share_of_every_usable_processor_in_permille() {
        let half_s = Duration::from_millis(500);
        // 0.25 s of CPU (25 ticks at 100 Hz) in 0.5 s on 2 processors: a quarter, 250 ‰.
        assert_eq!(load_permille(25, 100, half_s, 2), 250);
        // On one processor the same is half of it.
        assert_eq!(load_permille(25, 100, half_s, 1), 500);
        // More than there is (ticks rounded up at both ends) reads full, never beyond.
        assert_eq!(load_permille(300, 100, half_s, 2), 1000);
        // One tick is the resolution: 10 ms in 500 ms on 2 processors, 10 ‰.
        assert_eq!(load_permille(1, 100, half_s, 2), 10);
        for (ticks, per_s, interval, cpus) in [
            (5, 0, half_s, 2),
            (5, 100, Duration::ZERO, 2),
            (5, 100, half_s, 0),
        ] {
            assert_eq!(load_permille(ticks, per_s, interval, cpus), 0);
        }
    }

    /// A fabricated `/proc` with this process's siblings and strangers.
    struct FakeProc(std::path::PathBuf);

    impl FakeProc {
        fn new(tag: &str) -> Self {
            let dir = std::env::temp_dir().join(format!("rins-proc-{tag}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            Self(dir)
        }

        fn set(&self, pid: u32, comm: &str, ppid: u32, utime: u64, stime: u64) {
            let d = self.0.join(pid.to_string());
            std::fs::create_dir_all(&d).unwrap();
            std::fs::write(d.join("stat"), stat_line(pid, comm, ppid, utime, stime)).unwrap();
        }
    }

    impl Drop for FakeProc {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    #[test]
    fn the_sampler_sums_only_this_process_and_its_siblings() {
        let proc = FakeProc::new("siblings");
        let me = std::process::id();
        // SAFETY: getppid has no preconditions.
        let parent = u32::try_from(unsafe { libc::getppid() }).unwrap();
        let comm = "rins-svc";
        proc.set(me, comm, parent, 100, 0);
        proc.set(me + 1, comm, parent, 40, 10);
        // Strangers: another parent, another program with the same parent.
        proc.set(me + 2, comm, parent + 1, 0, 0);
        proc.set(me + 3, "bash", parent, 0, 0);
        std::fs::create_dir_all(proc.0.join("self")).unwrap();
        let mut sampler = Sampler::new(&proc.0).unwrap();
        assert_eq!(sampler.comm, comm);
        let t0 = Instant::now();
        assert_eq!(sampler.sample(t0), Ok(None));
        // Siblings use 50 + 25 ticks; the strangers 1000 each, unseen.
        proc.set(me, comm, parent, 150, 0);
        proc.set(me + 1, comm, parent, 60, 15);
        proc.set(me + 2, comm, parent + 1, 1000, 0);
        proc.set(me + 3, "bash", parent, 1000, 0);
        let interval = Duration::from_secs(1);
        let expected = load_permille(75, sampler.ticks_per_s, interval, sampler.cpus);
        assert!(expected > 0);
        assert_eq!(sampler.sample(t0 + interval), Ok(Some(expected)));
    }

    #[test]
    fn an_unreadable_proc_is_an_error_that_names_it() {
        let missing = std::env::temp_dir().join("rins-no-such-proc");
        let err = Sampler::new(&missing).err().unwrap();
        assert!(err.contains("rins-no-such-proc"), "{err}");
        // Readable at first, gone later: an error, and the next interval starts afresh.
        let proc = FakeProc::new("vanishing");
        // SAFETY: getppid has no preconditions.
        let parent = u32::try_from(unsafe { libc::getppid() }).unwrap();
        proc.set(std::process::id(), "rins", parent, 1, 1);
        let mut sampler = Sampler::new(&proc.0).unwrap();
        assert_eq!(sampler.sample(Instant::now()), Ok(None));
        std::fs::remove_dir_all(&proc.0).unwrap();
        assert!(sampler.sample(Instant::now()).is_err());
        assert_eq!(sampler.previous_at, None);
    }
}
