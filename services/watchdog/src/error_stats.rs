//! RMS and largest of a stream of errors: the figure every accuracy score of a run is given in.

/// RMS and largest of a stream of errors.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ErrorStats {
    n: u64,
    sum_sq: f64,
    max: f64,
}

impl ErrorStats {
    /// Adds one error sample.
    pub fn push(&mut self, error: f64) {
        self.n += 1;
        self.sum_sq += error * error;
        self.max = self.max.max(error.abs());
    }

    /// Samples added so far.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Root mean square; `None` before the first sample.
    pub fn rms(&self) -> Option<f64> {
        (self.n > 0).then(|| (self.sum_sq / self.n as f64).sqrt())
    }

    /// The largest error, once there is a sample.
    pub fn max(&self) -> Option<f64> {
        (self.n > 0).then_some(self.max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rms_and_max() {
        let mut s = ErrorStats::default();
        assert_eq!(s.rms(), None);
        for e in [3.0, -4.0] {
            s.push(e);
        }
        assert!((s.rms().unwrap() - (12.5f64).sqrt()).abs() < 1e-12);
        assert_eq!(s.max(), Some(4.0));
    }
}
