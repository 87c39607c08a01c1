//! `rins up --profile`: how the deployment uses the machine's CPUs, on top of `[wait]` and
//! `[realtime]`.
//!
//! - `shared` (the default): `[wait]` and `[realtime]` as configured.
//! - `dedicated`: acquisition, fusion and the primary navigator lane each own a CPU, at SCHED_FIFO;
//!   fusion and the navigator spin on theirs (nothing else runs there to be starved), acquisition
//!   blocks on its serial read. Every other process shares the remaining CPUs and waits on events,
//!   so that it never competes with the data path. Memory is locked as `--realtime` locks it.
//! - `auto`: `dedicated` when the machine has enough free CPUs for it, else `shared`.
//!
//! The choice is made once, by [`plan`], from what it is given (no system call), so that every
//! case can be tested; [`resolve`] reads the system and applies the plan to the configuration
//! before it is resolved for the children, so a restarted service gets the same settings.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

pub use crate::cli::RequestedProfile;
use crate::config::RinsConfig;
use crate::realtime_config::{RealtimeConfig, SERVICES};
use crate::wait_config::{STAGES, WaitKind};

/// The stages that own a CPU under `dedicated`, the first on the highest-numbered CPU.
pub const DEDICATED_STAGES: [&str; 3] = ["acquisition", "fusion", "navigator"];

/// The stages that spin on their CPU under `dedicated`: acquisition blocks on the serial read.
const SPINNING_STAGES: [&str; 2] = ["fusion", "navigator"];

/// Usable CPUs `dedicated` needs: one per dedicated stage, and one for everything else.
pub const DEDICATED_NEEDS: usize = DEDICATED_STAGES.len() + 1;

/// The load average file of Linux.
const LOADAVG: &str = "/proc/loadavg";

/// The profile a deployment runs with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// `[wait]` and `[realtime]` as configured.
    Shared,
    /// The data path on CPUs of its own.
    Dedicated,
}

impl Profile {
    /// The name as the summary and `rins status` print it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Shared => "shared",
            Self::Dedicated => "dedicated",
        }
    }
}

/// The 1-minute load average, or why it is unknown.
#[derive(Debug, Clone, PartialEq)]
pub enum Load {
    /// Runnable tasks averaged over the last minute.
    Average(f64),
    /// The file could not be read or parsed: the reason, for the profile's reason.
    Unknown(String),
}

/// Which CPU each dedicated stage owns, and the CPUs everything else shares.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CpuSplit {
    /// Acquisition's CPU.
    pub acquisition: usize,
    /// Fusion's CPU.
    pub fusion: usize,
    /// The primary navigator lane's CPU.
    pub navigator: usize,
    /// Every other process's CPUs (never empty), ascending.
    pub rest: Vec<usize>,
}

impl CpuSplit {
    /// The highest-numbered usable CPUs go to the data path and the rest keep CPU 0 (where the
    /// kernel's housekeeping usually runs) and the others: the same split on every start.
    /// `None` with fewer than [`DEDICATED_NEEDS`] CPUs.
    fn of(usable: &[usize]) -> Option<Self> {
        let n = usable.len();
        if n < DEDICATED_NEEDS {
            return None;
        }
        Some(Self {
            acquisition: usable[n - 1],
            fusion: usable[n - 2],
            navigator: usable[n - 3],
            rest: usable[..n - DEDICATED_STAGES.len()].to_vec(),
        })
    }

    /// The dedicated stages with their CPUs, in [`DEDICATED_STAGES`] order.
    pub fn dedicated(&self) -> [(&'static str, usize); 3] {
        [
            ("acquisition", self.acquisition),
            ("fusion", self.fusion),
            ("navigator", self.navigator),
        ]
    }

    /// "acquisition on CPU 15, fusion on 14, navigator on 13; the rest on 0-12".
    fn describe(&self) -> String {
        format!(
            "acquisition on CPU {}, fusion on {}, navigator on {}; the rest on {}",
            self.acquisition,
            self.fusion,
            self.navigator,
            cpu_list(&self.rest)
        )
    }
}

/// The `[wait]` and `[realtime]` settings a profile imposes, whatever the configuration says.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Overrides {
    /// `wait.services`: the strategy of every stage `[wait]` can name.
    pub wait: BTreeMap<&'static str, WaitKind>,
    /// `realtime.priority` of the dedicated stages (other services keep theirs).
    pub priority: BTreeMap<&'static str, u8>,
    /// `realtime.cpus` of every service `[realtime]` can name.
    pub cpus: BTreeMap<&'static str, Vec<usize>>,
    /// The CPUs of `rins up` itself: the simulator and the recorder it starts inherit them.
    pub watchdog_cpus: Vec<usize>,
}

