//! ODOMETRY (#331), the message an autopilot's estimator takes as an external source: pose in the
//! local NED frame, velocity and body rates in the body (FRD) frame, the covariance diagonal of
//! each from the filter, a reset counter that tells the receiver when the estimate jumped, and a
//! quality that says when it must not be used. [`odometry`] builds it in the generic frames
//! (`LOCAL_NED`, `BODY_FRD`); [`crate::autopilot`] relabels and blanks it for the receiver.

use ipc_types::{Integrity, NavMode, NavState};

use crate::dialect::{MavEstimatorType, MavFrame, ODOMETRY_DATA};
use crate::local_frame::LocalOrigin;
use crate::time_usec;

/// Index of each diagonal element in a MAVLink upper-triangular 6×6 covariance (21 entries, row
/// major): rows start at 0, 6, 11, 15, 18, 20.
pub const COVARIANCE_DIAGONAL: [usize; 6] = [0, 6, 11, 15, 18, 20];

/// Counts the resets of the published estimate: a lane switch of the consumer's selector (it
/// follows another filter from now on) or a new solution in a lane (a new alignment, a state taken
/// over from the other lane). A single sample the selector took from the other lane to fill a
/// hole is not a reset: both lanes run the same filter on the same samples. The receiver re-bases
/// its own fusion when the counter changes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ResetCounter {
    count: u8,
    /// The selector's switch count at the last sample.
    switches: u64,
    /// The solution each lane delivered last (its first sample's sequence number).
    solutions: [Option<u64>; 2],
}

impl ResetCounter {
    /// Counts a reset that does not come from the lanes: the local frame's origin moved, so every
    /// local position jumps.
    pub fn bump(&mut self) {
        self.count = self.count.wrapping_add(1);
    }

    /// The counter for `nav`, delivered after `switches` lane switches of the selector.
    pub fn observe(&mut self, nav: &NavState, switches: u64) -> u8 {
        let lane = usize::from(nav.lane.min(1));
        let new_solution = self.solutions[lane].is_some_and(|s| s != nav.solution_start_seq);
        if new_solution || switches != self.switches {
            self.count = self.count.wrapping_add(1);
        }
        self.solutions[lane] = Some(nav.solution_start_seq);
        self.switches = switches;
        self.count
    }
}

/// The horizontal position σ (m) of `nav`: the root of the north and east variances' sum (the
/// distance RMS, √2 times the per-axis σ of a round error); NaN when either is not a variance.
pub fn horizontal_sigma_m(nav: &NavState) -> f64 {
    let (var_n, var_e) = (nav.covariance_diag[6], nav.covariance_diag[7]);
    if var_n >= 0.0 && var_e >= 0.0 {
        (var_n + var_e).sqrt()
    } else {
        f64::NAN
    }
}

/// Quality in percent, from the horizontal σ and the integrity: −1 ("failed") while the solution
/// is not usable, its integrity invalid or its covariance not a variance; otherwise
/// `100·σ₀²/(σ₀² + σ_h²)` with `σ₀ = sigma_50_m` (`[mavlink] odometry_quality_sigma_m`), so that
/// σ_h = σ₀ gives 50 and a larger σ less (rounded down), halved while the integrity is degraded,
/// and at least 1 (0 would mean "unknown").
pub fn quality(nav: &NavState, sigma_50_m: f64) -> i8 {
    let usable = NavMode::from_u8(nav.mode).is_some_and(NavMode::is_usable);
    let scale = match Integrity::from_u8(nav.integrity) {
        Some(Integrity::Ok) if usable => 1.0,
        Some(Integrity::Degraded) if usable => 0.5,
        _ => return -1,
    };
    let sigma = horizontal_sigma_m(nav);
    if !sigma.is_finite() {
        return -1;
    }
    let s0 = sigma_50_m * sigma_50_m;
    let percent = scale * 100.0 * s0 / (s0 + sigma * sigma);
    // Rounded down, so that any σ_h above σ₀ is below 50; in 1..=100, the cast cannot wrap.
    percent.floor().clamp(1.0, 100.0) as i8
}

