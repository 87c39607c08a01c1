//! The parts of the `rins` executable other programs build on: its command line and its
//! configuration loader (the fuzz targets feed the loader arbitrary text).

pub mod built_services;
pub mod cli;
pub mod config;
pub mod deploy_profile;
pub mod deploy_profile_file;
pub mod realtime_config;
pub mod record;
pub mod replay;
pub mod wait_config;
