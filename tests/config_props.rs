//! The configuration loader under arbitrary and mutated input: the property-test counterpart of
//! the `config` fuzz target (`fuzz/fuzz_targets/config.rs`), run with every test. The loader never
//! panics, and whatever it accepts every service it configures accepts too, so nothing is refused
//! only once a process has started.

use std::time::Duration;

use proptest::prelude::*;
use rins::config::{BUILT_IN, RinsConfig};
use rins_watchdog::config::SUPERVISED;
use rins_watchdog::restart_policy::{MAX_RESTARTS_LIMIT, RestartWindow};

/// Builds what `rins up` builds from an accepted configuration, and the restart policy (with its
/// ring of exit instants) of every supervised service.
fn build_everything(cfg: &RinsConfig) {
    if let Err(e) = cfg.build_services() {
        panic!("an accepted configuration must build every service: {e}");
    }
    for name in SUPERVISED {
        let p = cfg.watchdog.policy_for(name);
        assert!(p.initial_backoff <= p.max_backoff, "{name}: {p:?}");
        assert!(p.max_backoff <= Duration::from_secs(3600), "{name}: {p:?}");
        assert!(p.max_restarts <= MAX_RESTARTS_LIMIT, "{name}: {p:?}");
        assert!(
            p.window >= Duration::from_millis(1) && p.window <= Duration::from_secs(86_400),
            "{name}: {p:?}"
        );
        assert!(
            p.stable_after <= Duration::from_secs(86_400),
            "{name}: {p:?}"
        );
        let _ = RestartWindow::new(&p);
    }
}

/// The keys of a `[watchdog.services.NAME]` section, and one it does not have.
const RESTART_KEYS: [&str; 7] = [
    "restart_initial_backoff_ms",
    "restart_max_backoff_ms",
    "restart_stable_after_s",
    "max_restarts",
    "restart_window_s",
    "give_up",
    "max_restart",
];

/// Names that are not supervised services (near misses included).
const NOT_SERVICES: [&str; 5] = ["gps", "Navigator", "navigator_standby", "", "watchdog"];

/// Values for the restart keys: valid ones, and ones that break naive range checks.
const RESTART_VALUES: [&str; 17] = [
    "0",
    "1",
    "10000",
    "10001",
    "3600000",
    "3600001",
    "86400",
    "86400.5",
    "-1",
    "-0.0",
    "nan",
    "inf",
    "1e-300",
    "18446744073709551615",
    "\"shutdown\"",
    "\"leave-down\"",
    "\"pray\"",
];

/// The built-in text with a `[watchdog.services.NAME]` section holding `lines`.
fn with_service_section(name: &str, lines: &[(&str, String)]) -> String {
    let mut text = format!("{BUILT_IN}\n[watchdog.services.\"{name}\"]\n");
    for (key, value) in lines {
        text.push_str(&format!("{key} = {value}\n"));
    }
    text
}

/// Values that break naive range checks.
const NASTY: [&str; 14] = [
    "0",
    "-0.0",
    "-1",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "1e-300",
    "65536",
    "4294967296",
    "18446744073709551615",
    "\"x\"",
    "[]",
];

/// Every `key = value` line of the built-in configuration.
fn value_lines() -> Vec<usize> {
    BUILT_IN
        .lines()
        .enumerate()
        .filter(|(_, l)| {
            let t = l.trim_start();
            !t.starts_with('#') && !t.starts_with('[') && t.contains('=')
        })
        .map(|(i, _)| i)
        .collect()
}

/// The built-in text with line `line`'s value replaced by `value` (the comment kept out).
fn with_value(line: usize, value: &str) -> String {
    BUILT_IN
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == line {
                let key = l.split('=').next().unwrap_or_default();
                format!("{key}= {value}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn the_built_in_configuration_builds_everything() {
    let cfg = RinsConfig::parse(BUILT_IN, "built-in").expect("built-in parses");
    build_everything(&cfg);
}

#[test]
fn every_value_of_the_built_in_file_replaced_by_every_nasty_one() {
    // The sampled property below meets a given line and value once in thousands of cases; this
    // walks them all, so a key whose extreme value breaks a service cannot wait for a lucky seed.
    for line in value_lines() {
        for nasty in NASTY {
            if let Ok(cfg) = RinsConfig::parse(&with_value(line, nasty), "every") {
                build_everything(&cfg);
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_text_never_panics(text in ".{0,400}") {
        if let Ok(cfg) = RinsConfig::parse(&text, "prop") {
            build_everything(&cfg);
        }
    }

    #[test]
    fn any_value_of_the_built_in_file_replaced_by_a_nasty_one(
        pick in any::<prop::sample::Index>(),
        nasty in prop::sample::select(NASTY.to_vec()),
        number in any::<f64>(),
        use_number in any::<bool>(),
    ) {
        let lines = value_lines();
        let line = lines[pick.index(lines.len())];
        let value = if use_number { format!("{number:?}") } else { nasty.to_string() };
        if let Ok(cfg) = RinsConfig::parse(&with_value(line, &value), "prop") {
            build_everything(&cfg);
        }
    }

    #[test]
    fn per_service_restart_settings_are_accepted_only_within_range(
        service in prop::sample::select(SUPERVISED.to_vec()),
        lines in prop::collection::vec(
            (
                prop::sample::select(RESTART_KEYS.to_vec()),
                prop::sample::select(RESTART_VALUES.to_vec()),
                any::<f64>(),
                any::<bool>(),
            ),
            1..4,
        ),
    ) {
        let lines: Vec<(&str, String)> = lines
            .into_iter()
            .map(|(key, value, number, use_number)| {
                (key, if use_number { format!("{number:?}") } else { value.to_string() })
            })
            .collect();
        if let Ok(cfg) = RinsConfig::parse(&with_service_section(service, &lines), "prop") {
            build_everything(&cfg);
        }
    }

    #[test]
    fn an_unknown_service_section_is_refused_naming_it(
        name in prop::sample::select(NOT_SERVICES.to_vec()),
        key in prop::sample::select(RESTART_KEYS[..6].to_vec()),
    ) {
        let value = if key == "give_up" { "\"leave-down\"" } else { "1" };
        let text = with_service_section(name, &[(key, value.to_string())]);
        let err = match RinsConfig::parse(&text, "prop") {
            Ok(_) => panic!("[watchdog.services.{name:?}] was accepted"),
            Err(e) => e.to_string(),
        };
        prop_assert!(
            err.contains(&format!("watchdog.services.{name}: no such service")),
            "{}", err
        );
        for valid in SUPERVISED {
            prop_assert!(err.contains(valid), "{}", err);
        }
    }

    #[test]
    fn dropping_or_repeating_a_line_never_panics(
        pick in any::<prop::sample::Index>(),
        repeat in any::<bool>(),
    ) {
        let lines: Vec<&str> = BUILT_IN.lines().collect();
        let i = pick.index(lines.len());
        let mut edited: Vec<&str> = lines.clone();
        if repeat {
            edited.insert(i, lines[i]);
        } else {
            edited.remove(i);
        }
        if let Ok(cfg) = RinsConfig::parse(&edited.join("\n"), "prop") {
            build_everything(&cfg);
        }
    }
}
