//! `[watchdog]` configuration.

use std::collections::BTreeMap;
use std::time::Duration;

use serde::Deserialize;

use crate::restart_policy::{GiveUp, RestartPolicy};

/// Services `[watchdog.services.NAME]` may name.
pub const SUPERVISED: [&str; 6] = [
    "acquisition",
    "fusion",
    "altimeter",
    "navigator",
    "navigator-standby",
    "sim",
];

/// Per-service restart settings; what is not given comes from `[watchdog]`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ServiceRestartConfig {
    pub restart_initial_backoff_ms: Option<u64>,
    pub restart_max_backoff_ms: Option<u64>,
    pub restart_stable_after_s: Option<f64>,
    pub max_restarts: Option<u32>,
    pub restart_window_s: Option<f64>,
    pub give_up: Option<GiveUp>,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WatchdogConfig {
    pub restart_initial_backoff_ms: u64,
    pub restart_max_backoff_ms: u64,
    /// A child that ran this long has its failure count reset. A crash loop (a child dying within
    /// this time of its start) backs off exponentially; a child that ran for a while and was killed
    /// comes back after the initial backoff, which keeps a killed service's outage short.
    pub restart_stable_after_s: f64,
    /// How long children get to stop after SIGTERM before they are killed.
    pub stop_grace_ms: u64,
    /// Print the status line this often; 0 turns it off.
    pub status_period_s: f64,
    /// A child whose heartbeat (once a second) is older than this is hung: it is killed and
    /// restarted. 0 turns the check off.
    pub heartbeat_timeout_s: f64,
    /// At most this many restarts of one child within `restart_window_s`; one more and the
    /// watchdog gives up on it (`give_up`). 0: never restart.
    pub max_restarts: u32,
    pub restart_window_s: f64,
    /// `shutdown` (stop everything, `rins up` fails naming the child) or `leave-down`.
    pub give_up: GiveUp,
    /// Overrides per service, `[watchdog.services.NAME]`.
    pub services: BTreeMap<String, ServiceRestartConfig>,
}

impl Default for WatchdogConfig {
    fn default() -> Self {
        Self {
            restart_initial_backoff_ms: 10,
            restart_max_backoff_ms: 5_000,
            restart_stable_after_s: 1.0,
            stop_grace_ms: 2_000,
            status_period_s: 1.0,
            heartbeat_timeout_s: 3.0,
            max_restarts: 20,
            restart_window_s: 60.0,
            give_up: GiveUp::Shutdown,
            services: BTreeMap::new(),
        }
    }
}

impl WatchdogConfig {
    pub fn validate(&self) -> Result<(), String> {
        validate_restart(
            "watchdog",
            self.restart_initial_backoff_ms,
            self.restart_max_backoff_ms,
            self.restart_stable_after_s,
            self.restart_window_s,
        )?;
        for (name, o) in &self.services {
            if !SUPERVISED.contains(&name.as_str()) {
                return Err(format!(
                    "watchdog.services.{name}: no such service (expected one of {})",
                    SUPERVISED.join(", ")
                ));
            }
            let p = self.policy_for(name);
            validate_restart(
                &format!("watchdog.services.{name}"),
                p.initial_backoff.as_millis() as u64,
                p.max_backoff.as_millis() as u64,
                o.restart_stable_after_s
                    .unwrap_or(self.restart_stable_after_s),
                o.restart_window_s.unwrap_or(self.restart_window_s),
            )?;
        }
        if !(self.status_period_s.is_finite() && self.status_period_s >= 0.0) {
            return Err(format!(
                "watchdog.status_period_s = {}: must be a non-negative number",
                self.status_period_s
            ));
        }
        let h = self.heartbeat_timeout_s;
        if !(h.is_finite() && (h == 0.0 || (1.5..=600.0).contains(&h))) {
            return Err(format!(
                "watchdog.heartbeat_timeout_s = {h}: must be 0 (off) or in [1.5, 600] s (heartbeats come once a second)"
            ));
        }
        if self.stop_grace_ms > 60_000 {
            return Err(format!(
                "watchdog.stop_grace_ms = {}: must be <= 60000",
                self.stop_grace_ms
            ));
        }
        Ok(())
    }

