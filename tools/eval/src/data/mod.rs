//! The recorded data sets the evaluations read, where each is published and how its files become
//! the layout under the recordings directory ([`crate::datasets::recordings_dir`]).
//!
//! Each set comes from one public git repository. A set whose files are already in the layout
//! read here is copied; the pyshoe walks are converted from the authors' processed MAT-files
//! ([`pyshoe_mat`]). The subset taken of each source is the one the figures in the
//! documentation were measured on. `rins data fetch` runs the plan; this module only describes
//! it, so that the plan, the list of expected files and the provenance note are tested without
//! a network.
//!
//! - [`mat`]: MATLAB level 5 MAT-files, read with the `matfile` crate, as real matrices.
//! - [`pyshoe_mat`]: one processed pyshoe trial into `<trial>.csv` and `<trial>.json`.

pub mod mat;
pub mod pyshoe_mat;

use std::fmt::Write as _;
use std::path::Path;

/// How a file of a set is made from a file of its source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Conversion {
    /// Copied unchanged.
    Copy,
    /// A processed pyshoe trial: one MAT-file gives `<trial>.csv` and `<trial>.json`.
    PyshoeMat,
}

/// One file of the source and what is made of it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Step {
    /// Path in the source repository.
    pub source: String,
    /// Paths written in the set directory (one for a copy, two for a converted trial).
    pub outputs: Vec<String>,
    /// How.
    pub conversion: Conversion,
}

/// One data set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DataSet {
    /// Directory name under the recordings directory.
    pub name: &'static str,
    /// What it is.
    pub description: &'static str,
    /// The git repository it is fetched from.
    pub url: &'static str,
    /// Its licence, and where the source states it.
    pub licence: &'static str,
    /// The authors and the publication to cite.
    pub citation: &'static str,
    /// What was taken from the source and how it was turned into this layout.
    pub conversion_note: &'static str,
    /// Where the peer figures the evaluations compare with come from.
    pub peer_figures: &'static str,
}

/// The quadrotor flights the evaluations use: `(group, path numbers)`.
pub const QUADROTOR_FLIGHTS: [(&str, std::ops::RangeInclusive<u32>); 2] =
    [("Horizontal", 1..=8), ("StraightLine", 1..=4)];

/// The files of one quadrotor flight.
const QUADROTOR_FILES: [&str; 5] = ["GT.csv", "IMU_1.csv", "IMU_2.csv", "IMU_3.csv", "IMU_4.csv"];

/// The pyshoe Vicon trials the evaluations use.
pub const PYSHOE_TRIALS: [&str; 12] = [
    "2017-11-22-11-22-03",
    "2017-11-22-11-26-46",
    "2017-11-22-11-35-59",
    "2017-11-22-11-40-44",
    "2017-11-22-11-50-42",
    "2017-11-27-11-12-18",
    "2017-11-27-11-14-52",
    "2017-11-27-11-23-18",
    "2017-12-15-18-00-13",
    "2017-12-15-18-03-05",
    "2018-02-09-11-29-43",
    "2018-02-22-10-10-56",
];

/// Where the processed pyshoe trials are in their repository.
const PYSHOE_PROCESSED: &str = "data/vicon/processed";

