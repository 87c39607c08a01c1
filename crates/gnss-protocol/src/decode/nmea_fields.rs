//! The fields of an NMEA 0183 sentence, read strictly: a field is either empty (the receiver has
//! no value) or a value in the standard's format and range; anything else makes the sentence
//! malformed. Nothing here allocates.

/// A field that is neither empty nor a value of its format or range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BadField;

/// What reading one field gives: `Ok(None)` for an empty field.
pub type Field<T> = Result<Option<T>, BadField>;

/// The comma-separated fields after the address, in order. A sentence shorter than the standard
/// (older receivers omit the trailing mode fields) reads as empty fields past its end.
pub struct Fields<'a>(core::str::Split<'a, char>);

impl<'a> Fields<'a> {
    /// The fields of `data` (the text between the address's comma and the `*`).
    pub fn new(data: &'a str) -> Self {
        Self(data.split(','))
    }

    /// The next field's text, empty past the end.
    pub fn text(&mut self) -> &'a str {
        self.0.next().unwrap_or("")
    }

    /// Skips `n` fields.
    pub fn skip(&mut self, n: usize) {
        for _ in 0..n {
            self.text();
        }
    }

    /// UTC time of day `hhmmss[.s…]`, µs.
    pub fn time_of_day_us(&mut self) -> Field<u64> {
        let text = self.text();
        if text.is_empty() {
            return Ok(None);
        }
        let (whole, fraction) = text.split_once('.').unwrap_or((text, ""));
        let b = whole.as_bytes();
        if b.len() != 6 || !b.iter().all(u8::is_ascii_digit) || fraction.len() > 6 {
            return Err(BadField);
        }
        let two = |i: usize| u64::from(b[i] - b'0') * 10 + u64::from(b[i + 1] - b'0');
        let (h, m, s) = (two(0), two(2), two(4));
        // 60 s: a leap second.
        if h > 23 || m > 59 || s > 60 {
            return Err(BadField);
        }
        let mut micros = 0u64;
        let mut scale = 100_000u64;
        for &d in fraction.as_bytes() {
            if !d.is_ascii_digit() {
                return Err(BadField);
            }
            micros += u64::from(d - b'0') * scale;
            scale /= 10;
        }
        Ok(Some(((h * 60 + m) * 60 + s) * 1_000_000 + micros))
    }

    /// Latitude `ddmm.mmmm` and its hemisphere `N`/`S`, degrees (south negative).
    pub fn latitude_deg(&mut self) -> Field<f64> {
        self.angle(90.0, b'N', b'S')
    }

    /// Longitude `dddmm.mmmm` and its hemisphere `E`/`W`, degrees (west negative).
    pub fn longitude_deg(&mut self) -> Field<f64> {
        self.angle(180.0, b'E', b'W')
    }

    fn angle(&mut self, max_deg: f64, positive: u8, negative: u8) -> Field<f64> {
        let (value, hemisphere) = (self.text(), self.text());
        if value.is_empty() && hemisphere.is_empty() {
            return Ok(None);
        }
        let sign = match hemisphere.as_bytes() {
            [h] if *h == positive => 1.0,
            [h] if *h == negative => -1.0,
            _ => return Err(BadField),
        };
        let Some(v) = unsigned_decimal(value) else {
            return Err(BadField);
        };
        let degrees = (v / 100.0).trunc();
        let minutes = v - degrees * 100.0;
        let angle = degrees + minutes / 60.0;
        if minutes >= 60.0 || angle > max_deg {
            return Err(BadField);
        }
        Ok(Some(sign * angle))
    }

    /// A decimal number without a sign.
    pub fn unsigned(&mut self) -> Field<f64> {
        let text = self.text();
        if text.is_empty() {
            return Ok(None);
        }
        unsigned_decimal(text).map(Some).ok_or(BadField)
    }

    /// A decimal number with an optional sign.
    pub fn signed(&mut self) -> Field<f64> {
        let text = self.text();
        let (sign, magnitude) = match text.as_bytes().first() {
            None => return Ok(None),
            Some(b'-') => (-1.0, &text[1..]),
            Some(b'+') => (1.0, &text[1..]),
            Some(_) => (1.0, text),
        };
        unsigned_decimal(magnitude)
            .map(|v| Some(sign * v))
            .ok_or(BadField)
    }

    /// A count of at most 255 (satellites).
    pub fn count(&mut self) -> Field<u8> {
        let text = self.text();
        if text.is_empty() {
            return Ok(None);
        }
        if text.len() > 3 || !text.bytes().all(|b| b.is_ascii_digit()) {
            return Err(BadField);
        }
        text.parse().map(Some).map_err(|_| BadField)
    }

    /// A one-character field, one of `allowed`.
    pub fn flag(&mut self, allowed: &[u8]) -> Field<u8> {
        match self.text().as_bytes() {
            [] => Ok(None),
            [c] if allowed.contains(c) => Ok(Some(*c)),
            _ => Err(BadField),
        }
    }

    /// A unit field: empty or exactly `unit`.
    pub fn unit(&mut self, unit: u8) -> Result<(), BadField> {
        self.flag(&[unit]).map(|_| ())
    }
}

