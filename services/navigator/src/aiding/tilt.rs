//! Gravity-referenced attitude (AHRS) for flight without position aiding: the mean specific force
//! of each short window levels the filter, so roll, pitch and the horizontal gyro biases no longer
//! drift freely.
//!
//! Two models of what the accelerometers measure, chosen by `[navigator.tilt] model`:
//! * `gravity` — the mean force is gravity's reaction (`ErrorStateEkf::gravity_tilt`). Wrong by the
//!   vehicle's own acceleration, so its σ grows with what betrays acceleration: the departure of
//!   |f̄| from g (`force_error_gain`) and the rotation rate (`rate_gain_mps`: a turn at rate ω and
//!   speed v accelerates the vehicle by v ω), and windows with | |f̄| − g | above
//!   `max_force_error_mps2` are not used at all. With `centripetal_correction` the acceleration
//!   of a turn, `ω × v` from the filter's own rate and velocity, is taken out first.
//! * `drag` — a multirotor's body x/y force is rotor drag, `−μ v_b` (`ErrorStateEkf::rotor_drag`):
//!   right during accelerations, which a multirotor makes by tilting, where the gravity model
//!   reads the tilt as level.
//!
//! One update per window of `window_s`; allocation-free.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::aiding::context::AidingContext;
use crate::aiding::source::{AidingSensor, Bucket};
use crate::ekf::{AidingSource, ErrorStateEkf, UpdateOutcome};
use crate::force_window::ForceWindow;

/// What the mean specific force is taken to measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum TiltModel {
    /// The reaction to gravity (a vehicle that is not accelerating).
    #[default]
    Gravity,
    /// Rotor drag in the body x/y plane, thrust along body z (a multirotor).
    Drag,
}

impl TiltModel {
    /// Name as written in the configuration.
    pub fn name(self) -> &'static str {
        match self {
            TiltModel::Gravity => "gravity",
            TiltModel::Drag => "drag",
        }
    }
}

/// When the drag model may also correct the heading (`[navigator.tilt] drag_heading`).
///
/// The drag ties the heading to the direction of the velocity through the air. Without a receiver
/// the filter's horizontal velocity is what the drag itself made it, the velocity through the air,
/// so the two agree whatever the (steady) wind, and the drag's heading information, through the
/// accelerations the filter integrates, holds the heading. Once a receiver's fixes set the
/// velocity over the ground, a wind of w at airspeed v turns that heading by up to w / v.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum DragHeading {
    /// Never: the update's heading column is zeroed.
    Never,
    /// Always, receiver or not.
    Always,
    /// While no receiver update was accepted in the last [`GROUND_VELOCITY_HOLD_S`].
    #[default]
    WithoutGnss,
}

/// After a receiver update the filter's velocity stays the velocity over the ground for this
/// long, s (a few of its fix intervals).
pub const GROUND_VELOCITY_HOLD_S: f64 = 2.0;

impl DragHeading {
    /// Name as written in the configuration.
    pub fn name(self) -> &'static str {
        match self {
            DragHeading::Never => "never",
            DragHeading::Always => "always",
            DragHeading::WithoutGnss => "without_gnss",
        }
    }

    /// Whether the drag corrects the heading now; `ground_velocity`: the filter's velocity is
    /// the receiver's, over the ground.
    pub fn applies(self, ground_velocity: bool) -> bool {
        match self {
            DragHeading::Never => false,
            DragHeading::Always => true,
            DragHeading::WithoutGnss => !ground_velocity,
        }
    }
}

/// Settings of the tilt updates (`[navigator.tilt]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TiltAidingConfig {
    /// Level the filter from the specific force in normal navigation.
    pub enabled: bool,
    /// What the specific force measures.
    pub model: TiltModel,
    /// Averaging window, s of device time: one update per window.
    pub window_s: f64,
    /// σ of each horizontal component of the window's mean force, m/s², before inflation.
    pub sigma_mps2: f64,
    /// σ grows by this times | |f̄| − g | (dimensionless).
    pub force_error_gain: f64,
    /// σ grows by this times the window's mean rate magnitude, m/s (rad/s × m/s = m/s²).
    pub rate_gain_mps: f64,
    /// Windows with | |f̄| − g | above this are not used, m/s².
    pub max_force_error_mps2: f64,
    /// Rotor drag coefficient μ of the `drag` model along body x, 1/s (specific force per unit
    /// airspeed).
    pub drag_per_s: f64,
    /// The same along body y, 1/s (an airframe is seldom as draggy sideways as forwards).
    pub lateral_drag_per_s: f64,
    /// `drag` model: when the drag also corrects the heading (see [`DragHeading`]).
    pub drag_heading: DragHeading,
    /// Innovation gate: largest accepted Mahalanobis distance.
    pub gate: f64,
    /// `gravity` model: the vehicle's acceleration is taken as the centripetal `ω × v` of its
    /// rotation (navigation frame) and the filter's velocity — a coordinated turn, where the
    /// specific force of a fixed wing stays along its z axis — instead of zero.
    pub centripetal_correction: bool,
}

