//! Directories that only their owner may touch: the IPC root and the run directory under it. Another
//! local user who can write where such a directory is expected (a world-writable /tmp) could plant a
//! file, a symbolic link to a directory of theirs or of someone else's, or a directory of their own
//! there; a process that used it blindly would fail to start, write through the link or trust what
//! that user put inside. So the path is inspected without following a symbolic link, and refused
//! unless it is a directory owned by the expected user with no group or other permission.

use std::fmt;
use std::fs::Metadata;
use std::os::unix::fs::{DirBuilderExt, MetadataExt};
use std::path::{Path, PathBuf};

use crate::user;

/// Permission bits a private directory must not have: any access by group or others.
const GROUP_OTHER_BITS: u32 = 0o077;

pub use rins_regular_file::kind_of;

/// A path that is not a private directory of the expected user, with what was found there.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NotPrivate {
    /// The path checked.
    pub path: PathBuf,
    /// What it is ("directory", "file", …), for the message.
    pub kind: &'static str,
    /// Its owner's uid.
    pub owner: u32,
    /// Its permission bits.
    pub mode: u32,
    /// The uid that should own it.
    pub expected_owner: u32,
}

impl fmt::Display for NotPrivate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let path = self.path.display();
        write!(
            f,
            "{path} is not a private directory: found a {} owned by {}, mode {:04o}; expected a directory owned by {}, mode 0700. ",
            self.kind,
            user::describe(self.owner),
            self.mode & 0o7777,
            user::describe(self.expected_owner),
        )?;
        if self.kind != "directory" {
            write!(
                f,
                "Another user may have planted it: remove it (it is not followed or used) or choose another directory."
            )
        } else if self.owner != self.expected_owner {
            write!(
                f,
                "It belongs to another user, who controls what is in it: choose another directory."
            )
        } else {
            write!(
                f,
                "Others may read or write it: `chmod 0700 {path}` or choose another directory."
            )
        }
    }
}

impl std::error::Error for NotPrivate {}

/// `path` without trailing slashes: `link/` names the directory a link points to, so a path
/// inspected with a trailing slash would be followed after all.
pub fn without_trailing_slash(path: &Path) -> &Path {
    let bytes = path.as_os_str().as_encoded_bytes();
    let mut end = bytes.len();
    while end > 1 && bytes[end - 1] == b'/' {
        end -= 1;
    }
    Path::new(
        std::str::from_utf8(&bytes[..end])
            .map(std::ffi::OsStr::new)
            .unwrap_or(path.as_os_str()),
    )
}

/// Checks, without following a symbolic link at `path`, that it is a directory owned by `owner`
/// with no group or other permission.
pub fn verify(path: &Path, owner: u32) -> anyhow::Result<()> {
    let path = without_trailing_slash(path);
    let meta = std::fs::symlink_metadata(path)
        .map_err(|e| anyhow::anyhow!("cannot inspect {}: {e}", path.display()))?;
    check(path, &meta, owner).map_err(anyhow::Error::from)
}

/// The test of [`verify`] on metadata already read.
pub fn check(path: &Path, meta: &Metadata, owner: u32) -> Result<(), NotPrivate> {
    let private =
        meta.file_type().is_dir() && meta.uid() == owner && meta.mode() & GROUP_OTHER_BITS == 0;
    if private {
        Ok(())
    } else {
        Err(NotPrivate {
            path: path.to_path_buf(),
            kind: kind_of(meta),
            owner: meta.uid(),
            mode: meta.mode(),
            expected_owner: owner,
        })
    }
}

