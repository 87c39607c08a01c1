//! `[watchdog]` configuration.

use std::collections::BTreeMap;
use std::time::Duration;

use serde::{Deserialize, Serialize};

use crate::restart_policy::{GiveUp, MAX_RESTARTS_LIMIT, RestartPolicy};

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
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ServiceRestartConfig {
    /// First restart delay, ms.
    pub restart_initial_backoff_ms: Option<u64>,
    /// Longest restart delay, ms.
    pub restart_max_backoff_ms: Option<u64>,
    /// A child running this long, s, restarts with the first delay again.
    pub restart_stable_after_s: Option<f64>,
    /// Exits allowed within the window before the child is given up.
    pub max_restarts: Option<u32>,
    /// The window the exits are counted in, s.
    pub restart_window_s: Option<f64>,
    /// What giving up a child does.
    pub give_up: Option<GiveUp>,
}

/// `[watchdog]` of the configuration: restarts, the checks that find a hung child, the status line.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct WatchdogConfig {
    /// First restart delay, ms.
    pub restart_initial_backoff_ms: u64,
    /// Longest restart delay, ms.
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
    /// A stage (fusion, altimeter, a navigator lane) whose input arrives while its output stays
    /// silent this long is hung: it is killed and restarted, without waiting for the heartbeat
    /// timeout. 0 turns the check off.
    pub output_deadline_s: f64,
    /// At most this many restarts of one child within `restart_window_s`; one more and the
    /// watchdog gives up on it (`give_up`). 0: never restart; at most
    /// [`MAX_RESTARTS_LIMIT`], which bounds the exit instants kept per child.
    pub max_restarts: u32,
    /// Seconds, in [0.001, 86400].
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
            output_deadline_s: 0.5,
            max_restarts: 20,
            restart_window_s: 60.0,
            give_up: GiveUp::Shutdown,
            services: BTreeMap::new(),
        }
    }
}