impl Overrides {
    fn dedicated(split: &CpuSplit) -> Self {
        let wait = STAGES
            .iter()
            .map(|&stage| {
                let kind = if SPINNING_STAGES.contains(&stage) {
                    WaitKind::Spin
                } else {
                    WaitKind::Event
                };
                (stage, kind)
            })
            .collect();
        let defaults = RealtimeConfig::default().priority;
        let priority = DEDICATED_STAGES
            .iter()
            .filter_map(|&stage| defaults.get(stage).map(|p| (stage, *p)))
            .collect();
        let owners: BTreeMap<&str, usize> = split.dedicated().into_iter().collect();
        let cpus = SERVICES
            .iter()
            .map(|&service| {
                let cpus = owners
                    .get(service)
                    .map_or_else(|| split.rest.clone(), |cpu| vec![*cpu]);
                (service, cpus)
            })
            .collect();
        Self {
            wait,
            priority,
            cpus,
            watchdog_cpus: split.rest.clone(),
        }
    }

    /// Writes these settings over `cfg`'s `[wait]` and `[realtime]`, and turns real-time settings
    /// and memory locking on.
    pub fn apply(&self, cfg: &mut RinsConfig) {
        for (stage, kind) in &self.wait {
            cfg.wait.services.insert((*stage).to_string(), *kind);
        }
        cfg.realtime.enabled = true;
        cfg.realtime.lock_memory = true;
        for (service, priority) in &self.priority {
            cfg.realtime
                .priority
                .insert((*service).to_string(), *priority);
        }
        for (service, cpus) in &self.cpus {
            cfg.realtime
                .cpus
                .insert((*service).to_string(), cpus.clone());
        }
    }
}

/// The profile chosen, why, and what it changes.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// What runs.
    pub profile: Profile,
    /// Why, for a person: the CPUs counted and, under `dedicated`, which stage has which CPU.
    pub reason: String,
    /// The settings to write over the configuration (`None`: it runs as configured).
    pub overrides: Option<Overrides>,
}

impl Plan {
    fn shared(reason: String) -> Self {
        Self {
            profile: Profile::Shared,
            reason,
            overrides: None,
        }
    }

    fn dedicated(split: &CpuSplit, reason: String) -> Self {
        Self {
            profile: Profile::Dedicated,
            reason,
            overrides: Some(Overrides::dedicated(split)),
        }
    }
}

/// Chooses the profile for `requested` on a process that may use the CPUs `usable` (in any order)
/// on a machine under `load`. An error, naming the flag and the numbers, when `dedicated` is asked
/// for and there are too few CPUs for it.
pub fn plan(requested: RequestedProfile, usable: &[usize], load: &Load) -> Result<Plan, String> {
    let mut usable = usable.to_vec();
    usable.sort_unstable();
    usable.dedup();
    let n = usable.len();
    match requested {
        RequestedProfile::Shared => Ok(Plan::shared(
            "shared: [wait] and [realtime] as configured".to_string(),
        )),
        RequestedProfile::Dedicated => {
            let split = CpuSplit::of(&usable).ok_or_else(|| {
                format!(
                    "--profile dedicated needs {DEDICATED_NEEDS} usable CPUs ({} dedicated, 1 \
                     shared); this process may use {n}{}: run it with more CPUs in its affinity \
                     mask, or use --profile shared",
                    DEDICATED_STAGES.len(),
                    listed(&usable)
                )
            })?;
            let reason = format!("dedicated as asked: {} ({})", cpus(n), split.describe());
            Ok(Plan::dedicated(&split, reason))
        }
        RequestedProfile::Auto => {
            let (busy, note) = match load {
                Load::Average(l) if l.is_finite() && *l >= 0.0 => (l.ceil(), String::new()),
                Load::Average(l) => (0.0, format!(" (load average {l} unusable, taken as 0)")),
                Load::Unknown(why) => (0.0, format!(" (load unknown, taken as 0: {why})")),
            };
            // A load above the CPU count leaves none free; the cast saturates.
            let free = n.saturating_sub(busy as usize);
            let counted = format!("auto: {}, {free} free{note}", cpus(n));
            match CpuSplit::of(&usable).filter(|_| free >= DEDICATED_NEEDS) {
                Some(split) => {
                    let reason = format!("{counted}: dedicated ({})", split.describe());
                    Ok(Plan::dedicated(&split, reason))
                }
                None => Ok(Plan::shared(format!(
                    "{counted}; dedicated needs {DEDICATED_NEEDS}: shared"
                ))),
            }
        }
    }
}

