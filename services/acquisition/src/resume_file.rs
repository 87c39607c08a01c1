//! The decoder's [`ResumePoint`] kept in a small file of the deployment's run directory, so that an
//! acquisition restarted by the watchdog continues the extended sequence numbers of the run it
//! replaces. Without it the numbers would start again from the 16-bit wire value, run backwards
//! downstream, and every consumer would take the new samples for old ones.
//!
//! The file is rewritten about once a second, by a write to a temporary file and a rename, so a
//! reader never sees half a file. A point up to a second old is good
//! enough: the extension only needs to be within 2^15 frames of the truth.

use std::io;
use std::path::Path;

use crate::protocol::{FrameType, ResumePoint};

const FIELDS: usize = FrameType::COUNT + 1;

/// How often the running acquisition saves its point.
pub const SAVE_PERIOD_NS: u64 = 1_000_000_000;

/// The file of the deployment on `settings`: in /dev/shm under the deployment's prefix, a memory
/// file system whose writes never wait for a disk (the file is written from the read loop), removed
/// with the deployment's shared memory and by `rins up` when a new deployment starts.
pub fn path_for(settings: &rins_runtime::ipc::IpcSettings) -> std::path::PathBuf {
    std::path::Path::new("/dev/shm").join(format!("{}acquisition.resume", settings.prefix))
}

/// `imu baro mag aux time_us`, `-` for a value not known yet.
pub fn format(point: &ResumePoint) -> String {
    let field = |v: Option<u64>| v.map_or_else(|| "-".to_string(), |v| v.to_string());
    let mut fields: Vec<String> = point.seq.iter().map(|&s| field(s)).collect();
    fields.push(field(point.time_us));
    fields.join(" ")
}

/// The point in `text`, or `None` when it is not one (a corrupt file is ignored: the numbering
/// then starts from the wire values, as on a first start).
pub fn parse(text: &str) -> Option<ResumePoint> {
    let values: Vec<Option<u64>> = text
        .split_whitespace()
        .map(|f| match f {
            "-" => Some(None),
            v => v.parse().ok().map(Some),
        })
        .collect::<Option<_>>()?;
    if values.len() != FIELDS {
        return None;
    }
    let mut point = ResumePoint::default();
    for (slot, value) in point.seq.iter_mut().zip(&values) {
        *slot = *value;
    }
    point.time_us = values[FrameType::COUNT];
    Some(point)
}

pub fn save(path: &Path, point: &ResumePoint) -> io::Result<()> {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, format(point))?;
    std::fs::rename(&tmp, path)
}

/// The saved point; `None` when there is none or it cannot be read.
pub fn load(path: &Path) -> Option<ResumePoint> {
    parse(&std::fs::read_to_string(path).ok()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_rejects() {
        let point = ResumePoint {
            seq: [Some(65_547), None, Some(3), Some(u64::MAX)],
            time_us: Some(1 << 40),
        };
        assert_eq!(
            format(&point),
            "65547 - 3 18446744073709551615 1099511627776"
        );
        assert_eq!(parse(&format(&point)), Some(point));
        assert_eq!(
            parse(&format(&ResumePoint::default())),
            Some(ResumePoint::default())
        );
        for bad in ["", "1 2 3 4", "1 2 3 4 5 6", "1 2 x 4 5", "-1 2 3 4 5"] {
            assert_eq!(parse(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn save_and_load_through_a_file() {
        let dir = std::env::temp_dir().join(format!("rins-resume-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("acquisition.resume");
        assert_eq!(load(&path), None);
        let point = ResumePoint {
            seq: [Some(7), Some(8), Some(9), None],
            time_us: Some(10),
        };
        save(&path, &point).unwrap();
        assert_eq!(load(&path), Some(point));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
