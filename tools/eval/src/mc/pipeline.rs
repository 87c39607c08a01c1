//! One simulated sensor block and the processing chain of the product run in-process on it:
//! simulator → fuser → navigator, barometer → altimeter → navigator, magnetometer → navigator.

use ipc_types::{ChannelState, MAX_CHANNELS, MAX_TEMPERATURES, NavMode};
use rins_altimeter::AltitudeEstimator;
use rins_fusion::{ImuFuser, ImuSample};
use rins_navigator::{NavOutput, Navigator};
use rins_protocol::{FrameType, ImuFrame, Payload};
use rins_sim::{ChannelFault, InertialSensor, Simulator, TickOutput, TruthSample};

use super::config::{McError, Prepared, PreparedSystem};

/// Body rate and specific force of one frame, and whether both have a solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FusedSample {
    pub rate_rps: [f64; 3],
    pub specific_force_mps2: [f64; 3],
    /// Variance of each rate axis, with fusion's bound on an unisolated fault.
    pub rate_var: [f64; 3],
    /// The fused sample's flags (`ipc_types::fused_flags`).
    pub flags: u32,
    /// Enough healthy channels of both kinds.
    pub usable: bool,
    /// Some channel of the frame did not enter the solution (dead, or excluded by the fuser), or
    /// the fuser flags a channel Suspect or a detected-but-unisolated fault: in a fault-free
    /// flight, a false alarm.
    pub degraded: bool,
    /// Fusion's per-channel states, reasons and parity verdict of the gyros.
    pub gyro_status: rins_fusion::SensorStatus,
    /// The same of the accelerometers.
    pub accel_status: rins_fusion::SensorStatus,
}

fn full_mask(n: usize) -> u32 {
    if n >= 32 { u32::MAX } else { (1u32 << n) - 1 }
}

/// A channel not Ok, or a detected-but-unisolated fault.
fn flagged(s: &rins_fusion::SensorStatus) -> bool {
    s.detected_not_isolated || s.states[..s.n].iter().any(|&st| st != ChannelState::Ok)
}

/// The one call into the fuser, so that a change of its interface touches only this function.
/// The frame goes in whole, as the acquisition would deliver it: counts, valid mask, device
/// status and module temperatures.
pub(crate) fn fuse_frame(fuser: &mut ImuFuser, imu: &ImuFrame) -> FusedSample {
    let n_gyro = usize::from(imu.n_gyro).min(MAX_CHANNELS);
    let n_accel = usize::from(imu.n_accel).min(MAX_CHANNELS);
    let n_temperature = usize::from(imu.n_temperature).min(MAX_TEMPERATURES);
    let mut temperatures_c = [0.0f32; MAX_TEMPERATURES];
    for (t, centi) in temperatures_c.iter_mut().zip(imu.temperature_centi_c) {
        *t = f32::from(centi) / 100.0;
    }
    let fused = fuser.fuse_sample(&ImuSample {
        gyro_counts: &imu.gyro_counts[..n_gyro],
        accel_counts: &imu.accel_counts[..n_accel],
        valid_mask: imu.valid_mask,
        status: u32::from(imu.status),
        temperatures_c: &temperatures_c[..n_temperature],
    });
    FusedSample {
        rate_rps: fused.rate,
        specific_force_mps2: fused.specific_force,
        rate_var: fused.rate_var,
        flags: fused.flags(),
        usable: rins_navigator::navigator::fused_sample_usable(fused.flags()),
        degraded: fused.gyro_mask != full_mask(n_gyro)
            || fused.accel_mask != full_mask(n_accel)
            || flagged(&fused.gyro_status)
            || flagged(&fused.accel_status),
        gyro_status: fused.gyro_status,
        accel_status: fused.accel_status,
    }
}

/// Simulator plus the processing chain, advanced one IMU tick at a time. Cloning it forks the
/// run: both copies continue from the same state (the fault experiment forks at the kill time).
#[derive(Debug, Clone)]
pub(crate) struct Pipeline {
    sim: Simulator,
    fuser: ImuFuser,
    altimeter: AltitudeEstimator,
    navigator: Navigator,
    tick: TickOutput,
    solution: Option<NavOutput>,
    degraded: bool,
    /// Fusion's output of the last tick (`None` before the first frame).
    fused: Option<FusedSample>,
}

impl Pipeline {
    pub fn new(prepared: &Prepared, system: &PreparedSystem, seed: u64) -> Result<Self, McError> {
        let axes = system.geometry.axes();
        let sim = Simulator::new(&prepared.sim, axes, axes, seed)?;
        let gyro_lsb = prepared.sim.gyro_lsb_rps();
        let mut fusion = system.fusion.clone();
        // Per-channel gyro biases at rest are the fuser's own start-up window; without it the
        // navigator's body-axis alignment estimate is the only bias correction.
        fusion.rest_bias_s = match prepared.gyro_channel_bias_ticks {
            Some(ticks) => ticks as f64 / prepared.sim.imu_rate_hz,
            None => 0.0,
        };
        let fuser = ImuFuser::new(&fusion, gyro_lsb, prepared.sim.accel_lsb_mps2())?;
        let altimeter = AltitudeEstimator::new(prepared.altimeter.clone())?;
        let navigator = Navigator::new(prepared.navigator.clone())?;
        Ok(Self::at_start(sim, fuser, altimeter, navigator))
    }