impl WatchdogConfig {
    /// Checks every value's range; the error names the field and the value.
    pub fn validate(&self) -> Result<(), String> {
        self.settings_for(None).validate("watchdog")?;
        for name in self.services.keys() {
            if !SUPERVISED.contains(&name.as_str()) {
                return Err(format!(
                    "watchdog.services.{name}: no such service (expected one of {})",
                    SUPERVISED.join(", ")
                ));
            }
            // Checked merged: an override must fit with the `[watchdog]` values it keeps.
            self.settings_for(Some(name))
                .validate(&format!("watchdog.services.{name}"))?;
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
        let o = self.output_deadline_s;
        if !(o.is_finite() && (o == 0.0 || (0.05..=60.0).contains(&o))) {
            return Err(format!(
                "watchdog.output_deadline_s = {o}: must be 0 (off) or in [0.05, 60] s"
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
        let s = self.settings_for(Some(name));
        let seconds = |s: f64| Duration::try_from_secs_f64(s).unwrap_or(Duration::MAX);
        RestartPolicy {
            initial_backoff: Duration::from_millis(s.initial_backoff_ms),
            max_backoff: Duration::from_millis(s.max_backoff_ms),
            stable_after: seconds(s.stable_after_s),
            max_restarts: s.max_restarts,
            window: seconds(s.window_s),
            give_up: s.give_up,
        }
    }

    /// The restart keys of service `name` (`None`: the `[watchdog]` values alone), as written, so
    /// that validation can quote them.
    fn settings_for(&self, name: Option<&str>) -> RestartSettings {
        let o = name
            .and_then(|n| self.services.get(n))
            .cloned()
            .unwrap_or_default();
        RestartSettings {
            initial_backoff_ms: o
                .restart_initial_backoff_ms
                .unwrap_or(self.restart_initial_backoff_ms),
            max_backoff_ms: o
                .restart_max_backoff_ms
                .unwrap_or(self.restart_max_backoff_ms),
            stable_after_s: o
                .restart_stable_after_s
                .unwrap_or(self.restart_stable_after_s),
            max_restarts: o.max_restarts.unwrap_or(self.max_restarts),
            window_s: o.restart_window_s.unwrap_or(self.restart_window_s),
            give_up: o.give_up.unwrap_or(self.give_up),
        }
    }
}

/// The restart keys of one service after the fallback to `[watchdog]`, before conversion to a
/// [`RestartPolicy`].
struct RestartSettings {
    initial_backoff_ms: u64,
    max_backoff_ms: u64,
    stable_after_s: f64,
    max_restarts: u32,
    window_s: f64,
    give_up: GiveUp,
}

impl RestartSettings {
    /// Range checks shared by `[watchdog]` and every `[watchdog.services.NAME]`; errors name
    /// `section.field` and the value.
    fn validate(&self, section: &str) -> Result<(), String> {
        let (initial_ms, max_ms) = (self.initial_backoff_ms, self.max_backoff_ms);
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
        let stable = self.stable_after_s;
        if !(stable.is_finite() && (0.0..=86_400.0).contains(&stable)) {
            return Err(format!(
                "{section}.restart_stable_after_s = {stable}: must be a number of seconds in [0, 86400]"
            ));
        }
        // A window shorter than the supervision loop's period (1 ms) would hold no earlier exit,
        // so the limit would never apply.
        let window = self.window_s;
        if !(window.is_finite() && (0.001..=86_400.0).contains(&window)) {
            return Err(format!(
                "{section}.restart_window_s = {window}: must be a number of seconds in [0.001, 86400]"
            ));
        }
        if self.max_restarts > MAX_RESTARTS_LIMIT {
            return Err(format!(
                "{section}.max_restarts = {}: must be <= {MAX_RESTARTS_LIMIT} (0: never restart)",
                self.max_restarts
            ));
        }
        Ok(())
    }
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

    #[test]
    fn the_output_deadline_is_off_or_in_range() {
        for ok in [0.0, 0.05, 0.5, 60.0] {
            let c = WatchdogConfig {
                output_deadline_s: ok,
                ..Default::default()
            };
            assert!(c.validate().is_ok(), "{ok}");
        }
        for bad in [0.01, -1.0, 61.0, f64::INFINITY, f64::NAN] {
            let c = WatchdogConfig {
                output_deadline_s: bad,
                ..Default::default()
            };
            let e = c.validate().unwrap_err();
            assert!(e.contains("watchdog.output_deadline_s = "), "{e}");
        }
    }

    fn parse(text: &str) -> WatchdogConfig {
        toml::from_str(text).unwrap()
    }

    /// Why `[watchdog]` text `text` parses but does not validate.
    #[track_caller]
    fn refusal(text: &str) -> String {
        parse(text).validate().unwrap_err()
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
        let err = refusal("[services.gps]\nmax_restarts = 1\n");
        assert!(
            err.starts_with("watchdog.services.gps: no such service"),
            "{err}"
        );
        let err = refusal("[services.fusion]\nrestart_window_s = -1\n");
        assert!(
            err.contains("watchdog.services.fusion.restart_window_s = -1"),
            "{err}"
        );
        let err = refusal("[services.fusion]\nrestart_initial_backoff_ms = 9000\n");
        assert!(
            err.contains("watchdog.services.fusion.restart_initial_backoff_ms = 9000"),
            "{err}"
        );
        assert!(
            toml::from_str::<WatchdogConfig>("[services.fusion]\ngive_up = \"pray\"\n").is_err()
        );
        assert!(toml::from_str::<WatchdogConfig>("[services.fusion]\nmax_restart = 3\n").is_err());
    }

    #[test]
    fn limits_and_windows_out_of_range_are_refused() {
        let err = refusal("[services.fusion]\nmax_restarts = 10001\n");
        assert_eq!(
            err,
            "watchdog.services.fusion.max_restarts = 10001: must be <= 10000 (0: never restart)"
        );
        assert!(parse("max_restarts = 10000\n").validate().is_ok());
        assert!(parse("max_restarts = 0\n").validate().is_ok());
        for window in ["0", "-0.0", "1e-300", "0.0009", "nan", "inf", "86400.5"] {
            let err = refusal(&format!("restart_window_s = {window}\n"));
            assert!(err.starts_with("watchdog.restart_window_s = "), "{err}");
            assert!(err.contains("[0.001, 86400]"), "{err}");
        }
        let err = refusal("[services.sim]\nrestart_stable_after_s = nan\n");
        assert!(
            err.starts_with("watchdog.services.sim.restart_stable_after_s = NaN"),
            "{err}"
        );
    }

    #[test]
    fn an_override_is_checked_with_the_values_it_keeps() {
        // Raising only the initial backoff above the global cap is refused; raising both is fine.
        assert!(
            parse("[services.navigator]\nrestart_initial_backoff_ms = 6000\n")
                .validate()
                .is_err()
        );
        let c = parse(
            "[services.navigator]\nrestart_initial_backoff_ms = 6000\nrestart_max_backoff_ms = 60000\n",
        );
        assert!(c.validate().is_ok());
        let p = c.policy_for("navigator");
        assert_eq!(
            (p.initial_backoff, p.max_backoff),
            (Duration::from_secs(6), Duration::from_secs(60))
        );
        // A service without a section gets the `[watchdog]` values.
        assert_eq!(c.policy_for("fusion"), RestartPolicy::default());
    }
}
