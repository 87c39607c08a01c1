//! The scored fused run of each flight, kept so that the running service (fusion and the
//! navigator lanes as separate processes, the receiver's messages published as the `gnss`
//! service publishes them) can repeat it and be scored the same way
//! (`rins eval quadrotor --mode gnss --live`). The per-flight and summary figures are the AHRS
//! mode's ([`crate::quadrotor_ahrs::live`]).

use ipc_types::{GnssFix, NavState};
use nalgebra::{Quaternion, UnitQuaternion};
use rins_earth::LocalOrigin;
use rins_navigator::attitude::euler_from_quaternion;
use rins_navigator::inertial_core::AidedConfig;
use rins_navigator::start::InFlightStart;

use super::receiver::LocalFix;
use super::run::{
    GnssTrace, Sample, StartKnowledge, gnss_start, navigate_with_gnss, receiver_messages,
};
use super::score;
use crate::datasets::quadrotor::TruthRow;
use crate::quadrotor_ahrs::live::RepeatableRun;
use crate::quadrotor_ahrs::mounting::roll_pitch_rmse_deg;
use crate::quadrotor_nav::frames::Motion;
use crate::quadrotor_nav::metrics::angle_error;
use crate::quadrotor_nav::run::Start;

/// One flight's scored fused run: what it was given and what it produced in process.
#[derive(Debug, Clone)]
pub struct ScoredGnssRun {
    /// `<group>/path_<N>`.
    pub flight: String,
    /// The fused motion, vehicle frame.
    pub motion: Motion,
    /// The reference state at t0.
    pub start: Start,
    /// The mounting and gyro bias the run started with.
    pub known: StartKnowledge,
    /// The run's settings (antenna, drift test; before [`gnss_start`]).
    pub config: AidedConfig,
    /// The receiver's epochs.
    pub fixes: Vec<LocalFix>,
    /// Where the receiver is cut, s (infinite: never).
    pub gnss_until_s: f64,
    /// The mounting tilt the score removes, rad.
    pub tilt_rad: [f64; 2],
    /// The reference rows.
    pub truth: Vec<TruthRow>,
    /// The in-process run.
    pub trace: GnssTrace,
}

impl ScoredGnssRun {
    /// The navigator's `[navigator.start]` and settings of this run.
    pub fn in_flight_start(&self) -> (InFlightStart, AidedConfig) {
        gnss_start(&self.start, &self.known, &self.config)
    }

    /// The receiver messages the run is fed, as the in-process run made them.
    pub fn messages(&self) -> Vec<GnssFix> {
        receiver_messages(
            &self.fixes,
            &self.origin(),
            self.start.t_s,
            self.gnss_until_s,
        )
    }

    fn origin(&self) -> LocalOrigin {
        let [lat, lon, alt] = self.config.origin;
        LocalOrigin::new(lat, lon, alt)
    }

    /// The same run in process on other samples of the motion (e.g. as a converter quantised
    /// them).
    pub fn rerun(&self, motion: &Motion) -> GnssTrace {
        navigate_with_gnss(
            motion,
            &self.start,
            &self.known,
            &self.config,
            &self.fixes,
            self.gnss_until_s,
        )
    }

    /// What a running navigator published, as a trace on the flight's time base:
    /// `(sample index, [w, x, y, z], latitude, longitude, altitude)` of every navigating sample
    /// after the start (in order).
    pub fn trace_from(
        &self,
        published: impl IntoIterator<Item = (usize, [f64; 4], [f64; 3])>,
    ) -> GnssTrace {
        let origin = self.origin();
        let mut trace = GnssTrace::default();
        for (j, [w, x, y, z], [lat, lon, alt]) in published {
            let t_s = self.motion.time(j);
            if t_s <= self.start.t_s {
                continue;
            }
            let q = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
            let [n, e, _] = origin.ned(lat, lon, alt);
            trace.samples.push(Sample {
                t_s,
                euler_rad: euler_from_quaternion(&q),
                north_east_m: [n, e],
            });
        }
        trace
    }

