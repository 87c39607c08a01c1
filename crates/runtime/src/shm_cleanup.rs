//! Removal of a deployment's shared memory and iceoryx2 records, for clean shutdown and tests — of
//! what is ours only. /dev/shm is writable by every local user, and the root may be a directory
//! that held other things before the deployment used it: so nothing is followed through a symbolic
//! link, nothing owned by another user is touched, and no directory is removed that is not empty.

use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::Path;

use crate::ipc::IpcSettings;
use crate::user;

/// Where iceoryx2 keeps its shared-memory segments.
pub const SHM_DIR: &str = "/dev/shm";

/// A /dev/shm entry named with a deployment's prefix, as lstat(2) sees it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShmEntry {
    /// The file name in /dev/shm.
    pub name: String,
    /// Its owner's uid.
    pub owner: u32,
    /// A regular file (iceoryx2 segments are); anything else was not made by iceoryx2.
    pub regular: bool,
}

impl ShmEntry {
    /// Whether this entry may be a segment of `uid`'s deployment.
    pub fn belongs_to(&self, uid: u32) -> bool {
        self.regular && self.owner == uid
    }
}

/// Names of the shared-memory objects under /dev/shm of this prefix, whoever owns them.
pub fn shm_entries(settings: &IpcSettings) -> Vec<String> {
    inspect(Path::new(SHM_DIR), &settings.prefix)
        .into_iter()
        .map(|e| e.name)
        .collect()
}

/// Every entry of `dir` named with `prefix`, with its owner and kind (never followed).
pub fn inspect(dir: &Path, prefix: &str) -> Vec<ShmEntry> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            if !name.starts_with(prefix) {
                return None;
            }
            // DirEntry::metadata does not follow a symbolic link.
            let meta = e.metadata().ok()?;
            Some(ShmEntry {
                name,
                owner: meta.uid(),
                regular: meta.file_type().is_file(),
            })
        })
        .collect()
}

/// The entries of this prefix in /dev/shm that are not `owner`'s regular files: another user
/// planted them or runs a deployment on the prefix. They are never opened or removed.
pub fn foreign_entries(settings: &IpcSettings, owner: u32) -> Vec<ShmEntry> {
    inspect(Path::new(SHM_DIR), &settings.prefix)
        .into_iter()
        .filter(|e| !e.belongs_to(owner))
        .collect()
}

