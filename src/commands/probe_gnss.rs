//! `rins probe --gnss`: listens to a GNSS receiver's serial device with the gnss service's
//! decoder and says what is on the line, or, with `--scan`, which standard rate carries its
//! sentences and frames. Needs no running pipeline.

use std::io::Read;
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow};
use ipc_types::{GnssFix, GnssFixType, GnssProtocol};
use rins_gnss::config::GnssConfig;
use rins_gnss_protocol::decode::GnssDecoder;
use rins_runtime::clock::monotonic_ns;
use rins_serial_reader::port;
use serde_json::{Value, json};
use serialport::{ClearBuffer, SerialPort};

use super::probe_gnss_report::{
    EpochTally, GnssLineReport, best_rate, counters, receiver_time_text, scan_verdict,
};
use super::probe_rates::rates_json;

/// The rates receivers are set to, tried in this order: NMEA 0183's own 4800, then those every
/// UART driver offers.
const SCAN_BAUDS: [u32; 9] = [
    4800, 9600, 19_200, 38_400, 57_600, 115_200, 230_400, 460_800, 921_600,
];

/// Read timeout while listening: short, so a listen ends on time on a silent line and an epoch
/// whose last sentence was lost is closed while listening.
const READ_TIMEOUT: Duration = Duration::from_millis(50);

/// The listen of `rins probe --gnss` at `baud` (default: `gnss.baud`) for `seconds`.
pub fn run(port: &str, baud: Option<u32>, seconds: f64, json_out: bool) -> Result<()> {
    let baud = baud.unwrap_or(GnssConfig::default().baud);
    if !json_out {
        eprintln!("listening to GNSS receiver {port} at {baud} baud for {seconds} s ...");
    }
    let report = listen(port, baud, seconds)?;
    if json_out {
        let mut v = report_json(&report);
        v["port"] = json!(port);
        v["baud"] = json!(baud);
        println!("{v}");
    } else {
        print!("{}", report_text(port, baud, &report));
    }
    Ok(())
}

/// Listens at every rate of [`SCAN_BAUDS`] and names the one with the most used sentences and
/// frames; a device that cannot be opened fails at the first rate.
pub fn scan(port: &str, seconds: f64, json_out: bool) -> Result<()> {
    let mut results = Vec::new();
    for baud in SCAN_BAUDS {
        if !json_out {
            eprintln!("listening to GNSS receiver {port} at {baud} baud for {seconds} s ...");
        }
        results.push((baud, listen(port, baud, seconds)?));
    }
    let best = best_rate(results.iter().map(|(baud, r)| (*baud, r.used())));
    let verdict = scan_verdict(&results);
    if json_out {
        let rates = rates_json(&results, report_json);
        let v = json!({
            "port": port,
            "seconds_per_rate": seconds,
            "rates": rates,
            "best_baud": best,
            "verdict": verdict,
        });
        println!("{v}");
    } else {
        println!("port {port}, {seconds} s at each rate");
        println!(
            "{:>7}  {:>8}  {:>9}  {:>10}  {:>6}  {:>8}  {:>8}  protocols",
            "baud", "bytes", "sentences", "ubx frames", "epochs", "checksum", "unframed"
        );
        for (baud, r) in &results {
            let s = &r.stats;
            println!(
                "{baud:>7}  {:>8}  {:>9}  {:>10}  {:>6}  {:>8}  {:>8}  {}",
                s.bytes,
                s.sentences,
                s.ubx_frames,
                r.tally.epochs,
                s.checksum_errors,
                s.framing.unframed_bytes,
                protocols_text(r)
            );
        }
        println!("verdict: {verdict}");
    }
    Ok(())
}

/// Opens `path` at `baud`, drops what the driver buffered before (bytes sent at another rate, or
/// long ago), reads for `seconds` and reports what the decoder made of it; the epoch still being
/// assembled at the end is counted too. A hang-up ends the listen early; other read errors are
/// returned, naming the device.
fn listen(path: &str, baud: u32, seconds: f64) -> Result<GnssLineReport> {
    let mut port = port::open(path, baud, READ_TIMEOUT)?;
    port.clear(ClearBuffer::Input)
        .map_err(|e| anyhow!("cannot clear the input of {path}: {e}"))?;
    let mut decoder = GnssDecoder::new();
    let mut tally = EpochTally::default();
    let mut buf = [0u8; 4096];
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    while Instant::now() < end {
        match port.read(&mut buf) {
            // The other end hung up: nothing more will come.
            Ok(0) => break,
            Ok(n) => decoder.push(&buf[..n], monotonic_ns(), |f| tally.observe(&f)),
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                ) =>
            {
                decoder.close_quiet(monotonic_ns(), |f| tally.observe(&f));
            }
            Err(e) => return Err(anyhow!("cannot read serial device {path}: {e}")),
        }
    }
    decoder.flush(monotonic_ns(), |f| tally.observe(&f));
    Ok(GnssLineReport {
        seconds,
        stats: decoder.stats(),
        tally,
    })
}

