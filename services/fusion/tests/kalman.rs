//! Kalman fuser: equivalence with the full N-channel filter, start-up, tracking of its own model,
//! channel changes, missing data, configuration.

use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::Normal;
use rins_fusion::kalman::{
    FusionMethod, KalmanConfig, KalmanError, KalmanFuser, KalmanProcessNoise,
};
use rins_fusion::{Geometry, GeometryConfig, WlsError, WlsSolver};

const DT: f64 = 0.001;

fn seed_pyramid() -> Geometry {
    GeometryConfig::seed_pyramid().build().unwrap()
}

/// Textbook Kalman filter on the raw channels: z (N) = [H 0] x + ε, R = diag(σ²), 6×6 P, with
/// the same two-point start (from its own least-squares estimates of the first two samples).
struct FullFilter {
    h: DMatrix<f64>,
    r: DMatrix<f64>,
    f: DMatrix<f64>,
    q: DMatrix<f64>,
    x: DVector<f64>,
    p: DMatrix<f64>,
    first: Option<DVector<f64>>,
    started: bool,
}

impl FullFilter {
    fn new(axes: &[[f64; 3]], variances: &[f64], q: f64) -> Self {
        let n = axes.len();
        let mut h = DMatrix::zeros(n, 6);
        for (i, a) in axes.iter().enumerate() {
            for c in 0..3 {
                h[(i, c)] = a[c];
            }
        }
        let mut f = DMatrix::identity(6, 6);
        let mut qm = DMatrix::zeros(6, 6);
        for k in 0..3 {
            f[(k, k + 3)] = DT;
            qm[(k, k)] = q * DT.powi(3) / 3.0;
            qm[(k, k + 3)] = q * DT * DT / 2.0;
            qm[(k + 3, k)] = q * DT * DT / 2.0;
            qm[(k + 3, k + 3)] = q * DT;
        }
        Self {
            h,
            r: DMatrix::from_diagonal(&DVector::from_column_slice(variances)),
            f,
            q: qm,
            x: DVector::zeros(6),
            p: DMatrix::zeros(6, 6),
            first: None,
            started: false,
        }
    }

    /// Least-squares estimate and its covariance from the rate columns of H.
    fn wls(&self, z: &DVector<f64>) -> (DVector<f64>, DMatrix<f64>) {
        let h = self.h.columns(0, 3).into_owned();
        let w = self.r.clone().try_inverse().unwrap();
        let c = (h.transpose() * &w * &h).try_inverse().unwrap();
        (&c * h.transpose() * w * z, c)
    }

    fn update(&mut self, z: &[f64]) -> [f64; 3] {
        let z = DVector::from_column_slice(z);
        if !self.started {
            let (y, c) = self.wls(&z);
            match self.first.take() {
                None => {
                    self.first = Some(y.clone());
                    return [y[0], y[1], y[2]];
                }
                Some(y1) => {
                    self.x.rows_mut(0, 3).copy_from(&y);
                    self.x.rows_mut(3, 3).copy_from(&((&y - y1) / DT));
                    self.p.view_mut((0, 0), (3, 3)).copy_from(&c);
                    self.p.view_mut((0, 3), (3, 3)).copy_from(&(&c / DT));
                    self.p.view_mut((3, 0), (3, 3)).copy_from(&(&c / DT));
                    self.p
                        .view_mut((3, 3), (3, 3))
                        .copy_from(&(&c * (2.0 / (DT * DT))));
                    self.p += &self.q;
                    self.started = true;
                    return [y[0], y[1], y[2]];
                }
            }
        }
        self.x = &self.f * &self.x;
        self.p = &self.f * &self.p * self.f.transpose() + &self.q;
        let s = &self.h * &self.p * self.h.transpose() + &self.r;
        let k = &self.p * self.h.transpose() * s.try_inverse().unwrap();
        self.x += &k * (z - &self.h * &self.x);
        self.p = (DMatrix::identity(6, 6) - &k * &self.h) * &self.p;
        [self.x[0], self.x[1], self.x[2]]
    }
}

