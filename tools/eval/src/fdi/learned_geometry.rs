//! The units' installation rotations and lever arms for a flight, learnt from the other flights.
//!
//! The units stay bolted to the airframe from one flight to the next, so what a flight's own data
//! say about their rotations and arms is also true of the other flights; but an estimate from the
//! flight being scored would also absorb part of that flight's faults and disagreements. Each
//! flight therefore gets the weighted mean of the other flights' estimates (same units): the
//! rotation vectors weighted by how much each flight rotated (a short straight flight barely
//! determines the rotation about the vertical), the arms by how much each flight excited them.
//! A flight whose units appear in no other flight keeps its own estimate, and is counted.

use nalgebra::{Rotation3, Vector3};

use crate::datasets::error::DatasetError;
use crate::datasets::quadrotor::lever_arm::{LeverArm, estimate_lever_arms};
use crate::datasets::quadrotor::projection::{Installation, estimate_installation};
use crate::datasets::quadrotor::{IMU_RATE_HZ, Trial};
use crate::installation::rotation_vector;

/// One flight's own estimates and how well its motion determines them.
#[derive(Debug, Clone)]
pub(crate) struct OwnGeometry {
    /// File numbers of the flight's units, in order.
    pub imus: Vec<usize>,
    pub installation: Installation,
    pub arms: Vec<Option<LeverArm>>,
    /// Σ|ω − ω̄|² of the reference unit over the flight, (rad/s)²·rows: the rotation's weight.
    pub excitation: f64,
}

/// Estimates one flight's installation and arms from its own data.
pub(crate) fn own_geometry(trial: &Trial) -> Result<OwnGeometry, DatasetError> {
    let installation = estimate_installation(trial)?;
    let arms = estimate_lever_arms(trial, &installation, IMU_RATE_HZ);
    let excitation = trial.imus.first().map_or(0.0, |reference| {
        let n = reference.samples.len().max(1) as f64;
        let mean = reference
            .samples
            .iter()
            .map(|s| Vector3::from(s.gyro_rps))
            .sum::<Vector3<f64>>()
            / n;
        reference
            .samples
            .iter()
            .map(|s| (Vector3::from(s.gyro_rps) - mean).norm_squared())
            .sum()
    });
    Ok(OwnGeometry {
        imus: trial.imus.iter().map(|s| s.imu).collect(),
        installation,
        arms,
        excitation,
    })
}

/// The geometry a flight is evaluated with, and where it came from.
pub(crate) struct LearnedGeometry {
    pub installation: Installation,
    pub arms: Vec<Option<LeverArm>>,
    /// Other flights pooled (0: the flight's own estimates, no other flight had its units).
    pub flights_pooled: usize,
}

/// The geometry for flight `index` of `all`: the weighted mean of the other flights' estimates
/// with the same units (see the module docs), or its own when there are none.
pub(crate) fn learned_geometry(all: &[OwnGeometry], index: usize) -> LearnedGeometry {
    let own = &all[index];
    let others: Vec<&OwnGeometry> = all
        .iter()
        .enumerate()
        .filter(|(j, g)| *j != index && g.imus == own.imus && g.excitation > 0.0)
        .map(|(_, g)| g)
        .collect();
    if others.is_empty() {
        return LearnedGeometry {
            installation: own.installation.clone(),
            arms: own.arms.clone(),
            flights_pooled: 0,
        };
    }
    let total: f64 = others.iter().map(|g| g.excitation).sum();
    let mut installation = own.installation.clone();
    for (u, unit) in installation.imus.iter_mut().enumerate() {
        let v: Vector3<f64> = others
            .iter()
            .map(|g| rotation_vector(&g.installation.imus[u].rotation) * (g.excitation / total))
            .sum();
        unit.rotation = Rotation3::new(v);
        unit.angle_deg = v.norm().to_degrees();
    }
    let arms = (0..own.arms.len())
        .map(|u| {
            let with: Vec<(&LeverArm, f64)> = others
                .iter()
                .filter_map(|g| g.arms[u].as_ref().map(|a| (a, g.excitation)))
                .collect();
            let w: f64 = with.iter().map(|(_, w)| w).sum();
            (w > 0.0).then(|| {
                let mut m = [0.0; 3];
                for (a, wi) in &with {
                    for k in 0..3 {
                        m[k] += a[k] * wi / w;
                    }
                }
                m
            })
        })
        .collect();
    LearnedGeometry {
        installation,
        arms,
        flights_pooled: others.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::datasets::quadrotor::projection::ImuInstallation;

    fn unit(imu: usize, rv: [f64; 3]) -> ImuInstallation {
        ImuInstallation::fixture(imu, Rotation3::new(Vector3::from(rv)))
    }

    fn flight(imus: &[usize], rv: f64, arm: f64, excitation: f64) -> OwnGeometry {
        OwnGeometry {
            imus: imus.to_vec(),
            installation: Installation {
                reference_imu: imus[0],
                // The reference unit is the identity, the others turned by `rv` about z.
                imus: imus
                    .iter()
                    .enumerate()
                    .map(|(k, &i)| unit(i, [0.0, 0.0, if k == 0 { 0.0 } else { rv }]))
                    .collect(),
            },
            arms: imus.iter().map(|_| Some([arm, 0.0, 0.0])).collect(),
            excitation,
        }
    }

    #[test]
    fn a_flight_gets_the_excitation_weighted_mean_of_the_others_and_never_its_own() {
        let all = vec![
            flight(&[1, 2], 0.5, 9.0, 1.0),
            flight(&[1, 2], 0.01, 0.1, 3.0),
            flight(&[1, 2], 0.03, 0.3, 1.0),
            flight(&[1, 3], 0.2, 2.0, 5.0),
        ];
        let g = learned_geometry(&all, 0);
        assert_eq!(g.flights_pooled, 2);
        // (0.01·3 + 0.03·1) / 4 = 0.015 rad about z; arms (0.1·3 + 0.3) / 4 = 0.15 m.
        let rz = rotation_vector(&g.installation.imus[1].rotation).z;
        assert!((rz - 0.015).abs() < 1e-12, "{rz}");
        let arm = g.arms[1].expect("arm");
        assert!((arm[0] - 0.15).abs() < 1e-12, "{arm:?}");
        // Units seen in no other flight: its own estimate, and said so.
        let alone = learned_geometry(&all, 3);
        assert_eq!(alone.flights_pooled, 0);
        assert!((rotation_vector(&alone.installation.imus[1].rotation).z - 0.2).abs() < 1e-12);
        // The reference unit (identity) stays the identity, not NaN.
        assert_eq!(
            rotation_vector(&g.installation.imus[0].rotation),
            Vector3::zeros()
        );
    }
}
