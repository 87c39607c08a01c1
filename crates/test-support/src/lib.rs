//! Helpers the workspace's tests share, so that each is written once: a dev-dependency only,
//! never part of a product build.
//!
//! - [`counting_alloc`]: a global allocator that counts this thread's allocations, for the
//!   allocation-free checks of the per-sample paths.
//! - [`private_ipc`]: a private iceoryx2 deployment per test, and another build's payload
//!   versions.
//! - [`pyramid`]: sensitive axes of the skewed pyramid layouts.
//! - [`scratch`]: a fresh, empty directory per test.
//! - [`signal`]: sending a signal to a child process (or any process a test started).

pub mod counting_alloc;
pub mod private_ipc;
pub mod pyramid;
pub mod scratch;
pub mod signal;
