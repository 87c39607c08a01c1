//! The smoother over a filter's history: a swing with a specific-force error the filter could not
//! know (it appears only while the foot moves, like a scale-factor error), bracketed by
//! zero-velocity updates, is put back where it was.

use rins_navigator::ekf::{EkfNoise, ErrorStateEkf};
use rins_navigator::mechanisation::{ImuBias, NominalState, StrapdownConfig};
use rins_navigator::smoother::Smoother;

const LAT: f64 = 0.8;
const RATE_HZ: f64 = 100.0;
/// The accelerometer's error along north during the swing, m/s².
const BIAS: f64 = 0.05;

/// North position (filtered, smoothed) per step of: 0.5 s still with ZUPTs, `swing_s` without
/// any update, 0.5 s still with ZUPTs. The foot never moves.
fn stance_swing_stance(swing_s: f64) -> (Vec<f64>, Vec<f64>, Vec<bool>) {
    let noise = EkfNoise {
        initial_heading_sigma: 1e-3,
        ..EkfNoise::default()
    };
    let start = NominalState::at_rest(LAT, 0.1, 100.0);
    let mut ekf = ErrorStateEkf::new(start, ImuBias::default(), StrapdownConfig::default(), noise);
    let r_n = rins_earth::meridian_radius(LAT) + 100.0;
    let dt = 1.0 / RATE_HZ;
    let (still, swing) = ((0.5 * RATE_HZ) as usize, (swing_s * RATE_HZ) as usize);
    let mut smoother = Smoother::default();
    let (mut filtered, mut in_swing) = (Vec::new(), Vec::new());
    for k in 0..2 * still + swing {
        let g = ekf.strapdown().gravity();
        let moving = (still..still + swing).contains(&k);
        let error = if moving { BIAS } else { 0.0 };
        assert!(ekf.predict([0.0; 3], [error, 0.0, -g], dt).is_applied());
        if !moving {
            assert!(ekf.zupt(0.01, 1e6).is_accepted());
        }
        let north = (ekf.state().lat - LAT) * r_n;
        smoother.record(&ekf, [north, 0.0, 0.0]);
        filtered.push(north);
        in_swing.push(moving);
    }
    let smoothed = smoother.smooth();
    assert_eq!(smoothed.singular_steps, 0);
    assert_eq!(smoothed.position_ned_m.len(), filtered.len());
    let s = smoothed.position_ned_m.iter().map(|p| p[0]).collect();
    (filtered, s, in_swing)
}

fn worst(v: &[f64], mask: &[bool]) -> f64 {
    v.iter()
        .zip(mask)
        .filter(|(_, m)| **m)
        .map(|(x, _)| x.abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_biased_swing_between_two_stances_is_smoothed_back_to_the_still_foot() {
    let (filtered, smoothed, swing) = stance_swing_stance(1.0);
    // Unaided for 1 s the filter drifts ½ b t² = 2.5 cm by the end of the swing.
    let drift = worst(&filtered, &swing);
    assert!((drift - 0.5 * BIAS).abs() < 0.005, "filtered drift {drift}");
    // The stance after it reveals the velocity error b·t; the smoother carries it back through
    // the swing: what is left is the part the model cannot tell from accelerometer noise.
    let left = worst(&smoothed, &swing);
    assert!(
        left < 0.2 * drift,
        "smoothed {left} against filtered {drift}"
    );
    // The last step has no future: smoothed and filtered agree there.
    let last = filtered.len() - 1;
    assert_eq!(smoothed[last], filtered[last]);
}

#[test]
fn nothing_recorded_smooths_to_nothing() {
    let s = Smoother::default().smooth();
    assert!(s.position_ned_m.is_empty() && s.singular_steps == 0);
}
