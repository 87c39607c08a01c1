//! One NMEA 0183 sentence as framed on the line: its checksum checked, its address split into
//! talker and kind, and the kinds the decoder does not use counted by kind.
//!
//! A sentence is `$` (some receivers write `$$`), an address, `,` and fields, `*` and two hex
//! digits of the XOR of everything between `$` and `*`. The address is a two-letter talker (GP
//! GPS, GL GLONASS, GA Galileo, GB/BD BeiDou, GQ/QZ QZSS, GN several systems combined, …) and a
//! three-letter sentence formatter, or `P` and a maker's own name for a proprietary sentence.

use super::nmea_fields::Fields;

/// The sentences the decoder reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Used {
    /// Fix data: time, position, quality, satellites, HDOP, altitude.
    Gga,
    /// GNSS fix data: GGA with a mode letter per satellite system.
    Gns,
    /// Recommended minimum: time, status, position, speed and course.
    Rmc,
    /// Geographic position: position, time, status.
    Gll,
    /// Pseudorange error statistics: position σ.
    Gst,
    /// Course and speed over ground (no time).
    Vtg,
    /// DOP and active satellites: the fix mode (no time).
    Gsa,
}

impl Used {
    /// How many kinds there are (for per-kind tables).
    pub const COUNT: usize = 7;
}

/// The talker of a sentence, as far as combining several in one epoch needs it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Talker {
    /// GPS.
    Gp,
    /// GLONASS.
    Gl,
    /// Galileo.
    Ga,
    /// BeiDou (`GB` or `BD`).
    Gb,
    /// QZSS (`GQ` or `QZ`).
    Gq,
    /// Several systems combined in one solution.
    Gn,
    /// Any other talker (`IN` integrated navigation, `II` instrument, …).
    Other,
}

impl Talker {
    /// How many talkers are told apart (for per-talker tables).
    pub const COUNT: usize = 7;

    fn from_address(t: &[u8]) -> Self {
        match t {
            b"GP" => Self::Gp,
            b"GL" => Self::Gl,
            b"GA" => Self::Ga,
            b"GB" | b"BD" => Self::Gb,
            b"GQ" | b"QZ" => Self::Gq,
            b"GN" => Self::Gn,
            _ => Self::Other,
        }
    }
}

/// What the NMEA side set aside, by kind. Well-formed sentences with a good checksum that the
/// decoder does not use: satellites in view (GSV), date (ZDA), text (TXT) and fault detection
/// (GBS) are what receivers send most besides the position and DOP (GSA); other
/// standard sentences (route, waypoint, heading, depth, …) and proprietary ones (`$P…`: PGRME,
/// PSTI, PMTK, PUBX, …) are counted together.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct NmeaStats {
    /// GSV: satellites in view.
    pub gsv: u64,
    /// GSA (DOP and active satellites, read for its fix mode) with no epoch in progress to place
    /// it in: sent before the receiver's first timed sentence. Not used.
    pub gsa: u64,
    /// ZDA: date and time.
    pub zda: u64,
    /// TXT: text messages.
    pub txt: u64,
    /// GBS: satellite fault detection.
    pub gbs: u64,
    /// Other standard sentences.
    pub other: u64,
    /// Proprietary sentences (`$P…`).
    pub proprietary: u64,
    /// Sentences of a used kind with nothing in them to use: no time to place them in an epoch
    /// (an RMC before the receiver knows the time), a GST without σ, a VTG with no epoch in
    /// progress.
    pub nothing_to_use: u64,
    /// Sentences without a checksum (also counted as checksum errors): they cannot be told from
    /// corrupted ones.
    pub without_checksum: u64,
    /// Epochs with sentences of their time but no position sentence (GST only): not published.
    pub epochs_without_position: u64,
    /// Epochs whose three-dimensional fix had values no receiver on a small aircraft measures
    /// (altitude, speed): published as without a fix.
    pub implausible_epochs: u64,
}

/// What a sentence is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// One the decoder reads.
    Used(Used),
    /// Satellites in view.
    Gsv,
    /// Date and time.
    Zda,
    /// Text.
    Txt,
    /// Satellite fault detection.
    Gbs,
    /// Another standard sentence.
    Other,
    /// A maker's own sentence.
    Proprietary,
}

impl NmeaStats {
    /// Counts one sentence of `kind` the decoder does not use.
    pub fn count(&mut self, kind: Kind) {
        let counter = match kind {
            Kind::Used(_) => &mut self.nothing_to_use,
            Kind::Gsv => &mut self.gsv,
            Kind::Zda => &mut self.zda,
            Kind::Txt => &mut self.txt,
            Kind::Gbs => &mut self.gbs,
            Kind::Other => &mut self.other,
            Kind::Proprietary => &mut self.proprietary,
        };
        *counter += 1;
    }
}

/// A sentence whose checksum matched.
pub struct Sentence<'a> {
    /// Its talker (`Other` for a proprietary sentence).
    pub talker: Talker,
    /// Its kind.
    pub kind: Kind,
    /// The fields after the address.
    pub fields: Fields<'a>,
}

/// Why a sentence was not taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refused {
    /// The checksum did not match.
    Checksum,
    /// No `*hh` at the end: nothing to check it by.
    WithoutChecksum,
    /// Not a sentence: no `$`, a character outside printable ASCII, an empty or non-alphanumeric
    /// address, or a checksum that is not two hex digits.
    Unreadable,
}

/// The longest address taken: proprietary ones are a few letters longer than the standard five.
const MAX_ADDRESS: usize = 16;

