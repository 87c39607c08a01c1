//! Repair of an IMU file's time column, and the counts of what was repaired.
//!
//! The published recordings hold defects a loader meets in the field; each is repaired and
//! counted rather than refused, so one bad row does not cost a flight:
//! - the unit's 32-bit microsecond counter wraps: time jumps back by 2³² µs and then continues
//!   regularly; every later row gets 2³² µs added;
//! - a step of two periods followed by a repeated timestamp, whose row has coarse inertial
//!   values: the attitude columns show that no sample is missing, only the timestamps are wrong,
//!   so the row before the repeat goes back one period and the repeated row's inertial values
//!   become the mean of its neighbours';
//! - a real missing sample (a step of k periods, 2 ≤ k ≤ [`MAX_FILL_ROWS`] + 1, no repeat): k − 1
//!   rows are interpolated linearly; a row with a non-finite value is removed first and filled
//!   the same way;
//! - a longer gap or any other step back: the file is cut there and the longest regular part
//!   kept.

use std::ops::{Add, AddAssign};

use serde::Serialize;

/// The span of the units' 32-bit microsecond counter, s.
pub const COUNTER_WRAP_S: f64 = 4294.967296;
/// Most rows a gap may be filled with (0.1 s at 120 Hz); a longer gap cuts the file.
pub const MAX_FILL_ROWS: usize = 12;
/// A step within this fraction of a period of an integer number of periods is that number.
const STEP_TOLERANCE: f64 = 0.25;

/// Counts of the repairs made while loading: per IMU file, per trial, per data set.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Repairs {
    /// Wraps of the 32-bit microsecond counter unwrapped.
    pub counter_wraps: usize,
    /// Repeated timestamps after a two-period step, put back on the grid.
    pub repeated_timestamps: usize,
    /// Rows interpolated into gaps (missing samples and rows with non-finite values).
    pub missing_samples_filled: usize,
    /// Rows removed because a value was not finite (each also filled or dropped).
    pub non_finite_rows: usize,
    /// Rows dropped outside the longest regular part of a file.
    pub rows_dropped: usize,
    /// IMU files present but skipped (unreadable, too short, not overlapping the others).
    pub imu_files_skipped: usize,
    /// Trials that could not be loaded at all.
    pub trials_failed: usize,
}

impl AddAssign for Repairs {
    fn add_assign(&mut self, o: Self) {
        self.counter_wraps += o.counter_wraps;
        self.repeated_timestamps += o.repeated_timestamps;
        self.missing_samples_filled += o.missing_samples_filled;
        self.non_finite_rows += o.non_finite_rows;
        self.rows_dropped += o.rows_dropped;
        self.imu_files_skipped += o.imu_files_skipped;
        self.trials_failed += o.trials_failed;
    }
}

impl Add for Repairs {
    type Output = Self;

    fn add(mut self, o: Self) -> Self {
        self += o;
        self
    }
}

impl Repairs {
    /// The non-zero counts as `"N what"` phrases, e.g. `["1 counter wrap", "2 rows dropped"]`.
    pub fn phrases(&self) -> Vec<String> {
        [
            (self.counter_wraps, "counter wraps unwrapped"),
            (
                self.repeated_timestamps,
                "repeated timestamps put back on the grid",
            ),
            (self.missing_samples_filled, "missing samples filled"),
            (self.non_finite_rows, "rows with non-finite values replaced"),
            (self.rows_dropped, "rows dropped"),
            (self.imu_files_skipped, "IMU files skipped"),
            (self.trials_failed, "trials failed"),
        ]
        .into_iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| format!("{n} {what}"))
        .collect()
    }

    /// True when nothing was repaired.
    pub fn is_clean(&self) -> bool {
        *self == Self::default()
    }
}

/// One IMU row as in the file: time s, Euler X/Y/Z °, Acc X/Y/Z m/s², Gyr X/Y/Z °/s.
pub type Row = [f64; 10];

/// Columns holding angles (interpolated along the short way round).
const ANGLES: std::ops::RangeInclusive<usize> = 1..=3;
/// Columns holding the inertial values (accelerometer and gyro).
const INERTIAL: std::ops::RangeInclusive<usize> = 4..=9;

