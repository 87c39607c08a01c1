//! `[watchdog]` configuration.

use std::time::Duration;

use serde::Deserialize;

use crate::restart_policy::RestartPolicy;

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
        }
    }
}

impl WatchdogConfig {
    pub fn validate(&self) -> Result<(), String> {
        if self.restart_initial_backoff_ms > self.restart_max_backoff_ms {
            return Err(format!(
                "watchdog.restart_initial_backoff_ms = {}: must be <= restart_max_backoff_ms ({})",
                self.restart_initial_backoff_ms, self.restart_max_backoff_ms
            ));
        }
        if !(self.restart_stable_after_s.is_finite() && self.restart_stable_after_s >= 0.0) {
            return Err(format!(
                "watchdog.restart_stable_after_s = {}: must be a non-negative number",
                self.restart_stable_after_s
            ));
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

    pub fn restart_policy(&self) -> RestartPolicy {
        RestartPolicy {
            initial_backoff: Duration::from_millis(self.restart_initial_backoff_ms),
            max_backoff: Duration::from_millis(self.restart_max_backoff_ms),
            stable_after: Duration::from_secs_f64(self.restart_stable_after_s),
        }
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
}
