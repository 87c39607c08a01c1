//! The position messages a capture itself carries, read without the product's decoder.
//!
//! A second reference beside gpsd's: every NMEA GGA, GNS, RMC and GLL sentence (any talker, good
//! checksum, not flagged "no fix") and every UBX NAV-PVT, NAV-POSLLH and NAV-SOL frame (not
//! flagged "no fix"), with the receiver's time it carries. The product's framer cuts the bytes
//! into sentences and frames (so "sentence" means what it means to the decoder), but the fields
//! are read here with their own simple code: this is a check of the product's NMEA and UBX
//! readers, so it shares none of their parsing. No byte sequence makes it panic.

use rins_gnss_protocol::decode::framer::{Framed, Framer};
use serde::Serialize;

/// µs in a UTC day.
pub const US_PER_DAY: u64 = 86_400_000_000;
/// ms in a GPS week.
pub const MS_PER_WEEK: u64 = 604_800_000;

/// Which message a position came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OwnMessage {
    /// NMEA GGA.
    Gga,
    /// NMEA GNS.
    Gns,
    /// NMEA RMC.
    Rmc,
    /// NMEA GLL.
    Gll,
    /// UBX NAV-PVT.
    NavPvt,
    /// UBX NAV-POSLLH.
    NavPosllh,
    /// UBX NAV-SOL.
    NavSol,
}

impl OwnMessage {
    /// The receiver's full solution of an epoch (GGA, GNS, NAV-PVT, NAV-POSLLH): the message a
    /// fix must agree with where the receiver sent one; RMC, GLL and NAV-SOL only otherwise.
    pub fn is_full_solution(self) -> bool {
        matches!(self, Self::Gga | Self::Gns | Self::NavPvt | Self::NavPosllh)
    }
}

/// The receiver's time a position message carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OwnTime {
    /// NMEA: UTC time of day, µs.
    UtcOfDayUs(u64),
    /// UBX: GPS time of week (iTOW), ms.
    TimeOfWeekMs(u64),
}

/// Where a position message puts the receiver.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OwnPlace {
    /// Geodetic latitude and longitude, degrees (WGS84).
    Geodetic {
        /// Latitude, degrees, north positive.
        lat_deg: f64,
        /// Longitude, degrees, east positive.
        lon_deg: f64,
    },
    /// Earth-centred, earth-fixed position, m (NAV-SOL).
    Ecef([f64; 3]),
}

/// One position message of a capture.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OwnPosition {
    /// The message.
    pub message: OwnMessage,
    /// Its receiver time.
    pub time: OwnTime,
    /// Its position.
    pub place: OwnPlace,
}

/// Every position message of a capture, and what was set aside.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct OwnPositions {
    /// The position messages, in the order of the bytes.
    pub positions: Vec<OwnPosition>,
    /// Position sentences without a checksum, or whose checksum does not match.
    pub bad_checksum: usize,
    /// Position messages whose status, quality or fix type says "no fix".
    pub no_fix: usize,
    /// Position messages with an empty or unreadable time or position field, or too short.
    pub unreadable: usize,
}

/// What reading one message gave.
enum Read {
    Position(OwnPosition),
    NoFix,
    Unreadable,
    BadChecksum,
    /// Not a position message.
    Other,
}

/// The position messages of `receiver_bytes` (a capture's bytes after its `#` comment lines).
pub fn own_positions(receiver_bytes: &[u8]) -> OwnPositions {
    let mut out = OwnPositions::default();
    let mut framer = Box::<Framer>::default();
    framer.push(receiver_bytes, |item| {
        let read = match item {
            Framed::Nmea(sentence) => read_sentence(sentence),
            Framed::Ubx { class, id, payload } => read_ubx(class, id, payload),
            _ => Read::Other,
        };
        match read {
            Read::Position(p) => out.positions.push(p),
            Read::NoFix => out.no_fix += 1,
            Read::Unreadable => out.unreadable += 1,
            Read::BadChecksum => out.bad_checksum += 1,
            Read::Other => {}
        }
    });
    out
}

