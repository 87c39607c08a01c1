//! `[realtime]`: the real-time settings each service asks for at its start (SCHED_FIFO priority,
//! CPU affinity, locked memory, a pre-faulted stack), off unless `enabled`. What the system
//! refuses is logged once by the service, which runs on without it.

use std::collections::BTreeMap;

use rins_runtime::realtime::{MAX_CPU, RealtimePlan};
use serde::{Deserialize, Serialize};

/// The services `[realtime.priority]` and `[realtime.cpus]` may name.
pub const SERVICES: [&str; 8] = [
    "acquisition",
    "fusion",
    "altimeter",
    "navigator",
    "navigator-standby",
    "gnss",
    "mavlink",
    "bridge",
];

/// Largest pre-faulted stack, KiB: well inside the main thread's 8 MiB.
const MAX_PREFAULT_KIB: u32 = 4096;

/// `[realtime]` of the configuration.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct RealtimeConfig {
    /// Whether the services ask for any of this (`rins up --realtime` turns it on).
    pub enabled: bool,
    /// `mlockall` of current and future memory.
    pub lock_memory: bool,
    /// Stack touched at the start, KiB (0: none).
    pub prefault_stack_kib: u32,
    /// SCHED_FIFO priority per service, 1..=99 (0 or absent: normal scheduling).
    pub priority: BTreeMap<String, u8>,
    /// CPUs per service (absent: all).
    pub cpus: BTreeMap<String, Vec<usize>>,
}

impl Default for RealtimeConfig {
    /// Off; when on, priorities fall along the data path — the serial reader highest, so that
    /// no consumer ever delays the reading of the line, then fusion, the primary navigator lane
    /// above its standby, the altimeter, the GNSS reader, the MAVLink output — all above any
    /// normal process; memory locked; 512 KiB of stack pre-faulted.
    fn default() -> Self {
        let priority = [
            ("acquisition", 80),
            ("fusion", 79),
            ("navigator", 78),
            ("navigator-standby", 77),
            ("altimeter", 76),
            ("gnss", 75),
            ("mavlink", 60),
        ]
        .into_iter()
        .map(|(s, p)| (s.to_string(), p))
        .collect();
        Self {
            enabled: false,
            lock_memory: true,
            prefault_stack_kib: 512,
            priority,
            cpus: BTreeMap::new(),
        }
    }
}

impl RealtimeConfig {
    /// Checks every field; the error names it and its value.
    pub fn validate(&self) -> Result<(), String> {
        if self.prefault_stack_kib > MAX_PREFAULT_KIB {
            return Err(format!(
                "realtime.prefault_stack_kib = {}: must be 0..={MAX_PREFAULT_KIB}",
                self.prefault_stack_kib
            ));
        }
        for (service, priority) in &self.priority {
            known(service, "priority")?;
            if *priority > 99 {
                return Err(format!(
                    "realtime.priority.{service} = {priority}: must be 0..=99 (0: normal scheduling)"
                ));
            }
        }
        for (service, cpus) in &self.cpus {
            known(service, "cpus")?;
            if cpus.is_empty() {
                return Err(format!(
                    "realtime.cpus.{service} = []: name at least one CPU, or leave the service out"
                ));
            }
            if let Some(cpu) = cpus.iter().find(|c| **c > MAX_CPU) {
                return Err(format!(
                    "realtime.cpus.{service} = {cpus:?}: CPU {cpu} is beyond {MAX_CPU}"
                ));
            }
        }
        Ok(())
    }

    /// What `service` asks for; `None` when real-time settings are off.
    pub fn plan_for(&self, service: &str) -> Option<RealtimePlan> {
        self.enabled.then(|| RealtimePlan {
            priority: self.priority.get(service).copied().filter(|p| *p > 0),
            cpus: self.cpus.get(service).cloned().unwrap_or_default(),
            lock_memory: self.lock_memory,
            prefault_stack_kib: self.prefault_stack_kib as usize,
        })
    }
}

fn known(service: &str, table: &str) -> Result<(), String> {
    if SERVICES.contains(&service) {
        Ok(())
    } else {
        Err(format!(
            "realtime.{table}.{service}: no such service (one of {})",
            SERVICES.join(", ")
        ))
    }
}

/// Applies `service`'s plan, when real-time settings are on, and logs what was granted and
/// each refusal once.
pub fn apply_for(config: &RealtimeConfig, service: &str) {
    let Some(plan) = config.plan_for(service) else {
        return;
    };
    let refused = rins_runtime::realtime::apply(&plan);
    for r in &refused {
        tracing::warn!(
            service,
            setting = r.setting,
            asked = %r.asked,
            error = %r.error,
            "real-time setting refused by the system; running without it"
        );
    }
    tracing::info!(
        service,
        priority = ?plan.priority,
        cpus = ?plan.cpus,
        lock_memory = plan.lock_memory,
        refused = refused.len(),
        "real-time settings applied"
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_is_off_and_ordered_along_the_data_path() {
        let c = RealtimeConfig::default();
        assert!(c.plan_for("fusion").is_none());
        let on = RealtimeConfig { enabled: true, ..c };
        let p = |s: &str| on.plan_for(s).unwrap().priority.unwrap();
        assert!(p("acquisition") > p("fusion"));
        assert!(p("fusion") > p("navigator"));
        assert!(p("navigator") > p("navigator-standby"));
        assert!(on.plan_for("fusion").unwrap().cpus.is_empty());
        assert!(on.validate().is_ok());
    }

    #[test]
    fn errors_name_the_field_and_the_value() {
        let mut c = RealtimeConfig::default();
        c.priority.insert("fusion".into(), 120);
        assert_eq!(
            c.validate().unwrap_err(),
            "realtime.priority.fusion = 120: must be 0..=99 (0: normal scheduling)"
        );
        let mut c = RealtimeConfig::default();
        c.priority.insert("fuson".into(), 10);
        assert!(
            c.validate()
                .unwrap_err()
                .starts_with("realtime.priority.fuson: no such service")
        );
        let mut c = RealtimeConfig::default();
        c.cpus.insert("navigator".into(), vec![]);
        assert!(
            c.validate()
                .unwrap_err()
                .starts_with("realtime.cpus.navigator = []")
        );
        let mut c = RealtimeConfig::default();
        c.cpus.insert("navigator".into(), vec![1, 5000]);
        assert!(c.validate().unwrap_err().contains("CPU 5000"));
        let c = RealtimeConfig {
            prefault_stack_kib: 9000,
            ..RealtimeConfig::default()
        };
        assert!(
            c.validate()
                .unwrap_err()
                .starts_with("realtime.prefault_stack_kib = 9000")
        );
    }

    #[test]
    fn priority_zero_keeps_normal_scheduling() {
        let mut c = RealtimeConfig {
            enabled: true,
            ..RealtimeConfig::default()
        };
        c.priority.insert("mavlink".into(), 0);
        assert_eq!(c.plan_for("mavlink").unwrap().priority, None);
        assert_eq!(c.plan_for("sim").unwrap().priority, None);
    }
}
