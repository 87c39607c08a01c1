//! The tilt-aiding settings `rins eval quadrotor --mode ahrs` chooses from by cross-validation.
//!
//! Both models of `[navigator.tilt]` over a small grid: the gravity model with a fixed σ or with
//! σ inflated by the departure of |f| from g and by the rotation rate, and the rotor-drag model
//! over the plausible drag coefficients of a small multirotor (0.3–0.6 /s forwards, 0.4–0.6 /s
//! sideways) and two σs, with and without σ growing with the rotation rate, with and without the
//! drag's heading information (`drag_heading`). Every other setting is the profile's.

use rins_navigator::aiding::tilt::{DragHeading, TiltAidingConfig, TiltModel};
use serde::Serialize;

/// Windows further than this from g are not used by any candidate, m/s²: the quadrotor's
/// manoeuvres stay within it, a knock or a landing does not.
pub const MAX_FORCE_ERROR_MPS2: f64 = 5.0;

/// σ growth with the rotation rate tried for the drag model, m/s: none, and 1 m/s² more per rad/s.
/// While the airframe rotates, the units (off its centre of mass) feel the angular acceleration and
/// the centripetal force of their lever arms, which the drag model does not hold.
pub const DRAG_RATE_GAINS_MPS: [f64; 2] = [0.0, 1.0];

/// One setting of the tilt updates.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Candidate {
    /// Short name for reports, e.g. `drag mu 0.6/0.4 sigma 1`.
    pub name: String,
    /// The settings.
    #[serde(skip)]
    pub tilt: TiltAidingConfig,
}

/// The grid, built on the profile's `[navigator.tilt]` (its window, gate and limits are kept;
/// the updates are switched on).
pub fn grid(base: &TiltAidingConfig) -> Vec<Candidate> {
    let mut out = Vec::new();
    for sigma in [1.0, 3.0] {
        for gain in [0.0, 2.0] {
            out.push(Candidate {
                name: format!("gravity sigma {sigma} gains {gain}"),
                tilt: TiltAidingConfig {
                    enabled: true,
                    model: TiltModel::Gravity,
                    sigma_mps2: sigma,
                    force_error_gain: gain,
                    rate_gain_mps: gain,
                    max_force_error_mps2: MAX_FORCE_ERROR_MPS2,
                    ..*base
                },
            });
        }
    }
    // Without a receiver `without_gnss` is `always`.
    for drag_heading in [DragHeading::Never, DragHeading::Always] {
        for rate_gain in DRAG_RATE_GAINS_MPS {
            for forward in [0.3, 0.4, 0.6] {
                for lateral in [0.4, 0.6] {
                    for sigma in [1.0, 1.5] {
                        out.push(drag(forward, lateral, sigma, rate_gain, drag_heading, base));
                    }
                }
            }
        }
    }
    out
}

/// A drag-model candidate.
fn drag(
    forward: f64,
    lateral: f64,
    sigma: f64,
    rate_gain: f64,
    drag_heading: DragHeading,
    base: &TiltAidingConfig,
) -> Candidate {
    let rate = if rate_gain > 0.0 {
        format!(" rate gain {rate_gain}")
    } else {
        String::new()
    };
    let heading = match drag_heading {
        DragHeading::Never => "",
        _ => " heading",
    };
    Candidate {
        name: format!("drag mu {forward}/{lateral} sigma {sigma}{rate}{heading}"),
        tilt: TiltAidingConfig {
            enabled: true,
            model: TiltModel::Drag,
            sigma_mps2: sigma,
            force_error_gain: 0.0,
            rate_gain_mps: rate_gain,
            max_force_error_mps2: MAX_FORCE_ERROR_MPS2,
            drag_per_s: forward,
            lateral_drag_per_s: lateral,
            drag_heading,
            ..*base
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_drag_setting_is_tried_with_each_rate_gain_and_heading_choice() {
        let base = TiltAidingConfig {
            window_s: 0.2,
            ..TiltAidingConfig::default()
        };
        let g = grid(&base);
        assert_eq!(g.len(), 4 + 12 * DRAG_RATE_GAINS_MPS.len() * 2);
        let drag: Vec<&Candidate> = g
            .iter()
            .filter(|c| c.tilt.model == TiltModel::Drag)
            .collect();
        for c in &drag {
            // The profile's window is kept, every candidate is on, the names are unique.
            assert!(c.tilt.enabled && c.tilt.window_s == 0.2, "{}", c.name);
            assert_eq!(
                g.iter().filter(|o| o.name == c.name).count(),
                1,
                "{}",
                c.name
            );
            let twin = drag.iter().find(|o| {
                o.tilt.drag_heading != c.tilt.drag_heading
                    && TiltAidingConfig {
                        drag_heading: c.tilt.drag_heading,
                        ..o.tilt
                    } == c.tilt
            });
            assert!(
                twin.is_some(),
                "{} has no twin with the other heading choice",
                c.name
            );
        }
        for gain in DRAG_RATE_GAINS_MPS {
            assert_eq!(
                drag.iter().filter(|c| c.tilt.rate_gain_mps == gain).count(),
                24
            );
        }
    }
}
