//! The deployment's iceoryx2 configuration as a file, for programs that are not rins processes (a
//! Python or C++ consumer): they cannot compute the prefix and root the way
//! [`IpcSettings::iceoryx_config`] does, but every iceoryx2 binding can load a configuration file.
//!
//! `rins up` writes it at start to [`IpcSettings::iceoryx_config_file`]
//! (`<root>/<prefix>run/iceoryx2.toml`) and removes it at stop, so its presence also tells a consumer
//! that a deployment is (or was, after a crash) there. The run directory is private to the
//! deployment's user, and the file is still written as if another user could reach it: created anew
//! under a temporary name, never through a symbolic link, mode 0600, then renamed into place, so a
//! reader never sees half a file.

use std::path::{Path, PathBuf};

use super::error::{IpcError, OtherError};
use super::settings::IpcSettings;

/// The file's name in the run directory.
pub const CONFIG_FILE_NAME: &str = "iceoryx2.toml";

impl IpcSettings {
    /// Where `rins up` writes the deployment's iceoryx2 configuration: [`CONFIG_FILE_NAME`] in
    /// [`Self::run_dir`].
    pub fn iceoryx_config_file(&self) -> PathBuf {
        self.run_dir().join(CONFIG_FILE_NAME)
    }

    /// [`Self::iceoryx_config`] as iceoryx2 reads it from a file (TOML).
    pub fn iceoryx_config_toml(&self) -> Result<String, IpcError> {
        toml::to_string(&self.iceoryx_config()?).map_err(|source| IpcError::ConfigEncode { source })
    }

    /// Writes [`Self::iceoryx_config_toml`] to [`Self::iceoryx_config_file`], replacing an earlier
    /// one; the run directory is created (and verified private) when missing. Returns the path.
    pub fn write_iceoryx_config_file(&self) -> Result<PathBuf, IpcError> {
        let text = self.iceoryx_config_toml()?;
        let dir = self.ensure_run_dir()?;
        let path = dir.join(CONFIG_FILE_NAME);
        let tmp = dir.join(format!("{CONFIG_FILE_NAME}.tmp"));
        write_new_private_file(&tmp, text.as_bytes())
            .and_then(|()| std::fs::rename(&tmp, &path).map_err(OtherError::from))
            .map_err(|source| {
                let _ = std::fs::remove_file(&tmp);
                IpcError::ConfigFile {
                    path: path.clone(),
                    source,
                }
            })?;
        Ok(path)
    }

    /// Removes [`Self::iceoryx_config_file`] (unlink never follows a link); a missing file is fine.
    pub fn remove_iceoryx_config_file(&self) {
        let _ = std::fs::remove_file(self.iceoryx_config_file());
    }
}

/// Writes `bytes` to a file that must not exist yet (a stale one is unlinked first: unlink never
/// follows a link), opened without following a link, mode 0600.
pub(super) fn write_new_private_file(path: &Path, bytes: &[u8]) -> Result<(), OtherError> {
    use std::io::Write;
    use std::os::unix::fs::OpenOptionsExt;
    let _ = std::fs::remove_file(path);
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o600)
        .custom_flags(libc::O_NOFOLLOW)
        .open(path)?;
    file.write_all(bytes)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use iceoryx2::prelude::{Config, FilePath, SemanticString};
    use std::os::unix::fs::MetadataExt;

    #[test]
    fn the_file_is_private_and_loads_as_the_same_configuration() {
        let base = std::env::temp_dir().join(format!("rins-ipc-config-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        std::fs::create_dir(&base).unwrap();
        let settings = IpcSettings::new("cfgfile_", base.join("root").to_string_lossy());
        let path = settings.write_iceoryx_config_file().unwrap();
        assert_eq!(path, settings.run_dir().join("iceoryx2.toml"));
        let meta = std::fs::symlink_metadata(&path).unwrap();
        assert!(meta.file_type().is_file());
        assert_eq!(meta.mode() & 0o777, 0o600);
        // Written again over the first (a restart after a crash): still one private file.
        settings.write_iceoryx_config_file().unwrap();
        let loaded =
            Config::from_file(&FilePath::new(path.to_string_lossy().as_bytes()).unwrap()).unwrap();
        assert_eq!(loaded, settings.iceoryx_config().unwrap());
        assert_eq!(loaded.global.prefix.to_string(), "cfgfile_");
        assert!(!settings.run_dir().join("iceoryx2.toml.tmp").exists());
        settings.remove_iceoryx_config_file();
        assert!(!path.exists());
        settings.remove_iceoryx_config_file();

        // Links planted at the file and at its temporary name are replaced, never written through.
        let secret = base.join("secret");
        std::fs::write(&secret, "secret").unwrap();
        std::os::unix::fs::symlink(&secret, &path).unwrap();
        std::os::unix::fs::symlink(&secret, settings.run_dir().join("iceoryx2.toml.tmp")).unwrap();
        settings.write_iceoryx_config_file().unwrap();
        assert_eq!(std::fs::read_to_string(&secret).unwrap(), "secret");
        assert!(
            std::fs::symlink_metadata(&path)
                .unwrap()
                .file_type()
                .is_file()
        );
        std::fs::remove_dir_all(&base).unwrap();
    }
}