/// The rows of one file on a regular grid of `period`, and what it took.
pub fn repair(rows: &[Row], period: f64) -> (Vec<Row>, Repairs) {
    let mut repairs = Repairs::default();
    let finite: Vec<Row> = rows
        .iter()
        .filter(|r| r.iter().all(|x| x.is_finite()))
        .copied()
        .collect();
    repairs.non_finite_rows = rows.len() - finite.len();
    let unwrapped = unwrap_counter(&finite, period, &mut repairs);

    let mut segments: Vec<Vec<Row>> = Vec::new();
    let mut current: Vec<Row> = Vec::new();
    let mut i = 0;
    while i < unwrapped.len() {
        let row = unwrapped[i];
        let Some(last) = current.last().copied() else {
            current.push(row);
            i += 1;
            continue;
        };
        let periods = (row[0] - last[0]) / period;
        let k = periods.round();
        let on_grid = (periods - k).abs() <= STEP_TOLERANCE;
        let repeat_follows = unwrapped
            .get(i + 1)
            .is_some_and(|next| ((next[0] - row[0]) / period).abs() <= STEP_TOLERANCE);
        if on_grid && k == 1.0 {
            current.push(row);
        } else if on_grid && k == 2.0 && repeat_follows {
            // Row i belongs one period earlier; row i + 1 keeps its time and gets the mean
            // inertial values of its neighbours (its own are coarse).
            let mut moved = row;
            moved[0] = last[0] + period;
            let mut repeated = unwrapped[i + 1];
            let after = unwrapped.get(i + 2).copied().unwrap_or(moved);
            for c in INERTIAL {
                repeated[c] = 0.5 * (moved[c] + after[c]);
            }
            current.push(moved);
            current.push(repeated);
            repairs.repeated_timestamps += 1;
            i += 1;
        } else if periods > 1.5 && k <= (MAX_FILL_ROWS + 1) as f64 {
            let k = k as usize;
            for m in 1..k {
                let mut filled = interpolate(&last, &row, m as f64 / k as f64);
                filled[0] = last[0] + m as f64 * period;
                current.push(filled);
            }
            current.push(row);
            repairs.missing_samples_filled += k - 1;
        } else {
            segments.push(std::mem::take(&mut current));
            current.push(row);
        }
        i += 1;
    }
    segments.push(current);
    let longest = segments
        .iter()
        .enumerate()
        .max_by_key(|(k, s)| (s.len(), std::cmp::Reverse(*k)))
        .map_or(0, |(k, _)| k);
    let kept = std::mem::take(&mut segments[longest]);
    repairs.rows_dropped = segments.iter().map(Vec::len).sum();
    (kept, repairs)
}

/// The rows with every 32-bit counter wrap (a step back by [`COUNTER_WRAP_S`], to within a second)
/// undone.
fn unwrap_counter(rows: &[Row], period: f64, repairs: &mut Repairs) -> Vec<Row> {
    let mut offset = 0.0;
    let mut previous: Option<f64> = None;
    rows.iter()
        .map(|r| {
            let mut out = *r;
            if let Some(p) = previous {
                let step = r[0] - p;
                if step < -0.5 * period && (step + COUNTER_WRAP_S).abs() < 1.0 {
                    offset += COUNTER_WRAP_S;
                    repairs.counter_wraps += 1;
                }
            }
            previous = Some(r[0]);
            out[0] += offset;
            out
        })
        .collect()
}

