//! The UAV flight profile as schedules of horizontal speed, heading rate and climb rate.
//!
//! A small fixed-wing-like vehicle: parked level, ground roll to cruise speed, climb at a constant
//! rate to cruise altitude, two rectangular circuits (right turns at 25° bank, then left turns at
//! 20°), a 180° reversal at 30° bank, a constant-rate descent whose final smooth step is the flare,
//! a landing roll to a stop, then parked for as long as the simulation runs.
//!
//! A longer flight (an endurance run) repeats the pair of circuits as many times as fit before
//! the reversal, so that the vehicle keeps turning, accelerating and heating its sensors instead
//! of standing parked for most of the run.

use super::schedule::Schedule;
use rins_earth::STANDARD_GRAVITY;

/// Horizontal ground speed in cruise, m/s.
pub const CRUISE_SPEED_MPS: f64 = 15.0;
/// Cruise altitude above the take-off point, m.
pub const CRUISE_ALTITUDE_AGL_M: f64 = 100.0;
/// Largest bank angle used by any turn, degrees.
pub const MAX_BANK_DEG: f64 = 30.0;
/// Smallest bank angle used by any turn, degrees.
pub const MIN_BANK_DEG: f64 = 20.0;

const GROUND_ROLL_S: f64 = 10.0;
const CLIMB_RATE_MPS: f64 = 2.5;
const CLIMB_TRANSITION_S: f64 = 4.0;
const DESCENT_RATE_MPS: f64 = 2.0;
const DESCENT_TRANSITION_S: f64 = 4.0;
const ROLL_TRANSITION_S: f64 = 3.0;
const LANDING_ROLL_HOLD_S: f64 = 3.0;
const LANDING_DECELERATION_S: f64 = 10.0;

/// One cruise leg: fly straight, then turn.
struct Leg {
    straight_s: f64,
    turn_deg: f64,
    bank_deg: f64,
}

const fn leg(straight_s: f64, turn_deg: f64, bank_deg: f64) -> Leg {
    Leg {
        straight_s,
        turn_deg,
        bank_deg,
    }
}

/// The pair of rectangular circuits: flown once, or repeated in a longer flight.
const CIRCUIT_LEGS: [Leg; 8] = [
    leg(60.0, 90.0, 25.0),
    leg(30.0, 90.0, 25.0),
    leg(60.0, 90.0, 25.0),
    leg(30.0, 90.0, 25.0),
    leg(60.0, -90.0, 20.0),
    leg(30.0, -90.0, 20.0),
    leg(60.0, -90.0, 20.0),
    leg(30.0, -90.0, 20.0),
];
/// After the circuits: the reversal towards the landing.
const REVERSAL: Leg = leg(20.0, 180.0, 30.0);
const FINAL_STRAIGHT_S: f64 = 30.0;

/// Schedules of the UAV profile and its landmark times.
#[derive(Debug, Clone)]
pub struct UavProfile {
    /// Horizontal ground speed, m/s.
    pub speed: Schedule,
    /// Heading rate, rad/s (its integral is the heading change).
    pub heading_rate: Schedule,
    /// Climb rate (−v_D), m/s (its integral is the altitude change).
    pub climb_rate: Schedule,
    /// Time the vehicle leaves the ground, s.
    pub lift_off_s: f64,
    /// Time the vehicle touches down, s.
    pub touchdown_s: f64,
    /// Time the vehicle is stopped on the ground again, s.
    pub end_s: f64,
}

impl UavProfile {
    /// Builds the profile with `static_s` seconds parked at the start and one pair of circuits.
    pub fn new(static_s: f64) -> Self {
        Self::with_circuits(static_s, 1)
    }

    /// Builds the profile with as many pairs of circuits (at least one) as fit for the whole
    /// flight, parking included, to end (stopped after the landing roll) by `flight_s`.
    pub fn lasting(static_s: f64, flight_s: f64) -> Self {
        let one = Self::with_circuits(static_s, 1).end_s;
        let extra = ((flight_s - one) / circuit_duration_s()).floor();
        // Bounded so that a huge request cannot build a schedule that exhausts memory: a day of
        // circuits is far more than any run needs.
        let extra = if extra.is_finite() {
            extra.clamp(0.0, 200.0) as usize
        } else {
            0
        };
        Self::with_circuits(static_s, 1 + extra)
    }