#[test]
fn equals_the_full_channel_filter_at_every_sample() {
    // A skewed 7-axis layout with unequal channel noise and one channel excluded, so that C is
    // full (coupled axes) and the reduction to the WLS estimate is really exercised.
    let axes = [
        [1.0, 0.2, 0.1],
        [0.1, 1.0, -0.3],
        [0.3, -0.2, 1.0],
        [0.7, 0.7, 0.2],
        [-0.5, 0.6, 0.6],
        [0.4, -0.8, 0.5],
        [0.9, 0.1, -0.6],
    ];
    let g = Geometry::from_axes(&axes).unwrap();
    let sigmas = [0.004, 0.006, 0.005, 0.009, 0.003, 0.007, 0.005];
    let variances: Vec<f64> = sigmas.iter().map(|s| s * s).collect();
    let mask = 0b1110111;
    let active: Vec<usize> = (0..7).filter(|i| mask & (1 << i) != 0).collect();
    let q = 40.0;
    let mut kf = KalmanFuser::new(&g, mask, &variances, DT, q).unwrap();
    let active_axes: Vec<[f64; 3]> = active.iter().map(|&i| g.axes()[i]).collect();
    let active_vars: Vec<f64> = active.iter().map(|&i| variances[i]).collect();
    let mut full = FullFilter::new(&active_axes, &active_vars, q);
    let mut steady_from = None;

    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let unit = Normal::new(0.0, 1.0).unwrap();
    let mut z = [f64::NAN; 16];
    for k in 0..3000 {
        let t = k as f64 * DT;
        let x = [(7.0 * t).sin(), 0.3 * t, (2.0 * t).cos() - 1.0];
        for &i in &active {
            let h = g.axes()[i];
            z[i] = h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + sigmas[i] * rng.sample(unit);
        }
        // The excluded channel holds garbage that must never be read.
        z[3] = f64::NAN;
        let (ours, _) = kf.update(&z);
        let zs: Vec<f64> = active.iter().map(|&i| z[i]).collect();
        let theirs = full.update(&zs);
        if kf.is_steady() && steady_from.is_none() {
            steady_from = Some(k);
        }
        for a in 0..3 {
            assert!(
                (ours[a] - theirs[a]).abs() < 1e-10,
                "sample {k} axis {a}: {} vs {}",
                ours[a],
                theirs[a]
            );
        }
    }
    // Most of the run used the frozen steady-state gain.
    let steady_from = steady_from.expect("covariance never converged");
    assert!(steady_from < 1000, "{steady_from}");
    let (_, var) = kf.estimate();
    for (a, v) in var.iter().enumerate() {
        assert!((v - full.p[(a, a)]).abs() < 1e-9 * full.p[(a, a)]);
    }
}

#[test]
fn starts_as_least_squares_then_differences_for_the_derivative() {
    let g = seed_pyramid();
    let variances = [1e-4; 4];
    let wls = WlsSolver::new(&g, g.full_mask(), &variances).unwrap();
    let mut kf = KalmanFuser::new(&g, g.full_mask(), &variances, DT, 10.0).unwrap();
    let z1 = [0.1, -0.2, 0.3, 0.05];
    let z2 = [0.11, -0.19, 0.32, 0.06];
    let (y1, c) = wls.solve(&z1);
    let (y2, _) = wls.solve(&z2);
    assert_eq!(kf.update(&z1), (y1, c));
    let (x2, v2) = kf.update(&z2);
    assert_eq!(x2, y2);
    for a in 0..3 {
        // C plus one step of process noise, q·dt³/3.
        assert!((v2[a] - (c[a] + 10.0 * DT.powi(3) / 3.0)).abs() < 1e-15);
    }
    let (d, dvar) = kf.derivative();
    for a in 0..3 {
        assert!((d[a] - (y2[a] - y1[a]) / DT).abs() < 1e-9);
        // 2C/dt² plus one step of process noise.
        assert!((dvar[a] - (2.0 * c[a] / (DT * DT) + 10.0 * DT)).abs() < 1e-9 * dvar[a]);
    }
    // From the third sample on it filters: the variance drops below the least-squares one.
    let (_, v3) = kf.update(&z2);
    assert!((0..3).all(|a| v3[a] < c[a]), "{v3:?} vs {c:?}");
    // Reset starts over.
    kf.reset();
    assert_eq!(kf.estimate(), ([0.0; 3], [0.0; 3]));
    assert_eq!(kf.update(&z1), (y1, c));
}