/// "1 usable CPU", "16 usable CPUs".
fn cpus(n: usize) -> String {
    if n == 1 {
        "1 usable CPU".to_string()
    } else {
        format!("{n} usable CPUs")
    }
}

/// " (CPUs 0-1)", " (CPU 3)", or nothing for no CPU.
fn listed(usable: &[usize]) -> String {
    match usable.len() {
        0 => String::new(),
        1 => format!(" (CPU {})", cpu_list(usable)),
        _ => format!(" (CPUs {})", cpu_list(usable)),
    }
}

/// Ascending CPUs as ranges, as Linux lists them: "0-12", "0,2,4", "0-2,5".
pub fn cpu_list(cpus: &[usize]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut i = 0;
    while i < cpus.len() {
        let start = cpus[i];
        let mut end = start;
        while i + 1 < cpus.len() && cpus[i + 1] == end + 1 {
            i += 1;
            end = cpus[i];
        }
        parts.push(if end == start {
            start.to_string()
        } else {
            format!("{start}-{end}")
        });
        i += 1;
    }
    parts.join(",")
}

/// The first field of `/proc/loadavg` text.
pub fn parse_loadavg(text: &str) -> Load {
    match text.split_ascii_whitespace().next() {
        None => Load::Unknown(format!("{LOADAVG} is empty")),
        Some(first) => match first.parse::<f64>() {
            Ok(l) if l.is_finite() && l >= 0.0 => Load::Average(l),
            _ => Load::Unknown(format!(
                "{LOADAVG} starts with {first:?}, not a load average"
            )),
        },
    }
}

/// The machine's 1-minute load average.
pub fn read_load() -> Load {
    match std::fs::read_to_string(LOADAVG) {
        Ok(text) => parse_loadavg(&text),
        Err(e) => Load::Unknown(format!("cannot read {LOADAVG}: {e}")),
    }
}

/// The CPUs this thread may run on (its affinity mask, which `taskset` or a cgroup's cpuset
/// narrows), ascending.
pub fn usable_cpus() -> std::io::Result<Vec<usize>> {
    // SAFETY: an all-zero cpu_set_t is the empty set; sched_getaffinity writes at most `size_of`
    // bytes into it; CPU_ISSET reads inside it for an index below CPU_SETSIZE.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return Err(std::io::Error::last_os_error());
        }
        Ok((0..libc::CPU_SETSIZE as usize)
            .filter(|&cpu| libc::CPU_ISSET(cpu, &set))
            .collect())
    }
}

/// Chooses the profile for `requested` on this machine and writes its settings over `cfg`.
/// `shared` reads nothing of the system.
pub fn resolve(requested: RequestedProfile, cfg: &mut RinsConfig) -> Result<Plan, String> {
    let (usable, load) = match requested {
        RequestedProfile::Shared => (Vec::new(), Load::Average(0.0)),
        RequestedProfile::Dedicated => (affinity(requested)?, Load::Average(0.0)),
        RequestedProfile::Auto => (affinity(requested)?, read_load()),
    };
    let plan = plan(requested, &usable, &load)?;
    if let Some(overrides) = &plan.overrides {
        overrides.apply(cfg);
        cfg.validate()
            .map_err(|e| format!("--profile {}: {e}", requested.name()))?;
    }
    Ok(plan)
}

fn affinity(requested: RequestedProfile) -> Result<Vec<usize>, String> {
    usable_cpus().map_err(|e| {
        format!(
            "--profile {}: cannot read this process's CPU affinity: {e}",
            requested.name()
        )
    })
}

