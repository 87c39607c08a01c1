//! iceoryx2's management segment of a deployment (`/dev/shm/<prefix>…_node.0_10_0.global_mgmt`):
//! the counter every node creation takes its id from. iceoryx2 0.10 makes it readable and writable
//! by every user (an explicit `fchmod` to 0666, which no umask narrows), so another user could
//! write into it and make every later node creation of the deployment fail, or truncate it and
//! make the next one wait for ever.
//!
//! So a rins process creates the segment itself before iceoryx2 comes to it: exclusively, without
//! following a link, write-only while it is filled (iceoryx2's own sign of a segment being set
//! up), then owner-only (0600). iceoryx2 opens an existing segment as it is and never changes its
//! mode. An existing segment is checked before use: a regular file of the deployment's owner,
//! long enough, holding iceoryx2's version. A damaged one is refused at once with its path and
//! what was found, instead of failing with an iceoryx2 error that names nothing, or hanging.

use std::io::{Read, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use iceoryx2::prelude::Config;

use super::error::IpcError;
use super::settings::IpcSettings;
use crate::{shm_cleanup, user};

/// SHA-1 (hex) of the type iceoryx2 keeps in the segment, which it puts in the segment's name.
/// Checked against the name iceoryx2 itself uses by the tests of this module.
const TYPE_HASH: &str = "9204dd183d1c4d8e1ff592a30766ffa6765aa8b5";
/// The segment's name within the deployment.
const NAME: &str = "node";
/// The iceoryx2 version that writes the segment, as it encodes it in the name and the contents.
const VERSION: [u16; 3] = [0, 10, 0];
/// The segment's length: the version (u64), the node counter (u32), padding to 8 bytes.
pub const SEGMENT_LEN: usize = 16;
/// Longest wait for a segment another process is filling (iceoryx2's own creation timeout).
const FILLING_WAIT: Duration = Duration::from_secs(1);

/// The version as iceoryx2 stores it in the segment's first 8 bytes.
fn version_word() -> u64 {
    (u64::from(VERSION[0]) << 32) | (u64::from(VERSION[1]) << 16) | u64::from(VERSION[2])
}

/// What a fresh segment holds: the version and a node counter of zero.
fn fresh_contents() -> [u8; SEGMENT_LEN] {
    let mut bytes = [0u8; SEGMENT_LEN];
    bytes[..8].copy_from_slice(&version_word().to_ne_bytes());
    bytes
}

/// The segment's file name for `prefix` under `config`.
pub fn segment_name(prefix: &str, config: &Config) -> String {
    let [major, minor, patch] = VERSION;
    format!(
        "{prefix}{TYPE_HASH}_{NAME}.{major}_{minor}_{patch}{}",
        config.global.node.global_mgmt_suffix
    )
}

/// Where the management segment of `settings`' deployment lives.
pub fn segment_path(settings: &IpcSettings, config: &Config) -> PathBuf {
    Path::new(shm_cleanup::SHM_DIR).join(segment_name(&settings.prefix, config))
}

/// What an existing segment was found to be.
#[derive(Debug, PartialEq, Eq)]
enum Found {
    /// Not there (any more).
    Missing,
    /// Write-only: its creator is still filling it.
    Filling,
    /// Fit for use.
    Ready,
}

fn damaged(path: &Path, problem: String) -> IpcError {
    IpcError::ManagementSegment {
        path: path.to_path_buf(),
        problem,
    }
}

/// Checks an existing segment without writing to it; one that is ours and open to others is made
/// owner-only (whoever opened it meanwhile keeps their descriptor: said in the warning).
fn inspect(path: &Path, owner: u32) -> Result<Found, IpcError> {
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path);
    let mut file = match file {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Found::Missing),
        Err(e) if e.raw_os_error() == Some(libc::ELOOP) => {
            return Err(damaged(path, "is a symbolic link".into()));
        }
        Err(e) => return Err(damaged(path, format!("cannot be opened: {e}"))),
    };
    let meta = file
        .metadata()
        .map_err(|e| damaged(path, format!("cannot be examined: {e}")))?;
    if !meta.file_type().is_file() {
        return Err(damaged(path, "is not a regular file".into()));
    }
    if meta.uid() != owner {
        return Err(damaged(
            path,
            format!(
                "belongs to uid {}, not to the deployment's owner (uid {owner})",
                meta.uid()
            ),
        ));
    }
    let mode = meta.mode() & 0o7777;
    if mode & 0o400 == 0 {
        return Ok(Found::Filling);
    }
    if meta.len() < SEGMENT_LEN as u64 {
        return Err(damaged(
            path,
            format!(
                "is {} bytes long where iceoryx2 writes {SEGMENT_LEN}: truncated or damaged",
                meta.len()
            ),
        ));
    }
    let mut word = [0u8; 8];
    file.read_exact(&mut word)
        .map_err(|e| damaged(path, format!("cannot be read: {e}")))?;
    let found = u64::from_ne_bytes(word);
    if found != version_word() {
        let [major, minor, patch] = VERSION;
        return Err(damaged(
            path,
            format!(
                "holds version word {found:#018x} where iceoryx2 {major}.{minor}.{patch} writes \
                 {:#018x}: damaged, or made by another iceoryx2 version",
                version_word()
            ),
        ));
    }
    if mode & 0o077 != 0 && meta.uid() == user::effective_uid() {
        // Made by another program (iceoryx2 itself, e.g. a consumer that is not rins) before any
        // rins process: narrowed now.
        file.set_permissions(std::fs::Permissions::from_mode(0o600))
            .map_err(|e| damaged(path, format!("cannot be made owner-only: {e}")))?;
        tracing::warn!(
            path = %path.display(),
            mode = format!("{mode:o}"),
            "iceoryx2's management segment was open to other users: made owner-only (a process that opened it before keeps its access)"
        );
    }
    Ok(Found::Ready)
}