/// The body of `sentence` (`$` through the line end) between `$` and `*`, when its checksum is
/// there and matches.
fn checked_body(sentence: &[u8]) -> Option<&[u8]> {
    let line = sentence.strip_prefix(b"$")?;
    let line = line.strip_suffix(b"\n").unwrap_or(line);
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    let star = line.iter().rposition(|&b| b == b'*')?;
    let (body, sum) = (&line[..star], &line[star + 1..]);
    let [hi, lo] = sum else { return None };
    let expected = hex(*hi)? << 4 | hex(*lo)?;
    (body.iter().fold(0_u8, |x, &b| x ^ b) == expected).then_some(body)
}

fn hex(b: u8) -> Option<u8> {
    char::from(b)
        .to_digit(16)
        .and_then(|d| u8::try_from(d).ok())
}

/// Reads a GGA, GNS, RMC or GLL sentence of any talker.
fn read_sentence(sentence: &[u8]) -> Read {
    let kind = match sentence.get(3..7) {
        Some(b"GGA,") => OwnMessage::Gga,
        Some(b"GNS,") => OwnMessage::Gns,
        Some(b"RMC,") => OwnMessage::Rmc,
        Some(b"GLL,") => OwnMessage::Gll,
        _ => return Read::Other,
    };
    let Some(body) = checked_body(sentence) else {
        return Read::BadChecksum;
    };
    let mut fields = [&b""[..]; 14];
    for (slot, field) in fields.iter_mut().zip(body.split(|&b| b == b',')) {
        *slot = field;
    }
    // Indices of time, latitude (hemisphere follows), longitude (hemisphere follows), and
    // whether the sentence's own status says there is no fix.
    let (time, lat, lon, no_fix) = match kind {
        OwnMessage::Gga => (1, 2, 4, fields[6] == b"0" || fields[6].is_empty()),
        OwnMessage::Gns => (1, 2, 4, fields[6].iter().all(|&m| m == b'N')),
        OwnMessage::Rmc => (1, 3, 5, fields[2] != b"A" || fields[12] == b"N"),
        _ => (5, 1, 3, fields[6] == b"V" || fields[7] == b"N"),
    };
    if no_fix {
        return Read::NoFix;
    }
    let place = degrees(fields[lat], fields[lat + 1], b'N', b'S', 90).zip(degrees(
        fields[lon],
        fields[lon + 1],
        b'E',
        b'W',
        180,
    ));
    match (time_of_day_us(fields[time]), place) {
        (Some(us), Some((lat_deg, lon_deg))) => Read::Position(OwnPosition {
            message: kind,
            time: OwnTime::UtcOfDayUs(us),
            place: OwnPlace::Geodetic { lat_deg, lon_deg },
        }),
        _ => Read::Unreadable,
    }
}

/// `dddmm.mmmm` with its hemisphere (`positive` or `negative`) as signed degrees, at most `max`.
fn degrees(value: &[u8], hemisphere: &[u8], positive: u8, negative: u8, max: u32) -> Option<f64> {
    let sign = match hemisphere {
        [h] if *h == positive => 1.0,
        [h] if *h == negative => -1.0,
        _ => return None,
    };
    let dot = value.iter().position(|&b| b == b'.').unwrap_or(value.len());
    let split = dot.checked_sub(2)?;
    let whole = digits(&value[..split])?;
    let minutes: f64 = std::str::from_utf8(&value[split..]).ok()?.parse().ok()?;
    let degrees = f64::from(whole) + minutes / 60.0;
    let valid = value[split..]
        .iter()
        .all(|b| b.is_ascii_digit() || *b == b'.')
        && minutes < 60.0
        && degrees <= f64::from(max);
    valid.then_some(sign * degrees)
}

/// `hhmmss` with an optional fraction of any length (`.s`, `.ss`, `.sss`) as µs of the day.
fn time_of_day_us(value: &[u8]) -> Option<u64> {
    let (whole, fraction) = match value.iter().position(|&b| b == b'.') {
        Some(dot) => (&value[..dot], &value[dot + 1..]),
        None => (value, &b""[..]),
    };
    let [h1, h2, m1, m2, s1, s2] = whole else {
        return None;
    };
    let (h, m, s) = (
        digits(&[*h1, *h2])?,
        digits(&[*m1, *m2])?,
        digits(&[*s1, *s2])?,
    );
    // Up to 60 s: a leap second.
    if h > 23 || m > 59 || s > 60 {
        return None;
    }
    let mut micro = 0_u64;
    let mut scale = 100_000_u64;
    for &b in fraction {
        let d = char::from(b).to_digit(10)?;
        micro += u64::from(d) * scale;
        scale /= 10;
    }
    Some((u64::from(h * 3600 + m * 60 + s)) * 1_000_000 + micro)
}

