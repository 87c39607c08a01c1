//! The cross-validated fused run of each flight, kept so that the running service (fusion and
//! the navigator lanes as separate processes) can repeat it and be scored the same way
//! (`rins eval quadrotor --mode ahrs --live`).

use ipc_types::{GnssFix, NavState};
use nalgebra::{Quaternion, UnitQuaternion};
use rins_navigator::attitude::euler_from_quaternion;
use rins_navigator::inertial_core::AidedConfig;
use rins_navigator::start::InFlightStart;
use serde::Serialize;

use super::mounting::{Paired, roll_pitch_rmse_deg};
use super::pair;
use super::run::{AttitudeTrace, GyroPrior, in_flight_start, navigate_ahrs};
use crate::quadrotor_nav::frames::Motion;
use crate::quadrotor_nav::metrics::{angle_error, mean};
use crate::quadrotor_nav::run::Start;

/// A flight's scored fused run that the running service repeats: what the live evaluation needs
/// of it, whatever aids it.
pub trait RepeatableRun {
    /// The solution over the flight.
    type Trace;
    /// `<group>/path_<N>`.
    fn flight(&self) -> &str;
    /// The fused motion, vehicle frame.
    fn motion(&self) -> &Motion;
    /// The navigator's `[navigator.start]` and settings of the run.
    fn in_flight_start(&self) -> (InFlightStart, AidedConfig);
    /// Receiver messages the run is fed besides the IMU (none by default).
    fn receiver_messages(&self) -> Vec<GnssFix> {
        Vec::new()
    }
    /// The in-process run.
    fn in_process(&self) -> &Self::Trace;
    /// The same run in process on other samples of the motion.
    fn rerun(&self, motion: &Motion) -> Self::Trace;
    /// What a running navigator published, `(sample index, state)` of every navigating sample in
    /// order, as a trace on the flight's time base.
    fn trace_from<'a>(
        &self,
        published: impl IntoIterator<Item = (usize, &'a NavState)>,
    ) -> Self::Trace;
    /// Roll/pitch RMSE of a trace, scored as the in-process run is, degrees.
    fn score_deg(&self, trace: &Self::Trace) -> f64;
    /// The largest attitude difference between two traces at the scored rows, degrees, and the
    /// rows where only one has a solution.
    fn max_difference_deg(&self, a: &Self::Trace, b: &Self::Trace) -> (f64, usize);
    /// The largest roll or pitch difference between two traces at the scored rows, degrees.
    fn max_tilt_difference_deg(&self, a: &Self::Trace, b: &Self::Trace) -> f64;
}

/// One flight's live figures: `live` (the running processes), `same_frames` (the same pipeline's
/// library code in process on the same frames), `same_input` (the run in process on what fusion
/// made of the frames), against the run's in-process solution; and what fusion flagged live.
pub fn live_flight<R: RepeatableRun>(
    run: &R,
    live: &R::Trace,
    same_frames: &R::Trace,
    same_input: &R::Trace,
    live_fdi_events: u64,
    live_excluded_channels: Vec<String>,
) -> LiveFlight {
    let (live_vs_offline, missing) = run.max_difference_deg(live, run.in_process());
    LiveFlight {
        live_roll_pitch_rmse_deg: run.score_deg(live),
        live_vs_offline_max_diff_deg: live_vs_offline,
        live_vs_same_input_max_diff_deg: run.max_difference_deg(live, same_frames).0,
        quantisation_max_diff_deg: run.max_difference_deg(same_input, run.in_process()).0,
        quantisation_max_tilt_diff_deg: run.max_tilt_difference_deg(same_input, run.in_process()),
        live_rows_missing: missing,
        live_fdi_events,
        live_excluded_channels,
    }
}