/// Every data set, in the order `rins data fetch` takes them.
pub const DATA_SETS: [DataSet; 3] = [
    DataSet {
        name: "quadrotor-4imu",
        description: "DJI Phantom 4 with four Xsens DOT IMUs (120 Hz) and RTK truth: 12 flights",
        url: "https://github.com/ansfl/Quadrotor-Dead-Reckoning-with-Multiple-Inertial-Sensors",
        licence: "CC BY 4.0 (Creative Commons Attribution 4.0), stated in the source's README.md; the repository has no licence file",
        citation: "D. Hurwitz and I. Klein, \"Quadrotor Dead Reckoning with Multiple Inertial Sensors\", arXiv:2310.13452, 2023",
        conversion_note: "copied unchanged: Horizontal/path_1..8 and StraightLine/path_1..4, each GT.csv (RTK truth) and IMU_1..4.csv (Xsens DOT: time, Euler angles of the unit's own filter, specific force, rate); README.md. Not taken: Horizontal/path_9..27, the Vertical flights (17 of 31 with one unit), the averaged IMU_avg, pairs/ and triplets/ files",
        peer_figures: "the peer (each unit's on-board filter) is the Euler_X/Y/Z columns of the IMU files themselves; no published figure is read",
    },
    DataSet {
        name: "pyshoe-vicon",
        description: "foot-mounted MicroStrain 3DM-GX5-25 walks (200 Hz) with Vicon foot position: 12 trials",
        url: "https://github.com/mtahakoroglu/gait-driven-inertial-navigation-dataset",
        licence: "MIT, the LICENSE file of the repository fetched (copied beside the trials). The MAT-files are the pyshoe authors' (https://github.com/utiasSTARS/pyshoe, whose repository carries no licence file; its full data set is on IEEE DataPort and its FTP server), redistributed by that repository",
        citation: "B. Wagstaff, V. Peretroukhin and J. Kelly, \"Robust Data-Driven Zero-Velocity Detection for Foot-Mounted Inertial Navigation\", IEEE Sensors Journal 20(2), 2020",
        conversion_note: "converted: data/vicon/processed/<trial>.mat (the pyshoe authors' processed Vicon trials, MATLAB level 5) of 12 of the 56 trials into <trial>.csv: t_s from `ts`, acc_x/y/z_mps2 from `imu` columns 1-3, gyr_x/y/z_radps from `imu` columns 4-6, gt_x/y/z_m from `gt`, one row per IMU sample, values to 9 significant digits; LICENSE copied",
        peer_figures: "<trial>.json: peer_2d_rmse_m_per_detector_tuned_per_trial is the MAT-file's `trial_error` (the authors' 2-D RMSE, m, with each detector's threshold tuned for the trial, in the order of pyshoe's process_error_vicon.py: shoe, ared, amvd, mbgtd, vicon); best_detector is its `best_detector`",
    },
    DataSet {
        name: "xio-gait",
        description: "foot-mounted NGIMU walks that end where they start: short_walk.csv, long_walk.csv",
        url: "https://github.com/xioTechnologies/Gait-Tracking",
        licence: "MIT, the source's LICENSE.md (copied)",
        citation: "x-io Technologies, Gait-Tracking",
        conversion_note: "copied unchanged: short_walk.csv, long_walk.csv (time s, gyroscope deg/s, accelerometer g), README.md, LICENSE.md",
        peer_figures: "the source's README.md: final displacement 82 mm for the ~25 m short_walk.csv and 421 mm for the ~60 m long_walk.csv (built into the evaluation)",
    },
];

/// The data set called `name`.
pub fn find(name: &str) -> Option<&'static DataSet> {
    DATA_SETS.iter().find(|s| s.name == name)
}

/// What installs the data set that a missing `path` belongs to, for error messages: `rins data
/// fetch <set>` when a component of the path names a set, else `rins data fetch` for all.
pub fn fetch_hint(path: &Path) -> String {
    let set = path
        .components()
        .rev()
        .find_map(|c| find(&c.as_os_str().to_string_lossy()));
    match set {
        Some(set) => format!("`rins data fetch {}` downloads it", set.name),
        None => "`rins data fetch` downloads the recorded data sets (`rins data list` shows which are present)".into(),
    }
}

/// The names of every data set, for messages.
pub fn names() -> String {
    DATA_SETS.map(|s| s.name).join(", ")
}

fn copy(path: String) -> Step {
    Step {
        outputs: vec![path.clone()],
        source: path,
        conversion: Conversion::Copy,
    }
}

