//! `rins geometry`: what the configured sensor geometries can do — noise amplification per axis,
//! parity dimension, and whether a failed channel can be detected, isolated, and a second one tolerated.

use anyhow::{Result, anyhow};
use rins_fusion::GeometryConfig;
use rins_fusion::capability::Capability;
use serde::Serialize;

use crate::config;

/// Elevation at which a pyramid of evenly spaced axes has HᵀH ∝ I: tan²α = 1/2 (35.26°).
fn optimal_pyramid_alpha_deg() -> f64 {
    (0.5f64).sqrt().atan().to_degrees()
}

#[derive(Serialize)]
struct SensorReport {
    sensor: &'static str,
    geometry: String,
    capability: Capability,
    /// For a pyramid: the same figures at the optimal elevation, to show the cost of the chosen one.
    #[serde(skip_serializing_if = "Option::is_none")]
    optimal_pyramid: Option<OptimalPyramid>,
}

#[derive(Serialize)]
struct OptimalPyramid {
    alpha_deg: f64,
    capability: Capability,
}

fn describe(cfg: &GeometryConfig) -> String {
    match cfg {
        GeometryConfig::Pyramid {
            n,
            alpha_deg,
            beta0_deg,
        } => format!("pyramid n = {n}, α = {alpha_deg}°, β0 = {beta0_deg}°"),
        GeometryConfig::Axes { axes } => format!("{} explicit axes", axes.len()),
        GeometryConfig::Triad {} => "orthogonal triad".into(),
        GeometryConfig::Dodecahedron {} => "dodecahedron (6 axes)".into(),
        GeometryConfig::Stacked { count, .. } => format!("{count} stacked triads"),
    }
}

fn report(sensor: &'static str, cfg: &GeometryConfig) -> Result<SensorReport> {
    let field = format!("fusion.geometry.{sensor}");
    let geometry = cfg.build().map_err(|e| anyhow!("{}", e.within(&field)))?;
    let optimal_pyramid = match cfg {
        GeometryConfig::Pyramid { n, beta0_deg, .. } => {
            let alpha_deg = optimal_pyramid_alpha_deg();
            let optimal = GeometryConfig::Pyramid {
                n: *n,
                alpha_deg,
                beta0_deg: *beta0_deg,
            }
            .build()
            .map_err(|e| anyhow!("{}", e.within(&field)))?;
            Some(OptimalPyramid {
                alpha_deg,
                capability: Capability::of(&optimal),
            })
        }
        _ => None,
    };
    Ok(SensorReport {
        sensor,
        geometry: describe(cfg),
        capability: Capability::of(&geometry),
        optimal_pyramid,
    })
}

fn yes_no(v: bool) -> &'static str {
    if v { "yes" } else { "no" }
}

fn print_text(r: &SensorReport) {
    let c = &r.capability;
    println!("{}: {} ({} channels)", r.sensor, r.geometry, c.n);
    println!(
        "  noise amplification σx/σ, σy/σ, σz/σ: {:.3} {:.3} {:.3}   (variance factors {:.3} {:.3} {:.3})",
        c.noise_amplification[0],
        c.noise_amplification[1],
        c.noise_amplification[2],
        c.variance_factors[0],
        c.variance_factors[1],
        c.variance_factors[2]
    );
    println!("  parity dimension: {}", c.parity_dimension);
    println!(
        "  detect: {}   isolate one: {}   tolerate two: {}",
        yes_no(c.detect),
        yes_no(c.isolate_one),
        yes_no(c.tolerate_two)
    );
    if let Some(opt) = &r.optimal_pyramid {
        let o = &opt.capability;
        println!(
            "  at the optimal α = {:.2}°: variance factors {:.3} {:.3} {:.3}; z-axis variance here is {:.1} % of optimal",
            opt.alpha_deg,
            o.variance_factors[0],
            o.variance_factors[1],
            o.variance_factors[2],
            100.0 * c.variance_factors[2] / o.variance_factors[2]
        );
    }
}

pub fn run(config_path: Option<&std::path::Path>, json: bool) -> Result<()> {
    let cfg = config::load(config_path)?;
    let reports = [
        report("gyro", &cfg.fusion.geometry.gyro)?,
        report("accel", &cfg.fusion.geometry.accel)?,
    ];
    if json {
        println!("{}", serde_json::to_string(&reports)?);
    } else {
        for r in &reports {
            print_text(r);
        }
    }
    Ok(())
}
