//! The configuration beside an imported recording: the navigator profile the evaluation uses
//! for that kind of recording, followed by the tables that describe the recorded block (its
//! converters, its channels' axes and noise) and, for a recording that starts in the air, the
//! state the navigator starts from.
//!
//! The text is built here and parsed by the product's configuration loader, which knows every
//! key; numbers are written in Rust's shortest round-trip form, so the file gives back exactly
//! the values the import used.

use std::fmt::Write as _;

use super::counts::{CONVERTER_BITS, Scales};

/// Noise densities of one channel, equal for every channel of a recording (fusion's least squares
/// then weights the channels equally).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseDensity {
    /// Gyro, °/s/√Hz.
    pub gyro_dps_rthz: f64,
    /// Accelerometer, µg/√Hz.
    pub accel_ug_rthz: f64,
    /// Where the figures come from, written as a comment.
    pub source: &'static str,
}

/// The in-flight start of `[navigator.start]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartTable {
    /// Device time of the state, s.
    pub time_s: f64,
    /// Vehicle roll, pitch, heading (ZYX, FRD → NED), degrees.
    pub euler_deg: [f64; 3],
    /// Velocity north, east, down, m/s.
    pub velocity_ned_mps: [f64; 3],
    /// Altitude, m.
    pub altitude_m: f64,
}

/// How the channels' sensing axes are written.
#[derive(Debug, Clone, PartialEq)]
pub enum Axes {
    /// Body x, y, z: `kind = "triad"`.
    Triad,
    /// One unit vector per channel, vehicle frame: `kind = "axes"`.
    Listed(Vec<[f64; 3]>),
}

/// Everything the tables state.
#[derive(Debug, Clone, PartialEq)]
pub struct Fragment<'a> {
    /// What the recording is, for the header comment.
    pub title: String,
    /// The navigator profile's text, written first (its tables may not be repeated below).
    pub profile: &'a str,
    /// Where the profile comes from, for a comment.
    pub profile_name: &'a str,
    /// Converter ranges.
    pub scales: Scales,
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Gyro and accelerometer channel axes (the same for both).
    pub axes: Axes,
    /// Why the axes are what they are, as comment lines.
    pub axes_comment: &'a str,
    /// Channel noise.
    pub noise: NoiseDensity,
    /// The `[fusion.fdi]` table the recorded block needs, if not the built-in one.
    pub fdi: Option<&'a str>,
    /// The in-flight start, if the recording starts in the air.
    pub start: Option<StartTable>,
    /// The navigator's position, latitude and longitude in degrees and altitude in metres:
    /// an in-flight start needs it, and a profile that leaves it unset navigates at 0, 0, 0.
    /// Written into the profile's `[navigator]` table when the profile does not give it.
    pub origin_deg: [f64; 3],
}

/// `profile` with `lines` added to its `[navigator]` table (a new one at its end when it has
/// none), unless it already sets `initial_latitude_deg`.
fn with_navigator_position(profile: &str, lines: &str) -> String {
    let sets = |key: &str| {
        profile.lines().any(|l| {
            l.trim_start()
                .strip_prefix(key)
                .is_some_and(|r| r.trim_start().starts_with('='))
        })
    };
    if sets("initial_latitude_deg") {
        return profile.trim_end().to_string();
    }
    let mut out = String::new();
    let mut inserted = false;
    for line in profile.trim_end().lines() {
        out.push_str(line);
        out.push('\n');
        if !inserted && line.trim() == "[navigator]" {
            out.push_str(lines);
            inserted = true;
        }
    }
    if !inserted {
        out.push_str("\n[navigator]\n");
        out.push_str(lines);
    }
    out.trim_end().to_string()
}

fn vector(v: &[f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2])
}

fn axes_table(out: &mut String, sensor: &str, axes: &Axes) {
    let _ = writeln!(out, "[fusion.geometry.{sensor}]");
    match axes {
        Axes::Triad => out.push_str("kind = \"triad\"\n"),
        Axes::Listed(list) => {
            out.push_str("kind = \"axes\"\naxes = [\n");
            for a in list {
                let _ = writeln!(out, "    {},", vector(a));
            }
            out.push_str("]\n");
        }
    }
    out.push('\n');
}

