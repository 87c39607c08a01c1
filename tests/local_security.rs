//! Another local user cannot make a deployment delete, overwrite or trust their files: each test
//! plays one attack of an unprivileged user against a real `rins` and checks that it is refused
//! (with a message that names the path, what was found and whose it is) and that nothing of the
//! attacker's or of a third party is touched. The attacker is uid 65534 (nobody): files are chowned
//! to it, commands run under it. Not running as root, the parts that need a second user are skipped
//! with a note; the rest still runs with files of our own (a link or a file where a directory
//! belongs is refused whoever owns it).

mod common;

use std::ffi::CString;
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Output, Stdio};
use std::time::{Duration, Instant};

use common::{Isolated, PipelineSlot, Scratch, stderr, stop_up};
use rins_test_support::signal::{Signal, send_signal};

/// The unprivileged attacker.
const NOBODY: u32 = 65534;
/// Longest a refused command may take: a refusal comes before anything starts.
const PROMPT: Duration = Duration::from_secs(10);

fn is_root() -> bool {
    // SAFETY: geteuid has no preconditions.
    unsafe { libc::geteuid() == 0 }
}

fn c_path(path: &Path) -> CString {
    CString::new(path.as_os_str().as_encoded_bytes()).expect("path without NUL")
}

/// Gives `path` (not a link's target) to `uid`.
fn give_to(path: &Path, uid: u32) {
    // SAFETY: a valid NUL-terminated path; lchown never follows a link.
    assert_eq!(unsafe { libc::lchown(c_path(path).as_ptr(), uid, uid) }, 0);
}

/// A directory with files in it, standing for whatever a planted link points at.
fn victim_dir(scratch: &Scratch) -> PathBuf {
    let dir = scratch.path().join("victim");
    std::fs::create_dir(&dir).unwrap();
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700)).unwrap();
    for name in ["a.txt", "b.txt"] {
        std::fs::write(dir.join(name), name).unwrap();
    }
    dir
}

fn assert_victim_intact(dir: &Path) {
    for name in ["a.txt", "b.txt"] {
        assert_eq!(
            std::fs::read_to_string(dir.join(name)).unwrap_or_default(),
            name,
            "{} was touched",
            dir.join(name).display()
        );
    }
}

/// `rins ARGS` on `ipc`, expected to fail promptly with every `expected` fragment in its stderr.
fn refused(ipc: &Isolated, args: &[&str], expected: &[&str]) -> Output {
    let started = Instant::now();
    let out = ipc.run_with_timeout(args, PROMPT);
    assert!(!out.status.success(), "{args:?} should be refused");
    let err = stderr(&out);
    for e in expected {
        assert!(err.contains(e), "{args:?}: stderr lacks {e:?}:\n{err}");
    }
    eprintln!("{args:?} refused in {:?}", started.elapsed());
    out
}

/// Pids of the processes whose environment names `prefix` as their IPC prefix.
fn processes_of(prefix: &str) -> Vec<u32> {
    let needle = format!("RINS_IPC_PREFIX={prefix}\0");
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    dir.filter_map(|e| e.ok())
        .filter_map(|e| e.file_name().to_str()?.parse::<u32>().ok())
        .filter(|pid| {
            std::fs::read(format!("/proc/{pid}/environ"))
                .map(|env| env.windows(needle.len()).any(|w| w == needle.as_bytes()))
                .unwrap_or(false)
        })
        .collect()
}

/// Sends `sig` to our own child, not reaped yet.
fn signal(child: &Child, sig: Signal) {
    send_signal(u64::from(child.id()), sig).expect("signal to our own child");
}

/// A process of the test that is stopped with SIGTERM (and reaped) however the test ends, so a
/// failing assertion leaves no deployment running.
struct Stopped(Option<Child>);

