//! The fuser over one prepared trial: the fault-free run (false alarms) and the faulted runs.

use anyhow::{Result, anyhow};
use ipc_types::ChannelState;
use rins_fusion::{FusionConfig, ImuFuser, SensorStatus};

use super::faults::{FaultKind, Injector};
use super::layout::Sensor;
use super::prepare::Prepared;
use crate::datasets::quadrotor::IMU_RATE_HZ;

/// Anything but all-Ok on one side.
fn alarmed(s: &SensorStatus) -> bool {
    s.detected_not_isolated || s.states[..s.n].iter().any(|&st| st != ChannelState::Ok)
}

fn excluded_mask(s: &SensorStatus) -> u32 {
    s.states[..s.n]
        .iter()
        .enumerate()
        .filter(|(_, st)| **st == ChannelState::Excluded)
        .fold(0, |m, (i, _)| m | 1 << i)
}

/// The lowest channel excluded now that was not in `before`.
fn newly_excluded(s: &SensorStatus, before: u32) -> Option<usize> {
    let new = excluded_mask(s) & !before;
    (new != 0).then(|| new.trailing_zeros() as usize)
}

/// What one faulted run showed.
#[derive(Debug, Clone, Copy)]
pub struct Outcome {
    /// Faulty samples processed when first flagged (1 = on the first faulty sample).
    pub detected: Option<usize>,
    pub isolated: Option<(usize, usize)>,
}

fn full_valid(n: usize) -> u32 {
    let m = (1u32 << n) - 1;
    m | m << rins_fusion::fuser::ACCEL_MASK_SHIFT
}

/// One injected fault: its kind, the faulty channel and type, and the reference σ in counts.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FaultRun {
    pub sensor: Sensor,
    pub channel: usize,
    pub kind: FaultKind,
    pub sigma_counts: f64,
}

/// Runs the fuser from the fault-free `snapshot` at row `t0` with `fault` injected from there on,
/// until the fuser excludes a channel or the flight ends.
pub(crate) fn run_fault(snapshot: &ImuFuser, p: &Prepared, t0: usize, fault: FaultRun) -> Outcome {
    let FaultRun {
        sensor,
        channel: ch,
        kind,
        sigma_counts,
    } = fault;
    let mut fuser = snapshot.clone();
    // Exclusions the fault-free run had already latched do not count for this fault.
    let before = match sensor {
        Sensor::Gyro => excluded_mask(fuser.monitor(ipc_types::SensorType::Gyro).status()),
        Sensor::Accel => excluded_mask(fuser.monitor(ipc_types::SensorType::Accel).status()),
    };
    let mut out = Outcome {
        detected: None,
        isolated: None,
    };
    let valid_all = full_valid(p.n);
    let shift = match sensor {
        Sensor::Gyro => 0,
        Sensor::Accel => rins_fusion::fuser::ACCEL_MASK_SHIFT,
    };
    let frozen = match sensor {
        Sensor::Gyro => p.gyro[t0.saturating_sub(1)][ch],
        Sensor::Accel => p.accel[t0.saturating_sub(1)][ch],
    };
    // The noise differs from channel to channel and type to type, and is the same in every run.
    let seed = (t0 as u64) << 16 | (ch as u64) << 1 | sensor as u64;
    let mut injector = Injector::new(kind, sigma_counts, IMU_RATE_HZ, frozen, seed);
    let valid = if injector.valid() {
        valid_all
    } else {
        valid_all & !(1 << (ch as u32 + shift))
    };
    for k in t0..p.gyro.len() {
        let mut g = p.gyro[k];
        let mut a = p.accel[k];
        let target = match sensor {
            Sensor::Gyro => &mut g,
            Sensor::Accel => &mut a,
        };
        target[ch] = injector.apply(k - t0, target[ch]);
        let fused = fuser.fuse(&g[..p.n], &a[..p.n], valid);
        let status = match sensor {
            Sensor::Gyro => &fused.gyro_status,
            Sensor::Accel => &fused.accel_status,
        };
        let d = k - t0 + 1;
        if out.detected.is_none() && alarmed(status) {
            out.detected = Some(d);
        }
        if let Some(x) = newly_excluded(status, before) {
            out.isolated = Some((d, x));
            break;
        }
    }
    out
}

/// Only channels held Suspect for a genuine over-range (the others put the true value beyond
/// the converter's range): a correct indication of the data, not a false alarm.
fn over_range_only(s: &SensorStatus) -> bool {
    !s.detected_not_isolated
        && s.states[..s.n]
            .iter()
            .zip(&s.reasons[..s.n])
            .all(|(st, r)| {
                *st == ChannelState::Ok
                    || (*st == ChannelState::Suspect && *r == ipc_types::FaultReason::Saturated)
            })
}

/// Fault-free run: false alarms; returns the fuser state at `t0`.
pub(crate) struct CleanRun {
    /// Episodes of genuine over-range per type (see [`over_range_only`]), not false alarms.
    pub over_range: [usize; 2],
    /// Alarm episodes (transitions into an alarmed state) per type.
    pub episodes: [usize; 2],
    /// Samples alarmed per type.
    pub samples: [usize; 2],
    /// Largest T / threshold after learning, per type.
    pub max_t_ratio: [f64; 2],
    /// Largest noise-outlier margin after learning, per type (above 1 = a noisy channel).
    pub max_noise_peak: [f64; 2],
    /// Each alarm episode's sensor, first row and reason.
    pub starts: Vec<(Sensor, usize, &'static str)>,
    pub snapshot: Option<ImuFuser>,
}

pub(crate) fn run_clean(
    fusion: &FusionConfig,
    lsb: [f64; 2],
    p: &Prepared,
    t0: usize,
) -> Result<CleanRun> {
    let mut fuser = ImuFuser::new(fusion, lsb[0], lsb[1]).map_err(|e| anyhow!("fusion: {e}"))?;
    let valid = full_valid(p.n);
    let mut run = CleanRun {
        over_range: [0; 2],
        episodes: [0; 2],
        samples: [0; 2],
        max_t_ratio: [0.0; 2],
        max_noise_peak: [0.0; 2],
        starts: Vec::new(),
        snapshot: None,
    };
    let mut was = [false; 2];
    let mut was_over_range = [false; 2];
    for k in 0..p.gyro.len() {
        if k == t0 {
            run.snapshot = Some(fuser.clone());
        }
        let fused = fuser.fuse(&p.gyro[k][..p.n], &p.accel[k][..p.n], valid);
        for (j, s) in [&fused.gyro_status, &fused.accel_status]
            .into_iter()
            .enumerate()
        {
            let over_range = alarmed(s) && over_range_only(s);
            run.over_range[j] += usize::from(over_range && !was_over_range[j]);
            was_over_range[j] = over_range;
            let a = alarmed(s) && !over_range;
            run.samples[j] += usize::from(a);
            run.episodes[j] += usize::from(a && !was[j]);
            if a && !was[j] {
                let why = if s.detected_not_isolated {
                    "detected-not-isolated"
                } else {
                    s.reasons[..s.n]
                        .iter()
                        .find(|r| **r != ipc_types::FaultReason::None)
                        .map_or("?", |r| r.name())
                };
                run.starts.push((Sensor::ALL[j], k, why));
            }
            was[j] = a;
            if !s.learning && s.threshold.is_finite() {
                run.max_t_ratio[j] = run.max_t_ratio[j].max(s.test_statistic / s.threshold);
            }
            if !s.learning {
                run.max_noise_peak[j] = run.max_noise_peak[j].max(s.noise_peak);
            }
        }
    }
    Ok(run)
}
