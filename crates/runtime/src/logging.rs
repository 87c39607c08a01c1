//! Structured logs to stderr; the level comes from `RINS_LOG` (tracing env-filter syntax), default `info`.

use tracing_subscriber::EnvFilter;

/// Sets up logging to stderr for process `process` (level from `RINS_LOG`).
pub fn init(process: &str) {
    let filter = EnvFilter::try_from_env("RINS_LOG")
        .unwrap_or_else(|_| EnvFilter::new("info,iceoryx2=warn"));
    // A second init (tests running several services in one process) is harmless: keep the first.
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .with_target(false)
        .try_init();
    tracing::debug!(process, "logging initialised");
}