/// A run of 1 to 9 decimal digits.
fn digits(value: &[u8]) -> Option<u32> {
    if value.is_empty() || value.len() > 9 {
        return None;
    }
    value.iter().try_fold(0_u32, |n, &b| {
        char::from(b).to_digit(10).map(|d| n * 10 + d)
    })
}

/// Little-endian u32 / i32 at `offset` of `payload`.
fn u32_at(payload: &[u8], offset: usize) -> Option<u32> {
    let bytes = payload.get(offset..offset + 4)?;
    Some(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]))
}

fn i32_at(payload: &[u8], offset: usize) -> Option<i32> {
    u32_at(payload, offset).map(|u| u as i32)
}

/// UBX class NAV and its NAV-POSLLH, NAV-SOL, NAV-PVT ids.
const NAV: u8 = 0x01;
const POSLLH: u8 = 0x02;
const SOL: u8 = 0x06;
const PVT: u8 = 0x07;

/// Reads a NAV-PVT (fixType at offset 20, 0 = no fix), NAV-POSLLH (no fix flag) or NAV-SOL
/// (gpsFix at offset 10, 0 = no fix) frame.
fn read_ubx(class: u8, id: u8, payload: &[u8]) -> Read {
    let message = match (class, id) {
        (NAV, PVT) => OwnMessage::NavPvt,
        (NAV, POSLLH) => OwnMessage::NavPosllh,
        (NAV, SOL) => OwnMessage::NavSol,
        _ => return Read::Other,
    };
    let fix_type_offset = match message {
        OwnMessage::NavPvt => Some(20),
        OwnMessage::NavSol => Some(10),
        _ => None,
    };
    if let Some(offset) = fix_type_offset
        && payload.get(offset) == Some(&0)
    {
        return Read::NoFix;
    }
    let deg = |offset| i32_at(payload, offset).map(|v| f64::from(v) * 1e-7);
    let cm = |offset| i32_at(payload, offset).map(|v| f64::from(v) * 0.01);
    let place = match message {
        OwnMessage::NavPvt => deg(28)
            .zip(deg(24))
            .map(|(lat_deg, lon_deg)| OwnPlace::Geodetic { lat_deg, lon_deg }),
        OwnMessage::NavPosllh => deg(8)
            .zip(deg(4))
            .map(|(lat_deg, lon_deg)| OwnPlace::Geodetic { lat_deg, lon_deg }),
        _ => match (cm(12), cm(16), cm(20)) {
            (Some(x), Some(y), Some(z)) => Some(OwnPlace::Ecef([x, y, z])),
            _ => None,
        },
    };
    match (u32_at(payload, 0), place) {
        (Some(itow), Some(place)) => Read::Position(OwnPosition {
            message,
            time: OwnTime::TimeOfWeekMs(u64::from(itow)),
            place,
        }),
        _ => Read::Unreadable,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rins_gnss_protocol::encode::write_ubx_frame;

    /// `$body*HH\r\n` with the checksum `body` has.
    fn sentence(body: &str) -> String {
        let sum = body.bytes().fold(0_u8, |x, b| x ^ b);
        format!("${body}*{sum:02X}\r\n")
    }

    /// A UBX frame of `class`, `id` and `payload`, with its checksum.
    fn ubx(class: u8, id: u8, payload: &[u8]) -> Vec<u8> {
        let mut frame = Vec::new();
        write_ubx_frame(class, id, payload, &mut frame);
        frame
    }

    fn put(payload: &mut [u8], offset: usize, value: i32) {
        payload[offset..offset + 4].copy_from_slice(&value.to_le_bytes());
    }

    fn geodetic(p: &OwnPosition) -> (f64, f64) {
        match p.place {
            OwnPlace::Geodetic { lat_deg, lon_deg } => (lat_deg, lon_deg),
            OwnPlace::Ecef(_) => panic!("not geodetic: {p:?}"),
        }
    }

    #[test]
    fn real_sentences_of_every_kind_and_hemisphere_are_read() {
        let bytes = concat!(
            "$GPGGA,193221.00,2037.72792,N,08704.08478,W,1,04,1.7,-30.40,M,-13.9,M,,*7D\r\n",
            "$GPGGA,030719.000,3747.0873,S,17518.8938,E,1,08,1.1,59.9,M,23.7,M,,0000*7D\r\n",
            "$GNGNS,074155.799,3114.8770,N,12135.2463,E,ANNA,05,1.3,156.9,8.3,,0000*52\r\n",
            "$GPRMC,193221.00,A,2037.7279,N,08704.0848,W,00.1,201.8,231207,01,W,A*2D\r\n",
            "$GPGLL,5201.0809,N,00832.0852,E,142819.299,A,A*5D\n",
        );
        let own = own_positions(bytes.as_bytes());
        assert_eq!((own.bad_checksum, own.no_fix, own.unreadable), (0, 0, 0));
        let kinds: Vec<_> = own.positions.iter().map(|p| p.message).collect();
        use OwnMessage::*;
        assert_eq!(kinds, [Gga, Gga, Gns, Rmc, Gll]);
        let times: Vec<_> = own.positions.iter().map(|p| p.time).collect();
        let us = |h: u64, m: u64, s: u64, micro: u64| {
            OwnTime::UtcOfDayUs(((h * 60 + m) * 60 + s) * 1_000_000 + micro)
        };
        assert_eq!(
            times,
            [
                us(19, 32, 21, 0),
                us(3, 7, 19, 0),
                us(7, 41, 55, 799_000),
                us(19, 32, 21, 0),
                us(14, 28, 19, 299_000),
            ]
        );
        // Degrees plus minutes / 60, negative south and west; 1e-9° is 0.1 mm.
        let expected = [
            (20.0 + 37.72792 / 60.0, -(87.0 + 4.08478 / 60.0)),
            (-(37.0 + 47.0873 / 60.0), 175.0 + 18.8938 / 60.0),
            (31.0 + 14.8770 / 60.0, 121.0 + 35.2463 / 60.0),
            (20.0 + 37.7279 / 60.0, -(87.0 + 4.0848 / 60.0)),
            (52.0 + 1.0809 / 60.0, 8.0 + 32.0852 / 60.0),
        ];
        for (p, (lat, lon)) in own.positions.iter().zip(expected) {
            let (la, lo) = geodetic(p);
            assert!((la - lat).abs() < 1e-9 && (lo - lon).abs() < 1e-9, "{p:?}");
        }
    }

    #[test]
    fn bad_checksums_no_fix_and_empty_fields_are_counted_apart() {
        let mut bytes = String::new();
        // A wrong checksum (a digit changed), and none at all.
        bytes += "$GPGGA,193221.00,2037.72792,N,08704.08479,W,1,04,1.7,-30.40,M,-13.9,M,,*7D\r\n";
        bytes += "$GPGGA,193221.00,2037.72792,N,08704.08478,W,1,04,1.7,-30.40,M,-13.9,M,,\r\n";
        // Receivers' "no fix": GGA quality 0, GNS mode all N, RMC and GLL status V.
        bytes += "$GNGGA,074150.799,,,,,0,00,,,M,0.0,M,,0000,*64\r\n";
        bytes += "$GNGNS,074150.799,,,,,NNNN,00,,,0.0,,0000*63\r\n";
        bytes += "$GPRMC,125106,V,3854.5087,N,07726.4523,W,0.0,0.0,241011,10.5,W,S*28\r\n";
        bytes += "$GPGLL,3854.5087,N,07726.4523,W,125106,V,S*55\r\n";
        // A fix with an empty latitude, a hemisphere that is none, an empty time, minutes of 60.
        bytes += &sentence("GPGGA,193221.00,,N,08704.08478,W,1,04,1.7,-30.40,M,-13.9,M,,");
        bytes += &sentence("GPGGA,193221.00,2037.72792,X,08704.08478,W,1,04,1.7,1,M,1,M,,");
        bytes += &sentence("GPRMC,,A,2037.7279,N,08704.0848,W,00.1,201.8,231207,01,W,A");
        bytes += &sentence("GPGLL,5260.0000,N,00832.0852,E,142819.299,A,A");
        // Not position sentences.
        bytes += &sentence("GPGSA,A,3,04,05,,09,12,,,24,,,,,2.5,1.3,2.1");
        let own = own_positions(bytes.as_bytes());
        assert!(own.positions.is_empty(), "{:?}", own.positions);
        assert_eq!((own.bad_checksum, own.no_fix, own.unreadable), (2, 4, 4));
    }

    #[test]
    fn times_with_one_to_three_decimals_or_none_are_us_of_the_day() {
        assert_eq!(time_of_day_us(b"000000"), Some(0));
        assert_eq!(time_of_day_us(b"235959.9"), Some(86_399_900_000));
        assert_eq!(time_of_day_us(b"125106.25"), Some(46_266_250_000));
        assert_eq!(time_of_day_us(b"125106.125"), Some(46_266_125_000));
        for bad in [
            &b""[..],
            b"12510",
            b"1251066",
            b"246000",
            b"12a106",
            b"125106.x",
        ] {
            assert_eq!(time_of_day_us(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn ubx_nav_pvt_posllh_and_sol_are_read_at_their_offsets() {
        let mut pvt = vec![0_u8; 92];
        put(&mut pvt, 0, 123_456_000);
        pvt[20] = 3;
        put(&mut pvt, 24, 71_234_567);
        put(&mut pvt, 28, -451_234_567);
        let mut posllh = vec![0_u8; 28];
        put(&mut posllh, 0, 123_457_000);
        put(&mut posllh, 4, -1_234_567_890);
        put(&mut posllh, 8, 123_456_789);
        let mut sol = vec![0_u8; 52];
        put(&mut sol, 0, 123_458_000);
        sol[10] = 3;
        put(&mut sol, 12, -148_867_311);
        put(&mut sol, 16, -339_108_817);
        put(&mut sol, 20, 510_218_653);
        let mut no_fix = pvt.clone();
        no_fix[20] = 0;
        let mut bytes = Vec::new();
        for (id, payload) in [(7, &pvt), (2, &posllh), (6, &sol), (7, &no_fix)] {
            bytes.extend(ubx(1, id, payload));
        }
        // A NAV-POSLLH cut short, and a frame of another message.
        bytes.extend(ubx(1, 2, &posllh[..6]));
        bytes.extend(ubx(1, 0x35, &[0; 8]));
        let own = own_positions(&bytes);
        assert_eq!((own.no_fix, own.unreadable, own.bad_checksum), (1, 1, 0));
        let [a, b, c] = own.positions[..] else {
            panic!("{:?}", own.positions);
        };
        assert_eq!(a.message, OwnMessage::NavPvt);
        assert_eq!(a.time, OwnTime::TimeOfWeekMs(123_456_000));
        let (lat, lon) = geodetic(&a);
        assert!((lat + 45.123_456_7).abs() < 1e-12 && (lon - 7.123_456_7).abs() < 1e-12);
        assert_eq!(b.message, OwnMessage::NavPosllh);
        assert_eq!(b.time, OwnTime::TimeOfWeekMs(123_457_000));
        let (lat, lon) = geodetic(&b);
        assert!((lat - 12.345_678_9).abs() < 1e-12 && (lon + 123.456_789).abs() < 1e-12);
        assert_eq!(c.message, OwnMessage::NavSol);
        let OwnPlace::Ecef(xyz) = c.place else {
            panic!("{c:?}")
        };
        assert_eq!(xyz, [-1_488_673.11, -3_391_088.17, 5_102_186.53]);
    }

    #[test]
    fn no_byte_sequence_panics() {
        use proptest::prelude::*;
        proptest!(|(bytes in proptest::collection::vec(any::<u8>(), 0..600))| {
            let _ = own_positions(&bytes);
            let mut framed = b"$GPGGA,".to_vec();
            framed.extend(bytes.iter().filter(|b| b.is_ascii_graphic()));
            framed.extend(b"\r\n");
            let _ = own_positions(&framed);
        });
    }
}
