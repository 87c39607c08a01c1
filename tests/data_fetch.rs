//! `rins data fetch` and `rins data list` through the binary, against local git repositories made
//! here in the published layouts (`--source SET=file://...`): the sets built in the layout the
//! evaluations read, a provenance note naming the commit, a second fetch that changes nothing,
//! and the errors for an unknown set, for a source that lacks a file and for a truncated MAT-file.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use rins_eval::data::PYSHOE_TRIALS;

struct Scratch(PathBuf);

impl Scratch {
    fn new(tag: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("rins-data-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn rins(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rins"))
        .args(args)
        .env_remove("RINS_DATA_DIR")
        .output()
        .expect("cannot run rins")
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

fn git(dir: &Path, args: &[&str]) -> String {
    let out = Command::new("git")
        .arg("-C")
        .arg(dir)
        .args(["-c", "user.name=rins", "-c", "user.email=rins@example.org"])
        .args(args)
        .output()
        .expect("cannot run git");
    assert!(out.status.success(), "git {args:?}: {}", text(&out));
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

/// A git repository at `dir` holding `files` (path, bytes) in one commit; its commit id.
fn repository(dir: &Path, files: &[(String, Vec<u8>)]) -> String {
    std::fs::create_dir_all(dir).unwrap();
    git(dir, &["init", "--quiet", "--initial-branch=main"]);
    for (path, bytes) in files {
        let p = dir.join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, bytes).unwrap();
    }
    git(dir, &["add", "--all"]);
    git(dir, &["commit", "--quiet", "-m", "data"]);
    git(dir, &["rev-parse", "HEAD"])
}

fn url(dir: &Path) -> String {
    format!("file://{}", dir.display())
}

/// MAT-file level 5 elements, as the pyshoe authors' processed files hold them.
fn element(kind: u32, data: &[u8]) -> Vec<u8> {
    let mut out = kind.to_le_bytes().to_vec();
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
    out.resize(out.len().next_multiple_of(8), 0);
    out
}

fn matrix(class: u32, name: &str, dims: [i32; 2], real: Vec<u8>) -> Vec<u8> {
    let mut body = element(6, &[class.to_le_bytes(), [0; 4]].concat());
    body.extend(element(
        5,
        &[dims[0].to_le_bytes(), dims[1].to_le_bytes()].concat(),
    ));
    body.extend(element(1, name.as_bytes()));
    body.extend(real);
    element(14, &body)
}

/// A double matrix from its columns.
fn doubles(name: &str, columns: &[&[f64]]) -> Vec<u8> {
    let data: Vec<u8> = columns
        .iter()
        .flat_map(|c| c.iter())
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let dims = [columns[0].len() as i32, columns.len() as i32];
    matrix(6, name, dims, element(9, &data))
}

/// A trial of three samples at 200 Hz: the foot still, z down, at (1, 2, 0).
fn pyshoe_trial() -> Vec<u8> {
    let mut file = b"MATLAB 5.0 MAT-file Platform: posix".to_vec();
    file.resize(124, b' ');
    file.extend_from_slice(&0x0100u16.to_le_bytes());
    file.extend_from_slice(b"IM");
    let zero = [0.0; 3];
    file.extend(doubles(
        "imu",
        &[&zero, &zero, &[-9.81, -9.81, -9.81], &zero, &zero, &zero],
    ));
    file.extend(doubles("ts", &[&[0.005], &[0.01], &[0.015]]));
    file.extend(doubles("gt", &[&[1.0; 3], &[2.0; 3], &zero]));
    file.extend(doubles(
        "trial_error",
        &[&[0.032], &[0.04], &[0.05], &[0.06], &[0.443]],
    ));
    file.extend(matrix(4, "best_detector", [1, 4], element(16, b"shoe")));
    file
}

fn quadrotor_files() -> Vec<(String, Vec<u8>)> {
    let mut files = vec![("README.md".to_string(), b"CC BY 4.0\n".to_vec())];
    for (group, count) in [("Horizontal", 9), ("StraightLine", 4), ("Vertical", 1)] {
        for n in 1..=count {
            for f in ["GT", "IMU_1", "IMU_2", "IMU_3", "IMU_4", "IMU_avg"] {
                let body = format!("time,{group},{n},{f}\n0.0,1,2,3\n");
                files.push((format!("{group}/path_{n}/{f}.csv"), body.into_bytes()));
            }
        }
    }
    files
}

fn pyshoe_files() -> Vec<(String, Vec<u8>)> {
    let mut files = vec![("LICENSE".to_string(), b"MIT License\n".to_vec())];
    for t in PYSHOE_TRIALS {
        files.push((format!("data/vicon/processed/{t}.mat"), pyshoe_trial()));
    }
    files.push((
        "data/vicon/processed/2018-02-09-11-16-53.mat".into(),
        pyshoe_trial(),
    ));
    files
}

fn xio_files() -> Vec<(String, Vec<u8>)> {
    [
        "short_walk.csv",
        "long_walk.csv",
        "README.md",
        "LICENSE.md",
        "gait_tracking.py",
    ]
    .iter()
    .map(|f| (f.to_string(), format!("{f}\n").into_bytes()))
    .collect()
}

#[test]
fn fetch_builds_every_set_with_its_provenance_and_a_second_fetch_changes_nothing() {
    let scratch = Scratch::new("fetch");
    let sources = scratch.0.join("sources");
    let quad_commit = repository(&sources.join("quad"), &quadrotor_files());
    let pyshoe_commit = repository(&sources.join("pyshoe"), &pyshoe_files());
    let xio_commit = repository(&sources.join("xio"), &xio_files());
    let data = scratch.0.join("data");
    let data_s = data.to_str().unwrap();
    let q = format!("quadrotor-4imu={}", url(&sources.join("quad")));
    let p = format!("pyshoe-vicon={}", url(&sources.join("pyshoe")));
    let x = format!("xio-gait={}", url(&sources.join("xio")));
    let args = [
        "data", "fetch", "--dir", data_s, "--source", &q, "--source", &p, "--source", &x,
    ];

    let list = rins(&["data", "list", "--dir", data_s, "--json"]);
    let v: serde_json::Value =
        serde_json::from_str(String::from_utf8_lossy(&list.stdout).trim()).unwrap();
    assert!(
        v["sets"]
            .as_array()
            .unwrap()
            .iter()
            .all(|s| s["status"] == "missing"),
        "{v}"
    );

    let out = rins(&args);
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        text(&out).contains("3 fetched, 0 already present, 0 failed"),
        "{}",
        text(&out)
    );

