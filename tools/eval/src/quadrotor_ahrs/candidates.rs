//! The tilt-aiding settings `rins eval quadrotor --mode ahrs` chooses from by cross-validation.
//!
//! Both models of `[navigator.tilt]` over a small grid: the gravity model with a fixed σ or with
//! σ inflated by the departure of |f| from g and by the rotation rate, and the rotor-drag model
//! over the plausible drag coefficients of a small multirotor (0.3–0.6 /s forwards, 0.4–0.6 /s
//! sideways) and two σs, with and without the drag's heading information (`drag_heading`). Every
//! other setting is the profile's.

use rins_navigator::aiding::tilt::{TiltAidingConfig, TiltModel};
use serde::Serialize;

/// Windows further than this from g are not used by any candidate, m/s²: the quadrotor's
/// manoeuvres stay within it, a knock or a landing does not.
pub const MAX_FORCE_ERROR_MPS2: f64 = 5.0;

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
    for drag_heading in [false, true] {
        for forward in [0.3, 0.4, 0.6] {
            for lateral in [0.4, 0.6] {
                for sigma in [1.0, 1.5] {
                    let heading = if drag_heading { " heading" } else { "" };
                    out.push(Candidate {
                        name: format!("drag mu {forward}/{lateral} sigma {sigma}{heading}"),
                        tilt: TiltAidingConfig {
                            enabled: true,
                            model: TiltModel::Drag,
                            sigma_mps2: sigma,
                            force_error_gain: 0.0,
                            rate_gain_mps: 0.0,
                            max_force_error_mps2: MAX_FORCE_ERROR_MPS2,
                            drag_per_s: forward,
                            lateral_drag_per_s: lateral,
                            drag_heading,
                            ..*base
                        },
                    });
                }
            }
        }
    }
    out
}
