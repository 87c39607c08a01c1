//! Taking over the other navigator lane's solution: how a lane restarted in flight navigates again.
//!
//! A restarted lane cannot align by itself in flight (the static alignment needs the vehicle at
//! rest). Its peer publishes the whole filter state with every sample — attitude, velocity,
//! position, bias estimates, error variances — stamped with the fused IMU sample it belongs to. The
//! restarted lane starts from a peer state and integrates, from the next sequence number on, the
//! same fused IMU samples the peer does; from then on the two lanes are independent again.
//!
//! Only a trusted peer is copied (navigating for the lane selector's settling time), so a lane never
//! copies a peer that itself just reset or took over, and two lanes starting together each do their
//! own alignment. The taken-over solution gets a new `solution_start_seq`, so the lane selector
//! does not trust it either until it has run for the settling time.

use ipc_types::{FusedImu, NAV_STATES, NavMode, NavState};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use thiserror::Error;

use crate::lanes::{SelectorConfig, trusted};
use crate::mechanisation::{ImuBias, NominalState};

/// Why a peer state cannot be taken over.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TakeOverError {
    /// The peer's mode is not a usable navigating mode; the value is its wire byte.
    #[error("the peer lane is not navigating (mode {0})")]
    NotNavigating(u8),
    /// The peer's solution has not run for the lane selector's settling time.
    #[error("the peer's solution is not settled yet (seq {seq}, started at {start})")]
    NotSettled {
        /// Origin sequence number of the peer's sample.
        seq: u64,
        /// Sequence number at which the peer's solution started (`solution_start_seq`).
        start: u64,
    },
    /// A component of the peer's state is NaN or infinite; names the component.
    #[error("the peer's {0} is not finite")]
    NotFinite(&'static str),
    /// The peer's attitude quaternion is not of unit norm.
    #[error("the peer's quaternion has norm {0}, not 1")]
    NotUnit(f64),
    /// An error variance in the peer's sample is negative or not finite.
    #[error("the peer's variance of error state {index} is {value}: must be finite and >= 0")]
    BadVariance {
        /// Index of the error state.
        index: usize,
        /// The variance in the sample.
        value: f64,
    },
}

/// The filter state in a peer's sample: device time (µs), nominal state, biases, error variances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeerSolution {
    /// Device time of the fused IMU sample the state belongs to, µs.
    pub device_time_us: u64,
    /// Attitude, velocity and position.
    pub state: NominalState,
    /// Gyro and accelerometer bias estimates.
    pub bias: ImuBias,
    /// Diagonal of the error-state covariance, in the filter's state order.
    pub covariance_diag: [f64; NAV_STATES],
}

/// Checks a peer's sample and reads its filter state.
pub fn peer_solution(peer: &NavState) -> Result<PeerSolution, TakeOverError> {
    // An invalid solution is not worth taking over: a lane that aligns on its own is better. A
    // mode this build cannot read is no usable solution either.
    if !NavMode::from_u8(peer.mode).is_some_and(NavMode::is_usable) {
        return Err(TakeOverError::NotNavigating(peer.mode));
    }
    if !trusted(peer, SelectorConfig::default().settle) {
        return Err(TakeOverError::NotSettled {
            seq: peer.header.origin_seq,
            start: peer.solution_start_seq,
        });
    }
    let finite = |name, values: &[f64]| {
        if values.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(TakeOverError::NotFinite(name))
        }
    };
    finite("quaternion", &peer.quaternion)?;
    finite("velocity", &peer.velocity_ned_mps)?;
    finite(
        "position",
        &[peer.latitude_rad, peer.longitude_rad, peer.altitude_m],
    )?;
    finite("gyro bias", &peer.gyro_bias_rps)?;
    finite("accelerometer bias", &peer.accel_bias_mps2)?;
    let [w, x, y, z] = peer.quaternion;
    let q = Quaternion::new(w, x, y, z);
    // Published unit quaternions carry rounding only; anything else is a corrupt sample.
    if (q.norm() - 1.0).abs() > 1e-6 {
        return Err(TakeOverError::NotUnit(q.norm()));
    }
    for (index, &value) in peer.covariance_diag.iter().enumerate() {
        if !(value.is_finite() && value >= 0.0) {
            return Err(TakeOverError::BadVariance { index, value });
        }
    }
    Ok(PeerSolution {
        device_time_us: peer.header.origin_device_time_us,
        state: NominalState {
            attitude: UnitQuaternion::from_quaternion(q),
            velocity_ned: Vector3::from(peer.velocity_ned_mps),
            lat: peer.latitude_rad,
            lon: peer.longitude_rad,
            alt: peer.altitude_m,
        },
        bias: ImuBias {
            gyro_rps: Vector3::from(peer.gyro_bias_rps),
            accel_mps2: Vector3::from(peer.accel_bias_mps2),
        },
        covariance_diag: peer.covariance_diag,
    })
}

