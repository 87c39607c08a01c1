//! Helpers for end-to-end tests: each test runs `rins` as real processes on its own iceoryx2 prefix
//! and root, and checks that nothing is left in /dev/shm afterwards.

#![allow(dead_code)]

pub mod device;
pub mod netns;
pub mod python;
pub mod topic_stream;

use rins_test_support::signal::{Signal, send_signal};
use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::atomic::{AtomicU32, Ordering};

pub const RINS: &str = env!("CARGO_BIN_EXE_rins");

/// A private IPC namespace for one test.
pub struct Isolated {
    pub prefix: String,
    pub root: PathBuf,
}

impl Isolated {
    pub fn new(test: &str) -> Self {
        static NEXT: AtomicU32 = AtomicU32::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        // Short: iceoryx2 names its event sockets ROOT/PREFIX<id>.event, and a socket's path is
        // limited (the test's name is there to recognise its files, its start is enough).
        let id = format!("rt{}_{n}", std::process::id());
        let name: String = test.chars().take(16).collect();
        let prefix = format!("{id}_{name}_");
        let root = std::env::temp_dir().join(id);
        Self { prefix, root }
    }

    pub fn command(&self) -> Command {
        let mut cmd = Command::new(RINS);
        cmd.env("RINS_IPC_PREFIX", &self.prefix)
            .env("RINS_IPC_ROOT", &self.root)
            .env("RINS_LOG", "warn");
        cmd
    }

    pub fn run(&self, args: &[&str]) -> Output {
        // A whole pipeline is six real-time processes: on a two-core machine, more than two at
        // once starve each other. Other commands run freely.
        let _slot = (args.first() == Some(&"up")).then(PipelineSlot::take);
        self.command().args(args).output().expect("cannot run rins")
    }

