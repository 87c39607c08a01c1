//! `rins bench rates`: the whole pipeline on the simulator at each IMU rate, once fault-free (false
//! alarms, drops, CPU, end-to-end latency) and with injected faults (detected, isolated, how fast).
//!
//! Each run is `rins up --imu-rate R --duration D --json` on the bench's own deployment (prefix
//! and root); its summary is the last line of its stdout. During the fault-free run the
//! end-to-end latency is measured from the header stamps as `rins latency` does. The faults are
//! a dead gyro and a stuck accelerometer (one run: different sensor types do not interfere) and a
//! gyro bias of [`BIAS_SIGMAS`] times the per-sample σ at that rate (its own run: after an
//! exclusion the gyros could no longer isolate it).

use std::io::Read;
use std::process::Stdio;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use rins_navigator::lanes::NavSubscriber;
use rins_runtime::ipc::create_node;
use rins_runtime::shutdown::Shutdown;
use serde::Serialize;
use serde_json::Value;

use super::{ChildGuard, Deployment};
use crate::cli::BenchRatesArgs;
use crate::commands::latency::{END_TO_END, measure_hops};
use rins::config::{self, MAX_IMU_RATE_HZ, MIN_IMU_RATE_HZ, RinsConfig};

/// The injected gyro bias in per-sample σ of the channel at the run's rate.
pub const BIAS_SIGMAS: f64 = 10.0;
/// Shortest run the bench accepts, s: start-up, alignment and a fault need this much.
pub const MIN_DURATION_S: f64 = 8.0;

/// One fault the bench injects.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InjectedFault {
    /// `gyro1`, `accel2`, ...
    pub channel: String,
    /// `dead`, `stuck`, `bias`.
    pub kind: String,
    /// The fault's parameter (the bias, rad/s), if any.
    pub param: Option<f64>,
    /// Device time of the injection, s.
    pub at_s: f64,
}

impl InjectedFault {
    /// The `--inject` specification.
    pub fn spec(&self) -> String {
        match self.param {
            Some(p) => format!("{}:{}={p}@{}s", self.channel, self.kind, self.at_s),
            None => format!("{}:{}@{}s", self.channel, self.kind, self.at_s),
        }
    }
}

/// The fault runs at one rate: each inner list is one `rins up`. `gyro_sigma_rps` is the
/// per-sample gyro σ at the rate; the faults come at 40 % and 50 % of the run, after the start-up
/// learning at every rate.
pub fn fault_runs(duration_s: f64, gyro_sigma_rps: f64) -> Vec<Vec<InjectedFault>> {
    let at = |fraction: f64| (duration_s * fraction * 10.0).round() / 10.0;
    let fault = |channel: &str, kind: &str, param: Option<f64>, at_s: f64| InjectedFault {
        channel: channel.into(),
        kind: kind.into(),
        param,
        at_s,
    };
    // Rounded up to 4 significant digits: at least BIAS_SIGMAS σ.
    let bias = round_up_4(BIAS_SIGMAS * gyro_sigma_rps);
    vec![
        vec![
            fault("gyro1", "dead", None, at(0.4)),
            fault("accel2", "stuck", None, at(0.5)),
        ],
        vec![fault("gyro3", "bias", Some(bias), at(0.5))],
    ]
}

fn round_up_4(v: f64) -> f64 {
    if !(v.is_finite() && v > 0.0) {
        return v;
    }
    let scale = 10f64.powi(3 - v.log10().floor() as i32);
    (v * scale).ceil() / scale
}

/// How one injected fault fared.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FaultOutcome {
    /// What was injected.
    #[serde(flatten)]
    pub fault: InjectedFault,
    /// Fusion declared it.
    pub detected: bool,
    /// Fusion excluded the channel.
    pub isolated: bool,
    /// Injection to detection, ms.
    pub detection_ms: Option<f64>,
    /// Injection to isolation, ms.
    pub isolation_ms: Option<f64>,
    /// Why the channel was excluded (`missing`, `stuck`, `stationary-reference`, ...).
    pub reason: Option<String>,
}

