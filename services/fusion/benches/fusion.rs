//! One fusion step (calibration + health checks + parity test + WLS, both sensor types) on
//! pre-generated noisy frames. Target: ≥ 2 M steps/s for N = 4 in release.
//!
//! Measured (release, 2-vCPU AMD EPYC VM): N = 4 pyramid 260 ns/step (3.84 M steps/s);
//! N = 6 dodecahedron 370 ns (2.71 M/s); N = 4 with adaptive parity noise 294 ns (3.40 M/s).

// `criterion_group!` generates `pub fn benches` and takes no attributes, so no doc can be attached
// to it; nothing else in this benchmark binary is public.
#![allow(missing_docs)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rins_fusion::{FusionConfig, GeometryConfig, ImuFuser};
use std::hint::black_box;

const GYRO_LSB: f64 = 300.0 * std::f64::consts::PI / 180.0 / 2048.0;
const ACCEL_LSB: f64 = 8.0 * 9.80665 / 2048.0;
const FRAMES: usize = 4096;

/// Noisy counts of a slowly rotating block (never stationary, no faults).
fn frames(fuser: &ImuFuser) -> Vec<(Vec<i16>, Vec<i16>)> {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut counts = |axes: &[[f64; 3]], x: [f64; 3], sigma: f64, lsb: f64| -> Vec<i16> {
        axes.iter()
            .map(|h| {
                let n: f64 = StandardNormal.sample(&mut rng);
                let v = h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + sigma * n;
                (v / lsb).round().clamp(-2048.0, 2047.0) as i16
            })
            .collect()
    };
    (0..FRAMES)
        .map(|k| {
            let t = k as f64 * 1e-3;
            let rate = [0.5 * (3.0 * t).sin(), 0.2, -0.1];
            let force = [0.3, -0.2, -9.8];
            (
                counts(fuser.gyro_geometry().axes(), rate, 0.005519, GYRO_LSB),
                counts(fuser.accel_geometry().axes(), force, 0.046517, ACCEL_LSB),
            )
        })
        .collect()
}

fn bench_step(c: &mut Criterion, name: &str, cfg: &FusionConfig) {
    let mut fuser = ImuFuser::new(cfg, GYRO_LSB, ACCEL_LSB).unwrap();
    let data = frames(&fuser);
    let n = fuser.gyro_geometry().n();
    let mask = ((1u32 << n) - 1) | (((1u32 << n) - 1) << 16);
    let mut group = c.benchmark_group("fusion_step");
    group.throughput(Throughput::Elements(1));
    let mut k = 0;
    group.bench_function(name, |b| {
        b.iter(|| {
            let (g, a) = &data[k % FRAMES];
            k += 1;
            black_box(fuser.fuse(black_box(g), black_box(a), mask))
        })
    });
    group.finish();
    // The bench must have run fault-free, or it measured the wrong path.
    assert_eq!(
        fuser
            .monitor(ipc_types::SensorType::Gyro)
            .active_mask()
            .count_ones() as usize,
        n
    );
}

fn fusion(c: &mut Criterion) {
    bench_step(c, "n4_pyramid", &FusionConfig::default());
    let mut six = FusionConfig::default();
    six.geometry.gyro = GeometryConfig::Dodecahedron {};
    six.geometry.accel = GeometryConfig::Dodecahedron {};
    bench_step(c, "n6_dodecahedron", &six);
    let mut adaptive = FusionConfig::default();
    adaptive.fdi.parity_noise = rins_fusion::ParityNoise::Adaptive;
    bench_step(c, "n4_pyramid_adaptive", &adaptive);
}

criterion_group!(benches, fusion);
criterion_main!(benches);