/// One line per entry for messages: `/dev/shm/NAME (owner, kind)`.
pub fn describe_entries(entries: &[ShmEntry]) -> String {
    entries
        .iter()
        .map(|e| {
            format!(
                "{SHM_DIR}/{} (owned by {}{})",
                e.name,
                user::describe(e.owner),
                if e.regular {
                    ""
                } else {
                    ", not a regular file"
                }
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Removes this deployment's shared memory and its records under the root: the /dev/shm entries of
/// the prefix that are regular files of this process's user, and under the root what this user
/// owns and named with the prefix (empty directories iceoryx2 made, too). The root itself goes only
/// when `remove_root` (this run created it) and it is empty. Call only when no process of the
/// deployment runs any more. Returns how many /dev/shm entries were removed.
pub fn remove_all(settings: &IpcSettings, remove_root: bool) -> usize {
    let uid = user::effective_uid();
    let removed = remove_owned_shm(Path::new(SHM_DIR), &settings.prefix, uid);
    let root = crate::private_dir::without_trailing_slash(Path::new(&settings.root));
    clean_root(root, &settings.prefix, uid);
    if remove_root {
        // rmdir(2): only an empty directory, never a link's target.
        let _ = std::fs::remove_dir(root);
    }
    removed
}

/// Removes the regular files of `dir` named with `prefix` that `uid` owns; returns how many.
pub fn remove_owned_shm(dir: &Path, prefix: &str, uid: u32) -> usize {
    inspect(dir, prefix)
        .into_iter()
        .filter(|e| e.belongs_to(uid))
        .filter(|e| std::fs::remove_file(dir.join(&e.name)).is_ok())
        .count()
}

/// Deepest directory level the walk of a root descends to (iceoryx2 uses two: `nodes/ID/`).
const MAX_DEPTH: usize = 4;

/// Removes, in the root `root` (itself already verified private), what `uid` owns and iceoryx2 or
/// rins made for `prefix`: entries named with the prefix (the whole of such a directory, e.g. the
/// run directory), and directories that this leaves empty. A symbolic link is removed, when ours,
/// never followed; entries of other users and of other prefixes stay.
pub fn clean_root(root: &Path, prefix: &str, uid: u32) {
    clean_dir(root, prefix, uid, false, 0);
}

fn clean_dir(dir: &Path, prefix: &str, uid: u32, all_ours: bool, depth: usize) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.filter_map(|e| e.ok()) {
        let Ok(meta) = entry.metadata() else {
            continue;
        };
        if meta.uid() != uid {
            continue;
        }
        let path = entry.path();
        let named = all_ours || entry.file_name().to_string_lossy().starts_with(prefix);
        let kind = meta.file_type();
        if kind.is_dir() {
            if depth < MAX_DEPTH {
                clean_dir(&path, prefix, uid, named, depth + 1);
            }
            // Fails, harmlessly, while anything is left in it.
            let _ = std::fs::remove_dir(&path);
        } else if named && (kind.is_file() || kind.is_symlink() || kind.is_socket()) {
            let _ = std::fs::remove_file(&path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        rins_test_support::scratch::scratch_dir("shm-cleanup", name)
    }

    #[test]
    fn only_our_regular_files_of_the_prefix_are_removed() {
        let dir = scratch("shm");
        let me = user::effective_uid();
        std::fs::write(dir.join("p_seg.data"), "x").unwrap();
        std::fs::write(dir.join("other_seg.data"), "x").unwrap();
        let target = dir.join("precious");
        std::fs::write(&target, "keep").unwrap();
        std::os::unix::fs::symlink(&target, dir.join("p_link")).unwrap();
        std::fs::create_dir(dir.join("p_dir")).unwrap();
        let seen = inspect(&dir, "p_");
        assert_eq!(seen.len(), 3, "{seen:?}");
        assert!(!seen.iter().find(|e| e.name == "p_link").unwrap().regular);
        // Removing as another user removes nothing.
        assert_eq!(remove_owned_shm(&dir, "p_", me.wrapping_add(1)), 0);
        assert_eq!(remove_owned_shm(&dir, "p_", me), 1);
        assert!(!dir.join("p_seg.data").exists());
        assert!(dir.join("other_seg.data").exists());
        assert!(dir.join("p_link").symlink_metadata().is_ok());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
        assert!(dir.join("p_dir").is_dir());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_root_walk_removes_our_records_and_nothing_else() {
        let root = scratch("root");
        let me = user::effective_uid();
        // What iceoryx2 and rins make: prefixed files at the top and in nodes/ID/, a run directory.
        std::fs::create_dir_all(root.join("nodes/123")).unwrap();
        std::fs::write(root.join("nodes/123/p_1.port_tag"), "").unwrap();
        std::fs::write(root.join("nodes/p_123.node_monitor"), "").unwrap();
        std::fs::create_dir(root.join("services")).unwrap();
        std::fs::write(root.join("services/p_abc.service"), "").unwrap();
        std::fs::create_dir(root.join("p_run")).unwrap();
        std::fs::write(root.join("p_run/acquisition.resume"), "").unwrap();
        // What was there before, or belongs to another prefix, and a link out of the root.
        std::fs::write(root.join("notes.txt"), "mine").unwrap();
        std::fs::write(root.join("services/q_abc.service"), "").unwrap();
        let outside = scratch("outside");
        std::fs::write(outside.join("p_victim"), "keep").unwrap();
        std::os::unix::fs::symlink(&outside, root.join("p_run/sim-tty")).unwrap();
        std::os::unix::fs::symlink(&outside, root.join("linked")).unwrap();

        // Another user's walk touches nothing.
        clean_root(&root, "p_", me.wrapping_add(1));
        assert!(root.join("nodes/123/p_1.port_tag").exists());

        clean_root(&root, "p_", me);
        assert!(
            !root.join("nodes").exists(),
            "empty iceoryx2 directories go"
        );
        assert!(!root.join("p_run").exists());
        assert!(!root.join("services/p_abc.service").exists());
        assert!(root.join("services/q_abc.service").exists());
        assert_eq!(
            std::fs::read_to_string(root.join("notes.txt")).unwrap(),
            "mine"
        );
        assert!(root.join("linked").symlink_metadata().is_ok());
        assert_eq!(
            std::fs::read_to_string(outside.join("p_victim")).unwrap(),
            "keep"
        );
        std::fs::remove_dir_all(&root).unwrap();
        std::fs::remove_dir_all(&outside).unwrap();
    }
}