    /// Roll/pitch RMSE of `trace` with the run's mounting, scored as the in-process run is,
    /// degrees.
    pub fn score_deg(&self, trace: &GnssTrace) -> f64 {
        let scores = score(None, trace, &self.truth, &self.start);
        roll_pitch_rmse_deg(&scores.paired, self.tilt_rad, 0.0)
    }

    /// The largest attitude difference between `a` and `b` at the scored reference rows,
    /// degrees, and the rows where one of them has a sample while the other has none.
    pub fn max_difference_deg(&self, a: &GnssTrace, b: &GnssTrace) -> (f64, usize) {
        self.max_difference(a, b, |x, y| {
            let q =
                |e: &[f64; 3]| rins_navigator::attitude::quaternion_from_euler(e[0], e[1], e[2]);
            q(&x.euler_rad).angle_to(&q(&y.euler_rad))
        })
    }

    /// The largest roll or pitch difference between `a` and `b` at the scored rows, degrees.
    pub fn max_tilt_difference_deg(&self, a: &GnssTrace, b: &GnssTrace) -> f64 {
        self.max_difference(a, b, |x, y| {
            angle_error(x.euler_rad[0], y.euler_rad[0])
                .abs()
                .max(angle_error(x.euler_rad[1], y.euler_rad[1]).abs())
        })
        .0
    }

    fn max_difference(
        &self,
        a: &GnssTrace,
        b: &GnssTrace,
        difference_rad: impl Fn(&Sample, &Sample) -> f64,
    ) -> (f64, usize) {
        let at = |trace: &GnssTrace, t: f64| {
            let i = trace.samples.partition_point(|s| s.t_s < t);
            trace
                .samples
                .get(i)
                .filter(|s| (s.t_s - t).abs() < 0.02)
                .copied()
        };
        let mut largest = 0.0_f64;
        let mut missing = 0;
        for row in self.truth.iter().skip(self.start.row) {
            match (at(a, row.t_s), at(b, row.t_s)) {
                (Some(x), Some(y)) => largest = largest.max(difference_rad(&x, &y).to_degrees()),
                (None, None) => {}
                _ => missing += 1,
            }
        }
        (largest, missing)
    }
}

impl RepeatableRun for ScoredGnssRun {
    type Trace = GnssTrace;
    fn flight(&self) -> &str {
        &self.flight
    }
    fn motion(&self) -> &Motion {
        &self.motion
    }
    fn in_flight_start(&self) -> (InFlightStart, AidedConfig) {
        ScoredGnssRun::in_flight_start(self)
    }
    fn receiver_messages(&self) -> Vec<GnssFix> {
        self.messages()
    }
    fn in_process(&self) -> &GnssTrace {
        &self.trace
    }
    fn rerun(&self, motion: &Motion) -> GnssTrace {
        ScoredGnssRun::rerun(self, motion)
    }
    fn trace_from<'a>(
        &self,
        published: impl IntoIterator<Item = (usize, &'a NavState)>,
    ) -> GnssTrace {
        ScoredGnssRun::trace_from(
            self,
            published.into_iter().map(|(j, n)| {
                (
                    j,
                    n.quaternion,
                    [n.latitude_rad, n.longitude_rad, n.altitude_m],
                )
            }),
        )
    }
    fn score_deg(&self, trace: &GnssTrace) -> f64 {
        ScoredGnssRun::score_deg(self, trace)
    }
    fn max_difference_deg(&self, a: &GnssTrace, b: &GnssTrace) -> (f64, usize) {
        ScoredGnssRun::max_difference_deg(self, a, b)
    }
    fn max_tilt_difference_deg(&self, a: &GnssTrace, b: &GnssTrace) -> f64 {
        ScoredGnssRun::max_tilt_difference_deg(self, a, b)
    }
}