/// Digits with at most one decimal point (`12.5`, `.5`, `12.`), and nothing else: no sign,
/// exponent, `inf` or `nan`, which `f64::from_str` would take.
fn unsigned_decimal(text: &str) -> Option<f64> {
    let mut digits = 0;
    let mut points = 0;
    for b in text.bytes() {
        match b {
            b'0'..=b'9' => digits += 1,
            b'.' => points += 1,
            _ => return None,
        }
    }
    if digits == 0 || points > 1 {
        return None;
    }
    text.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_of_day_read_with_any_fraction_and_nothing_else() {
        let mut f = Fields::new("123519,123519.5,000000.001,235960,,240000,12351,1235a9,123519.");
        assert_eq!(f.time_of_day_us(), Ok(Some(45_319_000_000)));
        assert_eq!(f.time_of_day_us(), Ok(Some(45_319_500_000)));
        assert_eq!(f.time_of_day_us(), Ok(Some(1_000)));
        assert_eq!(f.time_of_day_us(), Ok(Some(86_400_000_000)));
        assert_eq!(f.time_of_day_us(), Ok(None));
        for _ in 0..3 {
            assert_eq!(f.time_of_day_us(), Err(BadField));
        }
        assert_eq!(f.time_of_day_us(), Ok(Some(45_319_000_000)));
        // Past the end: empty.
        assert_eq!(f.time_of_day_us(), Ok(None));
    }

    #[test]
    fn angles_need_a_hemisphere_and_minutes_below_sixty() {
        let mut f = Fields::new("4807.038,N,01131.000,W,4807.038,,,N,4860.0,N,36000.0000,N,,");
        let lat = f.latitude_deg().unwrap().unwrap();
        assert!((lat - (48.0 + 7.038 / 60.0)).abs() < 1e-12);
        assert_eq!(f.longitude_deg(), Ok(Some(-(11.0 + 31.0 / 60.0))));
        assert_eq!(f.latitude_deg(), Err(BadField));
        assert_eq!(f.latitude_deg(), Err(BadField));
        assert_eq!(f.latitude_deg(), Err(BadField));
        assert_eq!(f.latitude_deg(), Err(BadField));
        assert_eq!(f.latitude_deg(), Ok(None));
    }

    #[test]
    fn numbers_refuse_what_a_receiver_does_not_write() {
        let mut f = Fields::new("1.5,-30.1,+2,inf,1e3,1.2.3,-,256,08");
        assert_eq!(f.unsigned(), Ok(Some(1.5)));
        assert_eq!(f.signed(), Ok(Some(-30.1)));
        assert_eq!(f.signed(), Ok(Some(2.0)));
        assert_eq!(f.unsigned(), Err(BadField));
        assert_eq!(f.unsigned(), Err(BadField));
        assert_eq!(f.unsigned(), Err(BadField));
        assert_eq!(f.signed(), Err(BadField));
        assert_eq!(f.count(), Err(BadField));
        assert_eq!(f.count(), Ok(Some(8)));
    }
}
