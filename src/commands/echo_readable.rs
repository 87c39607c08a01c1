//! The readable form of every payload `rins echo` prints by default: the wire form without its
//! padding, per-channel arrays cut to the channels fitted, enums by name, bit sets as lists of
//! names, and the angles people read (roll, pitch, yaw and latitude, longitude in degrees) beside
//! the quaternion and the radians. `rins echo --raw` prints the wire form instead.
//!
//! A number that names no variant of its enum, or a bit that has no name, is kept as its number
//! (`"bit N"` in a list): a newer writer or a corrupted sample is shown as it is, never guessed.

use ipc_types::{
    ChannelState, FaultReason, FusedImu, Health, HealthReport, Integrity, LinkError, NavMode,
    NavState, RawImu, ServiceKind, ServiceState, Stage, Truth, aiding, fused_flags,
    integrity_reason, status,
};
use serde::Serialize;
use serde_json::{Map, Value};

/// Fields that hold bit sets: the readable form lists the names of the bits set, and CSV puts
/// that list in one cell (`a|b`), so that the columns stay the same from row to row.
pub const BIT_FIELDS: [&str; 5] = [
    "flags",
    "aiding",
    "integrity_reasons",
    "status",
    "valid_mask",
];

/// A payload as `rins echo` shows it by default. A payload with nothing to name or cut keeps
/// the default: the wire form without padding, times by stage.
pub trait Readable: Serialize {
    /// The readable JSON object of this sample.
    fn readable(&self) -> serde_json::Result<Value> {
        let mut m = wire(self)?;
        header(&mut m);
        Ok(Value::Object(m))
    }
}

/// The wire form as a JSON object, without the padding fields (at any depth).
fn wire<T: Serialize + ?Sized>(sample: &T) -> serde_json::Result<Map<String, Value>> {
    let mut value = serde_json::to_value(sample)?;
    drop_padding(&mut value);
    Ok(match value {
        Value::Object(map) => map,
        // Every payload is a struct; anything else is shown under one key rather than lost.
        other => Map::from_iter([("value".to_string(), other)]),
    })
}

fn drop_padding(value: &mut Value) {
    match value {
        Value::Object(map) => {
            map.retain(|k, _| !k.starts_with("_pad"));
            map.values_mut().for_each(drop_padding);
        }
        Value::Array(items) => items.iter_mut().for_each(drop_padding),
        _ => {}
    }
}

/// Keeps the first `n` entries of the array `key`: the slots past them describe no channel.
fn cut(map: &mut Map<String, Value>, key: &str, n: u8) {
    if let Some(Value::Array(items)) = map.get_mut(key) {
        items.truncate(usize::from(n));
    }
}

/// Replaces the enum code at `key` (a number, or an array of numbers) by its name.
fn name(map: &mut Map<String, Value>, key: &str, decode: impl Fn(u8) -> Option<&'static str>) {
    let one = |v: &mut Value| {
        let known = v
            .as_u64()
            .and_then(|c| u8::try_from(c).ok())
            .and_then(&decode);
        if let Some(text) = known {
            *v = Value::from(text);
        }
    };
    match map.get_mut(key) {
        Some(Value::Array(items)) => items.iter_mut().for_each(one),
        Some(v) => one(v),
        None => {}
    }
}

