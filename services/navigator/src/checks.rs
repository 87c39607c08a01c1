//! Range checks shared by the settings structs: each returns the offending `(field, value)` so
//! the configuration layer can name it.

/// `Ok` when `value` is finite and positive, else `Err((name, value))` (NaN included).
pub(crate) fn positive(name: &'static str, value: f64) -> Result<(), (&'static str, f64)> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err((name, value))
    }
}
