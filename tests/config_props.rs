//! The configuration loader under arbitrary and mutated input: the property-test counterpart of
//! the `config` fuzz target (`fuzz/fuzz_targets/config.rs`), run with every test. The loader never
//! panics, and whatever it accepts every service it configures accepts too, so nothing is refused
//! only once a process has started.

use proptest::prelude::*;
use rins::config::{BUILT_IN, RinsConfig};
use rins_watchdog::config::SUPERVISED;

/// Builds what `rins up` builds from an accepted configuration, and the restart policies.
fn build_everything(cfg: &RinsConfig) {
    if let Err(e) = cfg.build_services() {
        panic!("an accepted configuration must build every service: {e}");
    }
    for name in SUPERVISED {
        let p = cfg.watchdog.policy_for(name);
        assert!(p.initial_backoff <= p.max_backoff, "{name}: {p:?}");
    }
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
