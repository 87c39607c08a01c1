//! The decoder's [`ResumePoint`] kept in a small file of the deployment's run directory, so that an
//! acquisition restarted by the watchdog continues the extended sequence numbers of the run it
//! replaces. Without it the numbers would start again from the 16-bit wire value, run backwards
//! downstream, and every consumer would take the new samples for old ones.
//!
//! The file is rewritten about once a second, by a write to a temporary file and a rename, so a
//! reader never sees half a file. A point up to a second old is good
//! enough: the extension only needs to be within 2^15 frames of the truth.
//!
//! The run directory is private to the deployment's user (verified before use), and the file is
//! still handled as if another user could reach it: the temporary file is created afresh, never
//! through a symbolic link, mode 0600; the point is read without following a link or blocking, and
//! used only from a small regular file of our own.

use std::io::{self, Read, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

use rins_protocol::{FrameType, ResumePoint};

const FIELDS: usize = FrameType::COUNT + 1;

/// How often the running acquisition saves its point.
pub const SAVE_PERIOD_NS: u64 = 1_000_000_000;

/// Largest file taken for a point: six numbers of at most 20 digits, their wire values and
/// separators are under two hundred bytes.
pub const MAX_FILE_BYTES: u64 = 512;

/// The file of the deployment on `settings`, in its run directory: removed with the deployment's
/// records and by `rins up` when a new deployment starts.
pub fn path_for(settings: &rins_runtime::ipc::IpcSettings) -> PathBuf {
    settings.run_dir().join("acquisition.resume")
}

/// `imu baro mag aux airspeed time_us` (one sequence per [`FrameType`], then the time), each `EXTENDED/WIRE` (the wire value it was given to; `EXTENDED`
/// alone when that is not known), `-` for a value not known yet.
pub fn format(point: &ResumePoint) -> String {
    let field = |v: Option<u64>, wire: Option<u64>| match (v, wire) {
        (Some(v), Some(w)) => format!("{v}/{w}"),
        (Some(v), None) => v.to_string(),
        (None, _) => "-".to_string(),
    };
    let mut fields: Vec<String> = point
        .seq
        .iter()
        .zip(point.seq_wire)
        .map(|(&s, w)| field(s, w.map(u64::from)))
        .collect();
    fields.push(field(point.time_us, point.time_wire.map(u64::from)));
    fields.join(" ")
}

/// One field of the file: `-`, `EXTENDED` or `EXTENDED/WIRE`; `None` when it is none of these.
fn parse_field(text: &str) -> Option<(Option<u64>, Option<u64>)> {
    if text == "-" {
        return Some((None, None));
    }
    match text.split_once('/') {
        Some((v, w)) => Some((Some(v.parse().ok()?), Some(w.parse().ok()?))),
        None => Some((Some(text.parse().ok()?), None)),
    }
}

/// The point in `text`, or `None` when it is not one (a corrupt file is ignored: the numbering
/// then starts from the wire values, as on a first start).
pub fn parse(text: &str) -> Option<ResumePoint> {
    let values: Vec<(Option<u64>, Option<u64>)> = text
        .split_whitespace()
        .map(parse_field)
        .collect::<Option<_>>()?;
    if values.len() != FIELDS {
        return None;
    }
    let mut point = ResumePoint::default();
    for (k, (value, wire)) in values[..FrameType::COUNT].iter().enumerate() {
        point.seq[k] = *value;
        point.seq_wire[k] = match wire {
            Some(w) => Some(u16::try_from(*w).ok()?),
            None => None,
        };
    }
    let (time, time_wire) = values[FrameType::COUNT];
    point.time_us = time;
    point.time_wire = match time_wire {
        Some(w) => Some(u32::try_from(w).ok()?),
        None => None,
    };
    Some(point)
}

/// Writes `point` to `path`: to `path.tmp` created anew (an existing one, or a link planted in
/// its place, is unlinked first; the open neither follows a link nor reuses a file), mode 0600,
/// then renamed over `path`.
pub fn save(path: &Path, point: &ResumePoint) -> io::Result<()> {
    let tmp = path.with_extension("tmp");
    match std::fs::remove_file(&tmp) {
        Ok(()) => {}
        Err(e) if e.kind() == io::ErrorKind::NotFound => {}
        Err(e) => return Err(e),
    }
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o600)
        .custom_flags(libc::O_NOFOLLOW)
        .open(&tmp)?;
    file.write_all(format(point).as_bytes())?;
    drop(file);
    std::fs::rename(&tmp, path)
}

/// What [`load`] found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Loaded {
    /// No file: a first start.
    Missing,
    /// A point written by an earlier run of this deployment.
    Point(ResumePoint),
    /// A file that is not to be trusted or not a point; the reason names the path.
    Ignored(String),
}

