//! Configuration errors that name the offending field and its value (shared by every service).

pub use rins_runtime::config_error::ConfigError;
