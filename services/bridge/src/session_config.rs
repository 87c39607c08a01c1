//! The Zenoh session's configuration from `[zenoh]`: Zenoh's own file when one is given (checked as
//! rins checks every file it trusts: a regular file, owned by the user rins runs as, writable by
//! nobody else, at most 1 MiB), then the mode and endpoints of `[zenoh]` on top, multicast scouting
//! off (discovery goes through the configured router, as ROS 2 nodes with rmw_zenoh do), and the
//! reconnection to a lost router from 0.25 s backing off to 4 s.

use std::os::unix::fs::MetadataExt;
use std::path::Path;

use anyhow::{Result, anyhow, bail};

use crate::config::ZenohConfig;

/// The largest configuration file read.
const FILE_LIMIT: u64 = 1 << 20;

/// Reads Zenoh's configuration file at `path`, refusing one that another user could have written.
fn read_file(path: &Path, owner: u32) -> Result<String> {
    let what = "zenoh.config_file";
    let shown = path.display();
    let (file, _) =
        rins_regular_file::open_regular(path, FILE_LIMIT).map_err(|e| anyhow!("{what} {e}"))?;
    let meta = file
        .metadata()
        .map_err(|e| anyhow!("{what} {shown}: cannot inspect: {e}"))?;
    if meta.uid() != owner && meta.uid() != 0 {
        bail!(
            "{what} {shown}: owned by uid {}, neither rins's user (uid {owner}) nor root",
            meta.uid()
        );
    }
    if meta.mode() & 0o022 != 0 {
        bail!(
            "{what} {shown}: mode {:04o} lets group or others change it: `chmod go-w {shown}`",
            meta.mode() & 0o7777
        );
    }
    let mut text = String::new();
    use std::io::Read;
    file.take(FILE_LIMIT + 1)
        .read_to_string(&mut text)
        .map_err(|e| anyhow!("{what} {shown}: cannot read as text: {e}"))?;
    Ok(text)
}

/// A JSON list of strings.
fn json_list(items: &[String]) -> String {
    serde_json::to_string(items).unwrap_or_else(|_| "[]".into())
}

/// The session configuration of `config`, read as the effective user `owner`.
pub fn session_config(config: &ZenohConfig, owner: u32) -> Result<zenoh::Config> {
    let mut z = match &config.config_file {
        Some(path) => {
            let text = read_file(Path::new(path), owner)?;
            zenoh::Config::from_json5(&text)
                .map_err(|e| anyhow!("zenoh.config_file {path}: {e}"))?
        }
        None => zenoh::Config::default(),
    };
    let mut set = |key: &str, value: String| {
        z.insert_json5(key, &value)
            .map_err(|e| anyhow!("zenoh: cannot set {key} = {value}: {e}"))
    };
    set("mode", format!("\"{}\"", config.mode))?;
    if !config.connect.is_empty() {
        set("connect/endpoints", json_list(&config.connect))?;
    }
    // Always set: a peer left to Zenoh's default would listen on every interface.
    set("listen/endpoints", json_list(&config.listen))?;
    set("scouting/multicast/enabled", "false".into())?;
    set(
        "connect/retry",
        "{ period_init_ms: 250, period_max_ms: 4000, period_increase_factor: 2 }".into(),
    )?;
    // rmw_zenoh's sessions stamp their samples; so do rins's.
    set("timestamping/enabled", "true".into())?;
    Ok(z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    fn uid() -> u32 {
        // SAFETY: geteuid has no preconditions.
        unsafe { libc::geteuid() }
    }

    #[test]
    fn the_endpoints_and_mode_go_into_the_session() {
        let config = ZenohConfig {
            connect: vec!["tcp/10.0.0.2:7447".into()],
            listen: vec!["tcp/0.0.0.0:7448".into()],
            mode: "client".into(),
            ..ZenohConfig::default()
        };
        let z = session_config(&config, uid()).unwrap();
        let text = format!("{z}");
        assert!(text.contains("tcp/10.0.0.2:7447"), "{text}");
        assert!(text.contains("tcp/0.0.0.0:7448"), "{text}");
    }

    #[test]
    fn the_documented_tls_and_access_control_file_is_one_this_zenoh_takes() {
        let text = include_str!("../../../deploy/zenoh-tls.json5");
        let z = zenoh::Config::from_json5(text).unwrap();
        let shown = format!("{z}");
        assert!(shown.contains("rins-publishes"), "{shown}");
        assert!(shown.contains("/etc/rins/zenoh/ca.pem"), "{shown}");
    }

    #[test]
    fn a_file_others_may_write_or_that_is_not_json5_is_refused() {
        let dir = std::env::temp_dir().join(format!("rins-zenoh-cfg-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("zenoh.json5");
        std::fs::write(&path, "{ mode: \"peer\" }").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o666)).unwrap();
        let config = ZenohConfig {
            config_file: Some(path.to_string_lossy().into_owned()),
            ..ZenohConfig::default()
        };
        let err = session_config(&config, uid()).unwrap_err().to_string();
        assert!(err.contains("lets group or others change it"), "{err}");
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644)).unwrap();
        session_config(&config, uid()).unwrap();
        std::fs::write(&path, "{ mode: ").unwrap();
        let err = session_config(&config, uid()).unwrap_err().to_string();
        assert!(err.contains("zenoh.config_file"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
