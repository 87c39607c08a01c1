//! What a tool (`rins echo`, `status`, `latency`, `inject`, `readmit`, `soak`) checks before it joins
//! a deployment: that the deployment belongs to the user it expects. Anyone can create shared memory
//! under any prefix; a tool that read whatever it found there would show another user's stream as
//! the navigation solution, and one that sent commands would send them to that user's processes.

use std::path::Path;

use anyhow::{Result, bail};

use crate::ipc::{IpcSettings, OWNER_ENV, PREFIX_ENV, ROOT_ENV};
use crate::{private_dir, shm_cleanup, user};

/// The settings of the deployment a tool is to join (`RINS_IPC_PREFIX`, `RINS_IPC_ROOT`,
/// `RINS_IPC_OWNER`), once [`check_joinable`] found it to be the expected user's. Every command
/// that joins a deployment starts here.
pub fn settings_to_join() -> Result<IpcSettings> {
    let settings = IpcSettings::joining_from_env()?;
    settings.check_name_lengths()?;
    check_joinable(&settings)?;
    Ok(settings)
}

/// Refuses unless the root is a private directory of `settings.owner` (or missing, when the owner
/// is this process's user, who will create it) and every /dev/shm entry of the prefix is a regular
/// file of that owner. The error says whose the deployment is and how to trust it.
pub fn check_joinable(settings: &IpcSettings) -> Result<()> {
    let root = private_dir::without_trailing_slash(Path::new(&settings.root));
    match std::fs::symlink_metadata(root) {
        Ok(meta) => {
            if let Err(e) = private_dir::check(root, &meta, settings.owner) {
                bail!(
                    "{ROOT_ENV}: {e}{}",
                    trust_hint(e.owner, e.kind == "directory")
                );
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            if settings.owner != user::effective_uid() {
                bail!(
                    "no deployment of {} at {} ({ROOT_ENV}): it does not exist",
                    user::describe(settings.owner),
                    root.display()
                );
            }
        }
        Err(e) => bail!("cannot inspect {}: {e}", root.display()),
    }
    let foreign = shm_cleanup::foreign_entries(settings, settings.owner);
    if let Some(first) = foreign.first() {
        bail!(
            "the shared memory on IPC prefix {:?} is not {}'s: {}. Another user runs a deployment on \
             this prefix or planted these files; nothing of it is read.{}",
            settings.prefix,
            user::describe(settings.owner),
            shm_cleanup::describe_entries(&foreign),
            trust_hint(first.owner, first.regular)
        );
    }
    Ok(())
}

/// How to join the deployment of `owner` on purpose; nothing to say for something that is not a
/// deployment at all (a planted link or file).
fn trust_hint(owner: u32, could_be_deployment: bool) -> String {
    if !could_be_deployment {
        return format!(
            " Use your own deployment ({PREFIX_ENV}, {ROOT_ENV}) or remove what was planted."
        );
    }
    format!(
        " To read {}'s deployment on purpose, set {OWNER_ENV}={}; otherwise use your own ({PREFIX_ENV}, {ROOT_ENV}).",
        user::describe(owner),
        owner
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    fn settings(name: &str, owner: u32) -> IpcSettings {
        let prefix = format!("rjc{}_{name}_", std::process::id());
        let root = std::env::temp_dir().join(format!("{prefix}root"));
        let mut s = IpcSettings::new(prefix, root.to_string_lossy().into_owned());
        s.owner = owner;
        s
    }

    #[test]
    fn a_missing_root_of_our_own_is_fine_and_another_users_is_not() {
        let me = user::effective_uid();
        check_joinable(&settings("missing", me)).unwrap();
        let err = check_joinable(&settings("missing_other", me.wrapping_add(1)))
            .unwrap_err()
            .to_string();
        assert!(err.contains("does not exist"), "{err}");
    }

    #[test]
    fn a_root_or_segment_of_another_user_is_refused_with_whose_it_is() {
        let me = user::effective_uid();
        let s = settings("ours", me);
        s.ensure_root().unwrap();
        check_joinable(&s).unwrap();
        // The same root, expected to be someone else's: refused, naming us as the owner found.
        let mut theirs = s.clone();
        theirs.owner = me.wrapping_add(1);
        let err = check_joinable(&theirs).unwrap_err().to_string();
        assert!(err.contains("belongs to another user"), "{err}");
        assert!(err.contains(&format!("{OWNER_ENV}={me}")), "{err}");

        // A link planted on the prefix: not a segment, refused without being followed.
        let link = Path::new(shm_cleanup::SHM_DIR).join(format!("{}link", s.prefix));
        std::os::unix::fs::symlink("/etc/passwd", &link).unwrap();
        let err = check_joinable(&s).unwrap_err().to_string();
        assert!(err.contains(&link.display().to_string()), "{err}");
        assert!(err.contains("not a regular file"), "{err}");
        std::fs::remove_file(&link).unwrap();

        // A segment of another user on the prefix.
        let seg = Path::new(shm_cleanup::SHM_DIR).join(format!("{}seg", s.prefix));
        std::fs::write(&seg, "x").unwrap();
        check_joinable(&s).unwrap();
        if me == 0 {
            let c = std::ffi::CString::new(seg.to_string_lossy().as_bytes()).unwrap();
            // SAFETY: a valid NUL-terminated path.
            assert_eq!(unsafe { libc::chown(c.as_ptr(), 65534, 65534) }, 0);
            let err = check_joinable(&s).unwrap_err().to_string();
            assert!(err.contains(&seg.display().to_string()), "{err}");
            assert!(
                err.contains("uid 65534") && err.contains("RINS_IPC_OWNER=65534"),
                "{err}"
            );
            assert!(seg.exists(), "never removed");
        } else {
            eprintln!("note: not root; another user's segment is not planted");
        }
        std::fs::remove_file(&seg).unwrap();
        std::fs::set_permissions(&s.root, std::fs::Permissions::from_mode(0o700)).unwrap();
        std::fs::remove_dir(&s.root).unwrap();
    }
}