/// The outcome of `fault` in a summary's `faults` list (not detected when it is not there).
pub fn outcome(summary: &Value, fault: &InjectedFault) -> FaultOutcome {
    let entry = summary["faults"].as_array().and_then(|list| {
        list.iter()
            .find(|f| f["channel"] == fault.channel.as_str() && f["kind"] == fault.kind.as_str())
    });
    let time = |key: &str| entry.and_then(|f| f[key].as_f64());
    let since = |t: Option<f64>| {
        t.map(|t| ((t - time("injected_at_s").unwrap_or(fault.at_s)) * 1e3).max(0.0))
    };
    let detected_at = time("detected_at_s");
    let isolated_at = time("isolated_at_s");
    FaultOutcome {
        fault: fault.clone(),
        detected: detected_at.is_some(),
        isolated: isolated_at.is_some(),
        detection_ms: since(detected_at),
        isolation_ms: since(isolated_at),
        reason: entry.and_then(|f| f["reason"].as_str().map(String::from)),
    }
}

/// One rate's row of `rins bench rates --json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RateRow {
    /// IMU rate, Hz.
    pub rate_hz: f64,
    /// Per-sample gyro σ at this rate (from the configured density), rad/s.
    pub gyro_sigma_rps: f64,
    /// Per-sample accelerometer σ at this rate, m/s².
    pub accel_sigma_mps2: f64,
    /// Fault-free run: persistent fault alarms.
    pub false_alarms: u64,
    /// Fault-free run: frames dropped anywhere along the pipeline.
    pub dropped: u64,
    /// Fault-free run: frames lost on the serial line.
    pub lost_frames: u64,
    /// Fault-free run: IMU frames fused.
    pub frames: u64,
    /// Fault-free run: the pipeline's CPU, % of one core.
    pub pipeline_cpu_pct: f64,
    /// Fault-free run: serial receive to navigation state published, µs (`None`: not measured).
    pub e2e_p50_us: Option<f64>,
    /// See `e2e_p50_us`.
    pub e2e_p99_us: Option<f64>,
    /// False alarms of the fault runs (alarms on channels no fault was injected into).
    pub fault_run_false_alarms: u64,
    /// Every injected fault.
    pub faults: Vec<FaultOutcome>,
}

impl RateRow {
    /// No false alarm, nothing dropped or lost, every fault detected and isolated.
    pub fn passed(&self) -> bool {
        self.false_alarms == 0
            && self.fault_run_false_alarms == 0
            && self.dropped == 0
            && self.lost_frames == 0
            && self.faults.iter().all(|f| f.detected && f.isolated)
    }
}

fn count(summary: &Value, key: &str) -> u64 {
    summary[key].as_u64().unwrap_or(0)
}

/// The summary's `false_alarms`: the watchdog counts alarms on channels without an injected
/// fault.
fn false_alarms(summary: &Value) -> u64 {
    count(summary, "false_alarms")
}

pub fn run_rates(args: &BenchRatesArgs) -> Result<()> {
    let d = args.duration;
    if !(d.is_finite() && (MIN_DURATION_S..=3600.0).contains(&d)) {
        bail!("--duration {d}: must be {MIN_DURATION_S}..=3600 s");
    }
    if args.rates.is_empty() {
        bail!("--rates: give at least one rate");
    }
    for &r in &args.rates {
        if !(r.is_finite() && (MIN_IMU_RATE_HZ..=MAX_IMU_RATE_HZ).contains(&r)) {
            bail!("--rates {r}: each must be {MIN_IMU_RATE_HZ}..={MAX_IMU_RATE_HZ} Hz");
        }
    }
    let base = config::load(args.config.as_deref())?;
    let shutdown = Shutdown::install()?;
    let total = args.rates.len() * 3;
    let mut step = 0;
    let mut rows = Vec::with_capacity(args.rates.len());
    for &rate in &args.rates {
        let mut cfg = base.clone();
        cfg.set_imu_rate(rate)?;
        let (gyro_sigma, accel_sigma) = per_sample_sigmas(&cfg)?;
        step += 1;
        progress(step, total, rate, "fault-free run with latency");
        let deployment = Deployment::new("r")?;
        let (summary, e2e) = run_up(&deployment, args, rate, &[], true, &shutdown)?;
        drop(deployment);
        let mut row = RateRow {
            rate_hz: rate,
            gyro_sigma_rps: gyro_sigma,
            accel_sigma_mps2: accel_sigma,
            false_alarms: false_alarms(&summary),
            dropped: count(&summary, "dropped"),
            lost_frames: count(&summary, "lost_frames"),
            frames: count(&summary, "frames"),
            pipeline_cpu_pct: summary["pipeline_cpu_pct"].as_f64().unwrap_or(f64::NAN),
            e2e_p50_us: e2e.map(|e| e.0),
            e2e_p99_us: e2e.map(|e| e.1),
            fault_run_false_alarms: 0,
            faults: Vec::new(),
        };
        for faults in fault_runs(d, gyro_sigma) {
            step += 1;
            let names: Vec<String> = faults.iter().map(InjectedFault::spec).collect();
            progress(step, total, rate, &names.join(" "));
            let deployment = Deployment::new("f")?;
            let (summary, _) = run_up(&deployment, args, rate, &names, false, &shutdown)?;
            row.fault_run_false_alarms += false_alarms(&summary);
            row.faults
                .extend(faults.iter().map(|f| outcome(&summary, f)));
        }
        if args.json {
            println!("{}", serde_json::to_string(&row)?);
        }
        rows.push(row);
    }
    if !args.json {
        print_table(&rows);
    }
    Ok(())
}

