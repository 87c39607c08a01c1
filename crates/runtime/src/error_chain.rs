//! An error printed with its causes, `context: cause: cause`, for log fields: the typed errors of
//! this crate keep iceoryx2's error as their source instead of repeating it in their message.

use std::error::Error;
use std::fmt;

/// Displays an error and every source under it, separated by `: ` (what anyhow's `{:#}` prints),
/// without allocating.
pub struct ErrorChain<'a>(pub &'a (dyn Error + 'static));

impl fmt::Display for ErrorChain<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)?;
        let mut source = self.0.source();
        while let Some(cause) = source {
            write!(f, ": {cause}")?;
            source = cause.source();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, thiserror::Error)]
    #[error("cannot open topic \"imu\"")]
    struct Outer {
        source: std::io::Error,
    }

    #[test]
    fn prints_the_context_then_each_cause() {
        let e = Outer {
            source: std::io::Error::other("no memory"),
        };
        assert_eq!(
            ErrorChain(&e).to_string(),
            "cannot open topic \"imu\": no memory"
        );
    }
}