/// The row a fraction `f` of the way from `a` to `b`; angles along the short way round.
fn interpolate(a: &Row, b: &Row, f: f64) -> Row {
    std::array::from_fn(|c| {
        if ANGLES.contains(&c) {
            let d = (b[c] - a[c] + 180.0).rem_euclid(360.0) - 180.0;
            (a[c] + f * d + 180.0).rem_euclid(360.0) - 180.0
        } else {
            a[c] + f * (b[c] - a[c])
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const P: f64 = 1.0 / 120.0;

    /// Row j of a regular file: time j·P, and values that identify the row.
    fn row(j: usize, t: f64) -> Row {
        let v = j as f64;
        [
            t,
            v,
            -v,
            170.0 + v,
            10.0 + v,
            20.0 + v,
            30.0 + v,
            40.0 + v,
            50.0 + v,
            60.0 + v,
        ]
    }

    fn regular(n: usize) -> Vec<Row> {
        (0..n).map(|j| row(j, j as f64 * P)).collect()
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn a_regular_file_is_left_alone() {
        let rows = regular(50);
        let (out, repairs) = repair(&rows, P);
        assert_eq!(out, rows);
        assert!(repairs.is_clean());
    }

    #[test]
    fn a_counter_wrap_is_unwrapped() {
        // Times near the end of the counter's span, wrapping after row 6.
        let t0 = COUNTER_WRAP_S - 6.5 * P;
        let mut rows: Vec<Row> = (0..20).map(|j| row(j, t0 + j as f64 * P)).collect();
        for r in rows.iter_mut().skip(7) {
            r[0] -= COUNTER_WRAP_S;
        }
        assert!(rows[7][0] > 0.0 && rows[7][0] < P);
        let (out, repairs) = repair(&rows, P);
        assert_eq!(repairs.counter_wraps, 1);
        assert_eq!(repairs.rows_dropped, 0);
        assert_eq!(out.len(), 20);
        for (j, r) in out.iter().enumerate() {
            assert!(close(r[0], t0 + j as f64 * P), "row {j}: {}", r[0]);
            assert_eq!(r[1], j as f64);
        }
    }

    #[test]
    fn a_repeated_timestamp_goes_back_on_the_grid() {
        // Row 5 is stamped one period late, row 6 repeats its stamp with coarse values.
        let mut rows = regular(10);
        rows[5][0] = 6.0 * P;
        rows[6] = [6.0 * P, 6.0, -6.0, 176.0, -4.0, 0.1, 4.0, 35.0, -3.0, -2.0];
        let (out, repairs) = repair(&rows, P);
        assert_eq!(repairs.repeated_timestamps, 1);
        assert_eq!(repairs.missing_samples_filled, 0);
        assert_eq!(out.len(), 10);
        assert!(close(out[5][0], 5.0 * P) && close(out[6][0], 6.0 * P));
        // Inertial values of row 6: the mean of rows 5 and 7; its angles are kept.
        for c in 4..=9 {
            assert!(
                close(out[6][c], 0.5 * (rows[5][c] + rows[7][c])),
                "column {c}"
            );
            assert!(close(out[6][c], rows[0][c] + 6.0), "column {c}");
        }
        assert_eq!(out[6][1..=3], [6.0, -6.0, 176.0]);
        assert_eq!(out[5][1..], rows[5][1..]);
    }

    #[test]
    fn a_gap_is_filled_and_a_long_one_cuts_the_file() {
        // Rows 4, 5 and 6 missing: a step of 4 periods, 3 rows filled; yaw crosses ±180°.
        let mut rows = regular(12);
        rows.drain(4..7);
        rows[3][3] = 178.0;
        rows[4][3] = -178.0;
        let (out, repairs) = repair(&rows, P);
        assert_eq!(repairs.missing_samples_filled, 3);
        assert_eq!(out.len(), 12);
        for (j, r) in out.iter().enumerate() {
            assert!(close(r[0], j as f64 * P), "row {j}");
            assert!(close(r[5], 20.0 + j as f64), "row {j}: {}", r[5]);
        }
        // 178° → −178° is 4° the short way: 1° per row, through 180°.
        assert!(close(out[4][3], 179.0) && close(out[5][3].abs(), 180.0));
        assert!(close(out[6][3], -179.0));

        // A gap of 14 periods (13 rows) is too long: the longer part after it is kept.
        let mut rows = regular(40);
        rows.drain(5..18);
        let (out, repairs) = repair(&rows, P);
        assert_eq!(repairs.rows_dropped, 5);
        assert_eq!(repairs.missing_samples_filled, 0);
        assert_eq!(out.len(), 22);
        assert!(close(out[0][0], 18.0 * P));
    }

    #[test]
    fn non_finite_rows_are_filled_and_a_step_back_cuts() {
        let mut rows = regular(20);
        rows[7][8] = f64::NAN;
        let (out, repairs) = repair(&rows, P);
        assert_eq!(repairs.non_finite_rows, 1);
        assert_eq!(repairs.missing_samples_filled, 1);
        assert!(close(out[7][8], 57.0));

        let mut rows = regular(20);
        rows[15][0] = 0.0;
        let (out, repairs) = repair(&rows, P);
        // 0..15 kept; row 15 (back in time) and rows 16..20 (16 periods after it, too long a
        // gap to fill) dropped.
        assert_eq!(out.len(), 15);
        assert_eq!(repairs.rows_dropped, 5);
        assert_eq!(repairs.counter_wraps, 0);
    }

    #[test]
    fn repairs_add_up_and_read_as_phrases() {
        let a = Repairs {
            counter_wraps: 1,
            rows_dropped: 2,
            ..Repairs::default()
        };
        let mut b = a + a;
        b += Repairs {
            trials_failed: 1,
            ..Repairs::default()
        };
        assert_eq!(
            (b.counter_wraps, b.rows_dropped, b.trials_failed),
            (2, 4, 1)
        );
        assert_eq!(
            b.phrases(),
            [
                "2 counter wraps unwrapped",
                "4 rows dropped",
                "1 trials failed"
            ]
        );
    }
}