impl RepeatableRun for ScoredRun {
    type Trace = AttitudeTrace;
    fn flight(&self) -> &str {
        &self.flight
    }
    fn motion(&self) -> &Motion {
        &self.motion
    }
    fn in_flight_start(&self) -> (InFlightStart, AidedConfig) {
        ScoredRun::in_flight_start(self)
    }
    fn in_process(&self) -> &AttitudeTrace {
        &self.trace
    }
    fn rerun(&self, motion: &Motion) -> AttitudeTrace {
        ScoredRun::rerun(self, motion)
    }
    fn trace_from<'a>(
        &self,
        published: impl IntoIterator<Item = (usize, &'a NavState)>,
    ) -> AttitudeTrace {
        ScoredRun::trace_from(self, published.into_iter().map(|(j, n)| (j, n.quaternion)))
    }
    fn score_deg(&self, trace: &AttitudeTrace) -> f64 {
        ScoredRun::score_deg(self, trace)
    }
    fn max_difference_deg(&self, a: &AttitudeTrace, b: &AttitudeTrace) -> (f64, usize) {
        ScoredRun::max_difference_deg(self, a, b)
    }
    fn max_tilt_difference_deg(&self, a: &AttitudeTrace, b: &AttitudeTrace) -> f64 {
        ScoredRun::max_tilt_difference_deg(self, a, b)
    }
}

/// One flight's scored fused run: what it was given and the attitude it produced in process.
#[derive(Debug, Clone)]
pub struct ScoredRun {
    /// `<group>/path_<N>`.
    pub flight: String,
    /// The fused motion, vehicle frame.
    pub motion: Motion,
    /// The reference state at t0.
    pub start: Start,
    /// The chosen candidate's settings.
    pub config: AidedConfig,
    /// The unit's mounting fitted on the other flights.
    pub mounting: UnitQuaternion<f64>,
    /// The gyro bias prior from the other flights.
    pub prior: Option<GyroPrior>,
    /// The mounting tilt the score removes, rad.
    pub tilt_rad: [f64; 2],
    /// Reference rows scored: time, roll, pitch.
    pub rows: Vec<(f64, f64, f64)>,
    /// The in-process attitude.
    pub trace: AttitudeTrace,
}

impl ScoredRun {
    /// The navigator's `[navigator.start]` and settings of this run.
    pub fn in_flight_start(&self) -> (InFlightStart, AidedConfig) {
        in_flight_start(
            &self.start,
            &self.config,
            &self.mounting,
            self.prior.as_ref(),
        )
    }

    /// The same run in process on other samples of the motion (e.g. as a converter quantised
    /// them).
    pub fn rerun(&self, motion: &Motion) -> AttitudeTrace {
        navigate_ahrs(
            motion,
            &self.start,
            &self.config,
            &self.mounting,
            self.prior.as_ref(),
        )
        .trace
    }

    /// The attitude a running navigator published, as a trace on the flight's time base: the
    /// start state, then `(sample index, [w, x, y, z])` of every navigating sample after the
    /// start (in order).
    pub fn trace_from(
        &self,
        published: impl IntoIterator<Item = (usize, [f64; 4])>,
    ) -> AttitudeTrace {
        let (start, aided) = self.in_flight_start();
        let mut trace = AttitudeTrace::default();
        trace.t_s.push(self.start.t_s);
        trace.attitude.push(start.state(&aided).state.attitude);
        for (j, [w, x, y, z]) in published {
            let t = self.motion.time(j);
            if t <= self.start.t_s {
                continue;
            }
            trace.t_s.push(t);
            trace
                .attitude
                .push(UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)));
        }
        trace
    }

    /// `trace` at the reference rows.
    pub fn paired(&self, trace: &AttitudeTrace) -> Paired {
        pair(trace, self.start.t_s, &self.rows)
    }

    /// Roll/pitch RMSE of `trace`, scored as the in-process run is, degrees.
    pub fn score_deg(&self, trace: &AttitudeTrace) -> f64 {
        roll_pitch_rmse_deg(&self.paired(trace), self.tilt_rad, 0.0)
    }

    /// The largest attitude difference between `a` and `b` at the reference rows, degrees, and
    /// the rows where one of them has no attitude while the other has.
    pub fn max_difference_deg(&self, a: &AttitudeTrace, b: &AttitudeTrace) -> (f64, usize) {
        self.max_difference(a, b, |x, y| x.angle_to(y))
    }

    /// The largest roll or pitch difference between `a` and `b` at the reference rows, degrees
    /// (the heading, which nothing aids here, left out).
    pub fn max_tilt_difference_deg(&self, a: &AttitudeTrace, b: &AttitudeTrace) -> f64 {
        self.max_difference(a, b, |x, y| {
            let (ex, ey) = (euler_from_quaternion(x), euler_from_quaternion(y));
            angle_error(ex[0], ey[0])
                .abs()
                .max(angle_error(ex[1], ey[1]).abs())
        })
        .0
    }

    fn max_difference(
        &self,
        a: &AttitudeTrace,
        b: &AttitudeTrace,
        difference_rad: impl Fn(&UnitQuaternion<f64>, &UnitQuaternion<f64>) -> f64,
    ) -> (f64, usize) {
        let mut largest = 0.0_f64;
        let mut missing = 0;
        for &(t, _, _) in &self.rows {
            match (a.at(t), b.at(t)) {
                (Some(x), Some(y)) => largest = largest.max(difference_rad(&x, &y).to_degrees()),
                (None, None) => {}
                _ => missing += 1,
            }
        }
        (largest, missing)
    }
}

