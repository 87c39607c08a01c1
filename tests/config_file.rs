//! `config/rins.toml` documents the loader: every key the loader knows appears in it with its
//! default (or says what a missing key takes instead), and the file loads and validates. The loader's defaults are serialised to a TOML tree
//! and walked, so a key added to any service's configuration without a line in the file fails here.

use rins::config::{BUILT_IN, RinsConfig, load};
use toml::Value;

/// Key paths whose line in the file says what a missing key takes instead (`(absent: ...)`):
/// the file's value differs from the loader's default there, on purpose.
fn marked_absent(text: &str) -> Vec<String> {
    let mut table = String::new();
    let mut marked = Vec::new();
    for line in text.lines().map(str::trim) {
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            table = name.to_string();
        } else if !line.starts_with('#')
            && line.contains("(absent:")
            && let Some((key, _)) = line.split_once('=')
        {
            marked.push(format!("{table}.{}", key.trim()));
        }
    }
    marked
}

/// Whether the file shows `default`: floats to the digits written (the noise σ are rounded),
/// everything else exactly.
fn same(default: &Value, shown: &Value) -> bool {
    match (default, shown) {
        (Value::Float(d), Value::Float(s)) => (d - s).abs() <= 1e-4 * d.abs(),
        (Value::Array(d), Value::Array(s)) => {
            d.len() == s.len() && d.iter().zip(s).all(|(d, s)| same(d, s))
        }
        _ => default == shown,
    }
}

/// Every key path of `defaults` that `file` lacks (`missing`), and every value the file shows
/// otherwise (`different`), below `path`. An empty table of the defaults is one whose keys are
/// free names (`[watchdog.services.NAME]`): nothing to name.
fn compare(
    defaults: &Value,
    file: &Value,
    path: &str,
    missing: &mut Vec<String>,
    different: &mut Vec<String>,
) {
    let Value::Table(table) = defaults else {
        if !same(defaults, file) {
            different.push(path.to_string());
        }
        return;
    };
    for (key, default) in table {
        let key_path = if path.is_empty() {
            key.clone()
        } else {
            format!("{path}.{key}")
        };
        match file.get(key) {
            _ if default.as_table().is_some_and(toml::Table::is_empty) => {}
            None => missing.push(key_path),
            Some(value) => compare(default, value, &key_path, missing, different),
        }
    }
}

#[test]
fn the_file_names_every_key_the_loader_knows_with_its_default() {
    let defaults = Value::try_from(RinsConfig::default()).expect("the defaults serialise");
    let file: Value = toml::from_str(BUILT_IN).expect("config/rins.toml is TOML");
    let (mut missing, mut different) = (Vec::new(), Vec::new());
    compare(&defaults, &file, "", &mut missing, &mut different);
    assert!(
        missing.is_empty(),
        "config/rins.toml lacks {} keys:\n{}",
        missing.len(),
        missing.join("\n")
    );
    // What a file without the key gets is what the file shows, unless its line says otherwise.
    let mut marked = marked_absent(BUILT_IN);
    different.sort();
    marked.sort();
    assert_eq!(
        different, marked,
        "keys whose value is not the default, against keys marked (absent: ...)"
    );
}

#[test]
fn the_file_loads_validates_and_is_the_built_in_configuration() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/rins.toml");
    let from_file = load(Some(std::path::Path::new(path))).expect("config/rins.toml loads");
    from_file.validate().expect("config/rins.toml validates");
    assert_eq!(from_file, load(None).expect("built-in configuration"));
    // The loader's own check that every service builds from it.
    from_file
        .build_services()
        .expect("every service builds from config/rins.toml");
}