/// Rotation matrix body → NED of a quaternion [w, x, y, z].
fn body_to_ned(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// A 21-entry upper-triangular covariance with `diagonal` on its diagonal and zeros elsewhere (the
/// filter publishes only its diagonal).
fn covariance(diagonal: [f64; 6]) -> [f32; 21] {
    let mut c = [0.0f32; 21];
    for (i, v) in COVARIANCE_DIAGONAL.iter().zip(diagonal) {
        c[*i] = v as f32;
    }
    c
}

/// The odometry of `nav` in the local frame of `origin`, with the body rate (FRD, rad/s) and its
/// variance from the fused IMU, the reset counter, and the σ of quality 50 ([`quality`]).
pub fn odometry(
    nav: &NavState,
    origin: &LocalOrigin,
    body_rate_rps: [f64; 3],
    body_rate_var: [f64; 3],
    reset_counter: u8,
    quality_sigma_50_m: f64,
) -> ODOMETRY_DATA {
    let [x, y, z] = origin.ned(nav.latitude_rad, nav.longitude_rad, nav.altitude_m);
    let r = body_to_ned(nav.quaternion);
    let v_n = nav.velocity_ned_mps;
    let p = &nav.covariance_diag;
    // Velocity and its variance in the body frame: v_b = Rᵀ v_n; with only the NED diagonal
    // known, var(v_b,i) = Σ_j R_ji² var(v_n,j).
    let mut v_b = [0.0; 3];
    let mut v_b_var = [0.0; 3];
    for i in 0..3 {
        for j in 0..3 {
            v_b[i] += r[j][i] * v_n[j];
            v_b_var[i] += r[j][i] * r[j][i] * p[3 + j];
        }
    }
    let [w, qx, qy, qz] = nav.quaternion;
    ODOMETRY_DATA {
        time_usec: time_usec(nav),
        frame_id: MavFrame::MAV_FRAME_LOCAL_NED,
        child_frame_id: MavFrame::MAV_FRAME_BODY_FRD,
        x: x as f32,
        y: y as f32,
        z: z as f32,
        q: [w as f32, qx as f32, qy as f32, qz as f32],
        vx: v_b[0] as f32,
        vy: v_b[1] as f32,
        vz: v_b[2] as f32,
        rollspeed: body_rate_rps[0] as f32,
        pitchspeed: body_rate_rps[1] as f32,
        yawspeed: body_rate_rps[2] as f32,
        // Position NED, then the small attitude errors about north, east, down as roll, pitch
        // and yaw variances (equal for small tilts).
        pose_covariance: covariance([p[6], p[7], p[8], p[0], p[1], p[2]]),
        velocity_covariance: covariance([
            v_b_var[0],
            v_b_var[1],
            v_b_var[2],
            body_rate_var[0],
            body_rate_var[1],
            body_rate_var[2],
        ]),
        reset_counter,
        // An inertial solution aided by baro and magnetometer has no type of its own in the
        // enumeration (GPS_INS needs satellites): unknown is the honest answer.
        estimator_type: MavEstimatorType::MAV_ESTIMATOR_TYPE_UNKNOWN,
        quality: quality(nav, quality_sigma_50_m),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn navigating() -> NavState {
        let mut covariance_diag = [0.0; ipc_types::NAV_STATES];
        for (i, c) in covariance_diag.iter_mut().enumerate() {
            *c = (i + 1) as f64;
        }
        NavState {
            mode: NavMode::Navigating as u8,
            velocity_ned_mps: [3.0, 4.0, -1.0],
            covariance_diag,
            solution_start_seq: 10,
            ..NavState::default()
        }
    }

    #[test]
    fn the_covariance_diagonal_lands_on_the_triangle_diagonal() {
        let nav = navigating();
        let origin = LocalOrigin::new(0.0, 0.0, 0.0);
        let m = odometry(&nav, &origin, [0.0; 3], [0.01, 0.02, 0.03], 0, SIGMA_50_M);
        let diag: Vec<f32> = COVARIANCE_DIAGONAL
            .iter()
            .map(|&i| m.pose_covariance[i])
            .collect();
        // Position NED is states 6..9 (variances 7, 8, 9), attitude 0..3 (1, 2, 3).
        assert_eq!(diag, [7.0, 8.0, 9.0, 1.0, 2.0, 3.0]);
        let off: f32 = (0..21)
            .filter(|i| !COVARIANCE_DIAGONAL.contains(i))
            .map(|i| m.pose_covariance[i].abs())
            .sum();
        assert_eq!(off, 0.0);
        // Level, facing north: body axes are NED axes, so the velocity variances are 4, 5, 6.
        let diag: Vec<f32> = COVARIANCE_DIAGONAL
            .iter()
            .map(|&i| m.velocity_covariance[i])
            .collect();
        assert_eq!(diag, [4.0, 5.0, 6.0, 0.01, 0.02, 0.03]);
        assert_eq!((m.vx, m.vy, m.vz), (3.0, 4.0, -1.0));
        // σ_h = √(7 + 8) m: 100·100/(100 + 15) = 86.96.
        assert_eq!(m.quality, 86);
    }

    #[test]
    fn velocity_goes_into_the_body_frame() {
        // Yawed 90° right: the body's forward axis points east.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let nav = NavState {
            quaternion: [h, 0.0, 0.0, h],
            ..navigating()
        };
        let m = odometry(
            &nav,
            &LocalOrigin::new(0.0, 0.0, 0.0),
            [0.0; 3],
            [0.0; 3],
            0,
            SIGMA_50_M,
        );
        // North 3, east 4 → forward 4, right −3.
        assert!(
            (m.vx - 4.0).abs() < 1e-6 && (m.vy + 3.0).abs() < 1e-6,
            "{m:?}"
        );
        assert!((m.vz + 1.0).abs() < 1e-6);
        // The north and east variances (4, 5) swap places.
        assert!((m.velocity_covariance[0] - 5.0).abs() < 1e-6);
        assert!((m.velocity_covariance[6] - 4.0).abs() < 1e-6);
    }

    /// The built-in σ of quality 50.
    const SIGMA_50_M: f64 = 10.0;

    /// A navigating solution of horizontal σ `sigma_h_m`, all of it north.
    fn with_horizontal_sigma(sigma_h_m: f64) -> NavState {
        let mut nav = navigating();
        nav.covariance_diag[6] = sigma_h_m * sigma_h_m;
        nav.covariance_diag[7] = 0.0;
        nav
    }

    #[test]
    fn quality_falls_with_the_horizontal_sigma() {
        // 100·σ₀²/(σ₀² + σ_h²), rounded down.
        for (sigma_h, expected) in [
            (0.0, 100),
            (1.0, 99),  // 100/1.01
            (10.0, 50), // σ_h = σ₀
            (15.0, 30), // 100/3.25 = 30.8
            (47.0, 4),  // free-inertial drift: 100/23.09
            (72.0, 1),  // 100/52.84 = 1.9
            (1e6, 1),   // never 0, which means "unknown"
        ] {
            let nav = with_horizontal_sigma(sigma_h);
            assert_eq!(quality(&nav, SIGMA_50_M), expected, "σ_h {sigma_h} m");
        }
        // North and east add up: 6 m and 8 m make σ_h = 10 m.
        let mut nav = navigating();
        (nav.covariance_diag[6], nav.covariance_diag[7]) = (36.0, 64.0);
        assert_eq!(horizontal_sigma_m(&nav), 10.0);
        assert_eq!(quality(&nav, SIGMA_50_M), 50);
        // Any σ_h above σ₀ is below 50, and the curve never rises with σ_h.
        let mut last = 100;
        for i in 0..4000 {
            let sigma_h = f64::from(i) * 0.025;
            let q = quality(&with_horizontal_sigma(sigma_h), SIGMA_50_M);
            assert!(q <= last, "σ_h {sigma_h}: {q} after {last}");
            if sigma_h > SIGMA_50_M {
                assert!(q < 50, "σ_h {sigma_h} m: quality {q}");
            }
            last = q;
        }
        // A tighter σ₀ judges the same solution worse.
        let nav = with_horizontal_sigma(3.0);
        assert!(quality(&nav, 2.0) < quality(&nav, SIGMA_50_M));
    }

    #[test]
    fn quality_fails_unless_the_solution_is_usable() {
        let nav = with_horizontal_sigma(0.0);
        assert_eq!(quality(&nav, SIGMA_50_M), 100);
        let degraded = NavState {
            integrity: Integrity::Degraded as u8,
            ..nav
        };
        assert_eq!(quality(&degraded, SIGMA_50_M), 50);
        let mut no_variance = nav;
        no_variance.covariance_diag[7] = f64::NAN;
        let mut negative = nav;
        negative.covariance_diag[6] = -1.0;
        for not_usable in [
            NavState {
                mode: NavMode::Aligning as u8,
                ..nav
            },
            NavState {
                integrity: Integrity::Invalid as u8,
                ..nav
            },
            NavState { mode: 77, ..nav },
            no_variance,
            negative,
        ] {
            assert_eq!(quality(&not_usable, SIGMA_50_M), -1);
        }
    }

    #[test]
    fn the_reset_counter_moves_on_a_lane_switch_or_a_new_solution_only() {
        let mut c = ResetCounter::default();
        let nav = navigating();
        assert_eq!(c.observe(&nav, 0), 0);
        assert_eq!(c.observe(&nav, 0), 0);
        // A hole filled from the other lane: no reset.
        assert_eq!(c.observe(&NavState { lane: 1, ..nav }, 0), 0);
        assert_eq!(c.observe(&nav, 0), 0);
        // The selector switched.
        assert_eq!(c.observe(&NavState { lane: 1, ..nav }, 1), 1);
        assert_eq!(c.observe(&NavState { lane: 1, ..nav }, 1), 1);
        // The lane started a new solution.
        let new = NavState {
            lane: 1,
            solution_start_seq: 99,
            ..nav
        };
        assert_eq!(c.observe(&new, 1), 2);
        assert_eq!(c.observe(&new, 1), 2);
        // The origin moved.
        c.bump();
        assert_eq!(c.observe(&new, 1), 3);
    }
}