/// The configuration file's text.
pub fn render(f: &Fragment<'_>) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# {}", f.title);
    out.push_str(
        "# Written by `rins import`: the navigator profile below, then the recorded block.\n\n",
    );
    let _ = writeln!(out, "# --- {} ---", f.profile_name);
    if f.start.is_some() {
        let [lat, lon, alt] = f.origin_deg;
        let lines = format!(
            "# Where the evaluation navigates this recording (an in-flight start needs a position).\n\
             initial_latitude_deg = {lat:?}\ninitial_longitude_deg = {lon:?}\ninitial_altitude_m = {alt:?}\n"
        );
        out.push_str(&with_navigator_position(f.profile, &lines));
    } else {
        out.push_str(f.profile.trim_end());
    }
    out.push_str("\n\n# --- the recorded block ---\n\n");

    let s = &f.scales;
    out.push_str("[device]\n");
    let _ = writeln!(
        out,
        "# {CONVERTER_BITS}-bit counts; full scales just above the recording's largest |value|."
    );
    let _ = writeln!(out, "gyro_full_scale_dps = {:?}", s.gyro_full_scale_dps);
    let _ = writeln!(out, "accel_full_scale_g = {:?}", s.accel_full_scale_g);
    let _ = writeln!(out, "converter_bits = {CONVERTER_BITS}");
    let _ = writeln!(out, "imu_rate_hz = {:?}\n", f.rate_hz);

    out.push_str("[fusion]\n");
    // The evaluations subtract no start-up gyro bias (the flights start in the air; the walks'
    // start is not still enough): nor does fusion here.
    out.push_str("rest_bias_s = 0.0             # no start-up gyro bias window\n");
    out.push('\n');

    for line in f.axes_comment.lines() {
        let _ = writeln!(out, "# {line}");
    }
    axes_table(&mut out, "gyro", &f.axes);
    axes_table(&mut out, "accel", &f.axes);

    out.push_str("[fusion.noise]\n");
    let _ = writeln!(
        out,
        "# Equal for every channel (equal weights in the least squares): {}.",
        f.noise.source
    );
    let _ = writeln!(
        out,
        "gyro_noise_density_dps_rthz = {:?}",
        f.noise.gyro_dps_rthz
    );
    let _ = writeln!(
        out,
        "accel_noise_density_ug_rthz = {:?}",
        f.noise.accel_ug_rthz
    );

    if let Some(fdi) = f.fdi {
        out.push('\n');
        out.push_str(fdi.trim_end());
        out.push('\n');
    }

    if let Some(start) = &f.start {
        out.push_str("\n[navigator.start]\n");
        out.push_str(
            "# The recording starts in the air: the reference's state at the first sample the\n",
        );
        out.push_str("# evaluation starts from (no static alignment).\n");
        let _ = writeln!(out, "time_s = {:?}", start.time_s);
        let _ = writeln!(out, "roll_deg = {:?}", start.euler_deg[0]);
        let _ = writeln!(out, "pitch_deg = {:?}", start.euler_deg[1]);
        let _ = writeln!(out, "heading_deg = {:?}", start.euler_deg[2]);
        let _ = writeln!(
            out,
            "velocity_ned_mps = {}",
            vector(&start.velocity_ned_mps)
        );
        let _ = writeln!(out, "altitude_m = {:?}", start.altitude_m);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_position_goes_into_the_profiles_navigator_table_once() {
        let lines = "initial_latitude_deg = 0.0\ninitial_longitude_deg = 0.0\n";
        let text = with_navigator_position(
            "# x\n[navigator]\nalign_s = 1.0\n\n[navigator.mag]\n",
            lines,
        );
        assert_eq!(
            text,
            "# x\n[navigator]\ninitial_latitude_deg = 0.0\ninitial_longitude_deg = 0.0\nalign_s = 1.0\n\n[navigator.mag]"
        );
        let without = with_navigator_position("[navigator.mag]\nenabled = true\n", lines);
        assert!(
            without.ends_with(
                "\n[navigator]\ninitial_latitude_deg = 0.0\ninitial_longitude_deg = 0.0"
            ),
            "{without}"
        );
        let given = "[navigator]\ninitial_latitude_deg = 47.0\n";
        assert_eq!(with_navigator_position(given, lines), given.trim_end());
        let table: toml::Table = toml::from_str(&without).unwrap();
        assert_eq!(
            table["navigator"]["initial_latitude_deg"].as_float(),
            Some(0.0)
        );
    }
}
