//! The Python interpreter of the test venv (`RINS_PYTHON`, made by `.ci/run` with the packages of
//! `python/requirements-test.txt`): tests that talk to rins from Python run with it, and are skipped
//! with a note where there is none — unless `RINS_REQUIRE_PYTHON` is set, as CI sets it.

use std::path::PathBuf;
use std::process::{Command, Output};

/// The venv's interpreter, or `None` (after a note on stderr) when the test must be skipped.
pub fn interpreter(test: &str) -> Option<PathBuf> {
    match std::env::var_os("RINS_PYTHON") {
        Some(p) => Some(PathBuf::from(p)),
        None if std::env::var_os("RINS_REQUIRE_PYTHON").is_some() => {
            panic!("{test}: RINS_REQUIRE_PYTHON is set but RINS_PYTHON is not")
        }
        None => {
            eprintln!(
                "{test}: skipped: RINS_PYTHON is not set (run python/setup-venv and set it to the \
                 venv's python)"
            );
            None
        }
    }
}

/// Runs `script` (a path from the repository root) with `args` under `ipc`'s prefix and root.
pub fn run_script(python: &PathBuf, ipc: &super::Isolated, script: &str, args: &[&str]) -> Output {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(script);
    Command::new(python)
        .arg(script)
        .args(args)
        .env("RINS_IPC_PREFIX", &ipc.prefix)
        .env("RINS_IPC_ROOT", &ipc.root)
        .env("RINS_LOG", "warn")
        .output()
        .expect("cannot run python")
}

/// A UDP port free on the loopback now.
pub fn free_udp_port() -> u16 {
    std::net::UdpSocket::bind("127.0.0.1:0")
        .and_then(|s| s.local_addr())
        .map(|a| a.port())
        .expect("no free UDP port")
}