/// Confines this process (and what it starts from now on) to the CPUs the plan leaves to the rest
/// of the deployment; the system's refusal, when it refuses, for the caller to report. Nothing
/// under `shared`.
pub fn confine_this_process(plan: &Plan) -> Option<String> {
    let cpus = &plan.overrides.as_ref()?.watchdog_cpus;
    let refused = rins_runtime::realtime::apply(&rins_runtime::realtime::RealtimePlan {
        cpus: cpus.clone(),
        ..Default::default()
    });
    refused.first().map(|r| {
        format!(
            "--profile {}: cannot confine rins up to CPU {}: {}",
            plan.profile.name(),
            cpu_list(cpus),
            r.error
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn range(n: usize) -> Vec<usize> {
        (0..n).collect()
    }

    fn config() -> RinsConfig {
        crate::config::load(None).unwrap()
    }

    #[test]
    fn two_cpus_refuse_dedicated_naming_the_counts_and_auto_stays_shared() {
        let err = plan(RequestedProfile::Dedicated, &range(2), &Load::Average(0.0)).unwrap_err();
        assert!(
            err.starts_with(
                "--profile dedicated needs 4 usable CPUs (3 dedicated, 1 shared); this process \
                 may use 2 (CPUs 0-1)"
            ),
            "{err}"
        );
        let p = plan(RequestedProfile::Auto, &range(2), &Load::Average(0.0)).unwrap();
        assert_eq!(p.profile, Profile::Shared);
        assert_eq!(
            p.reason,
            "auto: 2 usable CPUs, 2 free; dedicated needs 4: shared"
        );
        assert!(p.overrides.is_none());
    }

    #[test]
    fn four_cpus_are_enough_for_dedicated_but_not_for_auto_under_any_load() {
        let p = plan(RequestedProfile::Dedicated, &range(4), &Load::Average(3.0)).unwrap();
        assert_eq!(p.profile, Profile::Dedicated);
        assert_eq!(
            p.reason,
            "dedicated as asked: 4 usable CPUs (acquisition on CPU 3, fusion on 2, navigator on \
             1; the rest on 0)"
        );
        let o = p.overrides.unwrap();
        assert_eq!(o.cpus["acquisition"], vec![3]);
        assert_eq!(o.cpus["altimeter"], vec![0]);
        assert_eq!(o.watchdog_cpus, vec![0]);
        // An idle 4-CPU machine is all free; the least load takes one CPU.
        let idle = plan(RequestedProfile::Auto, &range(4), &Load::Average(0.0)).unwrap();
        assert_eq!(idle.profile, Profile::Dedicated);
        assert!(
            idle.reason
                .starts_with("auto: 4 usable CPUs, 4 free: dedicated (")
        );
        let busy = plan(RequestedProfile::Auto, &range(4), &Load::Average(0.05)).unwrap();
        assert_eq!(
            busy.reason,
            "auto: 4 usable CPUs, 3 free; dedicated needs 4: shared"
        );
    }

    #[test]
    fn sixteen_cpus_with_load_dedicate_the_highest_and_keep_the_rest_together() {
        let p = plan(RequestedProfile::Auto, &range(16), &Load::Average(0.4)).unwrap();
        assert_eq!(p.profile, Profile::Dedicated);
        assert_eq!(
            p.reason,
            "auto: 16 usable CPUs, 15 free: dedicated (acquisition on CPU 15, fusion on 14, \
             navigator on 13; the rest on 0-12)"
        );
        let heavy = plan(RequestedProfile::Auto, &range(16), &Load::Average(12.2)).unwrap();
        assert_eq!(
            heavy.reason,
            "auto: 16 usable CPUs, 3 free; dedicated needs 4: shared"
        );
        let over = plan(RequestedProfile::Auto, &range(16), &Load::Average(40.0)).unwrap();
        assert!(over.reason.contains("0 free"), "{}", over.reason);
    }

    #[test]
    fn a_sparse_mask_dedicates_its_own_cpus_whatever_their_order() {
        let p = plan(
            RequestedProfile::Dedicated,
            &[6, 2, 0, 4, 4],
            &Load::Average(0.0),
        )
        .unwrap();
        assert!(
            p.reason
                .ends_with("(acquisition on CPU 6, fusion on 4, navigator on 2; the rest on 0)"),
            "{}",
            p.reason
        );
        assert_eq!(cpu_list(&[0, 1, 2, 5, 7, 8]), "0-2,5,7-8");
        let p = plan(
            RequestedProfile::Auto,
            &[1, 3, 5, 7, 9],
            &Load::Average(0.9),
        )
        .unwrap();
        assert!(p.reason.ends_with("the rest on 1,3)"), "{}", p.reason);
        assert_eq!(p.overrides.unwrap().cpus["gnss"], vec![1, 3]);
    }

    #[test]
    fn an_unreadable_load_is_taken_as_zero_and_said() {
        let why = "cannot read /proc/loadavg: No such file or directory (os error 2)";
        let p = plan(
            RequestedProfile::Auto,
            &range(2),
            &Load::Unknown(why.into()),
        )
        .unwrap();
        assert_eq!(
            p.reason,
            format!(
                "auto: 2 usable CPUs, 2 free (load unknown, taken as 0: {why}); dedicated needs \
                 4: shared"
            )
        );
        let p = plan(
            RequestedProfile::Auto,
            &range(8),
            &Load::Unknown(why.into()),
        )
        .unwrap();
        assert_eq!(p.profile, Profile::Dedicated);
        assert_eq!(
            parse_loadavg("0.52 0.58 0.59 2/1012 4242\n"),
            Load::Average(0.52)
        );
        assert!(matches!(parse_loadavg(""), Load::Unknown(_)));
        assert!(matches!(parse_loadavg("nan 1 1"), Load::Unknown(_)));
        assert!(matches!(parse_loadavg("-1 1 1"), Load::Unknown(_)));
    }

    #[test]
    fn shared_changes_nothing_and_reads_nothing() {
        let mut cfg = config();
        let before = cfg.clone();
        let p = resolve(RequestedProfile::Shared, &mut cfg).unwrap();
        assert_eq!(p.profile, Profile::Shared);
        assert_eq!(cfg, before);
        let p = plan(RequestedProfile::Shared, &[], &Load::Unknown("x".into())).unwrap();
        assert_eq!(p.reason, "shared: [wait] and [realtime] as configured");
    }

    #[test]
    fn dedicated_overrides_the_configured_wait_and_realtime_fields_it_sets() {
        let text = "[wait]\nstrategy = \"hybrid\"\n[wait.services]\nfusion = \"event\"\n\
                    [realtime]\nlock_memory = false\n[realtime.priority]\nfusion = 10\n\
                    mavlink = 5\n[realtime.cpus]\nnavigator = [0]\n";
        let mut cfg = RinsConfig::parse(text, "t").unwrap();
        let p = plan(RequestedProfile::Dedicated, &range(6), &Load::Average(0.0)).unwrap();
        p.overrides.as_ref().unwrap().apply(&mut cfg);
        assert!(cfg.realtime.enabled && cfg.realtime.lock_memory);
        use rins_runtime::wait_strategy::WaitStrategy;
        assert_eq!(cfg.wait.for_service("fusion"), WaitStrategy::Spin);
        assert_eq!(cfg.wait.for_service("navigator"), WaitStrategy::Spin);
        assert_eq!(cfg.wait.for_service("altimeter"), WaitStrategy::Event);
        assert_eq!(
            cfg.wait.for_service("navigator-standby"),
            WaitStrategy::Event
        );
        let plan_of = |s: &str| cfg.realtime.plan_for(s).unwrap();
        assert_eq!(plan_of("acquisition").priority, Some(80));
        assert_eq!(plan_of("fusion").priority, Some(79));
        assert_eq!(plan_of("navigator").priority, Some(78));
        // What the profile does not set stays as configured.
        assert_eq!(plan_of("mavlink").priority, Some(5));
        assert_eq!(plan_of("acquisition").cpus, vec![5]);
        assert_eq!(plan_of("fusion").cpus, vec![4]);
        assert_eq!(plan_of("navigator").cpus, vec![3]);
        for other in [
            "navigator-standby",
            "altimeter",
            "gnss",
            "mavlink",
            "bridge",
        ] {
            assert_eq!(plan_of(other).cpus, vec![0, 1, 2], "{other}");
        }
        assert!(cfg.validate().is_ok());
        // The resolved configuration carries it to every child, a restarted one included.
        let text = crate::config::resolved::to_text(&cfg).unwrap();
        assert_eq!(RinsConfig::parse(&text, "resolved").unwrap(), cfg);
    }

    #[test]
    fn this_process_has_cpus_and_auto_resolves_on_this_machine() {
        let usable = usable_cpus().unwrap();
        assert!(!usable.is_empty());
        let mut cfg = config();
        let p = resolve(RequestedProfile::Auto, &mut cfg).unwrap();
        assert!(
            p.reason.contains(&cpus(usable.len())),
            "{} / {usable:?}",
            p.reason
        );
        assert_eq!(cfg.realtime.enabled, p.profile == Profile::Dedicated);
    }
}