impl Stopped {
    /// Stops it now and returns its output.
    fn stop(mut self, limit: Duration) -> Output {
        let child = self.0.take().expect("still running");
        signal(&child, Signal::Terminate);
        wait_within(child, limit)
    }
}

impl Drop for Stopped {
    fn drop(&mut self) {
        if let Some(mut child) = self.0.take() {
            signal(&child, Signal::Terminate);
            let _ = child.wait();
        }
    }
}

/// Waits until `child` catches SIGTERM (its `SigCgt` mask in `/proc`), failing after 10 s.
fn wait_for_stop_handler(child: &Child) {
    let status = format!("/proc/{}/status", child.id());
    let sigterm_bit = 1u64 << (libc::SIGTERM - 1);
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let caught = std::fs::read_to_string(&status)
            .ok()
            .and_then(|text| {
                let mask = text.lines().find_map(|l| l.strip_prefix("SigCgt:"))?;
                u64::from_str_radix(mask.trim(), 16).ok()
            })
            .is_some_and(|mask| mask & sigterm_bit != 0);
        if caught {
            return;
        }
        assert!(Instant::now() < deadline, "no SIGTERM handler within 10 s");
        std::thread::sleep(Duration::from_micros(200));
    }
}

/// Waits for `child` to end, killing it (and failing) after `limit`.
fn wait_within(mut child: Child, limit: Duration) -> Output {
    let deadline = Instant::now() + limit;
    while child.try_wait().expect("poll child").is_none() {
        if Instant::now() >= deadline {
            let _ = child.kill();
            panic!("did not end within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.wait_with_output().expect("collect output")
}

/// After a clean stop: exit 0, no error, no process, no shared memory, no root left (or, when a
/// tool created it before `rins up` came to, nothing left in it).
fn assert_stopped_clean(ipc: &Isolated, out: &Output, what: &str) {
    let err = stderr(out);
    assert!(out.status.success(), "{what}: {:?}\n{err}", out.status);
    assert!(
        !err.contains("error") && !err.contains("did not create"),
        "{what}: {err}"
    );
    assert_eq!(ipc.shm_entries(), Vec::<String>::new(), "{what}");
    assert_eq!(processes_of(&ipc.prefix), Vec::<u32>::new(), "{what}");
    let left: Vec<_> = std::fs::read_dir(&ipc.root)
        .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    assert_eq!(left, Vec::<PathBuf>::new(), "{what}: left in the root");
}

#[test]
fn a_symlinked_root_is_refused_and_the_target_directory_kept() {
    let ipc = Isolated::new("symroot");
    let scratch = Scratch::new("sec", "symroot");
    let victim = victim_dir(&scratch);
    std::os::unix::fs::symlink(&victim, &ipc.root).unwrap();
    if is_root() {
        give_to(&ipc.root, NOBODY);
    }
    let root = ipc.root.display().to_string();
    refused(&ipc, &["up", "--duration", "2"], &[&root, "symbolic link"]);
    refused(
        &ipc,
        &["echo", "nav", "--count", "1"],
        &[&root, "symbolic link"],
    );
    assert_victim_intact(&victim);
    assert!(
        ipc.root
            .symlink_metadata()
            .unwrap()
            .file_type()
            .is_symlink()
    );
    std::fs::remove_file(&ipc.root).unwrap();
}

#[test]
fn a_file_planted_where_the_root_belongs_is_refused_naming_it() {
    let ipc = Isolated::new("fileroot");
    std::fs::write(&ipc.root, "").unwrap();
    if is_root() {
        give_to(&ipc.root, NOBODY);
    }
    let root = ipc.root.display().to_string();
    refused(&ipc, &["up", "--duration", "2"], &[&root, "regular file"]);
    assert!(ipc.root.is_file(), "the planted file is left alone");
    std::fs::remove_file(&ipc.root).unwrap();
}

#[test]
fn another_users_directory_as_root_is_refused() {
    if !is_root() {
        eprintln!("note: not root; another user's directory cannot be made");
        return;
    }
    let ipc = Isolated::new("theirroot");
    std::fs::create_dir(&ipc.root).unwrap();
    std::fs::set_permissions(&ipc.root, std::fs::Permissions::from_mode(0o700)).unwrap();
    std::fs::write(ipc.root.join("theirs.txt"), "x").unwrap();
    give_to(&ipc.root, NOBODY);
    refused(
        &ipc,
        &["up", "--duration", "2"],
        &[&ipc.root.display().to_string(), "uid 65534", "another user"],
    );
    assert!(ipc.root.join("theirs.txt").exists());
}

#[test]
fn an_existing_directory_used_as_root_is_kept_with_its_files() {
    let ipc = Isolated::new("keeproot");
    std::fs::create_dir(&ipc.root).unwrap();
    std::fs::set_permissions(&ipc.root, std::fs::Permissions::from_mode(0o700)).unwrap();
    std::fs::write(ipc.root.join("notes.txt"), "mine").unwrap();
    let out = ipc.run(&["up", "--scenario", "static", "--duration", "2", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(common::num(&common::last_json(&out), "frames") > 0.0);
    assert_eq!(
        std::fs::read_to_string(ipc.root.join("notes.txt")).unwrap(),
        "mine"
    );
    // Only what was there before is left: the deployment's records are gone.
    let left: Vec<String> = std::fs::read_dir(&ipc.root)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, vec!["notes.txt".to_string()]);
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
}

/// The resume point an attacker would plant: far in the future, so that a deployment that trusted
/// it would wait for ever for the device's time to catch up.
const EXTREME_POINT: &str = "18446744073709551000 - - - 18446744073709551000";

#[test]
fn a_planted_resume_point_and_symlinked_temporary_file_are_neither_followed_nor_trusted() {
    let scratch = Scratch::new("sec", "resume");
    let secret = scratch.path().join("root-only");
    std::fs::write(&secret, "root-only").unwrap();
    std::fs::set_permissions(&secret, std::fs::Permissions::from_mode(0o600)).unwrap();

    // Where the resume point used to live, /dev/shm under the prefix, writable by anyone: planted
    // while the deployment runs (it saves its point once a second), the link must not be written
    // through, nor the files deleted when they are another user's.
    let ipc = Isolated::new("resume");
    let _slot = PipelineSlot::take();
    let up = common::spawn_up_navigating(
        &ipc,
        &["--scenario", "static", "--duration", "60", "--json"],
    );
    let shm = Path::new("/dev/shm");
    let point = shm.join(format!("{}acquisition.resume", ipc.prefix));
    let tmp = shm.join(format!("{}acquisition.tmp", ipc.prefix));
    std::fs::write(&point, EXTREME_POINT).unwrap();
    std::os::unix::fs::symlink(&secret, &tmp).unwrap();
    if is_root() {
        give_to(&point, NOBODY);
        give_to(&tmp, NOBODY);
    } else {
        eprintln!("note: not root; the planted files are our own");
    }
    // Two saves of the point, then a restarted acquisition that reads it.
    std::thread::sleep(Duration::from_millis(2500));
    signal(&up, Signal::Terminate);
    let out = wait_within(up, Duration::from_secs(30));
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(&secret).unwrap(), "root-only");
    assert!(
        tmp.symlink_metadata().is_ok(),
        "a link is never removed through"
    );
    if is_root() {
        assert!(point.exists(), "another user's file is left alone");
    }
    let _ = std::fs::remove_file(&point);
    std::fs::remove_file(&tmp).unwrap();
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
    drop(_slot);

    // In the run directory (private now), a stale link as temporary file and a point of another
    // user: the link is replaced, not written through.
    let ipc = Isolated::new("resume_run");
    let run = ipc.root.join(format!("{}run", ipc.prefix));
    std::fs::create_dir_all(&run).unwrap();
    for dir in [&ipc.root, &run] {
        std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o700)).unwrap();
    }
    std::os::unix::fs::symlink(&secret, run.join("acquisition.tmp")).unwrap();
    let out = ipc.run(&["up", "--scenario", "static", "--duration", "3", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(common::num(&common::last_json(&out), "frames") > 1000.0);
    assert_eq!(std::fs::read_to_string(&secret).unwrap(), "root-only");
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
}

#[test]
fn another_users_segments_on_our_prefix_make_up_and_echo_refuse_and_are_kept() {
    if !is_root() {
        eprintln!("note: not root; another user's shared memory cannot be planted");
        return;
    }
    let ipc = Isolated::new("planted");
    let planted = Path::new("/dev/shm").join(format!("{}planted.data", ipc.prefix));
    std::fs::write(&planted, "x").unwrap();
    give_to(&planted, NOBODY);
    let name = planted.display().to_string();
    refused(&ipc, &["up", "--duration", "2"], &[&name, "uid 65534"]);
    refused(
        &ipc,
        &["echo", "nav", "--count", "1", "--timeout", "2"],
        &[&name, "uid 65534", "RINS_IPC_OWNER=65534"],
    );
    refused(&ipc, &["status", "--timeout", "1"], &[&name]);
    assert_eq!(std::fs::metadata(&planted).unwrap().uid(), NOBODY);
}

#[test]
fn another_users_deployment_on_our_prefix_is_neither_joined_nor_removed() {
    if !is_root() {
        eprintln!("note: not root; no second user to run a deployment");
        return;
    }
    let ipc = Isolated::new("squat");
    let _slot = PipelineSlot::take();
    // The attacker runs a whole deployment on our prefix, with a root of their own.
    let their_root = std::env::temp_dir().join(format!("{}attacker", ipc.prefix));
    let mut attacker = ipc.command();
    attacker
        .args(["up", "--scenario", "static", "--duration", "60"])
        .env("RINS_IPC_ROOT", &their_root)
        .uid(NOBODY)
        .gid(NOBODY)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let attacker = Stopped(Some(attacker.spawn().expect("rins up as nobody")));
    let deadline = Instant::now() + Duration::from_secs(60);
    let theirs = || {
        ipc.shm_entries()
            .into_iter()
            .filter(|n| {
                std::fs::metadata(Path::new("/dev/shm").join(n)).is_ok_and(|m| m.uid() == NOBODY)
            })
            .collect::<Vec<_>>()
    };
    // Their navigation output exists once every service runs.
    while theirs().len() < 20 {
        assert!(
            Instant::now() < deadline,
            "the attacker's deployment did not start"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_secs(1));
    let before = theirs();
    refused(
        &ipc,
        &["echo", "nav", "--count", "1", "--timeout", "5"],
        &["nobody", "uid 65534", "nothing of it is read"],
    );
    refused(
        &ipc,
        &["up", "--duration", "2"],
        &["uid 65534", "left alone"],
    );
    let after = theirs();
    for name in &before {
        assert!(after.contains(name), "{name} of the attacker was removed");
    }
    let out = attacker.stop(Duration::from_secs(30));
    assert!(out.status.success(), "attacker: {}", stderr(&out));
    let _ = std::fs::remove_dir_all(&their_root);
}

#[test]
fn a_config_that_is_a_device_fifo_or_huge_is_refused_at_once() {
    let ipc = Isolated::new("cfgfile");
    refused(
        &ipc,
        &["up", "--config", "/dev/zero"],
        &["/dev/zero is a character device, not a regular file"],
    );
    let scratch = Scratch::new("sec", "cfgfile");
    let fifo = scratch.path().join("rins.toml");
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c_path(&fifo).as_ptr(), 0o600) }, 0);
    let fifo_s = fifo.display().to_string();
    refused(&ipc, &["up", "--config", &fifo_s], &[&fifo_s, "is a FIFO"]);
    refused(
        &ipc,
        &["sim", "--faults", &fifo_s],
        &["fault file", &fifo_s, "is a FIFO"],
    );
    let dir = scratch.path().display().to_string();
    refused(&ipc, &["geometry", "--config", &dir], &["is a directory"]);
    let huge = scratch.path().join("huge.toml");
    std::fs::write(&huge, format!("# {}\n", "x".repeat(2 << 20))).unwrap();
    let huge_s = huge.display().to_string();
    refused(
        &ipc,
        &["up", "--config", &huge_s],
        &[&huge_s, "more than the 1048576"],
    );
    assert!(!ipc.root.exists(), "nothing was set up");
}

#[test]
fn an_axis_that_is_not_a_unit_vector_is_refused() {
    let cfg = common::TempFile::new(
        "axes",
        "toml",
        "[fusion.geometry.gyro]\nkind = \"axes\"\naxes = [[5, 0, 0], [0, 1, 0], [0, 0, 1], [0.57735, 0.57735, 0.57735]]\n",
    );
    let ipc = Isolated::new("axes");
    refused(
        &ipc,
        &["up", "--config", cfg.path()],
        &["fusion.geometry.gyro.axes[0] = [5, 0, 0]: must be a unit vector (norm 5)"],
    );
}

/// A running pipeline stopped by `sig`: a clean stop, like SIGTERM.
fn stops_cleanly_on(sig: Signal, name: &str) {
    let ipc = Isolated::new(name);
    let _slot = PipelineSlot::take();
    let up = common::spawn_up_navigating(
        &ipc,
        &["--scenario", "static", "--duration", "120", "--json"],
    );
    let pids = processes_of(&ipc.prefix);
    assert!(
        pids.len() >= 6,
        "watchdog, services and simulator: {pids:?}"
    );
    signal(&up, sig);
    let out = wait_within(up, Duration::from_secs(30));
    let summary = common::last_json(&out);
    assert_eq!(common::num(&summary, "shm_leaked"), 0.0);
    assert_stopped_clean(&ipc, &out, name);
}

#[test]
fn sighup_stops_the_pipeline_cleanly() {
    stops_cleanly_on(Signal::Hangup, "sighup");
}

#[test]
fn sigusr1_stops_the_pipeline_cleanly() {
    stops_cleanly_on(Signal::User1, "sigusr1");
}

#[test]
fn sigterm_during_start_up_is_a_clean_stop() {
    // Children are started and the simulator's terminal awaited within the first few hundred
    // milliseconds: a stop at these moments used to exit 1 with a false "simulator did not create".
    for ms in [5, 10, 20, 60, 150] {
        let ipc = Isolated::new(&format!("early{ms}"));
        let _slot = PipelineSlot::take();
        let up = ipc
            .command()
            .args(["up", "--scenario", "static", "--duration", "60"])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("rins up");
        // Counted from the handler's installation, its first act: before it (the loader, the
        // command line) a stop signal ends the process by its default action, with nothing made
        // yet, and a loaded machine can take more than 5 ms to get there.
        wait_for_stop_handler(&up);
        std::thread::sleep(Duration::from_millis(ms));
        signal(&up, Signal::Terminate);
        let out = wait_within(up, Duration::from_secs(30));
        let what = format!("SIGTERM {ms} ms after launch");
        assert_stopped_clean(&ipc, &out, &what);
        assert!(
            !ipc.root.exists(),
            "{what}: the root this run created is left"
        );
    }
    // The same stop of an already running pipeline, by the helper every pipeline test uses.
    let ipc = Isolated::new("late");
    let _slot = PipelineSlot::take();
    let up = common::spawn_up(
        &ipc,
        &["--scenario", "static", "--duration", "60", "--json"],
    );
    std::thread::sleep(Duration::from_millis(500));
    stop_up(&ipc, up);
}

/// Every entry of a running deployment: its shared memory in /dev/shm and everything under its
/// root (the root itself first).
fn deployment_files(ipc: &Isolated) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = ipc
        .shm_entries()
        .into_iter()
        .map(|n| Path::new("/dev/shm").join(n))
        .collect();
    let mut dirs = vec![ipc.root.clone()];
    while let Some(dir) = dirs.pop() {
        files.push(dir.clone());
        for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            let path = entry.path();
            if entry.file_type().is_ok_and(|t| t.is_dir()) {
                dirs.push(path);
            } else {
                files.push(path);
            }
        }
    }
    files
}