/// "NMEA + UBX", or "none".
fn protocols_text(r: &GnssLineReport) -> String {
    let p = r.protocols();
    if p.is_empty() {
        "none".into()
    } else {
        p.join(" + ")
    }
}

/// The fix type's name ("3d", "rtk-fixed", ...), or the number this build does not know.
fn fix_type_name(fix: &GnssFix) -> String {
    GnssFixType::from_u8(fix.fix_type).map_or_else(|| fix.fix_type.to_string(), |t| t.name().into())
}

/// The protocol's name ("nmea", "ubx").
fn protocol_name(fix: &GnssFix) -> String {
    GnssProtocol::from_u8(fix.protocol)
        .map_or_else(|| fix.protocol.to_string(), |p| p.name().into())
}

/// A fix as JSON: degrees, metres (null for a height the receiver did not give).
fn fix_json(fix: &GnssFix) -> Value {
    json!({
        "time": receiver_time_text(fix),
        "receiver_time_us": fix.receiver_time_us,
        "latitude_deg": fix.latitude_rad.to_degrees(),
        "longitude_deg": fix.longitude_rad.to_degrees(),
        "altitude_m": fix.altitude_m.is_finite().then_some(fix.altitude_m),
        "satellites": fix.satellites,
        "fix_type": fix_type_name(fix),
        "protocol": protocol_name(fix),
    })
}

/// The report as one JSON object: every decoder counter under `counters`, by name.
fn report_json(r: &GnssLineReport) -> Value {
    let t = &r.tally;
    let mut counters_json = serde_json::Map::new();
    for (name, value) in counters(&r.stats) {
        counters_json.insert(name, json!(value));
    }
    json!({
        "seconds": r.seconds,
        "bytes": r.stats.bytes,
        "bytes_per_s": r.bytes_per_s(),
        "epochs": t.epochs,
        "epochs_3d": t.fix_3d,
        "epochs_2d": t.fix_2d,
        "epochs_no_fix": t.no_fix,
        "fix_hz": t.fix_hz(),
        "fix_arrival_hz": t.arrival_hz(),
        "protocols": r.protocols(),
        "lines_crlf": r.stats.framing.lines_crlf,
        "lines_lf": r.stats.framing.lines_lf,
        "counters": counters_json,
        "last_fix": t.last_fix.as_ref().map(fix_json),
        "verdict": r.verdict(),
    })
}

/// The report as the operator reads it.
fn report_text(port: &str, baud: u32, r: &GnssLineReport) -> String {
    let t = &r.tally;
    let s = &r.stats;
    let mut out = format!(
        "port        {port} at {baud} baud, {:.1} s\n\
         bytes       {} ({:.0} B/s)\n\
         epochs      {} published: {} with a 3-D fix, {} 2-D, {} without\n\
         protocols   {}\n\
         line ends   {} CR LF, {} LF\n",
        r.seconds,
        s.bytes,
        r.bytes_per_s(),
        t.epochs,
        t.fix_3d,
        t.fix_2d,
        t.no_fix,
        protocols_text(r),
        s.framing.lines_crlf,
        s.framing.lines_lf,
    );
    match &t.last_fix {
        Some(f) => {
            let altitude = if f.altitude_m.is_finite() {
                format!("{:.1} m", f.altitude_m)
            } else {
                "no height".into()
            };
            out.push_str(&format!(
                "last fix    {}, {:.7}° {:.7}°, {altitude}, {} satellites, {} ({})\n",
                receiver_time_text(f),
                f.latitude_rad.to_degrees(),
                f.longitude_rad.to_degrees(),
                f.satellites,
                fix_type_name(f),
                protocol_name(f),
            ));
        }
        None => out.push_str("last fix    none\n"),
    }
    out.push_str("counters\n");
    for (name, value) in counters(s) {
        out.push_str(&format!("  {name:<36} {value}\n"));
    }
    out.push_str(&format!("verdict: {}\n", r.verdict()));
    out
}
