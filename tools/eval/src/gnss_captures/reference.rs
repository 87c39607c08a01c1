//! The fix epochs a capture's receiver reported, read from gpsd's decode of the same bytes (the
//! capture's `.chk` file: one JSON object per line, other lines echo the input).
//!
//! A reference that does not come from rins's own decoder: gpsd is a second, widely used decoder
//! of these receivers, so an epoch rins does not publish, or publishes elsewhere, is a difference
//! between two independent readings of one byte stream.
//!
//! **Time-only epochs are not reference epochs.** A u-blox timing receiver in its fixed-position
//! mode reports fix type 5, "time only" (NAV-PVT fixType, NAV-SOL gpsFix): it solves for time
//! alone and repeats a position it was given. gpsd reports these epochs as 3-D fixes; the
//! product's decoder refuses them by design, as they measure no position. The epochs whose own
//! UBX output (NAV-PVT or NAV-SOL of the same iTOW) says time-only are therefore left out of the
//! reference and counted apart ([`Reference::time_only_epochs`]). The fix type byte is read from
//! the frames as the product's framer finds them, not through the decoder under evaluation.

use rins_gnss_protocol::decode::framer::{Framed, Framer};
use serde::Serialize;
use serde_json::Value;

/// Milliseconds in a day.
pub const MS_PER_DAY: u32 = 86_400_000;
/// Milliseconds in a GPS week.
pub const MS_PER_WEEK: u64 = 7 * MS_PER_DAY as u64;
/// Days from 1970-01-01 (Unix epoch) to 1980-01-06 (GPS epoch).
const GPS_EPOCH_DAY: i64 = 3_657;

/// A UTC instant at millisecond resolution: the day and the time of day.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct UtcTime {
    /// Days since 1970-01-01.
    pub day: i64,
    /// Milliseconds since midnight UTC, below [`MS_PER_DAY`].
    pub ms_of_day: u32,
}

impl UtcTime {
    /// GPS time of week, ms: what a u-blox receiver stamps its solutions with (iTOW). GPS time
    /// runs ahead of UTC by the leap seconds inserted since 1980 ([`gps_minus_utc_s`]).
    pub fn gps_time_of_week_ms(self) -> u64 {
        let days = (self.day - GPS_EPOCH_DAY).rem_euclid(7) as u64;
        let ms = days * u64::from(MS_PER_DAY)
            + u64::from(self.ms_of_day)
            + 1_000 * gps_minus_utc_s(self.day);
        ms % MS_PER_WEEK
    }
}

/// One epoch with a position, as gpsd reported it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReferenceEpoch {
    /// The epoch's UTC time.
    pub time: UtcTime,
    /// gpsd's fix mode: 2 (horizontal) or 3 (three-dimensional).
    pub mode: u8,
    /// Latitude, degrees.
    pub lat_deg: f64,
    /// Longitude, degrees.
    pub lon_deg: f64,
    /// Altitude above mean sea level, metres (`altMSL`, else `alt`), when reported.
    pub alt_msl_m: Option<f64>,
    /// The receiver's own Earth-centred, Earth-fixed position (`ecefx`, `ecefy`, `ecefz`), m,
    /// when reported. For a u-blox receiver that reports NAV-SOL alone gpsd repeats the first
    /// epoch's latitude and longitude while these follow the receiver, so they are the
    /// receiver's position where both are present.
    pub ecef_m: Option<[f64; 3]>,
}

/// What a `.chk` file yields.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Reference {
    /// The distinct epochs with a position, in file order (the first TPV of each time).
    pub epochs: Vec<ReferenceEpoch>,
    /// TPV reports with a position but no time (or a time that does not parse): not epochs that
    /// can be matched by time.
    pub fixes_without_time: usize,
    /// Lines that start like JSON (`{`) but do not parse.
    pub unreadable_lines: usize,
    /// gpsd's epochs with a position that the receiver's own UBX output calls time-only: not
    /// reference epochs.
    pub time_only_epochs: usize,
}

/// UBX fix type "time only" (NAV-PVT fixType, NAV-SOL gpsFix).
const TIME_ONLY: u8 = 5;

/// The times of week (iTOW, ms) of the epochs whose NAV-PVT or NAV-SOL in `receiver_bytes` says
/// time-only, sorted and without repeats.
pub fn time_only_itows_ms(receiver_bytes: &[u8]) -> Vec<u64> {
    let mut itows = Vec::new();
    let mut framer = Box::<Framer>::default();
    framer.push(receiver_bytes, |item| {
        let Framed::Ubx { class, id, payload } = item else {
            return;
        };
        // Offset of the fix type: NAV-PVT after iTOW and the date and time, NAV-SOL after iTOW,
        // fTOW and the week.
        let fix_type_at = match (class, id) {
            (0x01, 0x07) => 20,
            (0x01, 0x06) => 10,
            _ => return,
        };
        if let (Some(&TIME_ONLY), Some(itow)) = (payload.get(fix_type_at), payload.get(..4)) {
            itows.push(u64::from(u32::from_le_bytes([
                itow[0], itow[1], itow[2], itow[3],
            ])));
        }
    });
    itows.sort_unstable();
    itows.dedup();
    itows
}

