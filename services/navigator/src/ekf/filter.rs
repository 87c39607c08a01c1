//! The filter: covariance prediction on each IMU sample, gated Joseph-form updates, injection.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

use super::noise::EkfNoise;
use super::prediction::PredictionRecord;
use super::{ATT, BA, BG, Covariance, POS, STATES, VEL};
use crate::attitude::{rotation_vector_to_quaternion, wrap_pi};
use crate::mechanisation::{ImuBias, NominalState, StepOutcome, Strapdown, StrapdownConfig};
use rins_earth::{meridian_radius, prime_vertical_radius};

/// Smallest `cos φ` used when turning an east error into longitude.
const MIN_COS_LATITUDE: f64 = 1e-6;

/// Where a measurement comes from, for the accepted/rejected counts: the sources of the
/// navigation state's aiding bits and per-source counts, listed once in `ipc_types::aiding`.
pub use ipc_types::aiding::AidingSourceId as AidingSource;

/// Measurements of one source that passed and failed the innovation gate.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AidingCounts {
    /// Measurements applied.
    pub accepted: u64,
    /// Measurements outside the gate (or with a non-finite innovation), not applied.
    pub rejected: u64,
}

/// What became of one measurement.
#[must_use]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum UpdateOutcome {
    /// Applied; `d2` is the innovation's squared Mahalanobis distance.
    Accepted {
        /// Squared Mahalanobis distance of the innovation.
        d2: f64,
    },
    /// Outside the gate (or not finite): not applied.
    Rejected {
        /// Squared Mahalanobis distance of the innovation (may be NaN or infinite).
        d2: f64,
    },
    /// The innovation covariance was not positive definite: not applied.
    Singular,
}

impl UpdateOutcome {
    /// Whether the measurement was applied.
    pub fn is_accepted(self) -> bool {
        matches!(self, UpdateOutcome::Accepted { .. })
    }
}

/// Every correction the filter has injected into the position and velocity so far, on its own
/// clock: what a state remembered from the past lacks to be corrected like the present one (see
/// [`crate::state_history`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CorrectionTotals {
    /// Time the filter has propagated, s (the sum of the applied steps).
    pub elapsed_s: f64,
    /// Sum of the position corrections, NED m.
    pub position_ned_m: Vector3<f64>,
    /// Sum of the velocity corrections, NED m/s.
    pub velocity_ned_mps: Vector3<f64>,
    /// Sum of each velocity correction times the elapsed time it was made at, NED m·s/s.
    pub velocity_time: Vector3<f64>,
}

/// Error-state EKF around a [`Strapdown`] mechanisation. Allocation-free.
#[derive(Debug, Clone)]
pub struct ErrorStateEkf {
    strapdown: Strapdown,
    p: Covariance,
    noise: EkfNoise,
    counts: [AidingCounts; AidingSource::COUNT],
    corrections: CorrectionTotals,
    last_prediction: PredictionRecord,
}

/// `[v×]`, the matrix of `x ↦ v × x`.
pub(crate) fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// `F · m` for the error dynamics of the module docs, using only its non-zero blocks:
/// rows δθ = −C·m[δb_g], rows δv = −[fⁿ×]·m[δθ] − C·m[δb_a], rows δp = m[δv].
fn f_times(m: &Covariance, c: &Matrix3<f64>, f_skew: &Matrix3<f64>) -> Covariance {
    let mut out = Covariance::zeros();
    out.fixed_rows_mut::<3>(ATT)
        .copy_from(&(-c * m.fixed_rows::<3>(BG)));
    out.fixed_rows_mut::<3>(VEL)
        .copy_from(&(-f_skew * m.fixed_rows::<3>(ATT) - c * m.fixed_rows::<3>(BA)));
    out.fixed_rows_mut::<3>(POS)
        .copy_from(&m.fixed_rows::<3>(VEL));
    out
}

impl ErrorStateEkf {
    /// Starts from `state` and `bias` with the initial uncertainty of `noise`.
    pub fn new(
        state: NominalState,
        bias: ImuBias,
        strapdown: StrapdownConfig,
        noise: EkfNoise,
    ) -> Self {
        let diagonal = SVector::<f64, STATES>::from(noise.initial_variances());
        Self {
            strapdown: Strapdown::new(state, bias, strapdown),
            p: Covariance::from_diagonal(&diagonal),
            noise,
            counts: [AidingCounts::default(); AidingSource::COUNT],
            corrections: CorrectionTotals::default(),
            last_prediction: PredictionRecord::default(),
        }
    }