    /// Builds the profile with `circuits` pairs of circuits (at least one).
    fn with_circuits(static_s: f64, circuits: usize) -> Self {
        let mut speed = Schedule::new(0.0);
        let mut heading_rate = Schedule::new(0.0);
        let mut climb_rate = Schedule::new(0.0);
        let mut t = static_s;

        speed.step_to(t, GROUND_ROLL_S, CRUISE_SPEED_MPS);
        t += GROUND_ROLL_S;

        // Each smooth step contributes half its duration at full rate to the altitude change.
        let lift_off_s = t;
        let climb_hold_s = CRUISE_ALTITUDE_AGL_M / CLIMB_RATE_MPS - CLIMB_TRANSITION_S;
        climb_rate.step_to(t, CLIMB_TRANSITION_S, CLIMB_RATE_MPS);
        t += CLIMB_TRANSITION_S + climb_hold_s;
        climb_rate.step_to(t, CLIMB_TRANSITION_S, 0.0);
        t += CLIMB_TRANSITION_S;

        let legs = CIRCUIT_LEGS
            .iter()
            .cycle()
            .take(CIRCUIT_LEGS.len() * circuits.max(1));
        for leg in legs.chain([&REVERSAL]) {
            t += leg.straight_s;
            t += coordinated_turn(&mut heading_rate, t, leg.turn_deg, leg.bank_deg);
        }
        t += FINAL_STRAIGHT_S;

        let descent_hold_s = CRUISE_ALTITUDE_AGL_M / DESCENT_RATE_MPS - DESCENT_TRANSITION_S;
        climb_rate.step_to(t, DESCENT_TRANSITION_S, -DESCENT_RATE_MPS);
        t += DESCENT_TRANSITION_S + descent_hold_s;
        climb_rate.step_to(t, DESCENT_TRANSITION_S, 0.0);
        t += DESCENT_TRANSITION_S;
        let touchdown_s = t;

        t += LANDING_ROLL_HOLD_S;
        speed.step_to(t, LANDING_DECELERATION_S, 0.0);
        t += LANDING_DECELERATION_S;

        Self {
            speed,
            heading_rate,
            climb_rate,
            lift_off_s,
            touchdown_s,
            end_s: t,
        }
    }
}

/// Duration of one pair of circuits, s.
fn circuit_duration_s() -> f64 {
    CIRCUIT_LEGS
        .iter()
        .map(|l| l.straight_s + turn_duration_s(l.turn_deg, l.bank_deg))
        .sum()
}

/// Heading rate of a level coordinated turn at `bank_deg` and cruise speed, rad/s.
fn turn_rate_rps(bank_deg: f64) -> f64 {
    STANDARD_GRAVITY * bank_deg.to_radians().tan() / CRUISE_SPEED_MPS
}

/// Duration of a turn of `turn_deg` at `bank_deg`, s (see [`coordinated_turn`]).
fn turn_duration_s(turn_deg: f64, bank_deg: f64) -> f64 {
    let hold_s =
        (turn_deg.to_radians().abs() / turn_rate_rps(bank_deg) - ROLL_TRANSITION_S).max(0.0);
    2.0 * ROLL_TRANSITION_S + hold_s
}

/// Adds a level coordinated turn of `turn_deg` (positive = right) at `bank_deg` starting at `start_s`
/// to the heading-rate schedule; returns its duration. The heading rate rises to `g·tan(bank)/V`
/// through a smooth step, holds, and returns to zero; the two steps together turn as much as
/// one step's duration at full rate.
fn coordinated_turn(
    heading_rate: &mut Schedule,
    start_s: f64,
    turn_deg: f64,
    bank_deg: f64,
) -> f64 {
    let duration_s = turn_duration_s(turn_deg, bank_deg);
    let hold_s = duration_s - 2.0 * ROLL_TRANSITION_S;
    let rate = turn_rate_rps(bank_deg);
    heading_rate.step_to(start_s, ROLL_TRANSITION_S, rate * turn_deg.signum());
    heading_rate.step_to(start_s + ROLL_TRANSITION_S + hold_s, ROLL_TRANSITION_S, 0.0);
    duration_s
}
