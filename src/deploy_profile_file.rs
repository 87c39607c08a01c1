//! The profile a deployment runs with, as a small file in its run directory: `rins up` writes it
//! before the first child starts and removes it at stop; `rins status` reads it, since the health
//! report on shared memory carries no text.
//!
//! The run directory is private to the deployment's user, and the file is still handled as if
//! another user could reach it: written anew under a temporary name, never through a symbolic
//! link, mode 0600, then renamed into place (a reader never sees half a file); read only when it
//! is a small regular file of the deployment's owner, closed to others, holding a known profile
//! and a printable reason. Anything else reads as "unknown", with why.

use std::io::{Read, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use rins_runtime::ipc::IpcSettings;
use rins_runtime::private_dir;
use serde::{Deserialize, Serialize};

use crate::deploy_profile::Plan;

/// The file's name in the run directory.
pub const FILE_NAME: &str = "deploy-profile.json";

/// Largest file read, bytes: a reason is a line.
const LIMIT: u64 = 4096;

/// Permission bits the file must not have: any access by group or others.
const GROUP_OTHER_BITS: u32 = 0o077;

/// The profile of a deployment as `rins status` prints it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileRecord {
    /// `shared`, `dedicated`, or `unknown` when no valid record was found.
    pub profile: String,
    /// Why that profile runs (or why it is unknown).
    pub profile_reason: String,
}

impl ProfileRecord {
    /// The record of `plan`.
    pub fn of(plan: &Plan) -> Self {
        Self {
            profile: plan.profile.name().to_string(),
            profile_reason: plan.reason.clone(),
        }
    }

    fn unknown(why: String) -> Self {
        Self {
            profile: "unknown".to_string(),
            profile_reason: why,
        }
    }

    /// "profile: dedicated — <reason>", a line.
    pub fn line(&self) -> String {
        format!("profile: {} — {}\n", self.profile, self.profile_reason)
    }

    fn check(self) -> Result<Self, String> {
        if !matches!(self.profile.as_str(), "shared" | "dedicated") {
            return Err(format!("it names no known profile ({:?})", self.profile));
        }
        if self.profile_reason.chars().any(char::is_control) {
            return Err("its reason holds control characters".to_string());
        }
        Ok(self)
    }
}

/// Writes `record` to [`FILE_NAME`] in `run_dir` (a private directory of this user); an earlier
/// file there is replaced. Returns its path.
pub fn write(run_dir: &Path, record: &ProfileRecord) -> Result<PathBuf> {
    let path = run_dir.join(FILE_NAME);
    let tmp = run_dir.join(format!("{FILE_NAME}.tmp"));
    let text = serde_json::to_string(record).context("cannot write the profile as JSON")?;
    // A stale temporary file (or a link planted at its name) goes first: unlink never follows a
    // link, and the creation below refuses anything that appears meanwhile.
    let _ = std::fs::remove_file(&tmp);
    let written = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o600)
        .custom_flags(libc::O_NOFOLLOW)
        .open(&tmp)
        .and_then(|mut file| file.write_all(text.as_bytes()))
        .and_then(|()| std::fs::rename(&tmp, &path));
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(e).with_context(|| format!("cannot write the profile to {}", path.display()));
    }
    Ok(path)
}

/// Removes the file from `run_dir` (unlink never follows a link); a missing file is fine.
pub fn remove(run_dir: &Path) {
    let _ = std::fs::remove_file(run_dir.join(FILE_NAME));
}

/// The profile of the deployment of `settings`, or "unknown" with why.
pub fn read(settings: &IpcSettings) -> ProfileRecord {
    let run_dir = settings.run_dir();
    let path = run_dir.join(FILE_NAME);
    if let Err(e) = private_dir::verify(&run_dir, settings.owner) {
        return ProfileRecord::unknown(format!("the run directory is not usable: {e}"));
    }
    match read_file(&path, settings.owner) {
        Ok(record) => record,
        Err(why) => ProfileRecord::unknown(format!("{}: {why}", path.display())),
    }
}

