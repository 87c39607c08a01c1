//! One foot-mounted recording through the aided navigator, no IPC.

use rins_earth::{meridian_radius, prime_vertical_radius};
use rins_navigator::inertial_core::{AidedConfig, AidedNavigator};
use rins_navigator::smoother::Smoother;

use crate::datasets::foot::FootTrial;
use crate::integrity_tally::IntegrityTally;

/// The navigator's output over one recording.
#[derive(Debug, Clone, Default)]
pub struct FootRun {
    /// Position per sample, metres north, east, down from the start of navigation; zero while
    /// aligning.
    pub ned_m: Vec<[f64; 3]>,
    /// The position at the start of each stance phase.
    pub foot_down_m: Vec<[f64; 3]>,
    /// The stance detector's decision per sample.
    pub stance: Vec<bool>,
    /// Samples the stance detector fired on.
    pub stance_samples: usize,
    /// Zero-velocity updates the filter applied.
    pub zupt_accepted: u64,
    /// Zero-velocity updates the filter's χ² gate rejected.
    pub zupt_rejected: u64,
    /// Sample at which the alignment completed.
    pub aligned_at: Option<usize>,
    /// The integrity verdict of every sample after alignment.
    pub integrity: IntegrityTally,
    /// With [`run_trial_smoothed`]: the smoothed position per sample, same frame and length as
    /// `ned_m`; empty otherwise.
    pub smoothed_ned_m: Vec<[f64; 3]>,
    /// With [`run_trial_smoothed`]: steps whose predicted covariance could not be inverted.
    pub smoother_singular_steps: usize,
    /// Per sample: the smoother recorded the filter's step.
    recorded: Vec<bool>,
}

/// Runs `trial` through a navigator made from `config`.
pub fn run_trial(trial: &FootTrial, config: &AidedConfig) -> FootRun {
    run(trial, config, None)
}

/// As [`run_trial`], and then the Rauch–Tung–Striebel smoother over the filter's history
/// ([`FootRun::smoothed_ned_m`]).
pub fn run_trial_smoothed(trial: &FootTrial, config: &AidedConfig) -> FootRun {
    let mut smoother = Smoother::with_capacity(trial.samples.len());
    let mut run = run(trial, config, Some(&mut smoother));
    let smoothed = smoother.smooth();
    run.smoother_singular_steps = smoothed.singular_steps;
    // Each sample takes the smoothed value of the last step recorded at or before it (a sample
    // whose step was not applied left the state as it was); before the first, the filtered one.
    let mut recorded = 0;
    run.smoothed_ned_m = run
        .ned_m
        .iter()
        .zip(&run.recorded)
        .map(|(p, &was_recorded)| {
            recorded += usize::from(was_recorded);
            recorded
                .checked_sub(1)
                .and_then(|i| smoothed.position_ned_m.get(i))
                .copied()
                .unwrap_or(*p)
        })
        .collect();
    run
}

fn run(trial: &FootTrial, config: &AidedConfig, mut smoother: Option<&mut Smoother>) -> FootRun {
    // The recordings carry neither a barometer nor a magnetometer: the profile's sources that
    // never report would only read as silent (the navigation is the same either way).
    let mut config = *config;
    config.baro.enabled = false;
    config.mag.enabled = false;
    let config = &config;
    let mut nav = AidedNavigator::new(*config);
    let mut run = FootRun {
        ned_m: Vec::with_capacity(trial.samples.len()),
        stance: Vec::with_capacity(trial.samples.len()),
        recorded: Vec::with_capacity(trial.samples.len()),
        ..FootRun::default()
    };
    let t0 = trial.samples.first().map_or(0.0, |s| s.t_s);
    let [lat0, lon0, alt0] = config.origin;
    let (rn, re) = (
        meridian_radius(lat0) + alt0,
        prime_vertical_radius(lat0) + alt0,
    );
    let mut in_stance = false;
    for (k, s) in trial.samples.iter().enumerate() {
        let t_us = ((s.t_s - t0) * 1e6).round().max(0.0) as u64;
        let step = nav.on_imu(t_us, s.gyro_rps, s.accel_mps2, None);
        let applied = step.propagated.is_some_and(|o| o.is_applied());
        if nav.is_navigating() {
            run.integrity.push(nav.evaluate_integrity());
        }
        let p = nav.ekf().map_or([0.0; 3], |ekf| {
            let st = ekf.state();
            [
                (st.lat - lat0) * rn,
                (st.lon - lon0) * re * lat0.cos(),
                alt0 - st.alt,
            ]
        });
        if run.aligned_at.is_none() && nav.ekf().is_some() {
            run.aligned_at = Some(k);
        }
        if step.stance {
            run.stance_samples += 1;
            if !in_stance {
                run.foot_down_m.push(p);
            }
        }
        in_stance = step.stance;
        run.stance.push(step.stance);
        run.ned_m.push(p);
        let recorded = match (smoother.as_deref_mut(), nav.ekf()) {
            (Some(smoother), Some(ekf)) if applied => {
                smoother.record(ekf, p);
                true
            }
            _ => false,
        };
        run.recorded.push(recorded);
    }
    if let Some(ekf) = nav.ekf() {
        let c = ekf.counts(rins_navigator::ekf::AidingSource::Zupt);
        run.zupt_accepted = c.accepted;
        run.zupt_rejected = c.rejected;
    }
    run
}
