//! Feeds arbitrary text to the configuration loader, then builds what `rins up` builds from a
//! configuration it accepted: the sensor geometries, the fuser, the altimeter and the navigator.
//!
//! Beyond "never panics": a configuration the loader accepts must also be accepted by every
//! service it configures (the loader's checks are the services' checks, so nothing is refused
//! only once a process has started).

#![no_main]

use libfuzzer_sys::fuzz_target;
use rins::config::RinsConfig;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(cfg) = RinsConfig::parse(text, "fuzz") else {
        return;
    };
    let (gyro, accel) = cfg
        .geometries()
        .expect("an accepted configuration builds its geometries");
    assert!(gyro.n() >= 3 && accel.n() >= 3);
    rins_fusion::ImuFuser::new(
        &cfg.fusion,
        cfg.device.gyro_lsb_rps(),
        cfg.device.accel_lsb_mps2(),
    )
    .expect("an accepted configuration builds the fuser");
    rins_altimeter::AltitudeEstimator::new(cfg.altimeter.clone())
        .expect("an accepted configuration builds the altimeter");
    rins_navigator::Navigator::new(cfg.navigator.clone())
        .expect("an accepted configuration builds the navigator");
});
