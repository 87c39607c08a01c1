//! The multirotor flight profile as schedules of ground speed, course rate, climb rate, yaw offset
//! and gust.
//!
//! A quadrotor: parked level, rotors spun up on the ground, a vertical climb to the pattern height,
//! a hover, then a pattern of legs flown as many times as the flight length allows — bursts of
//! acceleration and braking between 0 and 10 m/s, sharp turns, a leg flown crabbed with the nose
//! 60° off the course, a climb and a descent, a pirouette in the hover — with one wind gust per
//! pattern; finally a hover, a vertical descent and the landing. Tilts reach about 30°.
//!
//! The schedules are smooth steps (see [`super::schedule`]), so acceleration and its rate are
//! continuous: the attitude that follows from them (see [`super::multirotor`]) has a continuous body
//! rate.

use super::schedule::Schedule;

/// Ground time with the rotors turning before the climb, s.
pub const SPIN_UP_S: f64 = 2.0;
/// Ground time with the rotors turning after the touchdown, s.
pub const SPIN_DOWN_S: f64 = 2.0;
const CLIMB_RATE_MPS: f64 = 3.0;
const DESCENT_RATE_MPS: f64 = 1.5;
const VERTICAL_TRANSITION_S: f64 = 2.0;
const HOVER_S: f64 = 5.0;
/// Time the course rate takes to rise to, or fall from, its value in a turn, s.
const TURN_TRANSITION_S: f64 = 1.0;
/// Climb (and descent) inside the pattern: rate, m/s, and its hold, s.
const PATTERN_CLIMB_MPS: f64 = 2.0;
const PATTERN_CLIMB_HOLD_S: f64 = 3.0;
/// When, after the pattern starts, the climb and the descent begin and the gust rises, s.
const PATTERN_CLIMB_AT_S: f64 = 20.0;
const PATTERN_DESCENT_AT_S: f64 = 50.0;
const GUST_AT_S: f64 = 8.0;
/// How long the gust holds its full strength, s.
const GUST_HOLD_S: f64 = 8.0;

/// One segment of the pattern, flown one after the other.
#[derive(Debug, Clone, Copy)]
enum Segment {
    /// Change the ground speed to `mps` in `s` seconds.
    Speed { mps: f64, s: f64 },
    /// Turn the course by `deg` (positive: right) at `dps` (degrees per second).
    Turn { deg: f64, dps: f64 },
    /// Point the nose `deg` to the right of the course, reaching it in `s` seconds.
    Yaw { deg: f64, s: f64 },
    /// Keep everything as it is for `s` seconds.
    Hold { s: f64 },
}

use Segment::{Hold, Speed, Turn, Yaw};

/// The pattern, flown from a hover back to a hover (about 73 s).
const PATTERN: [Segment; 20] = [
    Speed { mps: 8.0, s: 4.0 },
    Hold { s: 4.0 },
    Turn {
        deg: 90.0,
        dps: 35.0,
    },
    Hold { s: 3.0 },
    Speed { mps: 10.0, s: 4.0 },
    Hold { s: 3.0 },
    Turn {
        deg: -120.0,
        dps: 22.0,
    },
    Speed { mps: 4.0, s: 3.0 },
    Yaw { deg: 60.0, s: 2.0 },
    Hold { s: 5.0 },
    Turn {
        deg: 150.0,
        dps: 45.0,
    },
    Hold { s: 3.0 },
    Yaw { deg: 0.0, s: 2.0 },
    Speed { mps: 8.0, s: 3.0 },
    Hold { s: 4.0 },
    Turn {
        deg: -120.0,
        dps: 30.0,
    },
    Speed { mps: 0.0, s: 4.0 },
    Hold { s: 3.0 },
    // A pirouette: at zero speed the course turns the nose only.
    Turn {
        deg: 180.0,
        dps: 60.0,
    },
    Hold { s: 3.0 },
];