/// What another user's attempt on a file came to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Attempt {
    /// Refused with EACCES or EPERM.
    Refused,
    /// It worked: the file was theirs to change.
    Done,
    /// Refused otherwise (the errno).
    Other(i32),
}

/// As uid and gid 65534, in a child process, tries to open each path for writing, to truncate it
/// and to delete it; returns what each of the three came to, per path.
fn try_as_nobody(paths: &[PathBuf]) -> Vec<[Attempt; 3]> {
    let names: Vec<CString> = paths.iter().map(|p| c_path(p)).collect();
    let mut fds = [0i32; 2];
    // SAFETY: a valid two-int array.
    assert_eq!(unsafe { libc::pipe(fds.as_mut_ptr()) }, 0);
    // Everything the child needs is made before the fork: between fork and _exit it only calls
    // async-signal-safe functions.
    let mut codes = vec![0u8; names.len() * 3];
    // SAFETY: fork in a test process; the child only makes system calls and ends with _exit.
    let pid = unsafe { libc::fork() };
    assert!(pid >= 0, "fork");
    if pid == 0 {
        let code = |r: libc::c_int| -> u8 {
            if r >= 0 {
                return 1;
            }
            // SAFETY: errno of this thread.
            match unsafe { *libc::__errno_location() } {
                libc::EACCES | libc::EPERM => 0,
                e => 2 + (e.clamp(0, 250) as u8),
            }
        };
        // SAFETY: plain system calls on valid NUL-terminated paths and our own pipe; the child
        // ends with _exit whatever happens.
        unsafe {
            if libc::setgroups(0, std::ptr::null()) != 0
                || libc::setgid(NOBODY) != 0
                || libc::setuid(NOBODY) != 0
            {
                libc::_exit(99);
            }
            for (i, name) in names.iter().enumerate() {
                let fd = libc::open(
                    name.as_ptr(),
                    libc::O_WRONLY | libc::O_NOFOLLOW | libc::O_NONBLOCK,
                );
                codes[i * 3] = code(fd);
                if fd >= 0 {
                    libc::close(fd);
                }
                codes[i * 3 + 1] = code(libc::truncate(name.as_ptr(), 0));
                codes[i * 3 + 2] = code(libc::unlink(name.as_ptr()));
            }
            libc::write(fds[1], codes.as_ptr().cast(), codes.len());
            libc::_exit(0);
        }
    }
    // SAFETY: our end of the pipe, and our own child.
    unsafe { libc::close(fds[1]) };
    let mut status = 0;
    // SAFETY: waiting for our own child.
    assert_eq!(unsafe { libc::waitpid(pid, &mut status, 0) }, pid);
    assert_eq!(status, 0, "the child could not become uid {NOBODY}");
    // SAFETY: reading into a buffer of that length from our end of the pipe.
    let n = unsafe { libc::read(fds[0], codes.as_mut_ptr().cast(), codes.len()) };
    // SAFETY: our own descriptor.
    unsafe { libc::close(fds[0]) };
    assert_eq!(n as usize, codes.len(), "the child's report");
    let attempt = |c: u8| match c {
        0 => Attempt::Refused,
        1 => Attempt::Done,
        e => Attempt::Other(i32::from(e) - 2),
    };
    codes
        .chunks(3)
        .map(|c| [attempt(c[0]), attempt(c[1]), attempt(c[2])])
        .collect()
}

