//! The recordings directory: checked before anything is written there, its own recordings listed
//! (and only those: names of [`super::naming`], regular files of this user, never a link followed),
//! and the oldest of them chosen for deletion when a new file would pass the total.

use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use super::naming::{self, Sequence};

/// One of rins's own recordings in the directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OwnRecording {
    /// Its path.
    pub path: PathBuf,
    /// Its place among the recordings.
    pub seq: Sequence,
    /// Its size, bytes.
    pub bytes: u64,
}

/// Creates `dir` when missing (mode 0700, with its missing parents) and checks that it is a
/// directory of this user that nobody else may write to, without following a link: another user
/// able to write there could plant a link under a recording's name, or files rins would count as
/// its own. The error names `field` (where the directory came from) and what was found.
pub fn prepare(dir: &Path, field: &str) -> Result<()> {
    if let Err(e) = std::fs::symlink_metadata(dir)
        && e.kind() == std::io::ErrorKind::NotFound
    {
        std::fs::DirBuilder::new()
            .recursive(true)
            .mode(0o700)
            .create(dir)
            .with_context(|| format!("{field} {}: cannot create it", dir.display()))?;
    }
    let meta = std::fs::symlink_metadata(dir)
        .with_context(|| format!("{field} {}: cannot inspect it", dir.display()))?;
    // SAFETY: geteuid(2) has no preconditions and cannot fail.
    let uid = unsafe { libc::geteuid() };
    check(&meta, uid).map_err(|why| anyhow::anyhow!("{field} {}: {why}", dir.display()))
}

/// Why a directory of `meta` is no place for `uid`'s recordings; `Ok` when it is one.
fn check(meta: &std::fs::Metadata, uid: u32) -> Result<(), String> {
    let mode = meta.permissions().mode() & 0o7777;
    if meta.file_type().is_symlink() {
        return Err(
            "it is a symbolic link: name the directory itself, a link is never followed".into(),
        );
    }
    if !meta.is_dir() {
        return Err("it is not a directory".into());
    }
    if meta.uid() != uid {
        return Err(format!(
            "it belongs to uid {}, not to this user (uid {uid}): recordings go only into a \
             directory of the user running rins",
            meta.uid()
        ));
    }
    if mode & 0o022 != 0 {
        return Err(format!(
            "mode {mode:04o} lets other users write there: use a directory only its owner may \
             write to (chmod go-w, or 0700)"
        ));
    }
    Ok(())
}

/// rins's own recordings in `dir`, oldest first: names of [`naming`], regular files (a link is
/// skipped, never followed) of `uid`.
pub fn own_recordings(dir: &Path, uid: u32) -> Result<Vec<OwnRecording>> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("cannot list {}", dir.display()))? {
        let entry = entry.with_context(|| format!("cannot list {}", dir.display()))?;
        let Some(seq) = entry.file_name().to_str().and_then(naming::parse) else {
            continue;
        };
        // The entry's own metadata: a link is a link here, not what it points to.
        let Ok(meta) = entry.metadata() else {
            continue;
        };
        if meta.file_type().is_file() && meta.uid() == uid {
            found.push(OwnRecording {
                path: entry.path(),
                seq,
                bytes: meta.len(),
            });
        }
    }
    found.sort_by_key(|r| r.seq);
    Ok(found)
}

/// The run number after every run in `own`.
pub fn next_run(own: &[OwnRecording]) -> u64 {
    own.iter().map(|r| r.seq.run).max().map_or(1, |r| r + 1)
}

/// Which of `own` (oldest first) to delete, oldest first, so that they and a new file of up to
/// `reserve` bytes take at most `total` bytes; those in `in_use` (still being written) are kept
/// whatever their size.
pub fn to_delete(
    own: &[OwnRecording],
    in_use: &[Sequence],
    reserve: u64,
    total: u64,
) -> Vec<usize> {
    let mut sum: u64 = own
        .iter()
        .map(|r| r.bytes)
        .sum::<u64>()
        .saturating_add(reserve);
    let mut chosen = Vec::new();
    for (i, r) in own.iter().enumerate() {
        if sum <= total {
            break;
        }
        if !in_use.contains(&r.seq) {
            sum -= r.bytes;
            chosen.push(i);
        }
    }
    chosen
}

