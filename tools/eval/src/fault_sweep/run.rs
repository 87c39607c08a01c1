//! One run of the sweep: the chain forked at an injection time, one fault set, followed to the
//! end of the window; and the clean run that counts false alarms.

use ipc_types::{ChannelState, FaultReason, Integrity};
use rins_navigator::NavOutput;
use rins_sim::{InertialSensor, TruthSample};
use serde::Serialize;

use super::config::{Prepared, SweepChannel, SweepFault};
use crate::mc::McError;
use crate::mc::NavErrors;
use crate::mc::pipeline::{FusedSample, Pipeline};
use crate::mc::run::attitude_difference_deg;

/// What one fault did, times relative to the first faulty sample, s.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FaultRun {
    /// Injection time, s of device time.
    pub inject_at_s: f64,
    /// `gyro2`, `accel0`, ...; `-` for the fault-free reference of the same window.
    pub channel: String,
    /// `bias`, `ramp`, `noise`; `none` for the reference.
    pub kind: &'static str,
    /// The fault in σ, as the table shows it (`bias 20σ`).
    pub label: String,
    /// The fault's size in σ of the channel (the ramp: what it reaches after its time; the
    /// noise: its factor); `None` for the reference.
    pub size_sigma: Option<f64>,
    /// The channel's per-sample σ fault detection uses, rad/s or m/s².
    pub sigma: Option<f64>,
    /// The simulator's fault parameter: bias (rad/s, m/s²), ramp rate (per s), added noise σ.
    pub param: Option<f64>,
    /// First sample with the channel not Ok or a detected-not-isolated fault on its sensor type.
    pub detected_after_s: Option<f64>,
    /// First sample with the channel excluded.
    pub isolated_after_s: Option<f64>,
    /// Fusion's reason for the exclusion.
    pub reason: Option<&'static str>,
    /// The first other channel of the same type fusion excluded instead (a wrong isolation: the
    /// faulty channel stays in the solution), and when.
    pub wrongly_excluded: Option<String>,
    /// When it was excluded, s after the injection.
    pub wrongly_excluded_after_s: Option<f64>,
    /// Largest attitude error against the truth after the injection, degrees.
    pub att_err_deg_max: Option<f64>,
    /// The same over the samples whose integrity was ok.
    pub att_err_deg_max_while_ok: Option<f64>,
    /// Largest tilt error (roll and pitch, √(Δφ² + Δθ²)) of the samples whose integrity was ok,
    /// degrees: the attitude error without the heading's.
    pub tilt_err_deg_max_while_ok: Option<f64>,
    /// Largest horizontal position error of the samples whose integrity was ok, m.
    pub horiz_err_m_max_while_ok: Option<f64>,
    /// Share of the samples after the injection with integrity ok (a tick without a solution is
    /// not ok), 0..=1.
    pub ok_share: f64,
    /// Share with the navigator reporting `sensor-fault-unisolated`, 0..=1.
    pub unisolated_share: f64,
}

/// The fault-free flight from the start to the end of the latest window.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CleanRun {
    /// End of the flight, s of device time.
    pub duration_s: f64,
    /// Episodes of a sensor type flagged (a channel leaving Ok, or a fault detected but not
    /// isolated) with no fault injected: false alarms.
    pub false_alarms: usize,
    /// Time some channel was flagged, s.
    pub flagged_s: f64,
    /// Time of the first false alarm, s of device time.
    pub first_false_alarm_s: Option<f64>,
    /// Largest attitude error from the alignment on, degrees.
    pub att_err_deg_max: Option<f64>,
    /// The same over the samples whose integrity was ok.
    pub att_err_deg_max_while_ok: Option<f64>,
    /// Largest tilt error of the samples whose integrity was ok, degrees.
    pub tilt_err_deg_max_while_ok: Option<f64>,
    /// Share of the samples from the alignment on with integrity ok, 0..=1.
    pub ok_share: f64,
}

