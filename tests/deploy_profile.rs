//! `rins up --profile`: `dedicated` refuses a machine with too few CPUs before anything starts,
//! naming the counts; `auto` chooses by the free CPUs and says which profile runs and why, in the
//! run's summary and in `rins status`.

mod common;

use std::os::unix::process::CommandExt;

use common::{Isolated, PipelineSlot, spawn_up_navigating, stderr, stop_up};

/// The first `n` CPUs this test may use.
fn first_cpus(n: usize) -> Vec<usize> {
    let usable = rins::deploy_profile::usable_cpus().expect("this process's affinity");
    usable.into_iter().take(n).collect()
}

/// `cmd` with its affinity mask narrowed to `cpus` before it runs.
fn narrowed(mut cmd: std::process::Command, cpus: &[usize]) -> std::process::Command {
    let mask = cpus.to_vec();
    // SAFETY: between fork and exec the closure only builds a cpu_set_t on the stack and calls
    // sched_setaffinity(2), both async-signal-safe; CPU_SET writes inside the set for an index
    // the kernel reported usable (below CPU_SETSIZE).
    unsafe {
        cmd.pre_exec(move || {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            for &cpu in &mask {
                libc::CPU_SET(cpu, &mut set);
            }
            if libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
    cmd
}

#[test]
fn dedicated_with_fewer_than_four_cpus_is_refused_naming_the_counts() {
    // Two CPUs whatever the machine has: the child's affinity mask is narrowed before it runs.
    let cpus = first_cpus(2);
    let expected = format!(
        "--profile dedicated needs 4 usable CPUs (3 dedicated, 1 shared); this process may use {}",
        cpus.len()
    );
    let ipc = Isolated::new("profile_refused");
    let mut up = ipc.command();
    up.args(["up", "--profile", "dedicated", "--duration", "5"]);
    let out = narrowed(up, &cpus).output().expect("cannot run rins");
    let err = stderr(&out);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains(&expected), "{err}");
    // Refused before the deployment was set up: nothing of it was made.
    assert!(!ipc.root.exists(), "{}", ipc.root.display());
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());

    // A soak passes the profile on to the `rins up` it starts, and fails with its words.
    let mut soak = ipc.command();
    soak.args(["soak", "--minutes", "2", "--profile", "dedicated", "--json"]);
    let started = std::time::Instant::now();
    let out = narrowed(soak, &cpus).output().expect("cannot run rins");
    let err = stderr(&out);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("rins up did not start") && err.contains(&expected),
        "{err}"
    );
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(started.elapsed() < std::time::Duration::from_secs(60));
}

#[test]
fn auto_reports_the_profile_it_chose_and_why_in_the_summary_and_the_status() {
    let _slot = PipelineSlot::take();
    let usable = first_cpus(usize::MAX).len();
    let ipc = Isolated::new("profile_auto");
    let up = spawn_up_navigating(&ipc, &["--profile", "auto", "--duration", "120", "--json"]);
    let status = ipc.status();
    let summary = stop_up(&ipc, up);

    let profile = summary["profile"].as_str().expect("profile");
    let reason = summary["profile_reason"].as_str().expect("profile_reason");
    assert!(
        reason.starts_with(&format!("auto: {usable} usable CPUs, ")),
        "{reason}"
    );
    // The free CPUs counted when it started decide: 4 or more, dedicated; else shared.
    let free: usize = reason
        .split(", ")
        .nth(1)
        .and_then(|f| f.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no free count in {reason:?}"));
    assert!(free <= usable, "{reason}");
    if free >= 4 {
        assert_eq!(profile, "dedicated", "{reason}");
        assert!(
            reason.contains(": dedicated (acquisition on CPU "),
            "{reason}"
        );
    } else {
        assert_eq!(profile, "shared", "{reason}");
        assert!(reason.ends_with("; dedicated needs 4: shared"), "{reason}");
    }
    if usable < 4 {
        assert_eq!(profile, "shared", "{reason}");
    }
    // `rins status` says the same while it runs.
    assert_eq!(status["profile"], profile, "{status}");
    assert_eq!(status["profile_reason"], reason, "{status}");
    assert!(
        summary["nav_samples"].as_u64().unwrap_or(0) > 0,
        "{summary}"
    );
}
