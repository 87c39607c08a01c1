//! Runtime shared by every rins process: iceoryx2 node and topic set-up on an isolated prefix,
//! the monotonic clock, termination signals, heartbeats and log set-up, the loops the processes
//! run (topic-driven stages, clock-paced sources), and the checks that keep another local user's
//! files out of a deployment (private directories, owners, bounded files).

pub mod bounded_file;
pub mod clock;
pub mod config_error;
pub mod error_chain;
pub mod heartbeat;
pub mod input_watch;
pub mod ipc;
pub mod join_check;
pub mod logging;
pub mod paced_loop;
pub mod payload;
pub mod private_dir;
pub mod rate_gate;
pub mod realtime;
pub mod root_lock;
pub mod service;
pub mod service_loop;
pub mod setup_guard;
pub mod shm_cleanup;
pub mod shutdown;
pub mod stage_io;
pub mod stage_loop;
pub mod tool_node;
pub mod user;
pub mod wait_strategy;