fn max_opt(a: Option<f64>, b: f64) -> Option<f64> {
    Some(a.map_or(b, |a| a.max(b)))
}

/// Errors and integrity over a span of samples.
#[derive(Debug, Clone, Copy, Default)]
struct ErrorTrack {
    ticks: u64,
    ok_ticks: u64,
    unisolated_ticks: u64,
    att_max: Option<f64>,
    att_max_ok: Option<f64>,
    tilt_max_ok: Option<f64>,
    horiz_max_ok: Option<f64>,
}

impl ErrorTrack {
    fn push(&mut self, solution: Option<&NavOutput>, truth: &TruthSample) {
        self.ticks += 1;
        let Some(nav) = solution else {
            return;
        };
        let att = attitude_difference_deg(&nav.quaternion, &truth.quaternion);
        self.att_max = max_opt(self.att_max, att);
        if nav.integrity_reasons & ipc_types::integrity_reason::SENSOR_FAULT_UNISOLATED != 0 {
            self.unisolated_ticks += 1;
        }
        if nav.integrity == Integrity::Ok {
            self.ok_ticks += 1;
            self.att_max_ok = max_opt(self.att_max_ok, att);
            let e = NavErrors::of(nav, truth);
            self.tilt_max_ok = max_opt(self.tilt_max_ok, e.roll_deg.hypot(e.pitch_deg));
            self.horiz_max_ok = max_opt(self.horiz_max_ok, e.horizontal_m());
        }
    }

    fn share(&self, n: u64) -> f64 {
        if self.ticks == 0 {
            0.0
        } else {
            n as f64 / self.ticks as f64
        }
    }
}

fn status_of(fused: &FusedSample, sensor: InertialSensor) -> &rins_fusion::SensorStatus {
    match sensor {
        InertialSensor::Gyro => &fused.gyro_status,
        InertialSensor::Accel => &fused.accel_status,
    }
}

/// A sensor type is flagged: a channel not Ok, or a fault detected but not isolated.
fn type_flagged(status: &rins_fusion::SensorStatus) -> bool {
    status.detected_not_isolated
        || status.states[..status.n]
            .iter()
            .any(|&s| s != ChannelState::Ok)
}

/// The clean chain stepped to `tick` (exclusive): the state every run injected then forks from.
pub(crate) fn base_at(prepared: &Prepared, tick: u64) -> Result<Pipeline, McError> {
    let mut pipeline = Pipeline::from_parts(
        &prepared.sim,
        &prepared.fusion,
        &prepared.altimeter,
        &prepared.navigator,
        prepared.seed,
    )?;
    for _ in 0..tick {
        pipeline.step();
    }
    Ok(pipeline)
}

