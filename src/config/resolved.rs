//! The configuration a deployment runs with, resolved once by `rins up` (its file, the command
//! line's overrides and the defaults) and handed to every child as one private file: the children
//! read it as it is, so no stage can apply an override differently from another.

use std::io::Write;
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use rins_runtime::bounded_file;

use super::RinsConfig;

/// The resolved configuration's file name in the run directory.
pub const FILE_NAME: &str = "resolved-config.toml";

/// Permission bits the file must not have: any access by group or others (it may name devices
/// and signing-key files).
const GROUP_OTHER_BITS: u32 = 0o077;

/// `cfg` as TOML text that [`RinsConfig::parse`] reads back to the same configuration; an error
/// when it would not (a value TOML cannot carry exactly).
pub fn to_text(cfg: &RinsConfig) -> Result<String> {
    let text = toml::to_string(cfg).context("cannot write the resolved configuration as TOML")?;
    let back = RinsConfig::parse(&text, "resolved configuration")?;
    if &back != cfg {
        bail!("the resolved configuration does not read back as written");
    }
    Ok(text)
}

/// Writes `cfg` to [`FILE_NAME`] in `run_dir` (a private directory of this user), readable by
/// this user only; a previous run's file there is replaced, and one that appears between the
/// removal and the creation (planted) is refused, never written through.
pub fn write(cfg: &RinsConfig, run_dir: &Path) -> Result<PathBuf> {
    let text = to_text(cfg)?;
    let path = run_dir.join(FILE_NAME);
    match std::fs::remove_file(&path) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(e).with_context(|| format!("cannot replace {}", path.display())),
    }
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o600)
        .custom_flags(libc::O_NOFOLLOW)
        .open(&path)
        .with_context(|| {
            format!(
                "cannot create the resolved configuration {} (if it exists, another process put \
                 it there: it is not used)",
                path.display()
            )
        })?;
    file.write_all(text.as_bytes())
        .and_then(|()| file.sync_all())
        .with_context(|| format!("cannot write the resolved configuration {}", path.display()))?;
    Ok(path)
}

/// Reads a resolved configuration: a regular file owned by this user and closed to group and
/// others (anything else may have been planted or altered by another user, and is refused).
pub fn load(path: &Path) -> Result<RinsConfig> {
    let meta = std::fs::symlink_metadata(path)
        .with_context(|| format!("cannot read the resolved configuration {}", path.display()))?;
    // SAFETY: geteuid(2) has no preconditions and cannot fail.
    let me = unsafe { libc::geteuid() };
    if !meta.file_type().is_file() || meta.uid() != me || meta.mode() & GROUP_OTHER_BITS != 0 {
        bail!(
            "{}: not a private resolved configuration (found a {} owned by uid {}, mode {:04o}; \
             expected a regular file owned by uid {me}, mode 0600): it is not used",
            path.display(),
            rins_runtime::private_dir::kind_of(&meta),
            meta.uid(),
            meta.mode() & 0o7777
        );
    }
    let text =
        bounded_file::read_text(path, "resolved configuration", bounded_file::DEFAULT_LIMIT)?;
    RinsConfig::parse(&text, &path.display().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    /// A fresh 0700 directory of this test's own, removed at the end.
    struct PrivateDir(PathBuf);

    impl PrivateDir {
        fn new(name: &str) -> Self {
            let path =
                std::env::temp_dir().join(format!("rins-resolved-{name}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&path);
            std::fs::create_dir(&path).unwrap();
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o700)).unwrap();
            Self(path)
        }

        fn path(&self) -> &Path {
            &self.0
        }
    }

    impl Drop for PrivateDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    #[test]
    fn a_resolved_configuration_reads_back_identically() {
        let mut cfg = super::super::load(None).unwrap();
        cfg.set_imu_rate(2000.0).unwrap();
        cfg.enable_gnss();
        cfg.acquisition.port = Some("/run/rins/sim-tty".into());
        cfg.realtime.enabled = true;
        cfg.sim.seed = 12345;
        let dir = PrivateDir::new("round-trip");
        let path = write(&cfg, dir.path()).unwrap();
        let mode = std::fs::metadata(&path).unwrap().mode() & 0o777;
        assert_eq!(mode, 0o600);
        assert_eq!(load(&path).unwrap(), cfg);
        // A second run replaces its own previous file.
        cfg.sim.seed = 7;
        let again = write(&cfg, dir.path()).unwrap();
        assert_eq!(load(&again).unwrap().sim.seed, 7);
    }

    #[test]
    fn a_file_others_may_touch_or_a_link_is_refused() {
        let dir = PrivateDir::new("refused");
        let open = dir.path().join("open.toml");
        std::fs::write(&open, "").unwrap();
        std::fs::set_permissions(&open, std::fs::Permissions::from_mode(0o644)).unwrap();
        let err = format!("{:#}", load(&open).unwrap_err());
        assert!(
            err.contains("mode 0644") && err.contains("not used"),
            "{err}"
        );
        let link = dir.path().join("link.toml");
        std::os::unix::fs::symlink(&open, &link).unwrap();
        let err = format!("{:#}", load(&link).unwrap_err());
        assert!(
            err.contains("symbolic link") || err.contains("link"),
            "{err}"
        );
    }
}