/// The per-sample white-noise σ of the first gyro and accelerometer channel at the
/// configuration's rate (the one derivation fusion uses).
fn per_sample_sigmas(cfg: &RinsConfig) -> Result<(f64, f64)> {
    let first = |sensor| {
        cfg.fusion
            .channel_sigmas(sensor)
            .map_err(|e| anyhow::anyhow!("{}", e.within("fusion")))?
            .first()
            .copied()
            .context("no channel")
    };
    Ok((
        first(ipc_types::SensorType::Gyro)?,
        first(ipc_types::SensorType::Accel)?,
    ))
}

fn progress(step: usize, total: usize, rate: f64, what: &str) {
    eprintln!("rins bench rates: [{step}/{total}] {rate} Hz: {what}");
}

/// Runs `rins up` at `rate` with `inject`; with `latency`, measures the end-to-end latency while
/// it runs. Returns its summary and (p50, p99) µs.
fn run_up(
    deployment: &Deployment,
    args: &BenchRatesArgs,
    rate: f64,
    inject: &[String],
    latency: bool,
    shutdown: &Shutdown,
) -> Result<(Value, Option<(f64, f64)>)> {
    let duration = format!("{}", args.duration);
    let rate = format!("{rate}");
    let mut argv: Vec<&str> = vec!["up", "--duration", &duration, "--imu-rate", &rate, "--json"];
    if let Some(path) = args.config.as_deref().and_then(|p| p.to_str()) {
        argv.extend(["--config", path]);
    }
    for spec in inject {
        argv.extend(["--inject", spec.as_str()]);
    }
    let child = deployment
        .command(&argv)?
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .context("cannot start rins up")?;
    let mut guard = ChildGuard {
        child,
        grace: Duration::from_secs(30),
    };
    let mut stdout = guard.child.stdout.take().context("rins up's stdout")?;
    let e2e = if latency {
        measure_latency(deployment, args.duration, &mut guard, shutdown)?
    } else {
        None
    };
    // The run ends by itself after its duration (plus start-up); its summary follows.
    let limit = Instant::now() + Duration::from_secs_f64(args.duration * 3.0 + 120.0);
    loop {
        if shutdown.requested() {
            bail!("stopped");
        }
        if guard.child.try_wait()?.is_some() {
            break;
        }
        if Instant::now() > limit {
            bail!(
                "rins up at {rate} Hz did not end within {} s",
                args.duration * 3.0 + 120.0
            );
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let mut text = String::new();
    stdout
        .read_to_string(&mut text)
        .context("rins up's summary")?;
    let last = text.lines().last().unwrap_or("");
    let summary: Value = serde_json::from_str(last)
        .with_context(|| format!("rins up at {rate} Hz: no JSON summary (last line {last:?})"))?;
    Ok((summary, e2e))
}

/// Waits for navigation, a 2 s warm-up, then measures the end-to-end latency over a third of the
/// run (`None` when the run gave no navigation output to measure).
fn measure_latency(
    deployment: &Deployment,
    duration_s: f64,
    guard: &mut ChildGuard,
    shutdown: &Shutdown,
) -> Result<Option<(f64, f64)>> {
    let node = create_node("bench-rates", &deployment.settings)?;
    let mut nav = NavSubscriber::new(&node)?;
    let until = Instant::now() + Duration::from_secs_f64(duration_s + 60.0);
    loop {
        if shutdown.requested() {
            bail!("stopped");
        }
        if guard.child.try_wait()?.is_some() || Instant::now() > until {
            return Ok(None);
        }
        nav.wait(Duration::from_millis(100))?;
        if nav.receive()?.is_some() {
            break;
        }
    }
    drop(nav);
    std::thread::sleep(Duration::from_secs(2));
    // The tail is not reported per rate: a recorder of no capacity keeps nothing.
    let mut tail = crate::commands::latency::TailRecorder::new(0);
    let hops = measure_hops(
        &node,
        Duration::from_secs_f64(duration_s / 3.0),
        shutdown,
        &mut tail,
    )?;
    let e2e = &hops[END_TO_END];
    Ok((e2e.samples > 0).then_some((e2e.p50_us, e2e.p99_us)))
}

fn print_table(rows: &[RateRow]) {
    println!(
        "{:>7} {:>10} {:>7} {:>7} {:>6} {:>7} {:>8} {:>8}  faults (detected/isolated ms)",
        "Hz", "frames", "alarms", "dropped", "lost", "CPU %", "e2e p50", "e2e p99"
    );
    let us = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.0}"));
    let ms = |v: Option<f64>| v.map_or("no".to_string(), |v| format!("{v:.0}"));
    for r in rows {
        let faults: Vec<String> = r
            .faults
            .iter()
            .map(|f| {
                format!(
                    "{}:{} {}/{}",
                    f.fault.channel,
                    f.fault.kind,
                    ms(f.detection_ms),
                    ms(f.isolation_ms)
                )
            })
            .collect();
        println!(
            "{:>7} {:>10} {:>7} {:>7} {:>6} {:>7.1} {:>8} {:>8}  {}",
            r.rate_hz,
            r.frames,
            r.false_alarms + r.fault_run_false_alarms,
            r.dropped,
            r.lost_frames,
            r.pipeline_cpu_pct,
            us(r.e2e_p50_us),
            us(r.e2e_p99_us),
            faults.join(", ")
        );
    }
    let failed: Vec<String> = rows
        .iter()
        .filter(|r| !r.passed())
        .map(|r| r.rate_hz.to_string())
        .collect();
    if failed.is_empty() {
        println!("every rate: no false alarm, nothing dropped, every fault detected and isolated");
    } else {
        println!("NOT clean at {} Hz", failed.join(", "));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bias_is_ten_sigma_at_the_rate_and_faults_come_after_the_start() {
        let runs = fault_runs(25.0, 0.005519);
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0][0].spec(), "gyro1:dead@10s");
        assert_eq!(runs[0][1].spec(), "accel2:stuck@12.5s");
        assert_eq!(runs[1][0].spec(), "gyro3:bias=0.05519@12.5s");
        // √8 larger at 8 kHz.
        let fast = fault_runs(25.0, 0.005519 * 8f64.sqrt());
        assert_eq!(fast[1][0].param, Some(0.1562)); // 0.156101 rounded up
    }

    #[test]
    fn an_outcome_is_read_from_the_summary() {
        let summary: Value = serde_json::from_str(
            r#"{"faults":[{"channel":"gyro1","kind":"dead","injected_at_s":10.0,
                "detected_at_s":10.002,"isolated_at_s":10.5,"reason":"missing"}]}"#,
        )
        .unwrap();
        let runs = fault_runs(25.0, 0.005);
        let o = outcome(&summary, &runs[0][0]);
        assert!(o.detected && o.isolated);
        assert!((o.detection_ms.unwrap() - 2.0).abs() < 1e-6);
        assert!((o.isolation_ms.unwrap() - 500.0).abs() < 1e-6);
        assert_eq!(o.reason.as_deref(), Some("missing"));
        let missing = outcome(&summary, &runs[0][1]);
        assert!(!missing.detected && !missing.isolated && missing.detection_ms.is_none());
    }
}
