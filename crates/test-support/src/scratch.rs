//! Fresh, empty directories for tests that touch the file system.

use std::path::PathBuf;

/// An empty directory `rins-{owner}-{pid}-{name}` under the system's temporary directory,
/// emptied first if an earlier run left it there: the owner (the module under test) and the
/// test's `name` keep tests running at once apart, the process id keeps test binaries apart.
pub fn scratch_dir(owner: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rins-{owner}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    if let Err(e) = std::fs::create_dir(&dir) {
        panic!("scratch directory {}: {e}", dir.display());
    }
    dir
}
