//! Each default is stated once: the configuration `config/rins.toml` gives (the built-in one, what
//! a deployment runs with when no file is named) must be exactly `RinsConfig::default()`, key by
//! key, so the file and the code's defaults cannot drift apart. The only keys allowed to differ
//! are the few where the built-in file deliberately sets something other than what a file
//! without the key gets (a profile or a partial file relies on the latter); each is listed here
//! with why, and where its line says `(absent: X)`, X must be the default.

use rins::config::{BUILT_IN, RinsConfig, load};
use toml::Value;

/// Keys whose built-in value is not the default on purpose, and why.
const DELIBERATE: [(&str, &str); 5] = [
    (
        "navigator.initial_latitude_deg",
        "the built-in file starts at the simulator's origin; without a position the start is unknown until a GNSS fix",
    ),
    (
        "navigator.initial_longitude_deg",
        "with the latitude, or neither",
    ),
    (
        "navigator.initial_altitude_m",
        "the simulator origin's altitude; replaced by the first baro reading",
    ),
    (
        "navigator.mag.sigma_deg",
        "the built-in block's magnetometer is uncalibrated; the pedestrian profile relies on the default",
    ),
    (
        "sim.initial_heading_deg",
        "not north, so a heading error is not an angle wrap; the profiles fly from north",
    ),
];

/// The value `(absent: X)` on `key`'s line of `text` gives, if the line says one.
fn stated_absent(text: &str, key: &str) -> Option<Value> {
    let (table, name) = key.rsplit_once('.')?;
    let mut current = String::new();
    for line in text.lines().map(str::trim) {
        if let Some(t) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            current = t.to_string();
        } else if current == table
            && line.split_once('=').is_some_and(|(k, _)| k.trim() == name)
            && let Some((_, rest)) = line.split_once("(absent:")
        {
            let stated = rest.split(')').next()?.trim();
            return toml::from_str::<toml::Table>(&format!("v = {stated}"))
                .ok()?
                .remove("v");
        }
    }
    None
}

/// The value at dotted `key` in `tree`.
fn at<'a>(tree: &'a Value, key: &str) -> Option<&'a Value> {
    key.split('.').try_fold(tree, |t, k| t.get(k))
}

/// Numbers compared as numbers: `(absent: 0)` states the float 0.0.
fn same_number(a: &Value, b: &Value) -> bool {
    let n = |v: &Value| v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
    matches!((n(a), n(b)), (Some(a), Some(b)) if a == b) || a == b
}

/// Every key path below `path` where `a` and `b` differ, with both values; a key one side lacks
/// counts as a difference.
fn differences(a: &Value, b: &Value, path: &str, out: &mut Vec<String>) {
    match (a, b) {
        (Value::Table(a), Value::Table(b)) => {
            let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
            keys.sort();
            keys.dedup();
            for key in keys {
                let key_path = if path.is_empty() {
                    key.clone()
                } else {
                    format!("{path}.{key}")
                };
                match (a.get(key), b.get(key)) {
                    (Some(a), Some(b)) => differences(a, b, &key_path, out),
                    (a, b) => out.push(format!("{key_path}: {a:?} against {b:?}")),
                }
            }
        }
        (a, b) if a == b => {}
        (a, b) => out.push(format!("{path}: {a} against {b}")),
    }
}

#[test]
fn the_built_in_file_is_the_default_configuration_key_by_key() {
    let file = Value::try_from(load(None).expect("config/rins.toml loads")).expect("serialises");
    let defaults = Value::try_from(RinsConfig::default()).expect("the defaults serialise");
    let mut found = Vec::new();
    differences(&file, &defaults, "", &mut found);
    found.retain(|d| {
        !DELIBERATE
            .iter()
            .any(|(key, _)| d.starts_with(&format!("{key}: ")))
    });
    assert!(
        found.is_empty(),
        "config/rins.toml (left) and RinsConfig::default() (right) differ at {} keys:\n{}",
        found.len(),
        found.join("\n")
    );
    for (key, why) in DELIBERATE {
        assert_ne!(
            at(&file, key),
            at(&defaults, key),
            "{key} ({why}) no longer differs: take it off the list"
        );
        if let Some(stated) = stated_absent(BUILT_IN, key) {
            let default = at(&defaults, key).unwrap_or_else(|| panic!("{key} has no default"));
            assert!(
                same_number(&stated, default),
                "{key}: config/rins.toml says (absent: {stated}), the default is {default}"
            );
        }
    }
}

#[test]
fn the_defaults_are_a_valid_configuration() {
    RinsConfig::default()
        .validate()
        .expect("RinsConfig::default() validates");
}