    // Quadrotor: the 12 flights' truth and four units, copied byte for byte; nothing else.
    let quad = data.join("quadrotor-4imu");
    assert_eq!(
        std::fs::read_to_string(quad.join("StraightLine/path_4/IMU_3.csv")).unwrap(),
        "time,StraightLine,4,IMU_3\n0.0,1,2,3\n"
    );
    assert!(quad.join("Horizontal/path_8/GT.csv").is_file());
    assert!(!quad.join("Horizontal/path_9").exists());
    assert!(!quad.join("Vertical").exists());
    assert!(!quad.join("Horizontal/path_1/IMU_avg.csv").exists());
    let prov = std::fs::read_to_string(quad.join("PROVENANCE")).unwrap();
    assert!(prov.contains(&format!("commit: {quad_commit}\n")), "{prov}");
    assert!(prov.contains(&format!("source: {}\n", url(&sources.join("quad")))));
    assert!(prov.contains("licence: CC BY 4.0"));

    // pyshoe: each trial's MAT-file converted to the CSV and the authors' figures.
    let pyshoe = data.join("pyshoe-vicon");
    let csv = std::fs::read_to_string(pyshoe.join("2017-11-22-11-22-03.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 4);
    assert_eq!(lines[1], "0.005,0,0,-9.81,0,0,0,1,2,0");
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(pyshoe.join("2018-02-22-10-10-56.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(
        json["peer_2d_rmse_m_per_detector_tuned_per_trial"]["amvd"],
        0.05
    );
    assert_eq!(json["best_detector"], "shoe");
    assert!(!pyshoe.join("2018-02-09-11-16-53.csv").exists());
    assert!(pyshoe.join("LICENSE").is_file());
    let prov = std::fs::read_to_string(pyshoe.join("PROVENANCE")).unwrap();
    assert!(
        prov.contains(&format!("commit: {pyshoe_commit}\n")),
        "{prov}"
    );
    assert!(prov.contains("peer figures: <trial>.json"), "{prov}");

    let xio = data.join("xio-gait");
    assert_eq!(
        std::fs::read_to_string(xio.join("long_walk.csv")).unwrap(),
        "long_walk.csv\n"
    );
    assert!(!xio.join("gait_tracking.py").exists());
    let prov = std::fs::read_to_string(xio.join("PROVENANCE")).unwrap();
    assert!(prov.contains(&format!("commit: {xio_commit}\n")), "{prov}");

    // Idempotent: a second fetch finds every set complete and leaves it alone.
    let before = std::fs::metadata(xio.join("PROVENANCE"))
        .unwrap()
        .modified()
        .unwrap();
    let again = rins(&args);
    assert!(again.status.success(), "{}", text(&again));
    assert!(
        text(&again).contains("0 fetched, 3 already present, 0 failed"),
        "{}",
        text(&again)
    );
    let after = std::fs::metadata(xio.join("PROVENANCE"))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(before, after);

    // A set with a file removed is listed incomplete and built again (from the cached clone).
    std::fs::remove_file(pyshoe.join("2017-12-15-18-03-05.json")).unwrap();
    let list = rins(&["data", "list", "--dir", data_s, "--json"]);
    let v: serde_json::Value =
        serde_json::from_str(String::from_utf8_lossy(&list.stdout).trim()).unwrap();
    let status: Vec<&str> = v["sets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["status"].as_str().unwrap())
        .collect();
    assert_eq!(status, ["present", "incomplete", "present"], "{v}");
    let repair = rins(&[
        "data",
        "fetch",
        "--dir",
        data_s,
        "pyshoe-vicon",
        "--source",
        &p,
    ]);
    assert!(repair.status.success(), "{}", text(&repair));
    assert!(
        text(&repair).contains("reusing the clone"),
        "{}",
        text(&repair)
    );
    assert!(pyshoe.join("2017-12-15-18-03-05.json").is_file());
    assert!(!data.join(".pyshoe-vicon.partial").exists());

    // --force clones the source again and replaces a complete set.
    let forced = rins(&[
        "data", "fetch", "--dir", data_s, "--force", "xio-gait", "--source", &x,
    ]);
    assert!(forced.status.success(), "{}", text(&forced));
    let t = text(&forced);
    assert!(
        t.contains("cloning") && t.contains("1 fetched, 0 already present"),
        "{t}"
    );
}

#[test]
fn an_unknown_set_a_missing_file_and_a_truncated_trial_are_errors_that_name_them() {
    let scratch = Scratch::new("errors");
    let data = scratch.0.join("data");
    let data_s = data.to_str().unwrap();
    let out = rins(&["data", "fetch", "--dir", data_s, "nope"]);
    assert!(!out.status.success());
    assert!(
        text(&out)
            .contains("unknown data set \"nope\"; known: quadrotor-4imu, pyshoe-vicon, xio-gait"),
        "{}",
        text(&out)
    );

    // The walks' repository without long_walk.csv: the set fails, named, and is not installed.
    let mut files = xio_files();
    files.retain(|(p, _)| p != "long_walk.csv");
    let source = scratch.0.join("xio");
    repository(&source, &files);
    let s = format!("xio-gait={}", url(&source));
    let out = rins(&["data", "fetch", "--dir", data_s, "xio-gait", "--source", &s]);
    assert!(!out.status.success());
    let t = text(&out);
    assert!(
        t.contains("xio-gait: failed: long_walk.csv: not in the source checkout"),
        "{t}"
    );
    assert!(
        t.contains("0 fetched, 0 already present, 1 failed (xio-gait)"),
        "{t}"
    );
    assert!(!data.join("xio-gait").exists());

    // A trial cut short (an interrupted copy): the set fails, naming the file and the variable's
    // offset, rather than converting what is left.
    let mut files = pyshoe_files();
    let cut = &mut files[1].1;
    cut.truncate(cut.len() - 20);
    let cut_name = files[1].0.clone();
    let source = scratch.0.join("pyshoe");
    repository(&source, &files);
    let p = format!("pyshoe-vicon={}", url(&source));
    let out = rins(&[
        "data",
        "fetch",
        "--dir",
        data_s,
        "pyshoe-vicon",
        "--source",
        &p,
    ]);
    assert!(!out.status.success());
    let t = text(&out);
    assert!(
        t.contains(&format!(
            "pyshoe-vicon: failed: {cut_name}: not a readable MATLAB level 5 MAT-file: truncated: the variable at byte"
        )),
        "{t}"
    );
    assert!(!data.join("pyshoe-vicon").exists());
}