/// Creates the segment owner-only, filled as iceoryx2 fills a new one. `Ok(false)` when it
/// exists already.
fn create_private(path: &Path) -> Result<bool, IpcError> {
    let file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o200)
        .custom_flags(libc::O_NOFOLLOW)
        .open(path);
    let mut file = match file {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => return Ok(false),
        Err(e) => return Err(damaged(path, format!("cannot be created: {e}"))),
    };
    let filled = file
        .write_all(&fresh_contents())
        .and_then(|()| file.set_permissions(std::fs::Permissions::from_mode(0o600)));
    if let Err(e) = filled {
        let _ = std::fs::remove_file(path);
        return Err(damaged(path, format!("cannot be written: {e}")));
    }
    Ok(true)
}

/// Makes sure the deployment's management segment is one iceoryx2 can open at once and no other
/// user can write: creates it owner-only when missing (only on a deployment of this process's own
/// user), checks it otherwise. A segment another process is still filling is waited for, at most
/// a second.
pub fn prepare(settings: &IpcSettings, config: &Config) -> Result<(), IpcError> {
    let path = segment_path(settings, config);
    let ours = settings.owner == user::effective_uid();
    let give_up = Instant::now() + FILLING_WAIT;
    loop {
        match inspect(&path, settings.owner)? {
            Found::Ready => return Ok(()),
            Found::Missing if !ours => return Ok(()),
            Found::Missing => {
                if create_private(&path)? {
                    return Ok(());
                }
            }
            Found::Filling if Instant::now() >= give_up => {
                return Err(damaged(
                    &path,
                    format!(
                        "stayed write-only (being set up) for more than {} s: its creator died \
                         or it was damaged",
                        FILLING_WAIT.as_secs()
                    ),
                ));
            }
            Found::Filling => std::thread::sleep(Duration::from_millis(1)),
        }
    }
}