    /// The corrections injected so far, on the filter's own clock.
    pub fn corrections(&self) -> &CorrectionTotals {
        &self.corrections
    }

    /// The nominal state: attitude, velocity and position.
    pub fn state(&self) -> &NominalState {
        self.strapdown.state()
    }

    /// The nominal state, to initialise it from a reference (e.g. the truth at the start of a
    /// recording); the covariance is left as it is.
    pub fn state_mut(&mut self) -> &mut NominalState {
        self.strapdown.state_mut()
    }

    /// The current gyro and accelerometer bias estimates, body FRD.
    pub fn bias(&self) -> &ImuBias {
        self.strapdown.bias()
    }

    /// Replaces the bias estimate (the covariance is left as it is).
    pub fn set_bias(&mut self, bias: ImuBias) {
        *self.strapdown.bias_mut() = bias;
    }

    /// The mechanisation the filter wraps, with its nominal state and biases.
    pub fn strapdown(&self) -> &Strapdown {
        &self.strapdown
    }

    /// The 15×15 error-state covariance, its blocks starting at [`super::ATT`], [`super::VEL`],
    /// [`super::POS`], [`super::BG`] and [`super::BA`].
    pub fn covariance(&self) -> &Covariance {
        &self.p
    }

    /// Forgets what the filter knew about error component `i`: its correlations with every other
    /// component are dropped and its variance set to `variance`. Used when a state is re-set from a
    /// measurement (the altitude from a baro reading after an outage).
    pub fn reset_component(&mut self, i: usize, variance: f64) {
        if i >= STATES {
            return;
        }
        for k in 0..STATES {
            self.p[(i, k)] = 0.0;
            self.p[(k, i)] = 0.0;
        }
        self.p[(i, i)] = variance;
    }

    /// Adds `variance` to error component `i`'s variance, its correlations kept: an error source
    /// the propagation does not model (a fault fusion has not isolated yet) widened it.
    pub fn inflate_component(&mut self, i: usize, variance: f64) {
        if i < STATES && variance.is_finite() && variance > 0.0 {
            self.p[(i, i)] += variance;
        }
    }

    /// Replaces the covariance by the diagonal `variances` (correlations dropped): a filter that
    /// takes over another's solution knows its uncertainties but not their correlations.
    pub fn set_covariance_diagonal(&mut self, variances: &[f64; STATES]) {
        self.p = Covariance::from_diagonal(&SVector::<f64, STATES>::from_column_slice(variances));
    }

    /// Standard deviation of error component `i`.
    pub fn sigma(&self, i: usize) -> f64 {
        self.p[(i, i)].max(0.0).sqrt()
    }

    /// Accepted and rejected measurements of `source` since the filter started.
    pub fn counts(&self, source: AidingSource) -> AidingCounts {
        self.counts[source as usize]
    }

    /// Propagates the nominal state by one IMU sample (see [`Strapdown::propagate`]) and the
    /// covariance with it. The covariance is only predicted when the step was applied.
    pub fn predict(
        &mut self,
        rate_rps: [f64; 3],
        specific_force: [f64; 3],
        dt_s: f64,
    ) -> StepOutcome {
        let c = self
            .strapdown
            .state()
            .attitude
            .to_rotation_matrix()
            .into_inner();
        let outcome = self.strapdown.propagate(rate_rps, specific_force, dt_s);
        if !outcome.is_applied() {
            return outcome;
        }
        let f_skew = skew(&self.strapdown.specific_force_ned());
        // Φ P Φᵀ with Φ = I + F Δt, expanded so that only F's non-zero blocks are multiplied.
        let fp = f_times(&self.p, &c, &f_skew);
        let fpft = f_times(&fp.transpose(), &c, &f_skew).transpose();
        let mut p = self.p + (fp + fp.transpose()) * dt_s + fpft * (dt_s * dt_s);
        let n = &self.noise;
        let q = [
            (ATT, n.gyro_noise_density),
            (VEL, n.accel_noise_density),
            (BG, n.gyro_bias_walk),
            (BA, n.accel_bias_walk),
        ];
        // G Q Gᵀ: the white noises enter through ±C, and C σ² I Cᵀ = σ² I.
        for (start, density) in q {
            for i in start..start + 3 {
                p[(i, i)] += density * density * dt_s;
            }
        }
        self.p = (p + p.transpose()) * 0.5;
        self.corrections.elapsed_s += dt_s;
        self.last_prediction = PredictionRecord {
            c,
            f_skew,
            dt_s,
            prior: self.p,
            injected: SVector::zeros(),
        };
        outcome
    }

