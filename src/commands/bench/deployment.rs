//! Where `rins bench` runs what it measures: a deployment of its own (prefix and private root)
//! removed at the end whatever happens, the children it starts stopped and reaped, and the one
//! configuration every measurement of a run shares.

use std::path::PathBuf;
use std::process::{Child, Command};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use rins::wait_config::WaitKind;
use rins_runtime::ipc::IpcSettings;
use rins_runtime::shm_cleanup;

use crate::cli::BenchIpcArgs;
use crate::config::RinsConfig;

/// The bench's own deployment: a prefix and a private root nobody else uses, removed at the end.
pub struct Deployment {
    pub settings: IpcSettings,
    pub root: PathBuf,
}

impl Deployment {
    /// `tag` tells apart the bench's deployments (each measurement has its own, so no service
    /// of one is open when the next starts).
    pub fn new(tag: &str) -> Result<Self> {
        let id = std::process::id();
        let root = std::env::temp_dir().join(format!("rins-bench-{id}-{tag}"));
        let settings = IpcSettings::new(
            format!("rinsbench{id}{tag}_"),
            root.to_string_lossy().into_owned(),
        );
        settings.ensure_root()?;
        Ok(Self { settings, root })
    }

    /// `rins ARGS` on this deployment.
    pub fn command(&self, args: &[&str]) -> Result<Command> {
        let exe = std::env::current_exe().context("cannot locate the rins executable")?;
        let mut cmd = Command::new(exe);
        cmd.args(args)
            .env(rins_runtime::ipc::PREFIX_ENV, &self.settings.prefix)
            .env(rins_runtime::ipc::ROOT_ENV, &self.settings.root);
        Ok(cmd)
    }
}

impl Drop for Deployment {
    fn drop(&mut self) {
        shm_cleanup::remove_all(&self.settings, true);
        let _ = std::fs::remove_dir_all(&self.root);
    }
}

/// A child stopped and reaped when dropped: SIGTERM, then SIGKILL after `grace`.
pub struct ChildGuard {
    pub child: Child,
    pub grace: Duration,
}

impl ChildGuard {
    pub fn stop(&mut self) {
        if matches!(self.child.try_wait(), Ok(Some(_))) {
            return;
        }
        if let Ok(pid) = i32::try_from(self.child.id()) {
            // SAFETY: kill(2) with our own child's pid; no memory is passed.
            unsafe { libc::kill(pid, libc::SIGTERM) };
        }
        let until = Instant::now() + self.grace;
        while Instant::now() < until {
            if matches!(self.child.try_wait(), Ok(Some(_))) {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for ChildGuard {
    fn drop(&mut self) {
        self.stop();
    }
}

/// The configuration every measurement runs on: `--config` (or the built-in one) with `--wait`
/// for every stage.
pub fn bench_config(args: &BenchIpcArgs) -> Result<RinsConfig> {
    let mut config = crate::config::load(args.config.as_deref())?;
    if let Some(kind) = args.wait {
        config.wait.strategy = kind;
        config.wait.services.clear();
    }
    Ok(config)
}

/// The strategy's name when every stage of the data path waits alike, else `mixed`.
pub fn wait_name(config: &RinsConfig) -> String {
    let kinds: Vec<WaitKind> = ["fusion", "navigator"]
        .iter()
        .map(|s| {
            config
                .wait
                .services
                .get(*s)
                .copied()
                .unwrap_or(config.wait.strategy)
        })
        .collect();
    match kinds.as_slice() {
        [a, b] if a == b => match a {
            WaitKind::Event => "event",
            WaitKind::Spin => "spin",
            WaitKind::Hybrid => "hybrid",
        },
        _ => "mixed",
    }
    .to_string()
}

/// The configuration as a file in the deployment's private root, for the processes it starts.
pub fn write_config(deployment: &Deployment, config: &RinsConfig) -> Result<PathBuf> {
    let path = deployment.root.join("bench.toml");
    let text = toml::to_string(config).context("the bench's configuration")?;
    let mut file = rins_recording::create_file(&path, false)
        .with_context(|| format!("creating {}", path.display()))?;
    std::io::Write::write_all(&mut file, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}
