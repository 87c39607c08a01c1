//! The watchdog: starts every rins process as a child, restarts the ones that exit, watches the
//! topics, prints a status line per second and, at the end of a timed run, a summary.

pub mod accuracy;
pub mod child_exit_wait;
pub mod config;
pub mod deployment_checks;
pub mod device_counters;
pub mod error_stats;
pub mod fault_tracking;
pub mod gnss_line;
pub mod health_publisher;
pub mod health_report;
pub mod horizontal;
pub mod kill_decisions;
pub mod link;
pub mod monitor;
pub mod output_deadline;
pub mod process_graph;
pub mod process_usage;
pub mod redundancy_view;
pub mod restart_policy;
pub mod restart_timing;
pub mod run_summary;
pub mod seq_gaps;
pub mod sim_start;
pub mod status;
pub mod status_rows;
pub mod summary;
pub mod summary_text;
pub mod supervision_loop;
pub mod supervisor;
