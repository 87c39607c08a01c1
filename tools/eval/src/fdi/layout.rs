//! The redundant configurations built from the recorded units, and the two sensor types.

use rins_fusion::GeometryConfig;
use serde::Serialize;

use crate::datasets::quadrotor::projection::stacked_axes;

/// Reference channel σ of one configuration: the unit in which injected bias steps, ramps and
/// noise increases are sized (fixed physical sizes, the same for every flight and setting), and
/// the centre of the detector noise settings the cross-validation chooses from.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct NoiseFit {
    /// Gyro channel σ, rad/s.
    pub gyro_sigma_rps: f64,
    /// Accelerometer channel σ, m/s².
    pub accel_sigma_mps2: f64,
}

/// A redundant configuration built from a flight's units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Layout {
    /// Channel i = unit i projected on the pyramid axis h_i (α = 28.7°, β0 = 45°): one
    /// single-axis channel per unit as on the product's block. Needs four units.
    Pyramid4,
    /// The units' triads turned into the reference unit's frame, three rows per unit.
    Stacked {
        /// Units stacked (2..=4).
        units: usize,
    },
}

impl Layout {
    /// The configurations a flight with `units` usable units is evaluated in: none for a single
    /// unit (no redundancy to monitor).
    pub(crate) fn for_units(units: usize) -> Vec<Layout> {
        match units {
            4 => vec![Layout::Pyramid4, Layout::Stacked { units: 4 }],
            2 | 3 => vec![Layout::Stacked { units }],
            _ => Vec::new(),
        }
    }

    pub(crate) fn name(self) -> &'static str {
        match self {
            Layout::Pyramid4 => "pyramid4",
            Layout::Stacked { units: 4 } => "stacked12",
            Layout::Stacked { units: 3 } => "stacked9",
            Layout::Stacked { .. } => "stacked6",
        }
    }

    pub(crate) fn geometry(self) -> GeometryConfig {
        match self {
            Layout::Pyramid4 => GeometryConfig::Pyramid {
                n: 4,
                alpha_deg: 28.7,
                beta0_deg: 45.0,
            },
            Layout::Stacked { units } => GeometryConfig::Axes {
                axes: stacked_axes(units),
            },
        }
    }

    /// The reference σ per type (see [`NoiseFit`]).
    pub(crate) fn noise(self) -> NoiseFit {
        match self {
            Layout::Pyramid4 => NoiseFit {
                gyro_sigma_rps: 0.023,
                accel_sigma_mps2: 0.7,
            },
            Layout::Stacked { .. } => NoiseFit {
                gyro_sigma_rps: 0.019,
                accel_sigma_mps2: 0.7,
            },
        }
    }

    /// The recorded unit (0-based) a channel comes from.
    pub(crate) fn unit_of(self, channel: usize) -> usize {
        match self {
            Layout::Pyramid4 => channel,
            Layout::Stacked { .. } => channel / 3,
        }
    }
}

/// Gyro or accelerometer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sensor {
    Gyro,
    Accel,
}

impl Sensor {
    pub(crate) const ALL: [Sensor; 2] = [Sensor::Gyro, Sensor::Accel];

    pub(crate) fn name(self) -> &'static str {
        match self {
            Sensor::Gyro => "gyro",
            Sensor::Accel => "accel",
        }
    }

    /// This type's entry of a per-type pair.
    pub(crate) fn of<T: Copy>(self, pair: [T; 2]) -> T {
        pair[self as usize]
    }

    /// The reference σ of this type in `noise`.
    pub(crate) fn sigma(self, noise: NoiseFit) -> f64 {
        match self {
            Sensor::Gyro => noise.gyro_sigma_rps,
            Sensor::Accel => noise.accel_sigma_mps2,
        }
    }
}
