//! Range checks shared by the settings structs: each returns the offending `(field, value)` so
//! the configuration layer can name it, or the configuration error itself.

use rins_runtime::config_error::ConfigError;

/// `Ok` when `value` is finite and positive, else `Err((name, value))` (NaN included).
pub(crate) fn positive(name: &'static str, value: f64) -> Result<(), (&'static str, f64)> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err((name, value))
    }
}

/// One settings table (`navigator`, `navigator.start`), whose range checks name their key within
/// it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Table(pub(crate) &'static str);

impl Table {
    /// `value` of `table.field` is finite and passes `ok`; otherwise the error names the key, the
    /// value and `reason`.
    pub(crate) fn check(
        self,
        field: &'static str,
        value: f64,
        ok: impl Fn(f64) -> bool,
        reason: &'static str,
    ) -> Result<(), ConfigError> {
        // `is_finite` first so that NaN and infinities are always rejected whatever the range
        // test says.
        if value.is_finite() && ok(value) {
            Ok(())
        } else {
            Err(ConfigError::new(field, value, reason).within(self.0))
        }
    }
}
