//! `rins probe --port PATH [--baud B] [--seconds S] [--scan] [--json]`: listens to a serial device
//! with acquisition's driver and decoder and says what is on the line, or, with `--scan`, which
//! standard baud rate carries the device's frames. Needs no running pipeline. With `--gnss`, the
//! device is a GNSS receiver: see `probe_gnss`.

use anyhow::{Result, bail};
use rins_acquisition::config::AcquisitionConfig;
use rins_acquisition::listen::listen;
use rins_protocol::{LineReport, scan_outcome};
use serde_json::{Value, json};

use crate::cli::ProbeArgs;

/// The rates every UART driver offers, tried in this order.
const STANDARD_BAUDS: [u32; 8] = [
    9600, 19_200, 38_400, 57_600, 115_200, 230_400, 460_800, 921_600,
];

/// Faster rates many USB adapters offer; skipped, with a note, where the driver refuses them.
const FAST_BAUDS: [u32; 3] = [1_500_000, 2_000_000, 3_000_000];

/// Longest listen, s.
const MAX_SECONDS: f64 = 3600.0;

pub fn run(args: &ProbeArgs) -> Result<()> {
    // A receiver sends one burst a second: a scan listens long enough to catch one whole.
    let default_s = match (args.scan, args.gnss) {
        (true, true) => 2.0,
        (true, false) => 1.0,
        (false, _) => 3.0,
    };
    let seconds = args.seconds.unwrap_or(default_s);
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= MAX_SECONDS) {
        bail!("--seconds {seconds}: must be > 0 and <= {MAX_SECONDS}");
    }
    let port = args.port.to_string_lossy().into_owned();
    if args.gnss && args.scan {
        return super::probe_gnss::scan(&port, seconds, args.json);
    }
    if args.gnss {
        return super::probe_gnss::run(&port, args.baud, seconds, args.json);
    }
    if args.scan {
        return scan(&port, seconds, args.json);
    }
    let baud = args.baud.unwrap_or(AcquisitionConfig::default().baud);
    if !args.json {
        eprintln!("listening to {port} at {baud} baud for {seconds} s ...");
    }
    let report = listen(&port, baud, seconds)?;
    if args.json {
        let mut v = report_json(&report);
        v["port"] = json!(port);
        v["baud"] = json!(baud);
        v["verdict"] = json!(report.verdict_line());
        println!("{v}");
    } else {
        print!("{}", report_text(&port, baud, &report));
    }
    Ok(())
}

/// Listens at every standard rate, then the fast ones the driver accepts; a device that cannot be
/// opened at all fails at the first rate, naming it and the system's reason.
fn scan(port: &str, seconds: f64, json_out: bool) -> Result<()> {
    let mut results = Vec::new();
    let mut skipped = Vec::new();
    for baud in STANDARD_BAUDS.into_iter().chain(FAST_BAUDS) {
        if !json_out {
            eprintln!("listening to {port} at {baud} baud for {seconds} s ...");
        }
        match listen(port, baud, seconds) {
            Ok(report) => results.push((baud, report)),
            Err(e) if FAST_BAUDS.contains(&baud) => skipped.push((baud, format!("{e:#}"))),
            Err(e) => return Err(e),
        }
    }
    let outcome = scan_outcome(&results);
    if json_out {
        let rates = super::probe_rates::rates_json(&results, report_json);
        let skipped: Vec<Value> = skipped
            .iter()
            .map(|(baud, why)| json!({ "baud": baud, "error": why }))
            .collect();
        let v = json!({
            "port": port,
            "seconds_per_rate": seconds,
            "rates": rates,
            "skipped": skipped,
            "best_baud": outcome.best_baud,
            "verdict": outcome.verdict,
        });
        println!("{v}");
    } else {
        println!("port {port}, {seconds} s at each rate");
        println!(
            "{:>8}  {:>9}  {:>7}  {:>5}  {:>9}  {:>9}  last error",
            "baud", "bytes", "frames", "crc", "malformed", "discarded"
        );
        for (baud, r) in &results {
            println!(
                "{baud:>8}  {:>9}  {:>7}  {:>5}  {:>9}  {:>9}  {}",
                r.bytes,
                r.valid_frames,
                r.crc_errors,
                r.malformed,
                r.discarded_bytes,
                r.last_error.name()
            );
        }
        for (baud, why) in &skipped {
            println!("{baud:>8}  not accepted: {why}");
        }
        println!("verdict: {}", outcome.verdict);
    }
    Ok(())
}

/// The report's counters as JSON, names rather than codes.
fn report_json(r: &LineReport) -> Value {
    let mut frames = serde_json::Map::new();
    for t in &r.types {
        frames.insert(
            t.frame_type.name().into(),
            json!({ "count": t.frames, "hz": t.hz, "arrival_hz": t.arrival_hz }),
        );
    }
    json!({
        "seconds": r.seconds,
        "bytes": r.bytes,
        "bytes_per_s": r.bytes as f64 / r.seconds,
        "valid_frames": r.valid_frames,
        "frames": frames,
        "crc_errors": r.crc_errors,
        "malformed": r.malformed,
        "discarded_bytes": r.discarded_bytes,
        "last_decode_error": r.last_error.name(),
    })
}

/// The report as the operator reads it.
fn report_text(port: &str, baud: u32, r: &LineReport) -> String {
    let frames = if r.types.is_empty() {
        "none".to_string()
    } else {
        r.types
            .iter()
            .map(|t| format!("{} {} ({:.0} Hz)", t.frame_type.name(), t.frames, t.hz))
            .collect::<Vec<_>>()
            .join(", ")
    };
    format!(
        "port        {port} at {baud} baud, {:.1} s\n\
         bytes       {} ({:.0} B/s)\n\
         frames      {frames}\n\
         crc errors  {}\n\
         malformed   {}\n\
         discarded   {} bytes\n\
         last error  {}\n\
         verdict: {}\n",
        r.seconds,
        r.bytes,
        r.bytes as f64 / r.seconds,
        r.crc_errors,
        r.malformed,
        r.discarded_bytes,
        r.last_error.name(),
        r.verdict_line()
    )
}
