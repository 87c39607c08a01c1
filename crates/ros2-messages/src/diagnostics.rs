//! `diagnostic_msgs/msg/DiagnosticArray`: the health of a system as ROS 2's diagnostic tools
//! (`rqt_robot_monitor`, the diagnostic aggregator) read it: one status per part, each with a
//! level, a message and its figures as key/value strings.

use crate::messages::Header;

/// `diagnostic_msgs/msg/KeyValue`.
#[derive(Debug, Clone, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct KeyValue {
    /// What the value is.
    pub key: String,
    /// The value, as text.
    pub value: String,
}

/// `diagnostic_msgs/msg/DiagnosticStatus`.
#[derive(Debug, Clone, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct DiagnosticStatus {
    /// [`DiagnosticStatus::OK`], [`DiagnosticStatus::WARN`], [`DiagnosticStatus::ERROR`] or
    /// [`DiagnosticStatus::STALE`] (a `byte`).
    pub level: u8,
    /// The part this status speaks for.
    pub name: String,
    /// A short description of its state.
    pub message: String,
    /// The hardware the part runs on.
    pub hardware_id: String,
    /// Its figures.
    pub values: Vec<KeyValue>,
}

impl DiagnosticStatus {
    /// Working as it should.
    pub const OK: u8 = 0;
    /// Working, with something to look at.
    pub const WARN: u8 = 1;
    /// Not working.
    pub const ERROR: u8 = 2;
    /// Not heard from.
    pub const STALE: u8 = 3;

    /// The level by its name in `diagnostic_msgs` (`OK`, `WARN`, `ERROR`, `STALE`), or its number.
    pub fn level_name(level: u8) -> String {
        match level {
            Self::OK => "OK".into(),
            Self::WARN => "WARN".into(),
            Self::ERROR => "ERROR".into(),
            Self::STALE => "STALE".into(),
            other => format!("level {other}"),
        }
    }
}

/// `diagnostic_msgs/msg/DiagnosticArray`.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct DiagnosticArray {
    /// When the statuses were made.
    pub header: Header,
    /// One per part.
    pub status: Vec<DiagnosticStatus>,
}