/// Reads one sentence from `$` to its end (with or without `\r\n`).
pub fn read(raw: &[u8]) -> Result<Sentence<'_>, Refused> {
    let mut end = raw.len();
    while end > 0 && matches!(raw[end - 1], b'\r' | b'\n') {
        end -= 1;
    }
    let line = &raw[..end];
    let line = line.strip_prefix(b"$$").or_else(|| line.strip_prefix(b"$"));
    let Some(line) = line else {
        return Err(Refused::Unreadable);
    };
    if !line.iter().all(|b| (0x20..=0x7E).contains(b) && *b != b'$') {
        return Err(Refused::Unreadable);
    }
    let Some(star) = line.iter().rposition(|&b| b == b'*') else {
        return Err(Refused::WithoutChecksum);
    };
    let (body, given) = (&line[..star], &line[star + 1..]);
    let given = match given {
        [h, l] => hex(*h).zip(hex(*l)).map(|(h, l)| h << 4 | l),
        _ => None,
    };
    let Some(given) = given else {
        return Err(Refused::Unreadable);
    };
    if body.iter().fold(0, |c, b| c ^ b) != given {
        return Err(Refused::Checksum);
    }
    // All printable ASCII, checked above.
    let Ok(body) = core::str::from_utf8(body) else {
        return Err(Refused::Unreadable);
    };
    let (address, data) = body.split_once(',').unwrap_or((body, ""));
    if address.is_empty()
        || address.len() > MAX_ADDRESS
        || !address.bytes().all(|b| b.is_ascii_alphanumeric())
    {
        return Err(Refused::Unreadable);
    }
    let a = address.as_bytes();
    let (talker, kind) = if a[0] == b'P' {
        (Talker::Other, Kind::Proprietary)
    } else if a.len() == 5 {
        (Talker::from_address(&a[..2]), kind_of(&a[2..]))
    } else {
        (Talker::Other, Kind::Other)
    };
    Ok(Sentence {
        talker,
        kind,
        fields: Fields::new(data),
    })
}

fn kind_of(formatter: &[u8]) -> Kind {
    match formatter {
        b"GGA" => Kind::Used(Used::Gga),
        b"GNS" => Kind::Used(Used::Gns),
        b"RMC" => Kind::Used(Used::Rmc),
        b"GLL" => Kind::Used(Used::Gll),
        b"GST" => Kind::Used(Used::Gst),
        b"VTG" => Kind::Used(Used::Vtg),
        b"GSV" => Kind::Gsv,
        b"GSA" => Kind::Used(Used::Gsa),
        b"ZDA" => Kind::Zda,
        b"TXT" => Kind::Txt,
        b"GBS" => Kind::Gbs,
        _ => Kind::Other,
    }
}

fn hex(b: u8) -> Option<u8> {
    char::from(b).to_digit(16).map(|d| d as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kind(raw: &str) -> Result<(Talker, Kind), Refused> {
        read(raw.as_bytes()).map(|s| (s.talker, s.kind))
    }

    /// `$body*hh`.
    fn checked(body: &str) -> String {
        let checksum = body.bytes().fold(0u8, |c, b| c ^ b);
        format!("${body}*{checksum:02X}")
    }

    #[test]
    fn addresses_are_split_into_talker_and_kind() {
        let gga = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n";
        assert_eq!(kind(gga), Ok((Talker::Gp, Kind::Used(Used::Gga))));
        // A doubled `$`, and no line end.
        assert_eq!(kind(&format!("${}", gga.trim_end())), kind(gga));
        let cases = [
            (
                "BDGSA,A,3,,,,,,,,,,,,,1.2,0.7,1.0",
                Talker::Gb,
                Kind::Used(Used::Gsa),
            ),
            ("QZGSV,1,1,01,193,45,120,40", Talker::Gq, Kind::Gsv),
            ("GNZDA,012520.00,12,04,2019,00,00", Talker::Gn, Kind::Zda),
            (
                "PGRME,15.0,M,45.0,M,25.0,M",
                Talker::Other,
                Kind::Proprietary,
            ),
            ("PSTI,030,,V,,,,,,,,,,,,", Talker::Other, Kind::Proprietary),
            ("GPBOD,,T,,M,,", Talker::Gp, Kind::Other),
            ("STI,1", Talker::Other, Kind::Other),
            (
                "INGLL,4426.1130,N,07140.5579,W,194102,A",
                Talker::Other,
                Kind::Used(Used::Gll),
            ),
        ];
        for (body, talker, k) in cases {
            assert_eq!(kind(&checked(body)), Ok((talker, k)), "{body}");
        }
    }

    #[test]
    fn what_cannot_be_checked_is_refused_by_reason() {
        assert_eq!(
            kind("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,745.4,M,46.9,M,,*47"),
            Err(Refused::Checksum)
        );
        assert_eq!(
            kind("$GPGGA,222449,3349.0337,S,01843.9282,E,1,07,02.31,000115.4,M,0033.3,M,,"),
            Err(Refused::WithoutChecksum)
        );
        assert_eq!(kind("$GPGGA,1*4G"), Err(Refused::Unreadable));
        assert_eq!(kind("$GPGGA,1*4"), Err(Refused::Unreadable));
        assert_eq!(kind(&checked("GP GA,1")), Err(Refused::Unreadable));
        assert_eq!(kind(&checked(",1")), Err(Refused::Unreadable));
        assert_eq!(kind(&checked("GPG\u{7f}A,1")), Err(Refused::Unreadable));
        assert_eq!(kind(&checked("GPGGA,1")[1..]), Err(Refused::Unreadable));
    }
}
