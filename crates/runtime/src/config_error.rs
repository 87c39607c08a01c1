//! Configuration errors that name the offending field and its value.

use std::fmt::Display;

/// A rejected configuration value, displayed as `field = value: reason`,
/// e.g. `geometry.gyro.alpha_deg = 95: must be in (-90, 90)`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{field} = {value}: {reason}")]
pub struct ConfigError {
    /// Dotted path of the field, relative to where the error was last prefixed.
    pub field: String,
    /// The offending value as written.
    pub value: String,
    /// What the value must satisfy.
    pub reason: String,
}

impl ConfigError {
    /// Builds an error for `field` holding `value`.
    pub fn new(field: impl Into<String>, value: impl Display, reason: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }

    /// Prefixes the field path with the enclosing table, so nested configs report full paths.
    #[must_use]
    pub fn within(mut self, prefix: &str) -> Self {
        if prefix.is_empty() {
            return self;
        }
        self.field = if self.field.is_empty() {
            prefix.to_owned()
        } else if self.field.starts_with('[') {
            format!("{prefix}{}", self.field)
        } else {
            format!("{prefix}.{}", self.field)
        };
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_field_and_value() {
        let e = ConfigError::new("alpha_deg", 95.0, "must be in (-90, 90)")
            .within("gyro")
            .within("geometry");
        assert_eq!(
            e.to_string(),
            "geometry.gyro.alpha_deg = 95: must be in (-90, 90)"
        );
        let e = ConfigError::new("[2]", 0.0, "must be > 0").within("scale");
        assert_eq!(e.field, "scale[2]");
    }
}
