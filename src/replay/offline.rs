//! The pipeline in one process, without IPC: the raw samples of a recording through the same
//! library code the services run — fusion's fuser and message, the altimeter's estimator, each
//! navigator lane's aiding hold (every held reading it subscribes to), receiver hold and step — in
//! the order the sensor block sent them. What the live pipeline publishes for a sample does not depend on when
//! it arrived (the navigator holds aiding readings until the IMU stream passes their time), so
//! this gives the same output.

use ipc_types::{FusedImu, GnssFix, NavState, PAYLOAD_VERSION, RawImu};
use rins_altimeter::AltitudeEstimator;
use rins_altimeter::service::altitude_message;
use rins_fusion::ImuFuser;
use rins_fusion::service::{fused_message, rejected_message};
use rins_navigator::Navigator;
use rins_navigator::aiding::gnss::hold::GnssHold;
use rins_navigator::aiding::readings::{AidingQueue, HeldPayload, Reading};
use rins_navigator::service::step;

use super::input::{RawSample, ReplayInput};

/// One navigator lane in process.
struct Lane {
    nav: Navigator,
    aiding: AidingQueue,
    gnss: GnssHold,
    last: NavState,
    out: Vec<NavState>,
}

impl Lane {
    fn new(nav: Navigator, lane: u8) -> Self {
        let gnss = GnssHold::new(nav.config().gnss.delay_s);
        Self {
            nav,
            aiding: AidingQueue::default(),
            gnss,
            last: NavState {
                lane,
                ..NavState::default()
            },
            out: Vec::new(),
        }
    }

    /// What the navigator service does with an aiding reading: holds it, when it subscribes to
    /// its topic.
    fn on_reading(&mut self, r: Reading) {
        if r.subscribed(self.nav.config()) {
            self.aiding.hold(r, &mut self.nav);
        }
    }

    /// What the navigator service does with a receiver fix: holds it, when GNSS aiding is on.
    fn on_fix(&mut self, fix: &GnssFix) {
        if self.nav.config().gnss.enabled {
            self.gnss.push(*fix);
        }
    }

    /// What the navigator service does with a fused sample (without a peer to take over from).
    fn on_fused(&mut self, imu: &FusedImu) {
        if self.last.header.origin_seq != 0 && imu.header.origin_seq <= self.last.header.origin_seq
        {
            return;
        }
        self.aiding
            .release_to(imu.header.origin_device_time_us, &mut self.nav);
        let nav = &mut self.nav;
        self.gnss.release(
            imu.header.origin_device_time_us,
            imu.header.origin_rx_ns,
            |fix, t_us| {
                let _ = nav.on_gnss(fix, t_us);
            },
        );
        let mut state = step(&mut self.nav, imu, &self.last);
        state.version = PAYLOAD_VERSION;
        self.last = state;
        self.out.push(state);
    }
}

/// The services of one deployment, in process.
pub struct OfflinePipeline {
    fuser: ImuFuser,
    altimeter: AltitudeEstimator,
    lanes: Vec<Lane>,
}

impl OfflinePipeline {
    /// The pipeline of `lanes` navigator lanes (1 or 2), from the services a configuration built.
    pub fn new(
        fuser: ImuFuser,
        altimeter: AltitudeEstimator,
        navigator: Navigator,
        lanes: u8,
    ) -> Self {
        let lanes = (0..lanes.clamp(1, 2))
            .map(|lane| Lane::new(navigator.clone(), lane))
            .collect();
        Self {
            fuser,
            altimeter,
            lanes,
        }
    }

    /// Fusion's message for a raw IMU frame.
    fn fuse(&mut self, raw: &RawImu) -> FusedImu {
        let (n_gyro, n_accel) = (
            self.fuser.gyro_geometry().n(),
            self.fuser.accel_geometry().n(),
        );
        if usize::from(raw.n_gyro) != n_gyro || usize::from(raw.n_accel) != n_accel {
            return rejected_message(raw, &self.fuser);
        }
        let fused = self.fuser.fuse_raw(raw);
        fused_message(raw, &fused, n_gyro, n_accel)
    }

    /// Runs every raw sample of `input`; `progress` is told the share done now and then.
    pub fn run(mut self, input: &ReplayInput, mut progress: impl FnMut(f64)) -> [Vec<NavState>; 2] {
        let total = input.raw.len().max(1);
        for (i, sample) in input.raw.iter().enumerate() {
            match sample {
                // Other payload versions are refused by the services too.
                _ if sample.version() != PAYLOAD_VERSION => {}
                RawSample::Imu(raw) => {
                    let fused = self.fuse(raw);
                    for lane in &mut self.lanes {
                        lane.on_fused(&fused);
                    }
                }
                RawSample::Baro(raw) => {
                    let out = self
                        .altimeter
                        .update(raw.header.origin_device_time_us, raw.pressure_pa);
                    let alt = altitude_message(raw, &out);
                    for lane in &mut self.lanes {
                        lane.on_reading(alt.reading());
                    }
                }
                RawSample::Gnss(fix) => {
                    for lane in &mut self.lanes {
                        lane.on_fix(fix);
                    }
                }
                other => {
                    // The readings the navigator takes as they come; auxiliary samples feed no
                    // stage.
                    if let Some(r) = other.held_reading() {
                        for lane in &mut self.lanes {
                            lane.on_reading(r);
                        }
                    }
                }
            }
            if i % 10_000 == 0 {
                progress(i as f64 / total as f64);
            }
        }
        let mut lanes = self.lanes.into_iter();
        let first = lanes.next().map(|l| l.out).unwrap_or_default();
        let second = lanes.next().map(|l| l.out).unwrap_or_default();
        [first, second]
    }
}
