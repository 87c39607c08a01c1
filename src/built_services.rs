//! The services of a deployment built from its configuration, once: `rins up` builds them to refuse
//! a bad configuration before any child starts, `rins service NAME` to run one.

use std::time::Duration;

use anyhow::{Result, anyhow};
use rins_altimeter::AltitudeEstimator;
use rins_fusion::ImuFuser;
use rins_navigator::Navigator;

use crate::config::RinsConfig;

/// What each service is built from the configuration: a configuration `rins up` accepts is never
/// refused by a process it starts. (Acquisition builds nothing before it runs: its device is
/// opened, and retried, by the service itself.)
pub struct BuiltServices {
    /// Fusion's fuser, with the configured block's geometries and converters.
    pub fuser: ImuFuser,
    /// How long fusion waits for raw IMU before it reports acquisition stale.
    pub fusion_input_deadline: Duration,
    /// Fused samples a channel re-admitted by command stays on probation.
    pub readmit_probation_samples: u32,
    /// The altimeter's estimator.
    pub altimeter: AltitudeEstimator,
    /// The navigator (either lane runs one).
    pub navigator: Navigator,
}

impl RinsConfig {
    /// Builds what the services build from this configuration — the geometries, the fuser, the
    /// altimeter, the navigator. The loader's range checks should make this always succeed; the
    /// fuzz target and the configuration property tests hold it to that.
    pub fn build_services(&self) -> Result<BuiltServices> {
        let (gyro, accel) = self.geometries()?;
        if gyro.n() < 3 || accel.n() < 3 {
            return Err(anyhow!(
                "fusion.geometry: {} gyro and {} accelerometer axes, need at least 3 each",
                gyro.n(),
                accel.n()
            ));
        }
        let fuser = ImuFuser::new(
            &self.fusion,
            self.device.gyro_lsb_rps(),
            self.device.accel_lsb_mps2(),
        )
        .map_err(|e| anyhow!("{}", e.within("fusion")))?;
        let altimeter = AltitudeEstimator::new(self.altimeter.clone())
            .map_err(|e| anyhow!("{}", e.within("altimeter")))?;
        let navigator = Navigator::new(self.navigator.clone()).map_err(|e| anyhow!("{e}"))?;
        Ok(BuiltServices {
            fuser,
            fusion_input_deadline: rins_fusion::service::input_deadline(self.device.imu_rate_hz),
            readmit_probation_samples: self.fusion.fdi.readmit_probation_samples,
            altimeter,
            navigator,
        })
    }
}
