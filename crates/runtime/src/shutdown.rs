//! Termination requests as a flag the process loops poll: SIGINT and SIGTERM, and SIGHUP, SIGUSR1
//! and SIGUSR2, whose default action would end the process on the spot, leaving its children
//! running and its shared memory behind; rins has no other use for them, so they stop it cleanly.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// The flag of the handlers [`Shutdown::install`] installed, for code that cannot be handed it
/// (a guard on a tool's set-up).
static INSTALLED: OnceLock<Shutdown> = OnceLock::new();

/// The signals that request a clean stop.
pub const STOP_SIGNALS: [i32; 5] = [
    signal_hook::consts::SIGINT,
    signal_hook::consts::SIGTERM,
    signal_hook::consts::SIGHUP,
    signal_hook::consts::SIGUSR1,
    signal_hook::consts::SIGUSR2,
];

/// Set once one of [`STOP_SIGNALS`] arrived. Cheap to poll from a hot loop (one relaxed load).
#[derive(Clone)]
pub struct Shutdown(Arc<AtomicBool>);

impl Shutdown {
    /// Installs handlers for [`STOP_SIGNALS`] that set the flag.
    pub fn install() -> anyhow::Result<Self> {
        let flag = Arc::new(AtomicBool::new(false));
        for signal in STOP_SIGNALS {
            signal_hook::flag::register(signal, Arc::clone(&flag))?;
        }
        let shutdown = Self(flag);
        let _ = INSTALLED.set(shutdown.clone());
        Ok(shutdown)
    }

    /// The flag of the first [`Shutdown::install`] of this process; `None` when no handler was
    /// installed (a stop signal then ends the process by its default action).
    pub fn installed() -> Option<Self> {
        INSTALLED.get().cloned()
    }

    /// A flag no signal sets, for in-process use and tests.
    pub fn manual() -> Self {
        Self(Arc::new(AtomicBool::new(false)))
    }

    /// Whether a stop was requested (by a signal or [`Shutdown::request`]).
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// Requests a stop, as a termination signal would.
    pub fn request(&self) {
        self.0.store(true, Ordering::Relaxed);
    }
}