/// Fused IMU samples a lane keeps while it aligns, to replay after a takeover.
const IMU_KEPT: usize = 256;

/// What an aligning lane keeps to take over: the newest peer sample and its own recent fused IMU
/// samples. Fixed storage, no allocation per sample.
#[derive(Debug, Clone)]
pub struct Handover {
    peer: Option<NavState>,
    imu: Box<[FusedImu]>,
    /// Samples held in `imu`, the oldest at `(next - len) % IMU_KEPT`.
    len: usize,
    next: usize,
}

impl Default for Handover {
    fn default() -> Self {
        Self {
            peer: None,
            imu: vec![FusedImu::default(); IMU_KEPT].into_boxed_slice(),
            len: 0,
            next: 0,
        }
    }
}

impl Handover {
    /// A sample of the peer lane (they arrive in sequence order; the newest one counts).
    pub fn push_peer(&mut self, peer: NavState) {
        self.peer = Some(peer);
    }

    /// A fused IMU sample this lane received.
    pub fn push_imu(&mut self, imu: FusedImu) {
        self.imu[self.next] = imu;
        self.next = (self.next + 1) % IMU_KEPT;
        self.len = (self.len + 1).min(IMU_KEPT);
    }

    fn kept(&self) -> impl Iterator<Item = &FusedImu> {
        let start = (self.next + IMU_KEPT - self.len) % IMU_KEPT;
        (0..self.len).map(move |k| &self.imu[(start + k) % IMU_KEPT])
    }

    /// The peer sample to take over from, when there is a trusted one and this lane holds every
    /// fused IMU sample it received after it (none of them fell out of the ring): then the
    /// samples of [`Handover::replay`] bring the taken-over solution up to date.
    pub fn ready(&self) -> Option<NavState> {
        let peer = self.peer?;
        peer_solution(&peer).ok()?;
        let seq = peer.header.origin_seq;
        let oldest = self.kept().next().map(|s| s.header.origin_seq);
        // The ring must reach back to the sample after the peer's (or the peer is ahead of
        // everything we received).
        oldest.is_none_or(|o| o <= seq + 1).then_some(peer)
    }

    /// The kept samples after `seq`, in order.
    pub fn replay(&self, seq: u64) -> impl Iterator<Item = &FusedImu> {
        self.kept().filter(move |s| s.header.origin_seq > seq)
    }