/// Checks the deployment's management segment without creating it; `Ok` when it is missing or
/// fit for use. For a diagnosis when node creations keep failing.
pub fn check(settings: &IpcSettings) -> Result<(), IpcError> {
    let config = settings.iceoryx_config()?;
    inspect(&segment_path(settings, &config), settings.owner).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ipc::create_node;

    fn settings(name: &str) -> (IpcSettings, PathBuf) {
        let base = std::env::temp_dir().join(format!("rins-mgmt-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        std::fs::create_dir(&base).unwrap();
        let prefix = format!("mg{}{name}_", std::process::id());
        (
            IpcSettings::new(prefix, base.join("r").to_string_lossy().into_owned()),
            base,
        )
    }

    fn clean(settings: &IpcSettings, base: &Path) {
        for e in shm_cleanup::inspect(Path::new(shm_cleanup::SHM_DIR), &settings.prefix) {
            let _ = std::fs::remove_file(Path::new(shm_cleanup::SHM_DIR).join(&e.name));
        }
        let _ = std::fs::remove_dir_all(base);
    }

    /// Entries of the prefix in /dev/shm that end like a management segment.
    fn mgmt_entries(prefix: &str) -> Vec<String> {
        shm_cleanup::inspect(Path::new(shm_cleanup::SHM_DIR), prefix)
            .into_iter()
            .map(|e| e.name)
            .filter(|n| n.ends_with(".global_mgmt"))
            .collect()
    }

    /// The name, contents and layout assumed here are iceoryx2's own: a segment iceoryx2 made
    /// (a node created without rins' preparation) is found at the predicted path, as long and
    /// holding the same version word; and a segment prepared here is taken by iceoryx2 as it is.
    #[test]
    fn the_prepared_segment_is_iceoryx2s_own_and_stays_owner_only() {
        use iceoryx2::prelude::*;
        let (s, base) = settings("own");
        s.ensure_root().unwrap();
        let config = s.iceoryx_config().unwrap();
        let node = NodeBuilder::new()
            .config(&config)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .unwrap();
        let path = segment_path(&s, &config);
        assert_eq!(
            mgmt_entries(&s.prefix),
            vec![path.file_name().unwrap().to_string_lossy().into_owned()]
        );
        let meta = std::fs::metadata(&path).unwrap();
        // iceoryx2 alone opens it to everyone: what this module exists for.
        assert_eq!(meta.mode() & 0o777, 0o666);
        assert_eq!(meta.len(), SEGMENT_LEN as u64);
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes[..8], fresh_contents()[..8]);
        drop(node);
        clean(&s, &base);

        // Prepared first: created 0600, and iceoryx2 counts nodes in it without widening it.
        let (s, base) = settings("prep");
        let nodes: Vec<_> = (0..3)
            .map(|i| create_node(&format!("n{i}"), &s).unwrap())
            .collect();
        let path = segment_path(&s, &s.iceoryx_config().unwrap());
        let meta = std::fs::metadata(&path).unwrap();
        assert_eq!(meta.mode() & 0o777, 0o600);
        assert_eq!(mgmt_entries(&s.prefix).len(), 1);
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes[..8], fresh_contents()[..8]);
        assert_eq!(u32::from_ne_bytes(bytes[8..12].try_into().unwrap()), 3);
        drop(nodes);
        clean(&s, &base);
    }

    #[test]
    fn a_damaged_segment_is_refused_at_once_naming_it_and_what_was_found() {
        let (s, base) = settings("dmg");
        s.ensure_root().unwrap();
        let config = s.iceoryx_config().unwrap();
        let path = segment_path(&s, &config);
        let name = path.display().to_string();
        for (contents, expected) in [
            (Vec::new(), "is 0 bytes long where iceoryx2 writes 16"),
            (vec![0xFF; 16], "holds version word 0xffffffffffffffff"),
        ] {
            std::fs::write(&path, &contents).unwrap();
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
            let started = Instant::now();
            let Err(err) = create_node("dmg", &s) else {
                panic!("a damaged segment must be refused");
            };
            assert!(started.elapsed() < Duration::from_millis(500));
            let text = format!("{:#}", anyhow::Error::from(err));
            assert!(text.contains(&name) && text.contains(expected), "{text}");
            assert_eq!(std::fs::read(&path).unwrap(), contents, "left as found");
            assert!(check(&s).is_err());
        }
        // One left write-only (its creator died while filling it) is refused after a second.
        std::fs::write(&path, fresh_contents()).unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o200)).unwrap();
        let started = Instant::now();
        let Err(err) = create_node("dmg", &s) else {
            panic!("a segment left write-only must be refused");
        };
        let text = format!("{:#}", anyhow::Error::from(err));
        assert!(text.contains("stayed write-only"), "{text}");
        assert!(started.elapsed() < Duration::from_secs(3));
        // A sound segment made by someone else's iceoryx2 (mode 0666) is narrowed and used.
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o666)).unwrap();
        let node = create_node("dmg", &s).unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().mode() & 0o777, 0o600);
        assert!(check(&s).is_ok());
        drop(node);
        clean(&s, &base);
    }
}