/// Deletes `own[i]` for each of `chosen`; the paths deleted, and why any could not be.
pub fn delete(own: &[OwnRecording], chosen: &[usize]) -> (Vec<PathBuf>, Vec<String>) {
    let mut deleted = Vec::new();
    let mut failed = Vec::new();
    for r in chosen.iter().filter_map(|&i| own.get(i)) {
        match std::fs::remove_file(&r.path) {
            Ok(()) => deleted.push(r.path.clone()),
            // Gone already (an operator copied it away): nothing to do.
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => failed.push(format!("cannot delete {}: {e}", r.path.display())),
        }
    }
    (deleted, failed)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(run: u64, part: u64, bytes: u64) -> OwnRecording {
        OwnRecording {
            path: PathBuf::from(format!("r{run}p{part}")),
            seq: Sequence { run, part },
            bytes,
        }
    }

    #[test]
    fn the_oldest_are_deleted_until_the_new_file_fits_and_files_in_use_are_kept() {
        let own = [
            rec(1, 1, 100),
            rec(1, 2, 50),
            rec(2, 1, 100),
            rec(3, 1, 100),
        ];
        // 350 held + 100 for the new file against 400: the oldest goes.
        assert_eq!(to_delete(&own, &[], 100, 400), vec![0]);
        // Against 250: the three oldest.
        assert_eq!(to_delete(&own, &[], 100, 250), vec![0, 1, 2]);
        // Everything fits: nothing.
        assert_eq!(to_delete(&own, &[], 100, 450), Vec::<usize>::new());
        // The file still being finished is skipped, the next oldest taken instead.
        let in_use = [Sequence { run: 1, part: 1 }];
        assert_eq!(to_delete(&own, &in_use, 100, 400), vec![1]);
        // Nothing else left to delete: what is in use stays even over the total.
        let all: Vec<Sequence> = own.iter().map(|r| r.seq).collect();
        assert!(to_delete(&own, &all, 100, 10).is_empty());
    }

    #[test]
    fn the_next_run_follows_the_highest() {
        assert_eq!(next_run(&[]), 1);
        assert_eq!(next_run(&[rec(7, 3, 1), rec(2, 9, 1)]), 8);
    }

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("rins-record-dir-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn a_directory_is_created_private_and_an_open_or_linked_one_is_refused() {
        let base = scratch("prepare");
        let dir = base.join("a/b");
        prepare(&dir, "record.dir").unwrap();
        let mode = std::fs::metadata(&dir).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o700);
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o777)).unwrap();
        let e = format!("{:#}", prepare(&dir, "record.dir").unwrap_err());
        assert!(
            e.starts_with(&format!("record.dir {}: mode 0777", dir.display()))
                && e.contains("other users write"),
            "{e}"
        );
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
        prepare(&dir, "record.dir").unwrap();
        let link = base.join("link");
        std::os::unix::fs::symlink(&dir, &link).unwrap();
        let e = format!("{:#}", prepare(&link, "record.dir").unwrap_err());
        assert!(e.contains("symbolic link"), "{e}");
        let file = base.join("file");
        std::fs::write(&file, b"").unwrap();
        let e = format!("{:#}", prepare(&file, "--dir").unwrap_err());
        assert!(
            e.starts_with("--dir ") && e.contains("not a directory"),
            "{e}"
        );
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn only_own_named_regular_files_are_listed() {
        let dir = scratch("list");
        prepare(&dir, "d").unwrap();
        let t = std::time::UNIX_EPOCH;
        let name = |run, part| naming::file_name(Sequence { run, part }, t);
        std::fs::write(dir.join(name(2, 1)), b"12345").unwrap();
        std::fs::write(dir.join(name(1, 2)), b"123").unwrap();
        std::fs::write(dir.join("flight.mcap"), b"x").unwrap();
        std::fs::create_dir(dir.join(name(0, 1))).unwrap();
        let outside = scratch("list-outside");
        std::fs::write(&outside, b"precious").unwrap();
        std::os::unix::fs::symlink(&outside, dir.join(name(0, 2))).unwrap();
        // SAFETY: geteuid(2) has no preconditions.
        let uid = unsafe { libc::geteuid() };
        let own = own_recordings(&dir, uid).unwrap();
        let seen: Vec<(u64, u64, u64)> = own
            .iter()
            .map(|r| (r.seq.run, r.seq.part, r.bytes))
            .collect();
        assert_eq!(seen, vec![(1, 2, 3), (2, 1, 5)]);
        // Another user's files are not ours to count or delete.
        assert!(own_recordings(&dir, uid + 1).unwrap().is_empty());
        let (deleted, failed) = delete(&own, &[0]);
        assert_eq!(
            (deleted, failed),
            (vec![dir.join(name(1, 2))], Vec::<String>::new())
        );
        assert_eq!(std::fs::read(&outside).unwrap(), b"precious");
        std::fs::remove_dir_all(&dir).unwrap();
        std::fs::remove_file(&outside).unwrap();
    }
}