    /// The restart policy of service `name`: its overrides over the `[watchdog]` values. Call on
    /// a validated configuration (durations are then finite and non-negative).
    pub fn policy_for(&self, name: &str) -> RestartPolicy {
        let o = self.services.get(name).cloned().unwrap_or_default();
        let seconds = |s: f64| Duration::try_from_secs_f64(s).unwrap_or(Duration::MAX);
        RestartPolicy {
            initial_backoff: Duration::from_millis(
                o.restart_initial_backoff_ms
                    .unwrap_or(self.restart_initial_backoff_ms),
            ),
            max_backoff: Duration::from_millis(
                o.restart_max_backoff_ms
                    .unwrap_or(self.restart_max_backoff_ms),
            ),
            stable_after: seconds(
                o.restart_stable_after_s
                    .unwrap_or(self.restart_stable_after_s),
            ),
            max_restarts: o.max_restarts.unwrap_or(self.max_restarts),
            window: seconds(o.restart_window_s.unwrap_or(self.restart_window_s)),
            give_up: o.give_up.unwrap_or(self.give_up),
        }
    }
}

/// Range checks shared by `[watchdog]` and every `[watchdog.services.NAME]`.
fn validate_restart(
    section: &str,
    initial_ms: u64,
    max_ms: u64,
    stable_after_s: f64,
    window_s: f64,
) -> Result<(), String> {
    if initial_ms > max_ms {
        return Err(format!(
            "{section}.restart_initial_backoff_ms = {initial_ms}: must be <= restart_max_backoff_ms ({max_ms})"
        ));
    }
    if max_ms > 3_600_000 {
        return Err(format!(
            "{section}.restart_max_backoff_ms = {max_ms}: must be <= 3600000 (an hour)"
        ));
    }
    for (field, value) in [
        ("restart_stable_after_s", stable_after_s),
        ("restart_window_s", window_s),
    ] {
        if !(value.is_finite() && (0.0..=86_400.0).contains(&value)) {
            return Err(format!(
                "{section}.{field} = {value}: must be a number of seconds in [0, 86400]"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_valid_and_errors_name_the_field() {
        assert!(WatchdogConfig::default().validate().is_ok());
        let bad = WatchdogConfig {
            status_period_s: f64::NAN,
            ..Default::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .contains("watchdog.status_period_s = NaN")
        );
    }

    fn parse(text: &str) -> WatchdogConfig {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn service_overrides_fall_back_to_the_watchdog_values() {
        let c = parse(
            "max_restarts = 7\nrestart_window_s = 30\n\
             [services.altimeter]\nmax_restarts = 2\ngive_up = \"leave-down\"\n",
        );
        assert!(c.validate().is_ok());
        let alt = c.policy_for("altimeter");
        assert_eq!(
            (alt.max_restarts, alt.window, alt.give_up),
            (2, Duration::from_secs(30), GiveUp::LeaveDown)
        );
        let fusion = c.policy_for("fusion");
        assert_eq!(
            (fusion.max_restarts, fusion.give_up, fusion.initial_backoff),
            (7, GiveUp::Shutdown, Duration::from_millis(10))
        );
    }

    #[test]
    fn bad_overrides_name_the_key() {
        let err = parse("[services.gps]\nmax_restarts = 1\n")
            .validate()
            .unwrap_err();
        assert!(
            err.starts_with("watchdog.services.gps: no such service"),
            "{err}"
        );
        let err = parse("[services.fusion]\nrestart_window_s = -1\n")
            .validate()
            .unwrap_err();
        assert!(
            err.contains("watchdog.services.fusion.restart_window_s = -1"),
            "{err}"
        );
        let err = parse("[services.fusion]\nrestart_initial_backoff_ms = 9000\n")
            .validate()
            .unwrap_err();
        assert!(
            err.contains("watchdog.services.fusion.restart_initial_backoff_ms = 9000"),
            "{err}"
        );
        assert!(
            toml::from_str::<WatchdogConfig>("[services.fusion]\ngive_up = \"pray\"\n").is_err()
        );
    }
}