/// Creates `path` mode 0700 when it is missing (missing parents too, likewise), then [`verify`]s
/// it. Returns whether this call created it: only its creator may remove it again. An entry that
/// appears between the two steps is verified like any existing one: mkdir(2) never follows a link.
pub fn ensure(path: &Path, owner: u32) -> anyhow::Result<bool> {
    let path = without_trailing_slash(path);
    let created = match std::fs::DirBuilder::new().mode(0o700).create(path) {
        Ok(()) => true,
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => false,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            std::fs::DirBuilder::new()
                .mode(0o700)
                .recursive(true)
                .create(path)
                .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", path.display()))?;
            true
        }
        Err(e) => return Err(anyhow::anyhow!("cannot create {}: {e}", path.display())),
    };
    verify(path, owner)?;
    Ok(created)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    fn scratch(name: &str) -> PathBuf {
        let dir = rins_test_support::scratch::scratch_dir("private-dir", name);
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700)).unwrap();
        dir
    }

    fn not_private(path: &Path, owner: u32) -> NotPrivate {
        verify(path, owner)
            .unwrap_err()
            .downcast::<NotPrivate>()
            .unwrap()
    }

    #[test]
    fn creates_a_missing_directory_mode_0700_once() {
        let base = scratch("create");
        let me = user::effective_uid();
        let dir = base.join("a/b");
        assert!(ensure(&dir, me).unwrap());
        let meta = std::fs::symlink_metadata(&dir).unwrap();
        assert_eq!(meta.mode() & 0o777, 0o700);
        assert!(!ensure(&dir, me).unwrap(), "second call must not claim it");
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn a_symbolic_link_to_a_private_directory_is_refused_not_followed() {
        let base = scratch("link");
        let me = user::effective_uid();
        let target = base.join("target");
        std::fs::create_dir(&target).unwrap();
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o700)).unwrap();
        std::fs::write(target.join("keep"), "x").unwrap();
        let link = base.join("root");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        let e = not_private(&link, me);
        assert_eq!(e.kind, "symbolic link");
        let msg = e.to_string();
        assert!(msg.contains(&link.display().to_string()), "{msg}");
        assert!(msg.contains("planted"), "{msg}");
        assert!(ensure(&link, me).is_err());
        assert!(target.join("keep").exists());
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn a_trailing_slash_does_not_follow_a_link() {
        assert_eq!(
            without_trailing_slash(Path::new("/tmp/x//")),
            Path::new("/tmp/x")
        );
        assert_eq!(without_trailing_slash(Path::new("/")), Path::new("/"));
        let base = scratch("slash");
        let link = base.join("root");
        std::os::unix::fs::symlink(&base, &link).unwrap();
        let with_slash = PathBuf::from(format!("{}/", link.display()));
        assert_eq!(
            not_private(&with_slash, user::effective_uid()).kind,
            "symbolic link"
        );
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn a_plain_file_where_the_directory_belongs_is_refused() {
        let base = scratch("file");
        let path = base.join("root");
        std::fs::write(&path, "").unwrap();
        let e = not_private(&path, user::effective_uid());
        assert_eq!(e.kind, "regular file");
        assert!(ensure(&path, user::effective_uid()).is_err());
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn group_or_other_permission_is_refused() {
        let base = scratch("mode");
        let me = user::effective_uid();
        for mode in [0o755, 0o770, 0o701, 0o1777] {
            std::fs::set_permissions(&base, std::fs::Permissions::from_mode(mode)).unwrap();
            let e = not_private(&base, me);
            assert_eq!(e.mode & 0o7777, mode, "{e}");
            assert!(e.to_string().contains("chmod 0700"), "{e}");
        }
        std::fs::set_permissions(&base, std::fs::Permissions::from_mode(0o700)).unwrap();
        verify(&base, me).unwrap();
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn another_users_directory_is_refused() {
        // Our own directory checked against another uid: the same test as a directory of theirs
        // checked against ours, and it needs no second user.
        let base = scratch("owner");
        let other = user::effective_uid().wrapping_add(1);
        let e = not_private(&base, other);
        assert_eq!(e.owner, user::effective_uid());
        assert!(e.to_string().contains("belongs to another user"), "{e}");
        std::fs::remove_dir_all(&base).unwrap();
    }
}
