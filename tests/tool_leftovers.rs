//! The tools that join a deployment (`status`, `echo`, `latency`, `inject`, `readmit`) leave
//! nothing behind: with no pipeline, nothing of the prefix in /dev/shm and no root they created;
//! with a pipeline, nothing of their own once they exit.

mod common;

use std::collections::BTreeSet;
use std::path::Path;
use std::time::Duration;

use common::{Isolated, spawn_up_navigating, stderr, stop_up};

/// Each tool, with limits short enough that it gives up quickly when no pipeline runs.
const TOOLS: [&[&str]; 5] = [
    &["status", "--timeout", "1"],
    &["echo", "nav", "--count", "3", "--timeout", "1"],
    &["latency", "--seconds", "1"],
    &["inject", "gyro2", "dead"],
    &["readmit", "gyro2"],
];

/// Generous: a tool that hangs fails the test instead of stalling it.
const LIMIT: Duration = Duration::from_secs(60);

/// Every path under `dir`, relative to it.
fn files_under(dir: &Path) -> BTreeSet<String> {
    fn walk(base: &Path, dir: &Path, out: &mut BTreeSet<String>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.filter_map(Result::ok) {
            let path = e.path();
            out.insert(path.strip_prefix(base).unwrap().display().to_string());
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                walk(base, &path, out);
            }
        }
    }
    let mut out = BTreeSet::new();
    walk(dir, dir, &mut out);
    out
}

/// Waits until the deployment's files stay the same for a second (a bounded number of tries).
fn settle(ipc: &Isolated) {
    let snapshot = || {
        let mut all: BTreeSet<String> = ipc.shm_entries().into_iter().collect();
        all.extend(files_under(&ipc.root));
        all
    };
    let mut last = snapshot();
    for _ in 0..60 {
        std::thread::sleep(Duration::from_secs(1));
        let now = snapshot();
        if now == last {
            return;
        }
        last = now;
    }
    panic!("the deployment's files kept changing: {last:?}");
}

#[test]
fn without_a_pipeline_each_tool_fails_and_leaves_no_file_and_no_root() {
    let ipc = Isolated::new("leftover");
    for tool in TOOLS {
        let out = ipc.run_with_timeout(tool, LIMIT);
        assert!(!out.status.success(), "{tool:?} succeeded with no pipeline");
        assert_eq!(ipc.shm_entries(), Vec::<String>::new(), "after {tool:?}");
        assert!(
            !ipc.root.exists(),
            "after {tool:?}: root left: {:?}",
            files_under(&ipc.root)
        );
    }
}

#[test]
fn without_a_pipeline_a_root_that_was_there_stays_and_is_left_empty() {
    use std::os::unix::fs::DirBuilderExt;
    let ipc = Isolated::new("leftroot");
    std::fs::DirBuilder::new()
        .mode(0o700)
        .create(&ipc.root)
        .expect("cannot create the root");
    for tool in TOOLS {
        let out = ipc.run_with_timeout(tool, LIMIT);
        assert!(!out.status.success(), "{tool:?} succeeded with no pipeline");
        assert_eq!(ipc.shm_entries(), Vec::<String>::new(), "after {tool:?}");
        assert!(ipc.root.is_dir(), "after {tool:?}: the root was removed");
        assert_eq!(files_under(&ipc.root), BTreeSet::new(), "after {tool:?}");
    }
}

#[test]
fn with_a_pipeline_each_tool_takes_its_files_with_it() {
    let ipc = Isolated::new("leftlive");
    let up = spawn_up_navigating(
        &ipc,
        &["--scenario", "static", "--duration", "300", "--json"],
    );
    // The pipeline opens its last services a moment after the first navigation sample: what is
    // new after a tool must be the tool's.
    settle(&ipc);
    // The operator's sequence: kill a channel, clear the fault, re-admit the channel (fusion
    // refuses while the fault is present).
    let clear: &[&str] = &["inject", "gyro2", "clear"];
    let live = [TOOLS[0], TOOLS[1], TOOLS[2], TOOLS[3], clear, TOOLS[4]];
    for tool in live {
        let shm_before: BTreeSet<String> = ipc.shm_entries().into_iter().collect();
        let root_before = files_under(&ipc.root);
        let out = ipc.run_with_timeout(tool, LIMIT);
        assert!(out.status.success(), "{tool:?}: {}", stderr(&out));
        let shm_after: BTreeSet<String> = ipc.shm_entries().into_iter().collect();
        let new_shm: Vec<&String> = shm_after.difference(&shm_before).collect();
        assert!(new_shm.is_empty(), "{tool:?} left {new_shm:?}");
        let root_after = files_under(&ipc.root);
        let new_records: Vec<&String> = root_after.difference(&root_before).collect();
        assert!(new_records.is_empty(), "{tool:?} left {new_records:?}");
    }
    let summary = stop_up(&ipc, up);
    assert_eq!(summary["shm_leaked"], 0, "{summary}");
}
