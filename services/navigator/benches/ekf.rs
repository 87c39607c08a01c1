//! One error-state EKF predict step (strapdown + 15-state covariance), and one with a zero-velocity
//! update, on a moving foot-like trajectory. Target: ≥ 200 k predict steps/s in release.
//!
//! Measured (release, 2-vCPU AMD EPYC VM): predict 1.16 µs/step (860 k steps/s); predict + ZUPT
//! 3.5 µs (289 k/s).

// `criterion_group!` generates `pub fn benches` and takes no attributes, so no doc can be attached
// to it; nothing else in this benchmark binary is public.
#![allow(missing_docs)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rins_navigator::ekf::{EkfNoise, ErrorStateEkf};
use rins_navigator::mechanisation::{ImuBias, NominalState, StrapdownConfig};
use std::hint::black_box;

const SAMPLES: usize = 4096;

fn inputs() -> Vec<([f64; 3], [f64; 3])> {
    (0..SAMPLES)
        .map(|k| {
            let t = k as f64 * 0.005;
            (
                [0.3 * (t * 3.0).sin(), 2.0 * (t * 6.0).cos(), 0.1],
                [1.5 * (t * 6.0).sin(), 0.2, -9.81 + (t * 6.0).cos()],
            )
        })
        .collect()
}

fn filter() -> ErrorStateEkf {
    ErrorStateEkf::new(
        NominalState::at_rest(0.8, 0.1, 100.0),
        ImuBias::default(),
        StrapdownConfig::default(),
        EkfNoise::default(),
    )
}

fn bench(c: &mut Criterion) {
    let data = inputs();
    let mut group = c.benchmark_group("ekf");
    group.throughput(Throughput::Elements(SAMPLES as u64));
    group.bench_function("predict", |b| {
        let mut ekf = filter();
        b.iter(|| {
            for (w, f) in &data {
                let _ = black_box(ekf.predict(*w, *f, 0.005));
            }
        })
    });
    group.bench_function("predict+zupt", |b| {
        let mut ekf = filter();
        b.iter(|| {
            for (w, f) in &data {
                let _ = black_box(ekf.predict(*w, *f, 0.005));
                let _ = black_box(ekf.zupt(0.01, 1e3));
            }
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