/// One flight through the running processes.
#[derive(Debug, Clone, Default, Serialize)]
pub struct LiveFlight {
    /// Roll/pitch RMSE of the running navigator's attitude, scored as the in-process one, degrees.
    pub live_roll_pitch_rmse_deg: f64,
    /// Largest attitude difference to the in-process run at the scored rows, degrees.
    pub live_vs_offline_max_diff_deg: f64,
    /// Largest attitude difference to the same pipeline's library code run in this process
    /// (fusion, altimeter, navigator lanes: `rins replay --offline`) on the same frames, degrees:
    /// the processes' own share.
    pub live_vs_same_input_max_diff_deg: f64,
    /// Largest attitude difference the input makes in process: the run fed what fusion makes of
    /// the counts (quantised; channels fusion suspects or excludes) against the run on the
    /// evaluation's fused motion, degrees.
    pub quantisation_max_diff_deg: f64,
    /// The same in roll and pitch only (the heading, aided by nothing, wanders freely), degrees.
    pub quantisation_max_tilt_diff_deg: f64,
    /// Scored rows where one solution has an attitude and the other none.
    pub live_rows_missing: usize,
    /// Fusion's fault events seen live (a channel changing state).
    pub live_fdi_events: u64,
    /// Channels fusion excluded at some time during the flight (`gyro 2`, `accel 0`, ...).
    pub live_excluded_channels: Vec<String>,
}

/// Every flight through the running processes.
#[derive(Debug, Clone, Default, Serialize)]
pub struct LiveSummary {
    /// What the processes were fed.
    pub live_input: String,
    /// Mean over flights of the live roll/pitch RMSE, degrees.
    pub live_roll_pitch_rmse_deg: f64,
    /// The largest attitude difference to the in-process runs over every flight, degrees.
    pub live_vs_offline_max_diff_deg: f64,
    /// The same against the pipeline's library code in process on the same frames, degrees.
    pub live_vs_same_input_max_diff_deg: f64,
    /// The largest difference the input (counts, fusion's view of them) makes in process,
    /// degrees.
    pub quantisation_max_diff_deg: f64,
    /// The same in roll and pitch only, degrees.
    pub quantisation_max_tilt_diff_deg: f64,
    /// Scored rows missing live, over every flight.
    pub live_rows_missing: usize,
    /// Flights with a channel excluded live.
    pub flights_with_live_exclusions: usize,
}

/// The summary of the per-flight live figures.
pub fn summarise(input: &str, flights: &[LiveFlight]) -> LiveSummary {
    let max = |f: fn(&LiveFlight) -> f64| flights.iter().map(f).fold(0.0, f64::max);
    LiveSummary {
        live_input: input.to_string(),
        live_roll_pitch_rmse_deg: mean(
            &flights
                .iter()
                .map(|f| f.live_roll_pitch_rmse_deg)
                .collect::<Vec<_>>(),
        ),
        live_vs_offline_max_diff_deg: max(|f| f.live_vs_offline_max_diff_deg),
        live_vs_same_input_max_diff_deg: max(|f| f.live_vs_same_input_max_diff_deg),
        quantisation_max_diff_deg: max(|f| f.quantisation_max_diff_deg),
        quantisation_max_tilt_diff_deg: max(|f| f.quantisation_max_tilt_diff_deg),
        live_rows_missing: flights.iter().map(|f| f.live_rows_missing).sum(),
        flights_with_live_exclusions: flights
            .iter()
            .filter(|f| !f.live_excluded_channels.is_empty())
            .count(),
    }
}
