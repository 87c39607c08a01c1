//! Why a fault command, a `--inject` argument or a fault-file entry was refused: the piece of
//! input at fault and what it must be, shared by every parser of fault commands.

/// A fault command or schedule entry that could not be understood: `token` names the offending
/// piece of input (e.g. `bias STEP "abc"`), `reason` says what it must be.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{token}: {reason}")]
pub struct FaultParseError {
    /// The offending piece of input, as written.
    pub token: String,
    /// What it must be.
    pub reason: String,
}

impl FaultParseError {
    /// An error about `token`, saying what it must be.
    pub fn new(token: impl Into<String>, reason: impl Into<String>) -> Self {
        Self {
            token: token.into(),
            reason: reason.into(),
        }
    }

    /// The same error, located inside a larger piece of input (`where_` is prepended to the token).
    pub fn within(self, where_: &str) -> Self {
        Self {
            token: format!("{where_}: {}", self.token),
            reason: self.reason,
        }
    }
}
