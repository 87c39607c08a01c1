//! The naive fusion of the units' own on-board filters: at each reference row, the normalised
//! average of the units' attitude quaternions, each turned to the sign of the first (q and −q are
//! the same attitude, and averaging opposite signs would cancel them).

use nalgebra::{Quaternion, UnitQuaternion};

use super::mounting::Paired;
use super::run::AttitudeTrace;

/// The normalised average of `attitudes`, each sign-aligned to the first; `None` when there is
/// none. Aligned, every term has a non-negative component along the first, so the sum's is at
/// least 1 and it always has a direction.
pub fn average(attitudes: &[UnitQuaternion<f64>]) -> Option<UnitQuaternion<f64>> {
    let first = attitudes.first()?;
    let sum = attitudes
        .iter()
        .fold(Quaternion::new(0.0, 0.0, 0.0, 0.0), |sum, q| {
            let q = q.quaternion();
            if q.dot(first.quaternion()) < 0.0 {
                sum - q
            } else {
                sum + q
            }
        });
    Some(UnitQuaternion::new_normalize(sum))
}

/// The average of `traces` at each reference row (time, roll, pitch) where every trace has an
/// attitude, paired with the row as one trace is paired; rows that some trace does
/// not cover are left out.
pub fn pair_average(traces: &[AttitudeTrace], start_s: f64, rows: &[(f64, f64, f64)]) -> Paired {
    let mut paired = Paired::default();
    let mut at_row = Vec::with_capacity(traces.len());
    for &(t, roll, pitch) in rows {
        at_row.clear();
        at_row.extend(traces.iter().map_while(|trace| trace.at(t)));
        if at_row.len() < traces.len() {
            continue;
        }
        if let Some(q) = average(&at_row) {
            paired.push(t - start_s, q, roll, pitch);
        }
    }
    paired
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn about_x(angle: f64) -> UnitQuaternion<f64> {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), angle)
    }

    #[test]
    fn opposite_signs_of_one_attitude_average_to_it() {
        let q = about_x(0.4);
        let flipped = UnitQuaternion::new_unchecked(-q.into_inner());
        let avg = average(&[q, flipped, q]).unwrap_or_else(UnitQuaternion::identity);
        // Without the alignment the sum would be q alone (norm 1 of 3): still q, so check the
        // components, which carry the first's sign.
        assert!(
            (avg.into_inner() - q.into_inner()).norm() < 1e-12,
            "{avg:?}"
        );
        let avg = average(&[flipped, q]).unwrap_or_else(UnitQuaternion::identity);
        assert!(
            (avg.into_inner() + q.into_inner()).norm() < 1e-12,
            "{avg:?}"
        );
    }

    #[test]
    fn the_average_of_symmetric_rotations_is_their_middle_and_unit() {
        // ±a about x around 0.2: the sum lies on 0.2, of norm 2 cos(a/2) before normalising.
        let (mid, a) = (0.2, 0.3);
        let avg =
            average(&[about_x(mid + a), about_x(mid - a)]).unwrap_or_else(UnitQuaternion::identity);
        assert!((avg.angle() - mid).abs() < 1e-12, "{}", avg.angle());
        assert!((avg.into_inner().norm() - 1.0).abs() < 1e-12);
        // Four unequal tilts: the normalised mean of the quaternions, within the spread.
        let tilts = [0.01, 0.02, -0.005, 0.015];
        let qs: Vec<_> = tilts.iter().map(|&t| about_x(t)).collect();
        let avg = average(&qs).unwrap_or_else(UnitQuaternion::identity);
        let mean = tilts.iter().sum::<f64>() / 4.0;
        // For small angles the quaternion mean is the angle mean to third order in the spread.
        assert!((avg.angle() - mean).abs() < 1e-6, "{}", avg.angle());
    }

    #[test]
    fn nothing_has_no_average_and_far_apart_attitudes_still_have_one() {
        assert!(average(&[]).is_none());
        // Half-turns about x, y and z beside the identity: no pair is opposite after alignment,
        // and the average is a unit quaternion.
        let qs = [
            UnitQuaternion::identity(),
            about_x(std::f64::consts::PI),
            UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI),
        ];
        let avg = average(&qs).map(|q| q.into_inner().norm());
        assert!((avg.unwrap_or(0.0) - 1.0).abs() < 1e-12, "{avg:?}");
    }

    #[test]
    fn rows_are_paired_only_where_every_trace_has_an_attitude() {
        let trace = |from: f64, angle: f64| AttitudeTrace {
            t_s: vec![from, 10.0],
            attitude: vec![about_x(angle), about_x(angle)],
            tilt_sigma_rad: Vec::new(),
        };
        let traces = [trace(0.0, 0.1), trace(2.0, 0.3)];
        let rows = [(1.0, 0.0, 0.0), (3.0, 0.0, 0.0), (11.0, 0.0, 0.0)];
        let p = pair_average(&traces, 0.5, &rows);
        assert_eq!(p.since_start_s, vec![2.5]);
        assert!((p.estimate[0].angle() - 0.2).abs() < 1e-12);
    }
}