fn read_file(path: &Path, owner: u32) -> Result<ProfileRecord, String> {
    // O_NOFOLLOW: a link is refused, not followed; O_NONBLOCK: a FIFO does not block the open.
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK | libc::O_NOCTTY)
        .open(path)
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => {
                "missing (a rins up that predates --profile, or it is stopping)".to_string()
            }
            _ => format!("cannot open: {e}"),
        })?;
    // The open descriptor is inspected, not the path, which could be swapped in between.
    let meta = file
        .metadata()
        .map_err(|e| format!("cannot inspect: {e}"))?;
    if !meta.file_type().is_file() || meta.uid() != owner || meta.mode() & GROUP_OTHER_BITS != 0 {
        return Err(format!(
            "a {} owned by uid {}, mode {:04o}; expected a regular file owned by uid {owner}, \
             mode 0600: not used",
            private_dir::kind_of(&meta),
            meta.uid(),
            meta.mode() & 0o7777
        ));
    }
    let mut bytes = Vec::new();
    file.take(LIMIT + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read: {e}"))?;
    if bytes.len() as u64 > LIMIT {
        return Err(format!("more than the {LIMIT} bytes allowed"));
    }
    serde_json::from_slice::<ProfileRecord>(&bytes)
        .map_err(|e| format!("not a profile record: {e}"))?
        .check()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deploy_profile::{Load, RequestedProfile, plan};

    fn settings(name: &str) -> (IpcSettings, PathBuf) {
        let base = std::env::temp_dir().join(format!("rins-profile-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        std::fs::create_dir(&base).unwrap();
        let settings = IpcSettings::new("pf_", base.join("root").to_string_lossy());
        settings.ensure_run_dir().unwrap();
        (settings, base)
    }

    #[test]
    fn a_written_record_reads_back_and_a_removed_one_is_unknown() {
        let (settings, base) = settings("ok");
        let p = plan(
            RequestedProfile::Dedicated,
            &[0, 1, 2, 3],
            &Load::Average(0.0),
        )
        .unwrap();
        let record = ProfileRecord::of(&p);
        let path = write(&settings.run_dir(), &record).unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().mode() & 0o777, 0o600);
        assert_eq!(read(&settings), record);
        assert_eq!(
            record.line(),
            format!("profile: dedicated — {}\n", p.reason)
        );
        // Written again over the first (a restart after a crash).
        write(&settings.run_dir(), &record).unwrap();
        assert!(!settings.run_dir().join(format!("{FILE_NAME}.tmp")).exists());
        remove(&settings.run_dir());
        let missing = read(&settings);
        assert_eq!(missing.profile, "unknown");
        assert!(missing.profile_reason.contains("missing"), "{missing:?}");
        assert!(missing.line().starts_with("profile: unknown — "));
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn links_bad_modes_and_bad_contents_read_as_unknown() {
        let (settings, base) = settings("bad");
        let dir = settings.run_dir();
        let path = dir.join(FILE_NAME);
        let secret = base.join("secret");
        std::fs::write(&secret, r#"{"profile":"shared","profile_reason":"x"}"#).unwrap();
        std::os::unix::fs::symlink(&secret, &path).unwrap();
        assert_eq!(read(&settings).profile, "unknown");
        // Neither the link nor a link at the temporary name is written through.
        std::os::unix::fs::symlink(&secret, dir.join(format!("{FILE_NAME}.tmp"))).unwrap();
        let record = ProfileRecord {
            profile: "shared".into(),
            profile_reason: "y".into(),
        };
        write(&dir, &record).unwrap();
        assert!(std::fs::read_to_string(&secret).unwrap().contains("\"x\""));
        assert_eq!(read(&settings), record);
        for text in [
            "not json",
            r#"{"profile":"turbo","profile_reason":"x"}"#,
            "{\"profile\":\"shared\",\"profile_reason\":\"\\u001b[2J\"}",
        ] {
            std::fs::write(&path, text).unwrap();
            let r = read(&settings);
            assert_eq!(r.profile, "unknown", "{text}: {r:?}");
        }
        std::fs::write(&path, r#"{"profile":"shared","profile_reason":"x"}"#).unwrap();
        std::fs::set_permissions(&path, std::os::unix::fs::PermissionsExt::from_mode(0o644))
            .unwrap();
        assert!(read(&settings).profile_reason.contains("mode 0644"));
        std::fs::remove_dir_all(&base).unwrap();
    }
}
