//! VIBRATION: how much the airframe shakes the IMU — the standard deviation of the fused specific
//! force on each body axis over the interval since the last message — and how often the
//! accelerometers clipped (fused samples flagged saturated, counted since start, as the message
//! defines them).

use ipc_types::{FusedImu, fused_flags};

use crate::dialect::VIBRATION_DATA;

/// Running mean and spread of the specific force since the last message, and the clip count.
#[derive(Debug, Clone, Default)]
pub struct VibrationMeter {
    n: u64,
    mean: [f64; 3],
    /// Sum of squared deviations from the running mean (Welford), per axis.
    m2: [f64; 3],
    clipped: u32,
}

impl VibrationMeter {
    /// Takes one fused sample.
    pub fn add(&mut self, f: &FusedImu) {
        if f.flags & fused_flags::ACCEL_SATURATED != 0 {
            self.clipped = self.clipped.saturating_add(1);
        }
        if f.flags & fused_flags::INPUT_REJECTED != 0 {
            return;
        }
        self.n += 1;
        let n = self.n as f64;
        for (axis, x) in f.specific_force_mps2.iter().enumerate() {
            let delta = x - self.mean[axis];
            self.mean[axis] += delta / n;
            self.m2[axis] += delta * (x - self.mean[axis]);
        }
    }

    /// The message for the interval ending with the sample at `time_usec`; the next interval
    /// starts empty (the clip count goes on).
    pub fn take(&mut self, time_usec: u64) -> VIBRATION_DATA {
        let sd = |axis: usize| {
            if self.n < 2 {
                0.0
            } else {
                (self.m2[axis] / (self.n - 1) as f64).sqrt() as f32
            }
        };
        let m = VIBRATION_DATA {
            time_usec,
            vibration_x: sd(0),
            vibration_y: sd(1),
            vibration_z: sd(2),
            clipping_0: self.clipped,
            clipping_1: 0,
            clipping_2: 0,
        };
        *self = Self {
            clipped: self.clipped,
            ..Self::default()
        };
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(force: [f64; 3], flags: u32) -> FusedImu {
        FusedImu {
            specific_force_mps2: force,
            flags,
            ..FusedImu::default()
        }
    }

    #[test]
    fn spread_per_axis_and_clips_since_start() {
        let mut v = VibrationMeter::default();
        // x alternates ±1 about 0 (sd = 1 over an even count, sample sd √(n/(n−1))), y constant.
        for i in 0..1000 {
            let x = if i % 2 == 0 { 1.0 } else { -1.0 };
            v.add(&sample([x, 3.0, -9.8], 0));
        }
        v.add(&sample(
            [50.0, 0.0, 0.0],
            fused_flags::ACCEL_SATURATED | fused_flags::INPUT_REJECTED,
        ));
        let m = v.take(7);
        assert_eq!(m.time_usec, 7);
        assert!(
            (m.vibration_x - (1000.0f32 / 999.0).sqrt()).abs() < 1e-5,
            "{}",
            m.vibration_x
        );
        assert!(m.vibration_y.abs() < 1e-6);
        assert_eq!(m.clipping_0, 1);
        // The next interval starts afresh; clips are counted on.
        v.add(&sample([0.0; 3], fused_flags::ACCEL_SATURATED));
        let m = v.take(8);
        assert_eq!((m.vibration_x, m.clipping_0), (0.0, 2));
    }
}
