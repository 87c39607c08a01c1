//! Keys a configuration file may still carry from before the IMU rate was one key and the channel
//! noise a density: each is refused with what to write instead (a silently ignored rate or σ
//! would give a deployment the wrong noise model).

use rins_earth::STANDARD_GRAVITY;
use toml::{Table, Value};

/// The rate an old per-sample σ was stated at when the file says none, Hz.
const OLD_DEFAULT_RATE_HZ: f64 = 1000.0;

/// A per-sample σ key and the density key that replaced it.
struct SigmaKey {
    old: &'static str,
    new: &'static str,
    unit: &'static str,
    /// σ in the old unit to the new key's unit (before dividing by √rate).
    to_new_unit: fn(f64) -> f64,
}

const SIGMA_KEYS: [SigmaKey; 2] = [
    SigmaKey {
        old: "gyro_sigma_rps",
        new: "gyro_noise_density_dps_rthz",
        unit: "rad/s",
        to_new_unit: f64::to_degrees,
    },
    SigmaKey {
        old: "accel_sigma_mps2",
        new: "accel_noise_density_ug_rthz",
        unit: "m/s²",
        to_new_unit: mps2_to_ug,
    },
];

fn mps2_to_ug(v: f64) -> f64 {
    v / (1e-6 * STANDARD_GRAVITY)
}

/// Every retired key found in `table`, each with what replaces it, joined into one message;
/// `None` when there is none.
pub fn retired_keys(table: &Table) -> Option<String> {
    let get = |path: &[&str]| -> Option<&Value> {
        let (last, tables) = path.split_last()?;
        let mut t = table;
        for name in tables {
            t = t.get(*name)?.as_table()?;
        }
        t.get(*last)
    };
    let number = |v: &Value| v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
    // The rate the old σ were per sample at: fusion's old key, else the device's, else 1 kHz.
    let rate = get(&["fusion", "sample_rate_hz"])
        .or_else(|| get(&["device", "imu_rate_hz"]))
        .and_then(number)
        .filter(|r| r.is_finite() && *r > 0.0)
        .unwrap_or(OLD_DEFAULT_RATE_HZ);
    let mut found = Vec::new();
    for (path, instead) in [
        (
            &["fusion", "sample_rate_hz"][..],
            "the IMU rate is one key, device.imu_rate_hz",
        ),
        (
            &["fusion", "kalman", "sample_period_s"][..],
            "the Kalman filter's period is 1 / device.imu_rate_hz",
        ),
        (
            &["sim", "imu_rate_hz"][..],
            "the IMU rate is one key, device.imu_rate_hz",
        ),
        (
            &["fusion", "fdi", "stationary_window"][..],
            "the stationary block is given in seconds, fusion.fdi.stationary_window_s \
             (200 samples at 1 kHz: 0.2)",
        ),
    ] {
        if get(path).is_some() {
            found.push(format!("{} is no longer read: {instead}", path.join(".")));
        }
    }
    for SigmaKey {
        old,
        new,
        unit,
        to_new_unit,
    } in SIGMA_KEYS
    {
        let Some(value) = get(&["fusion", "noise", old]) else {
            continue;
        };
        let density = |s: f64| to_new_unit(s) / rate.sqrt();
        let written = match value {
            Value::Array(list) => {
                let parts: Option<Vec<String>> = list
                    .iter()
                    .map(|v| number(v).map(|s| significant(density(s))))
                    .collect();
                parts.map(|p| format!("[{}]", p.join(", ")))
            }
            v => number(v).map(|s| significant(density(s))),
        };
        let advice = match written {
            Some(w) => format!(
                "write fusion.noise.{new} = {w} (the {unit} per sample at {rate} Hz over √rate); \
                 the per-sample σ now follows from the density and device.imu_rate_hz"
            ),
            None => format!(
                "write fusion.noise.{new} (σ per sample over √rate); the per-sample σ now follows \
                 from the density and device.imu_rate_hz"
            ),
        };
        found.push(format!(
            "fusion.noise.{old} is no longer read: the noise is a density, {advice}"
        ));
    }
    (!found.is_empty()).then(|| found.join("; "))
}

/// `v` with four significant digits, trailing zeros dropped.
fn significant(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return v.to_string();
    }
    let decimals = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(text: &str) -> Option<String> {
        retired_keys(&text.parse::<Table>().unwrap())
    }

    #[test]
    fn old_rate_keys_name_the_one_rate_key() {
        let m = message("[fusion]\nsample_rate_hz = 500\n").unwrap();
        assert!(
            m.contains("fusion.sample_rate_hz is no longer read: the IMU rate is one key, device.imu_rate_hz"),
            "{m}"
        );
        let m = message("[sim]\nimu_rate_hz = 500\n[fusion.kalman]\nsample_period_s = 0.002\n")
            .unwrap();
        assert!(
            m.contains("sim.imu_rate_hz") && m.contains("fusion.kalman.sample_period_s"),
            "{m}"
        );
        assert_eq!(message("[device]\nimu_rate_hz = 500\n"), None);
        let m = message("[fusion.fdi]\nstationary_window = 200\n").unwrap();
        assert!(m.contains("fusion.fdi.stationary_window_s"), "{m}");
    }

    #[test]
    fn old_sigmas_give_the_density_to_write() {
        // Today's defaults at 1 kHz are 0.01 °/s/√Hz and 150 µg/√Hz.
        let m = message("[fusion.noise]\ngyro_sigma_rps = 0.005519\naccel_sigma_mps2 = 0.046517\n")
            .unwrap();
        assert!(m.contains("gyro_noise_density_dps_rthz = 0.01 "), "{m}");
        assert!(m.contains("accel_noise_density_ug_rthz = 150 "), "{m}");
        // Per channel, and at the rate the file stated.
        let m = message(
            "[fusion]\nsample_rate_hz = 4000\n[fusion.noise]\ngyro_sigma_rps = [0.011038, 0.022076]\n",
        )
        .unwrap();
        assert!(
            m.contains("gyro_noise_density_dps_rthz = [0.01, 0.02]"),
            "{m}"
        );
    }

    #[test]
    fn four_significant_digits() {
        assert_eq!(significant(0.0099998), "0.01");
        assert_eq!(significant(149.996), "150");
        assert_eq!(significant(1234.5678), "1235");
        assert_eq!(significant(0.000123456), "0.0001235");
    }
}
