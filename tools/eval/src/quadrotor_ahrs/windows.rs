//! How much of a flight's figure comes from its first seconds: the roll/pitch RMSE over
//! consecutive windows of time since the run's start, with the same mounting tilt that scores the
//! whole flight.

use super::SETTLE_S;
use super::mounting::{Paired, roll_pitch_rmse_between_deg};

/// Window starts since the run's start, s: `[SETTLE_S, 10)`, `[10, 30)` and `[30, end)`.
pub const WINDOW_STARTS_S: [f64; 3] = [SETTLE_S, 10.0, 30.0];

/// One RMSE per window, degrees; `None` where the flight has no row in the window.
pub type WindowRmse = [Option<f64>; 3];

/// The window `w` as `[from, to)`, s.
fn bounds(w: usize) -> (f64, f64) {
    let to = WINDOW_STARTS_S.get(w + 1).copied().unwrap_or(f64::INFINITY);
    (WINDOW_STARTS_S[w], to)
}

/// The RMSE of `p` with mounting `tilt_rad` over each window.
pub fn of(p: &Paired, tilt_rad: [f64; 2]) -> WindowRmse {
    std::array::from_fn(|w| {
        let (from, to) = bounds(w);
        let rmse = roll_pitch_rmse_between_deg(p, tilt_rad, from, to);
        rmse.is_finite().then_some(rmse)
    })
}

/// Per window, the mean over the flights that have rows in it.
pub fn mean<'a, const N: usize>(
    flights: impl IntoIterator<Item = &'a [Option<f64>; N]>,
) -> [Option<f64>; N] {
    let mut sum = [0.0; N];
    let mut n = [0usize; N];
    for f in flights {
        for (w, v) in f.iter().enumerate() {
            if let Some(v) = v {
                sum[w] += v;
                n[w] += 1;
            }
        }
    }
    std::array::from_fn(|w| (n[w] > 0).then(|| sum[w] / n[w] as f64))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;
    use rins_navigator::attitude::quaternion_from_euler;

    /// Rows every 0.5 s for `seconds`, with a roll error of 4° before 10 s, 2° to 30 s and 1°
    /// after.
    fn stepped(seconds: f64) -> Paired {
        let mut p = Paired::default();
        let mut t = 0.0;
        while t < seconds {
            let error = if t < 10.0 {
                4.0
            } else if t < 30.0 {
                2.0
            } else {
                1.0
            };
            p.push(
                t,
                quaternion_from_euler(f64::to_radians(error), 0.0, 0.0),
                0.0,
                0.0,
            );
            t += 0.5;
        }
        p
    }

    /// A roll error e alone pools to e/√2 with the zero pitch error.
    fn pooled(deg: f64) -> f64 {
        deg / 2_f64.sqrt()
    }

    #[test]
    fn each_window_holds_its_own_rows_only() {
        let w = of(&stepped(45.0), [0.0; 2]);
        let expected = [pooled(4.0), pooled(2.0), pooled(1.0)];
        for (got, want) in w.iter().zip(expected) {
            let got = got.unwrap_or(f64::NAN);
            assert!((got - want).abs() < 1e-9, "{w:?}");
        }
    }

    #[test]
    fn a_short_flight_has_no_last_window_and_the_mean_skips_it() {
        let short = of(&stepped(20.0), [0.0; 2]);
        assert!(short[2].is_none());
        let long = of(&stepped(45.0), [0.0; 2]);
        let m = mean([&short, &long]);
        assert!((m[0].unwrap_or(f64::NAN) - pooled(4.0)).abs() < 1e-9);
        assert!((m[2].unwrap_or(f64::NAN) - pooled(1.0)).abs() < 1e-9);
        assert_eq!(mean([]), [None; 3]);
    }

    #[test]
    fn the_rows_before_settling_are_left_out() {
        let mut p = Paired::default();
        p.push(1.0, UnitQuaternion::identity(), 0.3, 0.0);
        assert_eq!(of(&p, [0.0; 2]), [None; 3]);
    }
}