impl Default for TiltAidingConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            model: TiltModel::Gravity,
            window_s: 0.1,
            sigma_mps2: 0.5,
            force_error_gain: 2.0,
            rate_gain_mps: 2.0,
            max_force_error_mps2: 2.0,
            drag_per_s: 0.6,
            lateral_drag_per_s: 0.6,
            drag_heading: DragHeading::WithoutGnss,
            gate: 5.0,
            centripetal_correction: false,
        }
    }
}

impl TiltAidingConfig {
    /// Every number must be finite and positive (the gains may be zero): `(field, value)` of the
    /// first that is not.
    pub fn check(&self) -> Result<(), (&'static str, f64)> {
        let positive = [
            ("window_s", self.window_s),
            ("sigma_mps2", self.sigma_mps2),
            ("max_force_error_mps2", self.max_force_error_mps2),
            ("drag_per_s", self.drag_per_s),
            ("lateral_drag_per_s", self.lateral_drag_per_s),
            ("gate", self.gate),
        ];
        let non_negative = [
            ("force_error_gain", self.force_error_gain),
            ("rate_gain_mps", self.rate_gain_mps),
        ];
        if let Some(bad) = positive
            .into_iter()
            .find(|(_, v)| !(v.is_finite() && *v > 0.0))
        {
            return Err(bad);
        }
        match non_negative
            .into_iter()
            .find(|(_, v)| !(v.is_finite() && *v >= 0.0))
        {
            Some(bad) => Err(bad),
            None => Ok(()),
        }
    }
}

impl AidingSensor for TiltAidingConfig {
    fn source(&self) -> AidingSource {
        AidingSource::Gravity
    }

    /// The bucket is shared with the attitude recovery, which books there whatever the profile.
    /// It is never judged by the integrity monitor (see `judged_by_integrity`), so it has no
    /// inconsistency reason.
    fn buckets(&self) -> &'static [Bucket] {
        &[Bucket {
            source: AidingSource::Gravity,
            inconsistent: 0,
        }]
    }

    fn enabled(&self) -> bool {
        self.enabled
    }

    /// A pseudo-measurement made from the IMU samples: it has no stream of its own to go quiet.
    fn watched_for_staleness(&self) -> bool {
        false
    }

    /// Its updates share their bucket with the attitude recovery's, which levels the filter
    /// whatever the profile; a window gated out in a sustained manoeuvre is the model's limit,
    /// not a fault of the solution.
    fn judged_by_integrity(&self) -> bool {
        false
    }

    fn first_out_of_range(&self) -> Result<(), (&'static str, f64)> {
        self.check()
    }

    fn section(&self) -> (&'static str, &'static str) {
        ("navigator.tilt", "must be finite and > 0 (the gains >= 0)")
    }
}

/// The tilt aiding: its settings and the window in progress.
#[derive(Debug, Clone, Copy)]
pub struct TiltAiding {
    config: TiltAidingConfig,
    window: ForceWindow,
}

impl TiltAiding {
    /// No window open yet.
    pub fn new(config: TiltAidingConfig) -> Self {
        Self {
            config,
            window: ForceWindow::default(),
        }
    }

    /// One propagated sample at `t_us` in normal navigation (specific force as measured, rate
    /// bias-corrected): the update of a window that closed, booked.
    pub(crate) fn on_imu(
        &mut self,
        ctx: &mut AidingContext<'_>,
        t_us: u64,
        force_body: [f64; 3],
        rate_body: &Vector3<f64>,
    ) {
        if !self.config.enabled {
            return;
        }
        let hold_us = (GROUND_VELOCITY_HOLD_S * 1e6) as u64;
        let ground_velocity = ctx
            .last_accepted_us(AidingSource::Gnss)
            .is_some_and(|last| t_us.saturating_sub(last) <= hold_us);
        let Some(ekf) = ctx.filter_mut() else {
            return;
        };
        if let Some(result) = self.push(ekf, t_us, force_body, rate_body, ground_velocity) {
            ctx.book_update(AidingSource::Gravity, t_us, result, 2);
        }
    }