/// No file of a running deployment is another user's to write, truncate or delete: every shared
/// memory segment (iceoryx2's management segment included, which iceoryx2 alone makes 0666) and
/// every file under the root. Checked by modes and by trying, as uid 65534.
#[test]
fn no_file_of_a_running_deployment_can_be_written_truncated_or_deleted_by_another_user() {
    let ipc = Isolated::new("othuid");
    let _slot = PipelineSlot::take();
    let up = Stopped(Some(common::spawn_up_navigating(
        &ipc,
        &["--scenario", "static", "--duration", "60", "--json"],
    )));
    let files = deployment_files(&ipc);
    let shm: Vec<&PathBuf> = files.iter().filter(|p| p.starts_with("/dev/shm")).collect();
    assert!(
        shm.iter()
            .any(|p| p.to_string_lossy().ends_with(".global_mgmt")),
        "the management segment is among {shm:?}"
    );
    assert!(shm.len() > 20, "{shm:?}");
    // Modes: the shared memory owner-only, nothing under the root writable by others, the root
    // reachable by its owner only.
    for path in &files {
        let meta = std::fs::symlink_metadata(path).unwrap();
        let mode = meta.mode() & 0o7777;
        if meta.file_type().is_symlink() {
            continue;
        }
        if path.starts_with("/dev/shm") {
            assert_eq!(mode & 0o077, 0, "{} is mode {mode:o}", path.display());
        } else {
            assert_eq!(mode & 0o022, 0, "{} is mode {mode:o}", path.display());
        }
    }
    assert_eq!(std::fs::metadata(&ipc.root).unwrap().mode() & 0o777, 0o700);
    if !is_root() {
        eprintln!("note: not root; the modes were checked, the other user's attempts are not");
        return;
    }
    let attempts = try_as_nobody(&files);
    let allowed: Vec<String> = files
        .iter()
        .zip(&attempts)
        // A directory is never open for writing, whoever asks (EISDIR): what matters of it is
        // that it cannot be removed and that nothing in it can be reached.
        .filter(|(p, a)| {
            a.iter().any(|r| {
                *r != Attempt::Refused && !(p.is_dir() && *r == Attempt::Other(libc::EISDIR))
            })
        })
        .map(|(p, a)| format!("{} {a:?}", p.display()))
        .collect();
    assert_eq!(
        allowed,
        Vec::<String>::new(),
        "open/truncate/unlink as uid {NOBODY}"
    );
    // Nothing was touched: the deployment runs on.
    let out = ipc.run_with_timeout(&["echo", "nav", "--count", "10", "--timeout", "10"], PROMPT);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = up.stop(Duration::from_secs(30));
    assert!(out.status.success(), "{}", stderr(&out));
}