#[test]
fn tracks_a_ramp_without_steady_state_error() {
    // The model's own motion (constant derivative) is followed exactly once the start-up decays.
    let g = seed_pyramid();
    let mut kf = KalmanFuser::new(&g, g.full_mask(), &[1e-4; 4], DT, 10.0).unwrap();
    let slope = [2.0, -1.0, 0.5];
    let mut z = [0.0; 4];
    let mut est = [0.0; 3];
    for k in 0..2000 {
        let t = k as f64 * DT;
        let x = slope.map(|s| 0.2 + s * t);
        for (zi, h) in z.iter_mut().zip(g.axes()) {
            *zi = h[0] * x[0] + h[1] * x[1] + h[2] * x[2];
        }
        est = kf.update(&z).0;
        if k == 1999 {
            for a in 0..3 {
                assert!((est[a] - x[a]).abs() < 1e-9, "{est:?} vs {x:?}");
            }
        }
    }
    let (d, _) = kf.derivative();
    for a in 0..3 {
        assert!((d[a] - slope[a]).abs() < 1e-6, "{d:?}");
    }
    assert!(est.iter().all(|v| v.is_finite()));
}

#[test]
fn channel_change_keeps_the_state() {
    let g = GeometryConfig::Dodecahedron {}.build().unwrap();
    let variances = [1e-4; 6];
    let mut kf = KalmanFuser::new(&g, g.full_mask(), &variances, DT, 10.0).unwrap();
    let x = [0.4, -0.3, 0.2];
    let z: Vec<f64> = g
        .axes()
        .iter()
        .map(|h| h[0] * x[0] + h[1] * x[1] + h[2] * x[2])
        .collect();
    for _ in 0..1000 {
        kf.update(&z);
    }
    let (before, var_before) = kf.estimate();
    assert!(kf.is_steady());
    kf.set_channels(&g, 0b011111, &variances).unwrap();
    assert!(!kf.is_steady());
    assert_eq!(kf.mask(), 0b011111);
    assert_eq!(kf.estimate(), (before, var_before));
    let mut z5 = z.clone();
    z5[5] = f64::NAN;
    let (after, _) = kf.update(&z5);
    for a in 0..3 {
        assert!((after[a] - x[a]).abs() < 1e-9);
    }
    // Fewer channels: the steady-state variance rises towards the 5-channel figure.
    let mut var = [0.0; 3];
    for _ in 0..1000 {
        var = kf.update(&z5).1;
    }
    assert!(
        (0..3).any(|a| var[a] > var_before[a] * 1.01),
        "{var:?} vs {var_before:?}"
    );
    // A set that cannot be solved is refused and leaves the fuser as it was.
    let snapshot = kf;
    assert_eq!(
        kf.set_channels(&g, 0b11, &variances),
        Err(KalmanError::Channels(WlsError::InsufficientChannels {
            mask: 0b11,
            active: 2
        }))
    );
    assert_eq!(kf, snapshot);
}

#[test]
fn unusable_samples_only_predict() {
    let g = seed_pyramid();
    let mut kf = KalmanFuser::new(&g, g.full_mask(), &[1e-4; 4], DT, 10.0).unwrap();
    // Before any usable sample a NaN is passed through and leaves the state empty.
    let (x, _) = kf.update(&[f64::NAN; 4]);
    assert!(x[0].is_nan());
    assert_eq!(kf.estimate(), ([0.0; 3], [0.0; 3]));
    let z = [0.1, 0.2, 0.3, 0.4];
    for _ in 0..100 {
        kf.update(&z);
    }
    let (x0, v0) = kf.estimate();
    let (d0, _) = kf.derivative();
    let (x1, v1) = kf.update(&[0.1, f64::NAN, 0.3, 0.4]);
    assert!(!kf.is_steady());
    for a in 0..3 {
        assert!((x1[a] - (x0[a] + d0[a] * DT)).abs() < 1e-12);
        assert!(v1[a] > v0[a]);
    }
    // A short slice is missing data too.
    let (x2, _) = kf.update(&z[..3]);
    assert!(x2.iter().all(|v| v.is_finite()));
}