    /// One propagated sample at `t_us`: specific force as measured, rate bias-corrected;
    /// `ground_velocity`: a receiver has set the filter's velocity (see [`DragHeading`]). Returns
    /// the update made when a window closed (`None` while it is open or when it was not used).
    pub fn push(
        &mut self,
        ekf: &mut ErrorStateEkf,
        t_us: u64,
        force_body: [f64; 3],
        rate_body: &Vector3<f64>,
        ground_velocity: bool,
    ) -> Option<UpdateOutcome> {
        let config = &self.config;
        let mean =
            self.window
                .push(t_us, config.window_s, &Vector3::from(force_body), rate_body)?;
        let force_error = (mean.force.norm() - ekf.strapdown().gravity()).abs();
        if force_error > config.max_force_error_mps2 {
            return None;
        }
        let sigma = config.sigma_mps2
            + config.force_error_gain * force_error
            + config.rate_gain_mps * mean.rate.norm();
        Some(match config.model {
            TiltModel::Gravity => {
                let acceleration = if config.centripetal_correction {
                    let state = ekf.state();
                    (state.attitude * mean.rate)
                        .cross(&state.velocity_ned)
                        .into()
                } else {
                    [0.0; 3]
                };
                ekf.gravity_tilt_accelerating(mean.force.into(), acceleration, sigma, config.gate)
            }
            TiltModel::Drag => ekf.rotor_drag(
                mean.force.into(),
                [config.drag_per_s, config.lateral_drag_per_s],
                sigma,
                config.drag_heading.applies(ground_velocity),
                config.gate,
            ),
        })
    }