/// The deployment's iceoryx2 management segment, found among its shared memory.
fn management_segment(ipc: &Isolated) -> PathBuf {
    let name = ipc
        .shm_entries()
        .into_iter()
        .find(|n| n.ends_with(".global_mgmt"))
        .expect("the deployment has a management segment");
    Path::new("/dev/shm").join(name)
}

/// Where iceoryx2's management segment of `ipc`'s deployment is, before anything made it.
fn management_segment_to_be(ipc: &Isolated) -> PathBuf {
    let config = iceoryx2::prelude::Config::default();
    Path::new("/dev/shm").join(rins_runtime::ipc::mgmt_segment::segment_name(
        &ipc.prefix,
        &config,
    ))
}

/// The owner damages the management segment during a run and a service dies: no node can be made
/// any more, so the service cannot come back. The deployment does not go on reporting a
/// navigation that stopped: its restarts fail, it is given up and `rins up` stops with an error
/// naming the file.
#[test]
fn a_management_segment_damaged_during_a_run_stops_the_deployment_loudly() {
    let ipc = Isolated::new("mgmtdmg");
    let _slot = PipelineSlot::take();
    let up = common::spawn_up_navigating(
        &ipc,
        &["--scenario", "static", "--duration", "45", "--json"],
    );
    let report = ipc.status();
    let fusion = report["services"]
        .as_array()
        .and_then(|s| s.iter().find(|s| s["service"] == "fusion"))
        .and_then(|s| s["pid"].as_u64())
        .expect("fusion's pid");
    let segment = management_segment(&ipc);
    std::fs::write(&segment, [0xFFu8; 16]).unwrap();
    send_signal(fusion, Signal::Kill).expect("SIGKILL to fusion");
    let started = Instant::now();
    let out = wait_within(up, Duration::from_secs(30));
    let err = ipc.up_stderr();
    assert!(!out.status.success(), "rins up should fail:\n{err}");
    assert!(
        started.elapsed() < Duration::from_secs(20),
        "took {:?}",
        started.elapsed()
    );
    let name = segment.display().to_string();
    for part in [
        "fusion failed to start 5 times in a row",
        "stopping the pipeline",
        &name,
        "holds version word 0xffffffffffffffff",
    ] {
        assert!(err.contains(part), "{part:?} missing:\n{err}");
    }
    assert_eq!(processes_of(&ipc.prefix), Vec::<u32>::new());
}

