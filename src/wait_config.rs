//! `[wait]`: how the stages a topic drives (fusion, the altimeter, the navigator lanes) wait for
//! their input — `event` (sleep until notified), `spin` (poll without sleeping) or `hybrid` (poll
//! for `hybrid_spin_us` after each wake-up, then sleep) — for all of them or per service.

use std::collections::BTreeMap;
use std::time::Duration;

use rins_runtime::wait_strategy::WaitStrategy;
use serde::{Deserialize, Serialize};

/// The stages `[wait.services]` may name.
pub const STAGES: [&str; 4] = ["fusion", "altimeter", "navigator", "navigator-standby"];

/// Longest hybrid poll, µs: past a sample period at the slowest rate, spinning is all it does.
const MAX_SPIN_US: u32 = 20_000;

/// A strategy by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum WaitKind {
    /// Sleep on the listener until notified.
    #[default]
    Event,
    /// Poll the queue without sleeping.
    Spin,
    /// Poll for `hybrid_spin_us`, then sleep.
    Hybrid,
}

/// `[wait]` of the configuration.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct WaitConfig {
    /// Every stage's strategy unless `services` names it.
    pub strategy: WaitKind,
    /// How long `hybrid` polls after each wake-up, µs.
    pub hybrid_spin_us: u32,
    /// Per stage.
    pub services: BTreeMap<String, WaitKind>,
}

impl Default for WaitConfig {
    fn default() -> Self {
        Self {
            strategy: WaitKind::Event,
            hybrid_spin_us: 50,
            services: BTreeMap::new(),
        }
    }
}

impl WaitConfig {
    /// Checks every field; the error names it and its value.
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=MAX_SPIN_US).contains(&self.hybrid_spin_us) {
            return Err(format!(
                "wait.hybrid_spin_us = {}: must be 1..={MAX_SPIN_US}",
                self.hybrid_spin_us
            ));
        }
        if let Some(name) = self.services.keys().find(|n| !STAGES.contains(&n.as_str())) {
            return Err(format!(
                "wait.services.{name}: no such stage (one of {})",
                STAGES.join(", ")
            ));
        }
        Ok(())
    }

    /// The strategy of `service`.
    pub fn for_service(&self, service: &str) -> WaitStrategy {
        match self.services.get(service).copied().unwrap_or(self.strategy) {
            WaitKind::Event => WaitStrategy::Event,
            WaitKind::Spin => WaitStrategy::Spin,
            WaitKind::Hybrid => WaitStrategy::Hybrid {
                spin: Duration::from_micros(u64::from(self.hybrid_spin_us)),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stage_takes_its_own_strategy_or_the_common_one() {
        let text = "strategy = \"hybrid\"\nhybrid_spin_us = 80\n[services]\nfusion = \"spin\"\n";
        let c: WaitConfig = toml::from_str(text).unwrap();
        assert!(c.validate().is_ok());
        assert_eq!(c.for_service("fusion"), WaitStrategy::Spin);
        assert_eq!(
            c.for_service("navigator"),
            WaitStrategy::Hybrid {
                spin: Duration::from_micros(80)
            }
        );
        assert_eq!(
            WaitConfig::default().for_service("fusion"),
            WaitStrategy::Event
        );
    }

    #[test]
    fn errors_name_the_field_and_the_value() {
        let c = WaitConfig {
            hybrid_spin_us: 0,
            ..WaitConfig::default()
        };
        assert_eq!(
            c.validate().unwrap_err(),
            "wait.hybrid_spin_us = 0: must be 1..=20000"
        );
        let mut c = WaitConfig::default();
        c.services.insert("acquisition".into(), WaitKind::Spin);
        assert!(
            c.validate()
                .unwrap_err()
                .starts_with("wait.services.acquisition: no such stage")
        );
        assert!(toml::from_str::<WaitConfig>("strategy = \"busy\"").is_err());
    }
}
