//! Removal of a deployment's shared memory and iceoryx2 records, for clean shutdown and tests.

use std::path::Path;

use crate::ipc::IpcSettings;

/// Shared-memory objects under /dev/shm that belong to this prefix.
pub fn shm_entries(settings: &IpcSettings) -> Vec<String> {
    let Ok(dir) = std::fs::read_dir("/dev/shm") else {
        return Vec::new();
    };
    dir.filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|name| name.starts_with(&settings.prefix))
        .collect()
}

/// Removes every shared-memory object of this prefix and the root directory. Call only when no
/// process of the deployment runs any more. Returns how many /dev/shm entries were removed.
pub fn remove_all(settings: &IpcSettings) -> usize {
    let mut removed = 0;
    for name in shm_entries(settings) {
        if std::fs::remove_file(Path::new("/dev/shm").join(&name)).is_ok() {
            removed += 1;
        }
    }
    let _ = std::fs::remove_dir_all(&settings.root);
    removed
}