/// One run: `base` (stepped to `inject_tick`) forked, `fault` set on `channel` (none: the
/// reference), flown for the window.
pub(crate) fn run_fault(
    prepared: &Prepared,
    base: &Pipeline,
    inject_tick: u64,
    fault: Option<(SweepChannel, SweepFault)>,
) -> Result<FaultRun, McError> {
    let mut pipeline = base.clone();
    let tick_s = prepared.tick_s;
    let mut row = FaultRun {
        inject_at_s: inject_tick as f64 * tick_s,
        channel: "-".into(),
        kind: "none",
        label: "none".into(),
        size_sigma: None,
        sigma: None,
        param: None,
        detected_after_s: None,
        isolated_after_s: None,
        reason: None,
        wrongly_excluded: None,
        wrongly_excluded_after_s: None,
        att_err_deg_max: None,
        att_err_deg_max_while_ok: None,
        tilt_err_deg_max_while_ok: None,
        horiz_err_m_max_while_ok: None,
        ok_share: 0.0,
        unisolated_share: 0.0,
    };
    if let Some((channel, f)) = fault {
        let (fdi_sigma, sim_sigma) = prepared.sigmas(channel);
        pipeline.inject_fault(
            channel.sensor,
            channel.index,
            f.channel_fault(fdi_sigma, sim_sigma),
        )?;
        row.channel = channel.name();
        row.kind = f.kind();
        row.label = f.label();
        row.size_sigma = Some(match f {
            SweepFault::Bias { sigmas } | SweepFault::Ramp { sigmas, .. } => sigmas,
            SweepFault::Noise { factor } => factor,
        });
        row.sigma = Some(fdi_sigma);
        row.param = Some(f.param(fdi_sigma, sim_sigma));
    }
    let mut errors = ErrorTrack::default();
    for k in 0..prepared.window_ticks {
        pipeline.step();
        errors.push(pipeline.solution(), pipeline.truth());
        if let (Some((channel, _)), Some(fused)) = (fault, pipeline.fused()) {
            let status = status_of(fused, channel.sensor);
            let state = status.states[channel.index];
            let after_s = k as f64 * tick_s;
            if row.detected_after_s.is_none()
                && (state != ChannelState::Ok || status.detected_not_isolated)
            {
                row.detected_after_s = Some(after_s);
            }
            if row.isolated_after_s.is_none() && state == ChannelState::Excluded {
                row.isolated_after_s = Some(after_s);
                row.reason = Some(FaultReason::name(status.reasons[channel.index]));
            }
            if row.wrongly_excluded.is_none()
                && let Some(other) = (0..status.n)
                    .find(|&i| i != channel.index && status.states[i] == ChannelState::Excluded)
            {
                row.wrongly_excluded = Some(
                    SweepChannel {
                        sensor: channel.sensor,
                        index: other,
                    }
                    .name(),
                );
                row.wrongly_excluded_after_s = Some(after_s);
            }
        }
    }
    row.att_err_deg_max = errors.att_max;
    row.att_err_deg_max_while_ok = errors.att_max_ok;
    row.tilt_err_deg_max_while_ok = errors.tilt_max_ok;
    row.horiz_err_m_max_while_ok = errors.horiz_max_ok;
    row.ok_share = errors.share(errors.ok_ticks);
    row.unisolated_share = errors.share(errors.unisolated_ticks);
    Ok(row)
}

/// The fault-free flight for `ticks` ticks from the start: false alarms over all of it, errors
/// from the alignment on.
pub(crate) fn run_clean(prepared: &Prepared, ticks: u64) -> Result<CleanRun, McError> {
    let mut pipeline = base_at(prepared, 0)?;
    let tick_s = prepared.tick_s;
    let mut errors = ErrorTrack::default();
    let mut flagged_before = [false; 2];
    let mut false_alarms = 0;
    let mut flagged_ticks = 0u64;
    let mut first_false_alarm_s = None;
    for k in 0..ticks {
        pipeline.step();
        if pipeline.aligned() {
            errors.push(pipeline.solution(), pipeline.truth());
        }
        let Some(fused) = pipeline.fused() else {
            continue;
        };
        let flagged = [
            type_flagged(&fused.gyro_status),
            type_flagged(&fused.accel_status),
        ];
        for (now, before) in flagged.iter().zip(flagged_before.iter_mut()) {
            if *now && !*before {
                false_alarms += 1;
                first_false_alarm_s.get_or_insert(k as f64 * tick_s);
            }
            *before = *now;
        }
        flagged_ticks += u64::from(flagged[0] || flagged[1]);
    }
    Ok(CleanRun {
        duration_s: ticks as f64 * tick_s,
        false_alarms,
        flagged_s: flagged_ticks as f64 * tick_s,
        first_false_alarm_s,
        att_err_deg_max: errors.att_max,
        att_err_deg_max_while_ok: errors.att_max_ok,
        tilt_err_deg_max_while_ok: errors.tilt_max_ok,
        ok_share: errors.share(errors.ok_ticks),
    })
}