/// Schedules of the multirotor profile and its landmark times.
#[derive(Debug, Clone)]
pub struct MultirotorProfile {
    /// Horizontal ground speed, m/s.
    pub speed: Schedule,
    /// Course rate, rad/s (its integral is the course change).
    pub course_rate: Schedule,
    /// Climb rate (−v_D), m/s (its integral is the height change).
    pub climb_rate: Schedule,
    /// Yaw of the nose from the course, rad.
    pub yaw_offset: Schedule,
    /// Wind speed along the gust direction, m/s.
    pub gust: Schedule,
    /// Rotors start turning, s.
    pub rotors_on_s: f64,
    /// The vehicle leaves the ground, s.
    pub lift_off_s: f64,
    /// The vehicle touches down, s.
    pub touchdown_s: f64,
    /// Rotors stopped, at rest for good, s.
    pub end_s: f64,
}

impl MultirotorProfile {
    /// Builds the profile with `static_s` parked first, the pattern at `altitude_agl_m` flown once
    /// and a gust of `gust_mps` rising and falling in `gust_rise_s`.
    pub fn new(static_s: f64, altitude_agl_m: f64, gust_mps: f64, gust_rise_s: f64) -> Self {
        Self::with_patterns(static_s, altitude_agl_m, gust_mps, gust_rise_s, 1)
    }

    /// As [`Self::new`] with as many patterns (at least one) as fit for the whole flight, parking
    /// included, to end (rotors stopped) by `flight_s`.
    pub fn lasting(
        static_s: f64,
        altitude_agl_m: f64,
        gust_mps: f64,
        gust_rise_s: f64,
        flight_s: f64,
    ) -> Self {
        let one = Self::new(static_s, altitude_agl_m, gust_mps, gust_rise_s).end_s;
        let extra = ((flight_s - one) / pattern_duration_s()).floor();
        // Bounded so that a huge request cannot build a schedule that exhausts memory.
        let extra = if extra.is_finite() {
            extra.clamp(0.0, 200.0) as usize
        } else {
            0
        };
        Self::with_patterns(static_s, altitude_agl_m, gust_mps, gust_rise_s, 1 + extra)
    }

    fn with_patterns(
        static_s: f64,
        altitude_agl_m: f64,
        gust_mps: f64,
        gust_rise_s: f64,
        patterns: usize,
    ) -> Self {
        let mut p = Self {
            speed: Schedule::new(0.0),
            course_rate: Schedule::new(0.0),
            climb_rate: Schedule::new(0.0),
            yaw_offset: Schedule::new(0.0),
            gust: Schedule::new(0.0),
            rotors_on_s: static_s,
            lift_off_s: static_s + SPIN_UP_S,
            touchdown_s: 0.0,
            end_s: 0.0,
        };
        let mut t = p.lift_off_s;
        t += vertical(&mut p.climb_rate, t, altitude_agl_m, CLIMB_RATE_MPS);
        t += HOVER_S;
        for _ in 0..patterns.max(1) {
            p.pattern_extras(t, gust_mps, gust_rise_s);
            for segment in PATTERN {
                t += p.segment(t, segment);
            }
        }
        t += HOVER_S;
        t += vertical(&mut p.climb_rate, t, -altitude_agl_m, DESCENT_RATE_MPS);
        p.touchdown_s = t;
        p.end_s = t + SPIN_DOWN_S;
        p
    }

    /// The pattern's climb, descent and gust, which run alongside its segments.
    fn pattern_extras(&mut self, start_s: f64, gust_mps: f64, gust_rise_s: f64) {
        for (at_s, rate) in [
            (PATTERN_CLIMB_AT_S, PATTERN_CLIMB_MPS),
            (PATTERN_DESCENT_AT_S, -PATTERN_CLIMB_MPS),
        ] {
            let t = start_s + at_s;
            self.climb_rate.step_to(t, VERTICAL_TRANSITION_S, rate);
            let t = t + VERTICAL_TRANSITION_S + PATTERN_CLIMB_HOLD_S;
            self.climb_rate.step_to(t, VERTICAL_TRANSITION_S, 0.0);
        }
        let t = start_s + GUST_AT_S;
        self.gust.step_to(t, gust_rise_s, gust_mps);
        self.gust
            .step_to(t + gust_rise_s + GUST_HOLD_S, gust_rise_s, 0.0);
    }