/// The reference epochs of a `.chk` file: TPV reports with `mode` ≥ 2 and both `lat` and `lon`,
/// one per distinct `time` (gpsd reports some epochs twice as more sentences of it arrive),
/// except those that `receiver_bytes` (the capture gpsd decoded) report as time-only.
pub fn reference_epochs(chk: &str, receiver_bytes: &[u8]) -> Reference {
    let time_only = time_only_itows_ms(receiver_bytes);
    let mut time_only_seen = Vec::new();
    let mut reference = Reference::default();
    for line in chk.lines() {
        let line = line.trim();
        if !line.starts_with('{') {
            continue;
        }
        let Ok(value) = serde_json::from_str::<Value>(line) else {
            reference.unreadable_lines += 1;
            continue;
        };
        if value.get("class").and_then(Value::as_str) != Some("TPV") {
            continue;
        }
        let mode = value.get("mode").and_then(Value::as_u64).unwrap_or(0);
        let lat = value.get("lat").and_then(Value::as_f64);
        let lon = value.get("lon").and_then(Value::as_f64);
        let (Some(lat_deg), Some(lon_deg)) = (lat, lon) else {
            continue;
        };
        if mode < 2 {
            continue;
        }
        let Some(time) = value
            .get("time")
            .and_then(Value::as_str)
            .and_then(parse_utc)
        else {
            reference.fixes_without_time += 1;
            continue;
        };
        if reference.epochs.iter().any(|e| e.time == time) || time_only_seen.contains(&time) {
            continue;
        }
        if time_only.binary_search(&time.gps_time_of_week_ms()).is_ok() {
            time_only_seen.push(time);
            reference.time_only_epochs += 1;
            continue;
        }
        let alt_msl_m = value
            .get("altMSL")
            .or_else(|| value.get("alt"))
            .and_then(Value::as_f64);
        let axis = |key: &str| value.get(key).and_then(Value::as_f64);
        let ecef_m = match (axis("ecefx"), axis("ecefy"), axis("ecefz")) {
            (Some(x), Some(y), Some(z)) => Some([x, y, z]),
            _ => None,
        };
        reference.epochs.push(ReferenceEpoch {
            time,
            mode: mode.min(3) as u8,
            lat_deg,
            lon_deg,
            alt_msl_m,
            ecef_m,
        });
    }
    reference
}

/// Parses gpsd's ISO 8601 time, `YYYY-MM-DDTHH:MM:SS[.fff…]Z`, rounded to the millisecond.
pub fn parse_utc(text: &str) -> Option<UtcTime> {
    let text = text.strip_suffix('Z')?;
    let (date, clock) = text.split_once('T')?;
    let mut date = date.splitn(3, '-');
    let year: i64 = date.next()?.parse().ok()?;
    let month: u32 = date.next()?.parse().ok()?;
    let day: u32 = date.next()?.parse().ok()?;
    let mut clock = clock.splitn(3, ':');
    let hour: u32 = clock.next()?.parse().ok()?;
    let minute: u32 = clock.next()?.parse().ok()?;
    let seconds: f64 = clock.next()?.parse().ok()?;
    let valid = (1..=12).contains(&month)
        && (1..=31).contains(&day)
        && hour < 24
        && minute < 60
        && (0.0..61.0).contains(&seconds);
    if !valid {
        return None;
    }
    let ms = u64::from(hour * 3_600_000 + minute * 60_000) + (seconds * 1_000.0).round() as u64;
    let day = days_from_civil(year, month, day) + (ms / u64::from(MS_PER_DAY)) as i64;
    Some(UtcTime {
        day,
        ms_of_day: (ms % u64::from(MS_PER_DAY)) as u32,
    })
}

/// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's algorithm).
fn days_from_civil(year: i64, month: u32, day: u32) -> i64 {
    let year = if month <= 2 { year - 1 } else { year };
    let era = year.div_euclid(400);
    let year_of_era = year - era * 400;
    let month = i64::from(month);
    let day_of_year =
        (153 * (if month > 2 { month - 3 } else { month + 9 }) + 2) / 5 + i64::from(day) - 1;
    let day_of_era = year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
    era * 146_097 + day_of_era - 719_468
}