/// What is made of which file of the source, for `set`.
pub fn plan(set: &DataSet) -> Vec<Step> {
    match set.name {
        "quadrotor-4imu" => {
            let mut steps = Vec::new();
            for (group, paths) in QUADROTOR_FLIGHTS {
                for n in paths {
                    for file in QUADROTOR_FILES {
                        steps.push(copy(format!("{group}/path_{n}/{file}")));
                    }
                }
            }
            steps.push(copy("README.md".into()));
            steps
        }
        "pyshoe-vicon" => {
            let mut steps: Vec<Step> = PYSHOE_TRIALS
                .iter()
                .map(|t| Step {
                    source: format!("{PYSHOE_PROCESSED}/{t}.mat"),
                    outputs: vec![format!("{t}.csv"), format!("{t}.json")],
                    conversion: Conversion::PyshoeMat,
                })
                .collect();
            steps.push(copy("LICENSE".into()));
            steps
        }
        "xio-gait" => ["short_walk.csv", "long_walk.csv", "README.md", "LICENSE.md"]
            .map(|f| copy(f.into()))
            .to_vec(),
        _ => Vec::new(),
    }
}

/// The name of the provenance note written in each set directory.
pub const PROVENANCE_FILE: &str = "PROVENANCE";

/// The provenance note of `set`, fetched from `url` at `commit`.
pub fn provenance(set: &DataSet, url: &str, commit: &str) -> String {
    let mut text = String::new();
    let _ = writeln!(text, "data set: {}", set.name);
    let _ = writeln!(text, "what: {}", set.description);
    let _ = writeln!(text, "source: {url}");
    let _ = writeln!(text, "commit: {commit}");
    let _ = writeln!(text, "licence: {}", set.licence);
    let _ = writeln!(text, "cite: {}", set.citation);
    let _ = writeln!(text, "made: {}", set.conversion_note);
    let _ = writeln!(text, "peer figures: {}", set.peer_figures);
    let _ = writeln!(text, "files:");
    for step in plan(set) {
        let how = match step.conversion {
            Conversion::Copy => "copy of",
            Conversion::PyshoeMat => "converted from",
        };
        let _ = writeln!(
            text,
            "  {} ({how} {})",
            step.outputs.join(", "),
            step.source
        );
    }
    text
}

/// The commit named on the `commit:` line of a provenance note.
pub fn provenance_commit(text: &str) -> Option<&str> {
    text.lines()
        .find_map(|l| l.strip_prefix("commit: "))
        .map(str::trim)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_set_has_a_plan_and_names_are_unique() {
        let count = |name: &str| plan(find(name).unwrap()).len();
        // 12 flights of 5 files and the README; 12 trials and the licence; 2 walks, README, licence.
        assert_eq!(count("quadrotor-4imu"), 61);
        assert_eq!(count("pyshoe-vicon"), 13);
        assert_eq!(count("xio-gait"), 4);
        assert!(find("nope").is_none());
        assert_eq!(names(), "quadrotor-4imu, pyshoe-vicon, xio-gait");
        let pyshoe = plan(find("pyshoe-vicon").unwrap());
        assert_eq!(
            pyshoe[0].source,
            "data/vicon/processed/2017-11-22-11-22-03.mat"
        );
        assert_eq!(
            pyshoe[0].outputs,
            ["2017-11-22-11-22-03.csv", "2017-11-22-11-22-03.json"]
        );
    }

    #[test]
    fn the_hint_names_the_set_a_missing_path_belongs_to() {
        assert_eq!(
            fetch_hint(Path::new("data/xio-gait/short_walk.csv")),
            "`rins data fetch xio-gait` downloads it"
        );
        assert_eq!(
            fetch_hint(Path::new("/srv/quadrotor-4imu")),
            "`rins data fetch quadrotor-4imu` downloads it"
        );
        assert!(fetch_hint(Path::new("/srv/walks")).starts_with("`rins data fetch` downloads"));
    }

    #[test]
    fn provenance_names_source_commit_licence_and_every_file() {
        let set = find("xio-gait").unwrap();
        let text = provenance(set, set.url, "ac0dbf6");
        assert!(text.contains("source: https://github.com/xioTechnologies/Gait-Tracking\n"));
        assert_eq!(provenance_commit(&text), Some("ac0dbf6"));
        assert!(text.contains("licence: MIT"));
        assert!(text.contains("peer figures: the source's README.md"));
        assert!(text.contains("  short_walk.csv (copy of short_walk.csv)\n"));
        assert_eq!(provenance_commit("no such line"), None);
    }
}