#[test]
fn constructor_rejects_bad_inputs() {
    let g = seed_pyramid();
    let ok = [1e-4; 4];
    assert_eq!(
        KalmanFuser::new(&g, 0xF, &ok, 0.0, 1.0).unwrap_err(),
        KalmanError::SamplePeriod(0.0)
    );
    assert_eq!(
        KalmanFuser::new(&g, 0xF, &ok, DT, f64::NAN)
            .unwrap_err()
            .to_string(),
        "process noise = NaN: must be finite and > 0"
    );
    assert_eq!(
        KalmanFuser::new(&g, 0xF, &ok[..3], DT, 1.0).unwrap_err(),
        KalmanError::Channels(WlsError::VarianceCount {
            expected: 4,
            given: 3
        })
    );
    assert_eq!(
        KalmanFuser::new(&g, 0xF, &ok, 2.0, 1.0)
            .unwrap_err()
            .to_string(),
        "sample period = 2 s: must be in 1e-5..=1 s"
    );
}

#[test]
fn method_and_config_parse_and_validate() {
    #[derive(serde::Deserialize)]
    struct Holder {
        #[serde(default)]
        method: FusionMethod,
        #[serde(default)]
        kalman: KalmanConfig,
    }
    let h: Holder = toml::from_str("").unwrap();
    assert_eq!(h.method, FusionMethod::Wls);
    assert_eq!(h.kalman, KalmanConfig::default());
    h.kalman.validate().unwrap();
    let h: Holder =
        toml::from_str("method = \"kalman\"\n[kalman.process_noise]\ngyro = 3.5\n").unwrap();
    assert_eq!(h.method, FusionMethod::Kalman);
    assert_eq!(
        h.kalman,
        KalmanConfig {
            process_noise: KalmanProcessNoise {
                gyro: 3.5,
                accel: KalmanProcessNoise::default().accel
            },
        }
    );
    assert!(toml::from_str::<Holder>("method = \"ekf\"").is_err());
    assert!(toml::from_str::<Holder>("[kalman]\nprocess_nois = 1").is_err());

    let mut bad = KalmanConfig::default();
    bad.process_noise.accel = -1.0;
    assert_eq!(
        bad.validate().unwrap_err().to_string(),
        "process_noise.accel = -1: must be finite and > 0"
    );
    // The period is the IMU's, not a key: a file that still states it is refused.
    assert!(toml::from_str::<Holder>("[kalman]\nsample_period_s = 0.002").is_err());
}

proptest! {
    #[test]
    fn constant_input_converges_to_it(
        x in prop::array::uniform3(-5.0..5.0f64),
        q in 0.1..1e4f64,
        sigma in 1e-3..0.1f64,
    ) {
        let g = seed_pyramid();
        let mut kf = KalmanFuser::new(&g, g.full_mask(), &[sigma * sigma; 4], DT, q).unwrap();
        let z: Vec<f64> = g.axes().iter().map(|h| h[0] * x[0] + h[1] * x[1] + h[2] * x[2]).collect();
        let mut est = ([0.0; 3], [0.0; 3]);
        for _ in 0..3000 {
            est = kf.update(&z);
        }
        let wls_var = g.variance_factors().map(|f| f * sigma * sigma);
        for a in 0..3 {
            prop_assert!((est.0[a] - x[a]).abs() < 1e-9, "{:?} vs {x:?}", est.0);
            prop_assert!(est.1[a] > 0.0 && est.1[a] < wls_var[a]);
        }
    }
}