    /// The innovation covariance `H P Hᵀ + R` of a measurement and the innovation's squared
    /// Mahalanobis distance; `None` when it is not positive definite. Nothing is applied: a
    /// monitor judges a measurement with it before (or instead of) [`Self::update`].
    pub fn innovation_test<const M: usize>(
        &self,
        h: &SMatrix<f64, M, STATES>,
        innovation: &SVector<f64, M>,
        r: &SMatrix<f64, M, M>,
    ) -> Option<(SMatrix<f64, M, M>, f64)> {
        let s = h * self.p * h.transpose() + r;
        let chol = s.cholesky()?;
        Some((s, innovation.dot(&chol.solve(innovation))))
    }

    /// Applies measurement `innovation = z − h(x̂)` with Jacobian `h` and noise `r` when its
    /// squared Mahalanobis distance is at most `gate²`; counts it for `source`.
    pub fn update<const M: usize>(
        &mut self,
        source: AidingSource,
        h: &SMatrix<f64, M, STATES>,
        innovation: &SVector<f64, M>,
        r: &SMatrix<f64, M, M>,
        gate: f64,
    ) -> UpdateOutcome {
        let ph = self.p * h.transpose();
        let s = h * ph + r;
        let Some(chol) = s.cholesky() else {
            self.counts[source as usize].rejected += 1;
            return UpdateOutcome::Singular;
        };
        let d2 = innovation.dot(&chol.solve(innovation));
        if d2.is_nan() || d2 > gate * gate {
            self.counts[source as usize].rejected += 1;
            return UpdateOutcome::Rejected { d2 };
        }
        // K = P Hᵀ S⁻¹, from Kᵀ = S⁻¹ H P (S and P symmetric).
        let k = chol.solve(&ph.transpose()).transpose();
        let dx = k * innovation;
        let i_kh = Covariance::identity() - k * h;
        let p = i_kh * self.p * i_kh.transpose() + k * r * k.transpose();
        self.p = (p + p.transpose()) * 0.5;
        self.inject(&dx);
        self.counts[source as usize].accepted += 1;
        UpdateOutcome::Accepted { d2 }
    }

    /// The last prediction and the corrections since, for a smoother over the filter's history.
    pub fn last_prediction(&self) -> &PredictionRecord {
        &self.last_prediction
    }

    /// Moves the estimated error into the nominal state and biases (the error resets to zero).
    fn inject(&mut self, dx: &SVector<f64, STATES>) {
        self.last_prediction.injected += dx;
        let d_theta = Vector3::new(dx[ATT], dx[ATT + 1], dx[ATT + 2]);
        let d_v = Vector3::new(dx[VEL], dx[VEL + 1], dx[VEL + 2]);
        let s = self.strapdown.state_mut();
        let mut q = rotation_vector_to_quaternion(&d_theta) * s.attitude;
        q.renormalize();
        s.attitude = q;
        s.velocity_ned += d_v;
        let d_p = Vector3::new(dx[POS], dx[POS + 1], dx[POS + 2]);
        let totals = &mut self.corrections;
        totals.position_ned_m += d_p;
        totals.velocity_ned_mps += d_v;
        totals.velocity_time += d_v * totals.elapsed_s;
        let cos_lat = s.lat.cos().max(MIN_COS_LATITUDE);
        s.lat = (s.lat + dx[POS] / (meridian_radius(s.lat) + s.alt))
            .clamp(-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2);
        s.lon = wrap_pi(s.lon + dx[POS + 1] / ((prime_vertical_radius(s.lat) + s.alt) * cos_lat));
        s.alt -= dx[POS + 2];
        let b = self.strapdown.bias_mut();
        b.gyro_rps += Vector3::new(dx[BG], dx[BG + 1], dx[BG + 2]);
        b.accel_mps2 += Vector3::new(dx[BA], dx[BA + 1], dx[BA + 2]);
    }
}