    /// Forgets the open window (after a take-over or a loss of attitude).
    pub fn reset(&mut self) {
        self.window.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ekf::{ATT, BG, EkfNoise, VEL};
    use crate::mechanisation::{ImuBias, NominalState, StrapdownConfig, quaternion_from_euler};

    const RATE_HZ: f64 = 100.0;

    /// A filter at rest at 45° N whose attitude is off by `roll_error` about x, with the
    /// process noise and the accelerometer-bias prior so small that only the tilt is learnt.
    fn filter(roll_error: f64, gyro_bias_sigma: f64) -> ErrorStateEkf {
        let mut state = NominalState::at_rest(45_f64.to_radians(), 0.0, 100.0);
        state.attitude = quaternion_from_euler(roll_error, 0.0, 0.0);
        let noise = EkfNoise {
            gyro_noise_density: 1e-12,
            accel_noise_density: 1e-12,
            gyro_bias_walk: 1e-12,
            accel_bias_walk: 1e-12,
            initial_tilt_sigma: 2_f64.to_radians(),
            initial_heading_sigma: 2_f64.to_radians(),
            initial_velocity_sigma: 1.0,
            initial_position_sigma: 1.0,
            initial_gyro_bias_sigma: gyro_bias_sigma,
            initial_accel_bias_sigma: 1e-9,
        };
        ErrorStateEkf::new(state, ImuBias::default(), StrapdownConfig::default(), noise)
    }

    fn gravity_config(sigma_mps2: f64) -> TiltAidingConfig {
        TiltAidingConfig {
            enabled: true,
            sigma_mps2,
            force_error_gain: 0.0,
            rate_gain_mps: 0.0,
            gate: 1e6,
            ..TiltAidingConfig::default()
        }
    }

    /// Level and still: the true specific force is straight up; with a roll error δ the filter
    /// predicts a horizontal force g·δ. Each window is then one scalar measurement of δ with
    /// variance (σ/g)², and with no process noise the estimate after n windows is the
    /// information-weighted mean: the remaining error is δ · (1/P₀) / (1/P₀ + n g²/σ²).
    #[test]
    fn tilt_converges_as_the_information_form_predicts() {
        let delta = 1.5_f64.to_radians();
        let mut ekf = filter(delta, 1e-12);
        let g = ekf.strapdown().gravity();
        let sigma = 0.2;
        let config = gravity_config(sigma);
        let mut aiding = TiltAiding::new(config);
        let mut windows = 0;
        for k in 1..=100u64 {
            let force = [0.0, 0.0, -g];
            assert!(ekf.predict([0.0; 3], force, 1.0 / RATE_HZ).is_applied());
            let t_us = k * 10_000;
            if let Some(o) = aiding.push(&mut ekf, t_us, force, &Vector3::zeros(), false) {
                assert!(o.is_accepted(), "{o:?}");
                windows += 1;
            }
        }
        let p0 = 2_f64.to_radians().powi(2);
        let expected =
            delta * (1.0 / p0) / (1.0 / p0 + f64::from(windows) * g * g / (sigma * sigma));
        let [roll, _, _] = ekf.state().euler();
        assert!(windows >= 9, "{windows}");
        // Second-order terms (the small-angle model, the velocity the tilt error makes the filter
        // integrate) stay below 1 % of the correction.
        assert!(
            (roll - expected).abs() < 0.01 * delta,
            "roll {roll} expected {expected}"
        );
        // And the correction is most of the error: about 3 % of it is left.
        assert!(expected < 0.05 * delta, "{expected}");
    }

    /// A gyro bias tilts a still vehicle's solution at a constant rate; the tilt updates see it
    /// and the filter learns the bias of both horizontal axes.
    #[test]
    fn learns_a_horizontal_gyro_bias_on_a_still_vehicle() {
        let bias = [0.3_f64.to_radians(), -0.2_f64.to_radians(), 0.0];
        let mut ekf = filter(0.0, 0.5_f64.to_radians());
        let g = ekf.strapdown().gravity();
        let config = gravity_config(0.1);
        let mut aiding = TiltAiding::new(config);
        for k in 1..=(120.0 * RATE_HZ) as u64 {
            let force = [0.0, 0.0, -g];
            assert!(ekf.predict(bias, force, 1.0 / RATE_HZ).is_applied());
            let rate = Vector3::from(bias) - ekf.bias().gyro_rps;
            let _ = aiding.push(&mut ekf, k * 10_000, force, &rate, false);
        }
        let learnt = ekf.bias().gyro_rps;
        for axis in 0..2 {
            assert!(
                (learnt[axis] - bias[axis]).abs() < 0.005_f64.to_radians(),
                "axis {axis}: {} against {}",
                learnt[axis].to_degrees(),
                bias[axis].to_degrees()
            );
            assert!(ekf.sigma(BG + axis) < 0.01_f64.to_radians());
        }
        let [roll, pitch, _] = ekf.state().euler();
        assert!(roll.abs().max(pitch.abs()) < 0.01_f64.to_radians());
        assert!(ekf.sigma(ATT) < 0.05_f64.to_radians());
    }

    /// A coordinated right turn (yaw rate ω, speed v, bank φ with tan φ = ω v / g): the specific
    /// force stays on the body z axis. The filter's state is exact; with the centripetal
    /// correction the window is a measurement of zero error and the roll stays, without it the
    /// model reads the force as "level" and pulls the roll towards zero.
    #[test]
    fn the_centripetal_correction_keeps_a_coordinated_turn_banked() {
        let (omega, speed) = (0.2, 15.0);
        let roll_after = |centripetal_correction: bool| {
            let mut ekf = filter(0.0, 1e-12);
            let g = ekf.strapdown().gravity();
            let bank = (omega * speed / g).atan();
            let attitude = quaternion_from_euler(bank, 0.0, 0.0);
            ekf.state_mut().attitude = attitude;
            ekf.state_mut().velocity_ned = Vector3::new(speed, 0.0, 0.0);
            let acceleration = Vector3::new(0.0, omega * speed, 0.0);
            let force = attitude.inverse() * (acceleration - Vector3::new(0.0, 0.0, g));
            let rate = attitude.inverse() * Vector3::new(0.0, 0.0, omega);
            let config = TiltAidingConfig {
                centripetal_correction,
                max_force_error_mps2: 5.0,
                ..gravity_config(0.2)
            };
            let mut aiding = TiltAiding::new(config);
            for k in 0..=10u64 {
                let _ = aiding.push(&mut ekf, k * 10_000, force.into(), &rate, false);
            }
            (ekf.state().euler()[0], bank)
        };
        let (held, bank) = roll_after(true);
        assert!((held - bank).abs() < 1e-6, "{held} against {bank}");
        let (pulled, bank) = roll_after(false);
        assert!(
            bank - pulled > 0.5_f64.to_radians(),
            "{pulled} against {bank}"
        );
    }

    /// Steady flight north at 5 m/s through still air: the airframe pitches nose-down until the
    /// rotor drag balances, tan θ = −μ v / g, and the specific force is exactly gravity's. The
    /// filter starts 2° off in pitch with the velocity known only to 1 m/s; the drag model sees
    /// the velocity the tilt error makes it integrate and levels the filter on the true pitch.
    #[test]
    fn the_drag_model_finds_the_pitch_of_steady_flight() {
        let (mu, speed) = (0.4, 5.0);
        let mut ekf = filter(0.0, 1e-12);
        let g = ekf.strapdown().gravity();
        let pitch = (-mu * speed / g).atan();
        let truth = quaternion_from_euler(0.0, pitch, 0.0);
        ekf.state_mut().attitude = quaternion_from_euler(0.0, pitch + 2_f64.to_radians(), 0.0);
        ekf.state_mut().velocity_ned = Vector3::new(speed + 0.5, 0.0, 0.0);
        let force: [f64; 3] = (truth.inverse() * Vector3::new(0.0, 0.0, -g)).into();
        let config = TiltAidingConfig {
            model: TiltModel::Drag,
            drag_per_s: mu,
            lateral_drag_per_s: mu,
            ..gravity_config(0.05)
        };
        let mut aiding = TiltAiding::new(config);
        for k in 1..=(30.0 * RATE_HZ) as u64 {
            assert!(ekf.predict([0.0; 3], force, 1.0 / RATE_HZ).is_applied());
            let _ = aiding.push(&mut ekf, k * 10_000, force, &Vector3::zeros(), false);
        }
        let [_, estimated, _] = ekf.state().euler();
        assert!(
            (estimated - pitch).abs() < 0.05_f64.to_radians(),
            "pitch {} against {}",
            estimated.to_degrees(),
            pitch.to_degrees()
        );
        assert!((ekf.state().velocity_ned.x - speed).abs() < 0.05);
    }

    /// Flying north at 5 m/s over the ground with 1 m/s of wind from the east: the air comes from
    /// 11° right of the nose, so the drag has a sideways part the ground velocity cannot explain.
    /// With the drag's heading information a filter that knows its ground velocity turns most of
    /// its 2° heading σ towards the air; without it the heading is untouched.
    #[test]
    fn without_drag_heading_a_crosswind_does_not_turn_the_heading() {
        let (mu, speed, crosswind) = (0.4, 5.0, 1.0);
        let heading_after = |drag_heading: bool| {
            let mut ekf = filter(0.0, 1e-12);
            let g = ekf.strapdown().gravity();
            ekf.state_mut().velocity_ned = Vector3::new(speed, 0.0, 0.0);
            let force = [0.0, -mu * crosswind, -g];
            // The ground velocity known to 2 cm/s, as a receiver gives it.
            for axis in 0..3 {
                ekf.reset_component(VEL + axis, 0.02 * 0.02);
            }
            let outcome = ekf.rotor_drag(force, [mu, mu], 0.05, drag_heading, 1e6);
            assert!(
                matches!(outcome, UpdateOutcome::Accepted { .. }),
                "{outcome:?}"
            );
            ekf.state().euler()[2]
        };
        let turned = heading_after(true);
        let kept = heading_after(false);
        assert!(
            turned.abs() > 0.5_f64.to_radians(),
            "{}",
            turned.to_degrees()
        );
        assert!(kept.abs() < 1e-9, "{kept}");
    }

    #[test]
    fn the_drag_heading_follows_the_receiver_only_when_asked_to() {
        for (mode, without, with) in [
            (DragHeading::Never, false, false),
            (DragHeading::Always, true, true),
            (DragHeading::WithoutGnss, true, false),
        ] {
            assert_eq!(mode.applies(false), without, "{}", mode.name());
            assert_eq!(mode.applies(true), with, "{}", mode.name());
        }
        assert_eq!(
            TiltAidingConfig::default().drag_heading,
            DragHeading::WithoutGnss
        );
    }

    #[test]
    fn a_bad_setting_is_named() {
        let mut c = TiltAidingConfig::default();
        assert_eq!(c.check(), Ok(()));
        c.sigma_mps2 = -1.0;
        assert_eq!(c.check(), Err(("sigma_mps2", -1.0)));
        c = TiltAidingConfig {
            rate_gain_mps: f64::NAN,
            ..TiltAidingConfig::default()
        };
        assert!(matches!(c.check(), Err(("rate_gain_mps", v)) if v.is_nan()));
    }
}