    /// Forgets everything (after a takeover, or once aligned by itself).
    pub fn clear(&mut self) {
        self.peer = None;
        self.len = 0;
        self.next = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SETTLE: u64 = 2000;

    fn peer(seq: u64, start: u64) -> NavState {
        let mut s = NavState {
            mode: NavMode::Navigating as u8,
            solution_start_seq: start,
            quaternion: [0.5f64.sqrt(), 0.0, 0.0, 0.5f64.sqrt()],
            velocity_ned_mps: [10.0, -2.0, 0.5],
            latitude_rad: 0.8,
            longitude_rad: 0.15,
            altitude_m: 500.0,
            gyro_bias_rps: [1e-3, -2e-3, 3e-3],
            accel_bias_mps2: [0.01, 0.02, -0.03],
            covariance_diag: [1e-4; NAV_STATES],
            ..NavState::default()
        };
        s.header.origin_seq = seq;
        s.header.origin_device_time_us = seq * 1000;
        s
    }

    fn imu(seq: u64) -> FusedImu {
        let mut s = FusedImu::default();
        s.header.origin_seq = seq;
        s
    }

    #[test]
    fn a_settled_peer_is_read_exactly() {
        let p = peer(5000, 1000);
        let sol = peer_solution(&p).unwrap();
        assert_eq!(sol.device_time_us, 5_000_000);
        assert_eq!(sol.state.velocity_ned, Vector3::new(10.0, -2.0, 0.5));
        assert_eq!(
            (sol.state.lat, sol.state.lon, sol.state.alt),
            (0.8, 0.15, 500.0)
        );
        assert!((sol.state.attitude.euler_angles().2 - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(sol.bias.gyro_rps, Vector3::new(1e-3, -2e-3, 3e-3));
        assert_eq!(sol.covariance_diag, [1e-4; NAV_STATES]);
    }

    #[test]
    fn bad_or_young_peers_are_refused_naming_why() {
        assert_eq!(
            peer_solution(&peer(2999, 1000)),
            Err(TakeOverError::NotSettled {
                seq: 2999,
                start: 1000
            })
        );
        assert_eq!(
            peer_solution(&NavState {
                mode: NavMode::Aligning as u8,
                ..peer(5000, 1)
            }),
            Err(TakeOverError::NotNavigating(0))
        );
        let mut p = peer(5000, 1);
        p.velocity_ned_mps[1] = f64::NAN;
        assert_eq!(peer_solution(&p), Err(TakeOverError::NotFinite("velocity")));
        let mut p = peer(5000, 1);
        p.quaternion = [1.0, 0.1, 0.0, 0.0];
        assert!(matches!(peer_solution(&p), Err(TakeOverError::NotUnit(_))));
        let mut p = peer(5000, 1);
        p.covariance_diag[7] = -1.0;
        assert_eq!(
            peer_solution(&p),
            Err(TakeOverError::BadVariance {
                index: 7,
                value: -1.0
            })
        );
        assert_eq!(SelectorConfig::default().settle, SETTLE);
    }

    #[test]
    fn the_handover_needs_every_sample_after_the_peer() {
        let mut h = Handover::default();
        assert_eq!(h.ready(), None);
        for seq in 3000..3010 {
            h.push_imu(imu(seq));
        }
        // Peer at 3005: samples 3006..3009 are held, replayed in order.
        h.push_peer(peer(3005, 1));
        assert_eq!(h.ready().map(|p| p.header.origin_seq), Some(3005));
        let replayed: Vec<u64> = h.replay(3005).map(|s| s.header.origin_seq).collect();
        assert_eq!(replayed, [3006, 3007, 3008, 3009]);
        // A peer older than everything kept: samples in between are missing, no takeover.
        h.push_peer(peer(2990, 1));
        assert_eq!(h.ready(), None);
        // A peer ahead of everything received: take over, nothing to replay.
        h.push_peer(peer(3020, 1));
        assert_eq!(h.ready().map(|p| p.header.origin_seq), Some(3020));
        assert_eq!(h.replay(3020).count(), 0);
        // The ring keeps the newest IMU_KEPT samples.
        for seq in 3010..3010 + IMU_KEPT as u64 {
            h.push_imu(imu(seq));
        }
        assert_eq!(h.kept().next().map(|s| s.header.origin_seq), Some(3010));
        h.clear();
        assert_eq!(h.ready(), None);
    }
}
