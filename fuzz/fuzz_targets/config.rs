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
    if let Err(e) = cfg.build_services() {
        panic!("an accepted configuration must build every service: {e}");
    }
});