/// GPS time minus UTC, s, on a day (days since 1970-01-01): the leap seconds inserted since the
/// GPS epoch, from the IERS bulletins (none announced after the one at the end of 2016).
pub fn gps_minus_utc_s(day: i64) -> u64 {
    // The first day each offset applies.
    const STEPS: [(i64, u64); 18] = [
        (4_199, 1),   // 1981-07-01
        (4_564, 2),   // 1982-07-01
        (4_929, 3),   // 1983-07-01
        (5_660, 4),   // 1985-07-01
        (6_574, 5),   // 1988-01-01
        (7_305, 6),   // 1990-01-01
        (7_670, 7),   // 1991-01-01
        (8_217, 8),   // 1992-07-01
        (8_582, 9),   // 1993-07-01
        (8_947, 10),  // 1994-07-01
        (9_496, 11),  // 1996-01-01
        (10_043, 12), // 1997-07-01
        (10_592, 13), // 1999-01-01
        (13_149, 14), // 2006-01-01
        (14_245, 15), // 2009-01-01
        (15_522, 16), // 2012-07-01
        (16_617, 17), // 2015-07-01
        (17_167, 18), // 2017-01-01
    ];
    STEPS
        .iter()
        .take_while(|(first_day, _)| day >= *first_day)
        .last()
        .map_or(0, |(_, offset)| *offset)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rins_gnss_protocol::encode::write_ubx_frame;

    #[test]
    fn civil_days_match_known_dates() {
        assert_eq!(days_from_civil(1970, 1, 1), 0);
        assert_eq!(days_from_civil(1980, 1, 6), GPS_EPOCH_DAY);
        assert_eq!(days_from_civil(2000, 3, 1), 11_017);
        assert_eq!(days_from_civil(2017, 1, 1), 17_167);
        assert_eq!(days_from_civil(2015, 7, 1), 16_617);
        assert_eq!(days_from_civil(1981, 7, 1), 4_199);
    }

    #[test]
    fn times_parse_to_the_millisecond() {
        let t = parse_utc("2017-07-19T08:50:00.800Z").unwrap();
        assert_eq!(t.day, days_from_civil(2017, 7, 19));
        assert_eq!(t.ms_of_day, (8 * 3_600 + 50 * 60) * 1_000 + 800);
        let whole = parse_utc("2010-10-25T22:24:50Z").unwrap();
        assert_eq!(whole.ms_of_day, (22 * 3_600 + 24 * 60 + 50) * 1_000);
        // Rounding up past midnight moves to the next day.
        let late = parse_utc("2019-02-28T23:59:59.9996Z").unwrap();
        assert_eq!((late.day, late.ms_of_day), (days_from_civil(2019, 3, 1), 0));
    }

    #[test]
    fn malformed_times_are_refused() {
        for bad in [
            "",
            "2017-07-19T08:50:00",
            "2017-07-19 08:50:00Z",
            "2017-13-19T08:50:00Z",
            "2017-07-19T24:00:00Z",
            "2017-07-19T08:60:00Z",
            "2017-07-19T08:50:xxZ",
            "2017-07T08:50:00Z",
        ] {
            assert_eq!(parse_utc(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn gps_time_of_week_counts_from_sunday_plus_leap_seconds() {
        // 2019-01-06 was a Sunday (GPS week 2035 began): time of week is the time of day plus 18 s.
        let sunday = parse_utc("2019-01-06T00:00:00Z").unwrap();
        assert_eq!(sunday.gps_time_of_week_ms(), 18_000);
        let monday = parse_utc("2019-01-07T01:00:00.250Z").unwrap();
        assert_eq!(
            monday.gps_time_of_week_ms(),
            86_400_000 + 3_600_000 + 250 + 18_000
        );
        // The last seconds of Saturday UTC are already the next GPS week.
        let saturday = parse_utc("2019-01-12T23:59:50Z").unwrap();
        assert_eq!(saturday.gps_time_of_week_ms(), 8_000);
        // 2016-12-31 still had 17 s.
        assert_eq!(gps_minus_utc_s(days_from_civil(2016, 12, 31)), 17);
        assert_eq!(gps_minus_utc_s(days_from_civil(2017, 1, 1)), 18);
        assert_eq!(gps_minus_utc_s(days_from_civil(1980, 1, 6)), 0);
    }

    /// A UBX frame of `payload` with its checksum.
    fn ubx_frame(class: u8, id: u8, payload: &[u8]) -> Vec<u8> {
        let mut frame = Vec::new();
        write_ubx_frame(class, id, payload, &mut frame);
        frame
    }

    /// NAV-PVT (92 bytes) or NAV-SOL (52 bytes) of `itow` with fix type `fix_type`.
    fn solution(pvt: bool, itow: u32, fix_type: u8) -> Vec<u8> {
        let (id, len, at) = if pvt { (0x07, 92, 20) } else { (0x06, 52, 10) };
        let mut payload = vec![0u8; len];
        payload[..4].copy_from_slice(&itow.to_le_bytes());
        payload[at] = fix_type;
        ubx_frame(0x01, id, &payload)
    }

    #[test]
    fn epochs_the_receiver_calls_time_only_are_counted_apart() {
        // Monday 2019-01-07, 18 leap seconds: 10:00:0s UTC is iTOW 122 400 000 + 19 000 + s.
        let itow = |s: u32| 86_400_000 + 36_000_000 + 18_000 + 1_000 * s;
        let mut bytes = b"$GPTXT,01,01,02,x*00\r\n".to_vec();
        bytes.extend(solution(true, itow(0), 3));
        bytes.extend(solution(true, itow(1), 5));
        bytes.extend(solution(false, itow(1), 5));
        bytes.extend(solution(false, itow(2), 5));
        bytes.extend(ubx_frame(0x01, 0x02, &itow(3).to_le_bytes()));
        assert_eq!(
            time_only_itows_ms(&bytes),
            [itow(1), itow(2)].map(u64::from)
        );
        let tpv = |s: u32| {
            format!(
                "{{\"class\":\"TPV\",\"mode\":3,\"time\":\"2019-01-07T10:00:0{s}.000Z\",\
                 \"lat\":45.0,\"lon\":7.0}}\n"
            )
        };
        // Epoch 1 reported twice by gpsd, epoch 3 of another message.
        let chk: String = [0, 1, 1, 2, 3].map(tpv).concat();
        let reference = reference_epochs(&chk, &bytes);
        assert_eq!(reference.time_only_epochs, 2);
        let kept: Vec<u32> = reference.epochs.iter().map(|e| e.time.ms_of_day).collect();
        assert_eq!(kept, [36_000_000, 36_003_000]);
        // Without the receiver's bytes every epoch is a reference epoch.
        assert_eq!(reference_epochs(&chk, b"").epochs.len(), 4);
    }

    #[test]
    fn first_tpv_of_each_time_with_a_position_is_an_epoch() {
        let chk = concat!(
            "$GPGGA,222449,3349.0337,S,01843.9282,E,1,07,02.31,000115.4,M,0033.3,M,,\n",
            "{\"class\":\"TPV\",\"mode\":3,\"lat\":-33.8,\"lon\":18.7}\n",
            "{\"class\":\"SKY\",\"time\":\"2017-07-19T08:50:00.000Z\"}\n",
            "{\"class\":\"TPV\",\"mode\":1,\"time\":\"2017-07-19T08:50:00.000Z\"}\n",
            "{\"class\":\"TPV\",\"mode\":3,\"time\":\"2017-07-19T08:50:00.800Z\",",
            "\"lat\":-34.9062263,\"lon\":138.6081197,\"altMSL\":28.895,\"alt\":28.8,",
            "\"ecefx\":-3933349.97,\"ecefy\":3466291.61,\"ecefz\":-3629303.21}\n",
            "{\"class\":\"TPV\",\"mode\":3,\"time\":\"2017-07-19T08:50:00.800Z\",",
            "\"lat\":-34.0,\"lon\":138.0}\n",
            "{\"class\":\"TPV\",\"mode\":2,\"time\":\"2017-07-19T08:50:01.000Z\",",
            "\"lat\":-34.9062266,\"lon\":138.6081199}\n",
            "{\"class\":\"TPV\",\"mode\":3,\"time\":\"2017-07-19T08:50:02.000Z\",\"lat\":-34.9}\n",
            "{\"class\":\"TPV\",\"mode\":3,\"time\":\"2017-07-19T08:50:02\n",
        );
        let reference = reference_epochs(chk, b"");
        assert_eq!(reference.fixes_without_time, 1);
        assert_eq!(reference.unreadable_lines, 1);
        assert_eq!(reference.epochs.len(), 2);
        let first = reference.epochs[0];
        assert_eq!(first.time, parse_utc("2017-07-19T08:50:00.800Z").unwrap());
        assert_eq!(
            (first.mode, first.lat_deg, first.lon_deg),
            (3, -34.9062263, 138.6081197)
        );
        assert_eq!(first.alt_msl_m, Some(28.895));
        assert_eq!(
            first.ecef_m,
            Some([-3_933_349.97, 3_466_291.61, -3_629_303.21])
        );
        let second = reference.epochs[1];
        assert_eq!(
            (second.mode, second.alt_msl_m, second.ecef_m),
            (2, None, None)
        );
    }
}