    /// Runs `rins ARGS`, killing it (and failing) if it has not finished within `limit`.
    pub fn run_with_timeout(&self, args: &[&str], limit: std::time::Duration) -> Output {
        let mut child = self
            .command()
            .args(args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("cannot run rins");
        let deadline = std::time::Instant::now() + limit;
        while child.try_wait().expect("cannot poll child").is_none() {
            if std::time::Instant::now() >= deadline {
                let _ = child.kill();
                let out = child.wait_with_output().expect("cannot collect output");
                panic!(
                    "rins {args:?} did not finish within {limit:?}:\n{}",
                    stderr(&out)
                );
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        child.wait_with_output().expect("cannot collect output")
    }

    /// The watchdog's health report as `rins status --json` prints it.
    pub fn status(&self) -> serde_json::Value {
        let out = self.run(&["status", "--json", "--timeout", "10"]);
        assert!(out.status.success(), "{}", stderr(&out));
        last_json(&out)
    }

    /// Polls `rins status --json` until `done` holds of the report, and returns it; fails after
    /// `limit`.
    pub fn status_until(
        &self,
        limit: std::time::Duration,
        done: impl Fn(&serde_json::Value) -> bool,
    ) -> serde_json::Value {
        let start = std::time::Instant::now();
        loop {
            let report = self.status();
            if done(&report) {
                return report;
            }
            assert!(start.elapsed() < limit, "gave up waiting: {report}");
            std::thread::sleep(std::time::Duration::from_millis(200));
        }
    }

    /// Where [`spawn_up`] sends the pipeline's stderr: a file, not a pipe, so that a long run's
    /// warnings never fill a buffer no one reads, and a failure can show what the pipeline said.
    pub fn up_stderr_path(&self) -> PathBuf {
        std::env::temp_dir().join(format!("{}up-stderr.log", self.prefix))
    }

    /// What the pipeline from [`spawn_up`] wrote to stderr so far.
    pub fn up_stderr(&self) -> String {
        std::fs::read_to_string(self.up_stderr_path()).unwrap_or_default()
    }

    /// Shared-memory entries of this namespace still present.
    pub fn shm_entries(&self) -> Vec<String> {
        std::fs::read_dir("/dev/shm")
            .map(|d| {
                d.filter_map(|e| e.ok())
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .filter(|n| n.starts_with(&self.prefix))
                    .collect()
            })
            .unwrap_or_default()
    }
}

/// `rins up ARGS --json` on a private namespace: the summary, after checking a clean exit, an
/// empty /dev/shm for the test's prefix and no iceoryx2 root left behind.
pub fn up_json(test: &str, args: &[&str]) -> serde_json::Value {
    let ipc = Isolated::new(test);
    let mut all = vec!["up"];
    all.extend_from_slice(args);
    all.push("--json");
    let out = ipc.run(&all);
    assert!(
        out.status.success(),
        "rins up failed: {:?}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = last_json(&out);
    assert_eq!(
        ipc.shm_entries(),
        Vec::<String>::new(),
        "shared memory left behind"
    );
    assert_eq!(num(&summary, "shm_leaked"), 0.0);
    assert!(
        !ipc.root.exists(),
        "iceoryx2 root left behind: {}",
        ipc.root.display()
    );
    summary
}

/// At most [`PipelineSlot::MAX`] pipelines of one test binary run at the same time.
pub struct PipelineSlot;

static SLOTS: std::sync::Mutex<usize> = std::sync::Mutex::new(0);
static FREED: std::sync::Condvar = std::sync::Condvar::new();

impl PipelineSlot {
    pub const MAX: usize = 2;

    pub fn take() -> Self {
        let mut used = SLOTS.lock().unwrap_or_else(|e| e.into_inner());
        while *used >= Self::MAX {
            used = FREED.wait(used).unwrap_or_else(|e| e.into_inner());
        }
        *used += 1;
        PipelineSlot
    }
}

impl Drop for PipelineSlot {
    fn drop(&mut self) {
        let mut used = SLOTS.lock().unwrap_or_else(|e| e.into_inner());
        *used -= 1;
        FREED.notify_one();
    }
}

impl Drop for Isolated {
    fn drop(&mut self) {
        for name in self.shm_entries() {
            let _ = std::fs::remove_file(PathBuf::from("/dev/shm").join(name));
        }
        let _ = std::fs::remove_dir_all(&self.root);
        let _ = std::fs::remove_file(self.up_stderr_path());
    }
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The JSON object on the last line of stdout.
pub fn last_json(output: &Output) -> serde_json::Value {
    let stdout = String::from_utf8_lossy(&output.stdout);
    let last = stdout.lines().last().unwrap_or_default();
    serde_json::from_str(last).unwrap_or_else(|e| {
        panic!(
            "last line is not JSON ({e}): {last:?}\nstderr:\n{}",
            String::from_utf8_lossy(&output.stderr)
        )
    })
}

pub fn num(v: &serde_json::Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("summary has no number {key:?}: {v}"))
}

/// The pipeline published a navigation output for every frame that reached it: the only frames
/// without one (`dropped`) are those the serial line lost, and acquisition counted every one of
/// them (`lost_frames`). On a loaded test machine the simulator can find the pseudo-terminal full
/// for a moment and lose a frame or two on the line; more than one in a thousand is a failure.
pub fn assert_no_loss_beyond_the_line(s: &serde_json::Value) {
    assert_eq!(num(s, "dropped"), num(s, "lost_frames"), "{s}");
    assert!(num(s, "lost_frames") <= num(s, "frames") / 1000.0, "{s}");
}

/// A temporary file with the given text, removed when dropped; `kind` and `extension` name it.
pub struct TempFile(PathBuf);

impl TempFile {
    pub fn new(kind: &str, extension: &str, text: &str) -> Self {
        use std::io::Write;
        static N: AtomicU32 = AtomicU32::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        let path = std::env::temp_dir().join(format!(
            "rins-test-{kind}-{}-{n}.{extension}",
            std::process::id()
        ));
        std::fs::File::create(&path)
            .and_then(|mut f| f.write_all(text.as_bytes()))
            .expect("cannot write a temporary file");
        Self(path)
    }

    pub fn path(&self) -> &str {
        self.0.to_str().expect("temporary path is UTF-8")
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// A fresh private directory (mode 0700) under the system's temporary directory, named after the
/// test binary's `kind` and the test's `name`, removed with what it holds when dropped.
pub struct Scratch(PathBuf);

impl Scratch {
    pub fn new(kind: &str, name: &str) -> Self {
        use std::os::unix::fs::PermissionsExt;
        let dir = std::env::temp_dir().join(format!("rins-{kind}-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir(&dir).expect("scratch directory");
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700))
            .expect("scratch directory mode");
        Self(dir)
    }

    pub fn path(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The quadrotor recordings in the recordings directory, or `None` (with a note) when they are absent.
pub fn quadrotor_data_dir() -> Option<PathBuf> {
    rins_eval::datasets::recording_set("quadrotor-4imu")
}

/// `rins up ARGS` started in the background on `ipc`'s namespace, stdout piped for its summary.
pub fn spawn_up(ipc: &Isolated, args: &[&str]) -> std::process::Child {
    let log = std::fs::File::create(ipc.up_stderr_path()).expect("cannot create the stderr log");
    ipc.command()
        .arg("up")
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(log)
        .spawn()
        .expect("cannot start rins up")
}

/// [`spawn_up`], then waits (up to two minutes: a loaded machine starts six processes slowly) for
/// the first navigation sample, so the pipeline is known to run end to end.
pub fn spawn_up_navigating(ipc: &Isolated, args: &[&str]) -> std::process::Child {
    let mut up = spawn_up(ipc, args);
    let first = ipc.run(&["echo", "nav", "--count", "1", "--timeout", "120"]);
    if !first.status.success() {
        let exited = up.try_wait().ok().flatten();
        let _ = up.kill();
        let _ = up.wait();
        panic!(
            "no navigation sample: {first:?}\nrins up (exit: {exited:?}) wrote:\n{}",
            ipc.up_stderr()
        );
    }
    up
}

/// Stops a pipeline from [`spawn_up`] with SIGTERM, as an operator does, checks that it ended
/// cleanly with no shared memory left, and returns its JSON summary.
pub fn stop_up(ipc: &Isolated, up: std::process::Child) -> serde_json::Value {
    last_json(&stop_up_output(ipc, up))
}

/// [`stop_up`], returning everything `rins up` wrote: the status lines, then the summary.
pub fn stop_up_output(ipc: &Isolated, up: std::process::Child) -> Output {
    // Our own child process, not reaped yet.
    send_signal(u64::from(up.id()), Signal::Terminate).expect("SIGTERM to our own child");
    let out = up.wait_with_output().expect("rins up did not finish");
    assert!(
        out.status.success(),
        "rins up: {:?}\n{}",
        out.status,
        ipc.up_stderr()
    );
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
    out
}

/// Runs `rins ARGS` on a private namespace and checks that it fails with every `expected`
/// fragment in its stderr.
pub fn fails_with(test: &str, args: &[&str], expected: &[&str]) {
    let out = Isolated::new(test).run(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let stderr = String::from_utf8_lossy(&out.stderr);
    for e in expected {
        assert!(
            stderr.contains(e),
            "{args:?}: stderr lacks {e:?}:\n{stderr}"
        );
    }
}