    /// Adds one segment from `start_s`; returns its duration.
    fn segment(&mut self, start_s: f64, segment: Segment) -> f64 {
        match segment {
            Speed { mps, s } => {
                self.speed.step_to(start_s, s, mps);
                s
            }
            Yaw { deg, s } => {
                self.yaw_offset.step_to(start_s, s, deg.to_radians());
                s
            }
            Turn { deg, dps } => {
                let duration_s = turn_duration_s(deg, dps);
                let rate = dps.to_radians() * deg.signum();
                self.course_rate.step_to(start_s, TURN_TRANSITION_S, rate);
                self.course_rate.step_to(
                    start_s + duration_s - TURN_TRANSITION_S,
                    TURN_TRANSITION_S,
                    0.0,
                );
                duration_s
            }
            Hold { s } => s,
        }
    }
}

/// A climb (positive) or descent of `height_m` at `rate_mps` from `start_s` to a stop; returns
/// its duration. Each smooth step contributes half its duration at full rate to the height.
fn vertical(climb_rate: &mut Schedule, start_s: f64, height_m: f64, rate_mps: f64) -> f64 {
    let hold_s = (height_m.abs() / rate_mps - VERTICAL_TRANSITION_S).max(0.0);
    let rate = height_m.signum() * height_m.abs() / (hold_s + VERTICAL_TRANSITION_S);
    climb_rate.step_to(start_s, VERTICAL_TRANSITION_S, rate);
    climb_rate.step_to(
        start_s + VERTICAL_TRANSITION_S + hold_s,
        VERTICAL_TRANSITION_S,
        0.0,
    );
    hold_s + 2.0 * VERTICAL_TRANSITION_S
}

/// Duration of a turn of `deg` at `dps`: the two transitions together turn as much as one
/// transition at full rate.
fn turn_duration_s(deg: f64, dps: f64) -> f64 {
    (deg.abs() / dps).max(TURN_TRANSITION_S) + TURN_TRANSITION_S
}

/// Duration of one pattern, s.
pub fn pattern_duration_s() -> f64 {
    PATTERN
        .iter()
        .map(|s| match *s {
            Speed { s, .. } | Yaw { s, .. } | Hold { s } => s,
            Turn { deg, dps } => turn_duration_s(deg, dps),
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pattern_lasts_long_enough_for_its_climb_descent_and_gust() {
        let d = pattern_duration_s();
        assert!(d > PATTERN_DESCENT_AT_S + 2.0 * VERTICAL_TRANSITION_S + PATTERN_CLIMB_HOLD_S);
        assert!(d > GUST_AT_S + 2.0 * 10.0 + GUST_HOLD_S);
    }

    #[test]
    fn it_lands_where_it_took_off_stopped_and_calm() {
        let p = MultirotorProfile::lasting(3.0, 30.0, 3.0, 3.0, 600.0);
        assert!(p.end_s <= 600.0 && p.end_s > 600.0 - pattern_duration_s());
        let end = p.end_s + 1.0;
        assert!(p.climb_rate.sample(end).integral.abs() < 1e-9);
        assert_eq!(p.speed.sample(end).value, 0.0);
        assert_eq!(p.gust.sample(end).value, 0.0);
        assert!(p.climb_rate.sample(p.touchdown_s).value.abs() < 1e-12);
        // At the pattern height through the patterns.
        assert!((p.climb_rate.sample(p.lift_off_s + 30.0).integral - 30.0).abs() < 1e-9);
    }
}