    /// The chain of these stages before its first tick.
    fn at_start(
        sim: Simulator,
        fuser: ImuFuser,
        altimeter: AltitudeEstimator,
        navigator: Navigator,
    ) -> Self {
        Self {
            sim,
            fuser,
            altimeter,
            navigator,
            tick: TickOutput::default(),
            solution: None,
            degraded: false,
            fused: None,
        }
    }

    /// The chain as a deployment builds it from its configuration: the simulator with the
    /// configured block's axes, the fuser with the configured `[fusion]` table (its own rest-bias
    /// window included) and the simulated converters, the altimeter and the navigator as given.
    pub fn from_parts(
        sim: &rins_sim::SimConfig,
        fusion: &rins_fusion::FusionConfig,
        altimeter: &rins_altimeter::AltimeterConfig,
        navigator: &rins_navigator::NavigatorConfig,
        seed: u64,
    ) -> Result<Self, McError> {
        let gyro = fusion
            .geometry
            .gyro
            .build()
            .map_err(|e| e.within("fusion.geometry.gyro"))?;
        let accel = fusion
            .geometry
            .accel
            .build()
            .map_err(|e| e.within("fusion.geometry.accel"))?;
        let sim_model = Simulator::new(sim, gyro.axes(), accel.axes(), seed)?;
        let fuser = ImuFuser::new(fusion, sim.gyro_lsb_rps(), sim.accel_lsb_mps2())
            .map_err(|e| e.within("fusion"))?;
        let altimeter =
            AltitudeEstimator::new(altimeter.clone()).map_err(|e| e.within("altimeter"))?;
        let navigator = Navigator::new(navigator.clone())?;
        Ok(Self::at_start(sim_model, fuser, altimeter, navigator))
    }

    /// Sets a fault on one inertial channel from the next tick on.
    pub fn inject_fault(
        &mut self,
        sensor: InertialSensor,
        channel: usize,
        fault: ChannelFault,
    ) -> Result<(), McError> {
        self.sim.inject_fault(sensor, channel, fault)?;
        Ok(())
    }

    /// Fusion's output of the last tick, `None` before the first frame or when the last tick
    /// carried no IMU frame.
    pub fn fused(&self) -> Option<&FusedSample> {
        self.fused.as_ref()
    }

    /// Kills one gyro channel from the next tick on.
    pub fn kill_gyro(&mut self, channel: usize) -> Result<(), McError> {
        self.sim
            .inject_fault(InertialSensor::Gyro, channel, ChannelFault::Dead)?;
        Ok(())
    }

    /// Advances one IMU tick; allocation-free. Aiding goes first, as in the navigator process,
    /// where readings of the same device tick are drained before the IMU sample.
    pub fn step(&mut self) {
        self.sim.step(&mut self.tick);
        let time_us = self.tick.truth.device_time_us;
        if let Some(frame) = self.tick.frame(FrameType::Baro)
            && let Payload::Baro(baro) = frame.payload
        {
            let altitude = self.altimeter.update(time_us, f64::from(baro.pressure_pa));
            let _ = self.navigator.on_baro(
                time_us,
                altitude.height_m,
                altitude.height_var,
                altitude.valid,
            );
        }
        if let Some(frame) = self.tick.frame(FrameType::Mag)
            && let Payload::Mag(mag) = frame.payload
        {
            // The wire carries nanotesla, the navigator takes microtesla.
            let _ = self
                .navigator
                .on_mag(time_us, mag.field_nt.map(|nt| f64::from(nt) * 1e-3));
        }
        self.solution = None;
        self.fused = None;
        if let Payload::Imu(imu) = &self.tick.imu.payload {
            let fused = fuse_frame(&mut self.fuser, imu);
            self.degraded = fused.degraded;
            self.fused = Some(fused);
            if fused.usable {
                // As the navigator process does: fusion's fault report first.
                self.navigator.on_fusion_status(fused.flags, fused.rate_var);
                self.solution =
                    self.navigator
                        .on_imu(time_us, fused.rate_rps, fused.specific_force_mps2);
            }
        }
    }

    /// The navigation solution of the last tick, `None` while aligning or without fused data.
    pub fn solution(&self) -> Option<&NavOutput> {
        self.solution.as_ref()
    }

    /// Some channel of the last frame was left out of the solution or flagged.
    pub fn degraded(&self) -> bool {
        self.degraded
    }

    /// Truth of the last tick.
    pub fn truth(&self) -> &TruthSample {
        &self.tick.truth
    }

    /// True once the navigator has left its alignment.
    pub fn aligned(&self) -> bool {
        self.navigator.mode() != NavMode::Aligning
    }
}