/// A tool facing a damaged management segment (truncated to nothing, or overwritten) fails at
/// once, naming it, instead of waiting for ever or failing on an iceoryx2 error that names
/// nothing; and a tool without a timeout stops on SIGTERM.
#[test]
fn tools_facing_a_damaged_management_segment_fail_promptly_naming_it_and_stop_on_sigterm() {
    for (what, contents, expected) in [
        ("truncated", Vec::new(), "is 0 bytes long"),
        (
            "garbage",
            vec![0xFFu8; 16],
            "holds version word 0xffffffffffffffff",
        ),
    ] {
        let ipc = Isolated::new(&format!("mg{what}"));
        let segment = management_segment_to_be(&ipc);
        let plant = || {
            std::fs::write(&segment, &contents).unwrap();
            std::fs::set_permissions(&segment, std::fs::Permissions::from_mode(0o600)).unwrap();
        };
        let name = segment.display().to_string();
        plant();
        let started = Instant::now();
        let out = ipc.run_with_timeout(&["echo", "nav", "--timeout", "3"], Duration::from_secs(6));
        assert!(!out.status.success(), "{what}");
        assert!(
            started.elapsed() < Duration::from_secs(5),
            "{what}: {:?}",
            started.elapsed()
        );
        let err = stderr(&out);
        assert!(
            err.contains(&name) && err.contains(expected),
            "{what}: {err}"
        );
        plant();
        let out = ipc.run_with_timeout(&["status", "--timeout", "2"], Duration::from_secs(5));
        assert!(!out.status.success(), "{what}");
        assert!(stderr(&out).contains(&name), "{what}: {}", stderr(&out));
        for args in [
            &["inject", "gyro0", "dead"][..],
            &["readmit", "gyro0", "--timeout", "2"],
        ] {
            plant();
            let out = ipc.run_with_timeout(args, Duration::from_secs(5));
            assert!(!out.status.success(), "{what}: {args:?}");
            assert!(
                stderr(&out).contains(&name),
                "{what}: {args:?}: {}",
                stderr(&out)
            );
        }
        // No timeout: it ends on SIGTERM (or has ended by then), within two seconds.
        plant();
        let echo = ipc
            .command()
            .args(["echo", "nav"])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("rins echo");
        std::thread::sleep(Duration::from_millis(300));
        let _ = send_signal(u64::from(echo.id()), Signal::Terminate);
        let out = wait_within(echo, Duration::from_secs(2));
        assert!(!out.status.success(), "{what}: {}", stderr(&out));
    }
}