/// One list of bit names and what to append to each name (`-stale` for the aiding sources that
/// went quiet).
type BitGroup<'a> = (&'a [(u32, &'static str)], &'a str);

/// The names of the bits set in `bits`, group by group; a bit no group names as `"bit N"`.
fn named_bits(bits: u32, groups: &[BitGroup<'_>]) -> Vec<String> {
    let mut out = Vec::new();
    let mut named = 0u32;
    for (names, suffix) in groups {
        out.extend(
            ipc_types::bit_names(bits, names)
                .iter()
                .map(|n| format!("{n}{suffix}")),
        );
        named |= names.iter().fold(0, |all, (bit, _)| all | bit);
    }
    let unknown = bits & !named;
    out.extend(
        (0..32)
            .filter(|i| unknown & (1 << i) != 0)
            .map(|i| format!("bit {i}")),
    );
    out
}

/// Replaces the bit set at `key` by the list of its bits' names.
fn bits(map: &mut Map<String, Value>, key: &str, groups: &[BitGroup<'_>]) {
    if let Some(v) = map.get_mut(key)
        && let Some(set) = v.as_u64().and_then(|b| u32::try_from(b).ok())
    {
        *v = Value::from(named_bits(set, groups));
    }
}

/// The header's publish times by stage name instead of by index.
fn header(map: &mut Map<String, Value>) {
    let Some(Value::Object(h)) = map.get_mut("header") else {
        return;
    };
    if let Some(Value::Array(times)) = h.get("stage_pub_ns") {
        let by_stage: Map<String, Value> = times
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let key = Stage::from_index(i).map_or_else(|| i.to_string(), |s| s.name().into());
                (key, t.clone())
            })
            .collect();
        h.insert("stage_pub_ns".into(), Value::Object(by_stage));
    }
}

/// Roll, pitch, yaw (degrees) of the attitude and the position in degrees, beside the wire fields.
fn angles(map: &mut Map<String, Value>, quaternion: [f64; 4], lat_rad: f64, lon_rad: f64) {
    let [roll, pitch, yaw] = rins_earth::euler_deg(quaternion);
    for (key, v) in [
        ("roll_deg", roll),
        ("pitch_deg", pitch),
        ("yaw_deg", yaw),
        ("latitude_deg", lat_rad.to_degrees()),
        ("longitude_deg", lon_rad.to_degrees()),
    ] {
        map.insert(key.into(), Value::from(v));
    }
}

/// The redundant channels' fields that [`FusedImu`] and the health report's redundancy share:
/// cut to the channels fitted, states and reasons by name, flags by name.
fn channels(map: &mut Map<String, Value>, n_gyro: u8, n_accel: u8) {
    for (kind, n) in [("gyro", n_gyro), ("accel", n_accel)] {
        let state = format!("{kind}_state");
        let reason = format!("{kind}_reason");
        cut(map, &state, n);
        cut(map, &reason, n);
        name(map, &state, |c| {
            ChannelState::from_u8(c).map(ChannelState::name)
        });
        name(map, &reason, |c| {
            FaultReason::from_u8(c).map(FaultReason::name)
        });
    }
    bits(map, "flags", &[(&fused_flags::NAMES, "")]);
}

/// Mode, integrity and their bit sets, as [`NavState`] and the health report's nav carry them.
fn nav_status(map: &mut Map<String, Value>) {
    name(map, "mode", |c| NavMode::from_u8(c).map(NavMode::name));
    name(map, "integrity", |c| {
        Integrity::from_u8(c).map(Integrity::name)
    });
    bits(map, "aiding", &aiding::NAME_GROUPS);
    bits(map, "integrity_reasons", &[(&integrity_reason::NAMES, "")]);
}

/// Applies `edit` to the object at `key`.
fn within(map: &mut Map<String, Value>, key: &str, edit: impl FnOnce(&mut Map<String, Value>)) {
    if let Some(Value::Object(inner)) = map.get_mut(key) {
        edit(inner);
    }
}

/// The valid channels of a raw IMU frame by name (`gyro0`, `accel3`): bit i is gyro i, bit 16 + i
/// accel i.
fn valid_channel_names(mask: u32) -> Vec<String> {
    (0..32)
        .filter(|i| mask & (1 << i) != 0)
        .map(|i| match i {
            0..16 => format!("gyro{i}"),
            _ => format!("accel{}", i - 16),
        })
        .collect()
}

impl Readable for RawImu {
    fn readable(&self) -> serde_json::Result<Value> {
        let mut m = wire(self)?;
        header(&mut m);
        cut(&mut m, "gyro_counts", self.n_gyro);
        cut(&mut m, "accel_counts", self.n_accel);
        cut(&mut m, "temperature_c", self.n_temperature);
        bits(&mut m, "status", &[(&status::NAMES, "")]);
        m.insert(
            "valid_mask".into(),
            Value::from(valid_channel_names(self.valid_mask)),
        );
        Ok(Value::Object(m))
    }
}

impl Readable for FusedImu {
    fn readable(&self) -> serde_json::Result<Value> {
        let mut m = wire(self)?;
        header(&mut m);
        channels(&mut m, self.n_gyro, self.n_accel);
        Ok(Value::Object(m))
    }
}

/// A solution or its truth: the wire form with times by stage and the angles in degrees.
fn solution(
    sample: &impl Serialize,
    quaternion: [f64; 4],
    lat_rad: f64,
    lon_rad: f64,
) -> serde_json::Result<Map<String, Value>> {
    let mut m = wire(sample)?;
    header(&mut m);
    angles(&mut m, quaternion, lat_rad, lon_rad);
    Ok(m)
}

impl Readable for NavState {
    fn readable(&self) -> serde_json::Result<Value> {
        let mut m = solution(self, self.quaternion, self.latitude_rad, self.longitude_rad)?;
        nav_status(&mut m);
        Ok(Value::Object(m))
    }
}

impl Readable for Truth {
    fn readable(&self) -> serde_json::Result<Value> {
        solution(self, self.quaternion, self.latitude_rad, self.longitude_rad).map(Value::Object)
    }
}

impl Readable for Health {
    fn readable(&self) -> serde_json::Result<Value> {
        let mut m = wire(self)?;
        name(&mut m, "service", |c| {
            ServiceKind::from_u8(c).map(ServiceKind::name)
        });
        name(&mut m, "last_decode_error", |c| {
            LinkError::from_u8(c).map(LinkError::name)
        });
        Ok(Value::Object(m))
    }
}

impl Readable for HealthReport {
    fn readable(&self) -> serde_json::Result<Value> {
        let mut m = wire(self)?;
        cut(&mut m, "services", self.count);
        if let Some(Value::Array(services)) = m.get_mut("services") {
            for s in services.iter_mut().filter_map(Value::as_object_mut) {
                name(s, "service", |c| {
                    ServiceKind::from_u8(c).map(ServiceKind::name)
                });
                name(s, "state", |c| {
                    ServiceState::from_u8(c).map(ServiceState::name)
                });
            }
        }
        within(&mut m, "link", |l| {
            name(l, "last_decode_error", |c| {
                LinkError::from_u8(c).map(LinkError::name)
            });
        });
        let r = &self.redundancy;
        within(&mut m, "redundancy", |red| {
            channels(red, r.n_gyro, r.n_accel)
        });
        within(&mut m, "nav", nav_status);
        Ok(Value::Object(m))
    }
}

/// Every payload of the topic table is [`Readable`]: those with a form of their own, written
/// above, are named here once; every other one keeps the default form.
macro_rules! readable {
    (@one RawImu) => {};
    (@one FusedImu) => {};
    (@one NavState) => {};
    (@one Truth) => {};
    (@one Health) => {};
    (@one HealthReport) => {};
    (@one $payload:ident) => {
        impl Readable for ipc_types::$payload {}
    };
    ($($payload:ident $kind:ident;)+) => {
        $(readable!(@one $payload);)+
    };
}

ipc_types::for_each_topic!(payloads => readable);

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::{MAX_CHANNELS, RawAirspeed};

    fn fused_with_four_gyros() -> FusedImu {
        let mut f = FusedImu {
            n_gyro: 4,
            n_accel: 4,
            flags: fused_flags::GYRO_INSUFFICIENT | (1 << 30),
            ..FusedImu::default()
        };
        for i in 0..4 {
            f.gyro_state[i] = ChannelState::Ok as u8;
            f.accel_state[i] = ChannelState::Ok as u8;
        }
        f.gyro_state[2] = ChannelState::Excluded as u8;
        f.gyro_reason[2] = FaultReason::Parity as u8;
        // A code no variant has is shown as its number.
        f.accel_state[3] = 200;
        f
    }

    #[test]
    fn fused_imu_shows_the_four_channels_by_name() {
        let v = fused_with_four_gyros().readable().unwrap();
        assert_eq!(
            v["gyro_state"],
            serde_json::json!(["ok", "ok", "excluded", "ok"])
        );
        assert_eq!(
            v["gyro_reason"],
            serde_json::json!(["none", "none", "parity", "none"])
        );
        assert_eq!(v["accel_state"], serde_json::json!(["ok", "ok", "ok", 200]));
        assert_eq!(
            v["flags"],
            serde_json::json!(["gyro-insufficient", "bit 30"])
        );
        assert_eq!(v["header"]["stage_pub_ns"]["fusion"], 0);
        assert!(!v.to_string().contains("_pad"));
    }

    #[test]
    fn nav_state_has_euler_angles_and_degrees() {
        // 30° yaw about down: q = [cos 15°, 0, 0, sin 15°].
        let half = 15f64.to_radians();
        let nav = NavState {
            quaternion: [half.cos(), 0.0, 0.0, half.sin()],
            latitude_rad: 0.5,
            longitude_rad: -0.25,
            mode: NavMode::Navigating as u8,
            aiding: aiding::BARO | aiding::MAG_STALE,
            integrity: Integrity::Degraded as u8,
            integrity_reasons: integrity_reason::AIDING_STALE,
            ..NavState::default()
        };
        let v = nav.readable().unwrap();
        let close = |key: &str, want: f64| {
            let got = v[key].as_f64().unwrap();
            assert!((got - want).abs() < 1e-9, "{key}: {got} vs {want}");
        };
        close("roll_deg", 0.0);
        close("pitch_deg", 0.0);
        close("yaw_deg", 30.0);
        close("latitude_deg", 0.5f64.to_degrees());
        close("longitude_deg", -0.25f64.to_degrees());
        assert_eq!(v["mode"], "navigating");
        assert_eq!(v["integrity"], "degraded");
        assert_eq!(v["aiding"], serde_json::json!(["baro", "mag-stale"]));
        assert_eq!(v["integrity_reasons"], serde_json::json!(["aiding-stale"]));
        assert!(v.get("_pad").is_none());
    }

    #[test]
    fn nav_state_names_a_rejected_receiver() {
        let nav = NavState {
            aiding: aiding::BARO | aiding::GNSS_STALE | aiding::GNSS_REJECTED,
            ..NavState::default()
        };
        let v = nav.readable().unwrap();
        assert_eq!(
            v["aiding"],
            serde_json::json!(["baro", "gnss-stale", "gnss-rejected"])
        );
    }

    #[test]
    fn raw_imu_keeps_the_fitted_channels_and_names_valid_ones() {
        let mut raw = RawImu {
            n_gyro: 4,
            n_accel: 3,
            n_temperature: 2,
            status: status::SATURATION,
            valid_mask: 0b1011 | (1 << 16),
            ..RawImu::default()
        };
        raw.gyro_counts[..MAX_CHANNELS].fill(7);
        let v = raw.readable().unwrap();
        assert_eq!(v["gyro_counts"], serde_json::json!([7, 7, 7, 7]));
        assert_eq!(v["accel_counts"].as_array().unwrap().len(), 3);
        assert_eq!(v["temperature_c"].as_array().unwrap().len(), 2);
        assert_eq!(v["status"], serde_json::json!(["saturation"]));
        assert_eq!(
            v["valid_mask"],
            serde_json::json!(["gyro0", "gyro1", "gyro3", "accel0"])
        );
    }

    #[test]
    fn raw_airspeed_shows_the_differential_pressure_and_temperature() {
        let raw = RawAirspeed {
            diff_pressure_pa: 612.5,
            temperature_c: -12.25,
            ..RawAirspeed::default()
        };
        let v = raw.readable().unwrap();
        // Both values are exact in f32, so they print as written.
        assert_eq!(v["diff_pressure_pa"], serde_json::json!(612.5));
        assert_eq!(v["temperature_c"], serde_json::json!(-12.25));
        assert_eq!(v["header"]["stage_pub_ns"]["acquisition"], 0);
        assert!(!v.to_string().contains("_pad"));
    }

    #[test]
    fn health_report_lists_the_services_in_use() {
        let mut report = HealthReport {
            count: 2,
            ..HealthReport::default()
        };
        report.services[0].service = ServiceKind::Fusion as u8;
        report.services[0].state = ServiceState::Running as u8;
        report.services[1].service = ServiceKind::Simulator as u8;
        report.services[1].state = ServiceState::GivenUp as u8;
        report.redundancy.n_gyro = 4;
        report.nav.mode = NavMode::Coasting as u8;
        report.link.last_decode_error = LinkError::CrcMismatch as u8;
        let v = report.readable().unwrap();
        let services = v["services"].as_array().unwrap();
        assert_eq!(services.len(), 2);
        assert_eq!(services[0]["service"], "fusion");
        assert_eq!(services[1]["state"], "given-up");
        assert_eq!(v["redundancy"]["gyro_state"].as_array().unwrap().len(), 4);
        assert_eq!(v["redundancy"]["gyro_state"][0], "absent");
        assert_eq!(v["redundancy"]["accel_state"], serde_json::json!([]));
        assert_eq!(v["nav"]["mode"], "coasting");
        assert_eq!(v["link"]["last_decode_error"], "crc-mismatch");
        assert!(!v.to_string().contains("_pad"));
    }
}