/// The saved point, read without following a link or blocking, from a regular file of this
/// process's user of at most [`MAX_FILE_BYTES`].
pub fn load(path: &Path) -> Loaded {
    let shown = path.display();
    let file = match std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK | libc::O_NOCTTY)
        .open(path)
    {
        Ok(file) => file,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Loaded::Missing,
        Err(e) => return Loaded::Ignored(format!("{shown}: cannot open ({e})")),
    };
    let meta = match file.metadata() {
        Ok(meta) => meta,
        Err(e) => return Loaded::Ignored(format!("{shown}: cannot inspect ({e})")),
    };
    let uid = rins_runtime::user::effective_uid();
    if !meta.file_type().is_file() {
        return Loaded::Ignored(format!(
            "{shown}: a {}, not a regular file",
            rins_runtime::private_dir::kind_of(&meta)
        ));
    }
    if meta.uid() != uid {
        return Loaded::Ignored(format!(
            "{shown}: owned by {}, not by {}",
            rins_runtime::user::describe(meta.uid()),
            rins_runtime::user::describe(uid)
        ));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Loaded::Ignored(format!(
            "{shown}: {} bytes, more than the {MAX_FILE_BYTES} of a resume point",
            meta.len()
        ));
    }
    let mut text = String::new();
    if let Err(e) = file.take(MAX_FILE_BYTES).read_to_string(&mut text) {
        return Loaded::Ignored(format!("{shown}: cannot read ({e})"));
    }
    match parse(&text) {
        Some(point) => Loaded::Point(point),
        None => Loaded::Ignored(format!("{shown}: not a resume point")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_rejects() {
        let point = ResumePoint {
            seq: [Some(65_547), None, Some(3), Some(u64::MAX), Some(4)],
            seq_wire: [Some(11), None, None, Some(65_535), Some(4)],
            time_us: Some(1 << 40),
            time_wire: Some(7),
        };
        assert_eq!(
            format(&point),
            "65547/11 - 3 18446744073709551615/65535 4/4 1099511627776/7"
        );
        assert_eq!(parse(&format(&point)), Some(point));
        assert_eq!(
            parse(&format(&ResumePoint::default())),
            Some(ResumePoint::default())
        );
        for bad in [
            "",
            "1 2 3 4 5",
            "1 2 3 4 5 6 7",
            "1 2 x 4 5 6",
            "-1 2 3 4 5 6",
            "1/65536 2 3 4 5 6",
            "1 2 3 4 5 6/4294967296",
            "1/ 2 3 4 5 6",
            "1/2/3 2 3 4 5 6",
        ] {
            assert_eq!(parse(bad), None, "{bad:?}");
        }
    }

    fn scratch(name: &str) -> PathBuf {
        rins_test_support::scratch::scratch_dir("resume", name)
    }

    fn point() -> ResumePoint {
        ResumePoint {
            seq: [Some(7), Some(8), Some(9), None, Some(11)],
            time_us: Some(10),
            ..ResumePoint::default()
        }
    }

    #[test]
    fn save_and_load_through_a_file() {
        let dir = scratch("round");
        let path = dir.join("acquisition.resume");
        assert_eq!(load(&path), Loaded::Missing);
        save(&path, &point()).unwrap();
        assert_eq!(load(&path), Loaded::Point(point()));
        let meta = std::fs::metadata(&path).unwrap();
        assert_eq!(meta.mode() & 0o777, 0o600);
        // A stale temporary file of a killed run is replaced, not reused.
        std::fs::write(path.with_extension("tmp"), "junk").unwrap();
        save(&path, &point()).unwrap();
        assert_eq!(load(&path), Loaded::Point(point()));
        assert!(!path.with_extension("tmp").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_symlinked_temporary_file_is_not_written_through() {
        let dir = scratch("tmp-link");
        let victim = dir.join("victim");
        std::fs::write(&victim, "root-only").unwrap();
        let path = dir.join("acquisition.resume");
        std::os::unix::fs::symlink(&victim, path.with_extension("tmp")).unwrap();
        save(&path, &point()).unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "root-only");
        assert_eq!(load(&path), Loaded::Point(point()));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn ignored(path: &Path) -> String {
        match load(path) {
            Loaded::Ignored(why) => why,
            other => panic!("{} should be ignored, got {other:?}", path.display()),
        }
    }

    #[test]
    fn links_special_files_big_files_and_junk_are_ignored_naming_the_path() {
        let dir = scratch("ignored");
        let target = dir.join("target");
        std::fs::write(&target, format(&point())).unwrap();
        let link = dir.join("link.resume");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        let why = ignored(&link);
        assert!(why.contains(&link.display().to_string()), "{why}");
        let fifo = dir.join("fifo.resume");
        let c = std::ffi::CString::new(fifo.to_string_lossy().as_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        assert!(ignored(&fifo).contains("FIFO"));
        let big = dir.join("big.resume");
        std::fs::write(&big, " ".repeat(MAX_FILE_BYTES as usize + 1)).unwrap();
        assert!(ignored(&big).contains("bytes"));
        let junk = dir.join("junk.resume");
        std::fs::write(&junk, "1 2 x").unwrap();
        assert!(ignored(&junk).contains("not a resume point"));
        assert!(ignored(&dir).contains("directory") || ignored(&dir).contains("cannot"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn another_users_point_is_ignored() {
        let dir = scratch("owner");
        let path = dir.join("acquisition.resume");
        save(&path, &point()).unwrap();
        if rins_runtime::user::effective_uid() != 0 {
            eprintln!("note: not root; a point of another user cannot be planted");
            std::fs::remove_dir_all(&dir).unwrap();
            return;
        }
        let c = std::ffi::CString::new(path.to_string_lossy().as_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::chown(c.as_ptr(), 65534, 65534) }, 0);
        let why = ignored(&path);
        assert!(why.contains("owned by") && why.contains("65534"), "{why}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
