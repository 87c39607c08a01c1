//! Numeric CSV tables with a fixed header: every field a finite number.

use std::path::Path;

use super::error::DatasetError;

/// Reads a file whose first line is `header` (fields compared after trimming spaces) and whose
/// other non-empty lines hold `header.len()` finite numbers. Returns the rows.
pub(crate) fn read_numeric<const N: usize>(
    path: &Path,
    header: &[&str; N],
) -> Result<Vec<[f64; N]>, DatasetError> {
    read_with(path, header, Values::Finite)
}

/// [`read_numeric`], except that an empty field or a non-finite number (`NaN`, `inf`) is read as
/// NaN instead of refused: for files whose loader repairs such rows.
pub(crate) fn read_numeric_allowing_gaps<const N: usize>(
    path: &Path,
    header: &[&str; N],
) -> Result<Vec<[f64; N]>, DatasetError> {
    read_with(path, header, Values::GapsAsNan)
}

/// What a field may hold.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Values {
    /// Finite numbers only.
    Finite,
    /// Numbers, with empty and non-finite fields read as NaN.
    GapsAsNan,
}

fn read_with<const N: usize>(
    path: &Path,
    header: &[&str; N],
    values: Values,
) -> Result<Vec<[f64; N]>, DatasetError> {
    let text = std::fs::read_to_string(path).map_err(|source| DatasetError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_with(path, &text, header, values)
}

/// [`read_numeric`] on text already read; `path` only names the source in errors.
pub(crate) fn parse_numeric<const N: usize>(
    path: &Path,
    text: &str,
    header: &[&str; N],
) -> Result<Vec<[f64; N]>, DatasetError> {
    parse_with(path, text, header, Values::Finite)
}

fn parse_with<const N: usize>(
    path: &Path,
    text: &str,
    header: &[&str; N],
    values: Values,
) -> Result<Vec<[f64; N]>, DatasetError> {
    let mut lines = text.lines().map(|l| l.trim_end_matches('\r'));
    let first = lines.next().unwrap_or("");
    let found: Vec<&str> = first.split(',').map(str::trim).collect();
    if found != header[..] {
        return Err(DatasetError::Header {
            path: path.to_path_buf(),
            found: first.to_owned(),
            expected: header.join(","),
        });
    }
    let mut rows = Vec::new();
    for (index, line) in lines.enumerate() {
        let line_no = index + 2;
        if line.trim().is_empty() {
            continue;
        }
        let malformed = |reason: String| DatasetError::Malformed {
            path: path.to_path_buf(),
            line: line_no,
            reason,
        };
        let mut row = [0.0; N];
        let mut fields = line.split(',');
        for (column, (slot, name)) in row.iter_mut().zip(header).enumerate() {
            let field = fields.next().ok_or_else(|| {
                malformed(format!("{column} fields, expected {N} (missing {name})"))
            })?;
            let gaps = values == Values::GapsAsNan;
            let value: f64 = if gaps && field.trim().is_empty() {
                f64::NAN
            } else {
                field
                    .trim()
                    .parse()
                    .map_err(|_| malformed(format!("{name} = {:?}: not a number", field.trim())))?
            };
            if !value.is_finite() && !gaps {
                return Err(malformed(format!("{name} = {value}: not finite")));
            }
            *slot = value;
        }
        if fields.next().is_some() {
            return Err(malformed(format!(
                "{} fields, expected {N}",
                line.split(',').count()
            )));
        }
        rows.push(row);
    }
    Ok(rows)
}

/// A still recording for the loaders' tests: the `header` line, then `seconds` of rows at
/// `rate_hz`, each its time ((row number + `first_row`) / rate, s) followed by the same `values`.
#[cfg(test)]
pub(crate) fn still_rows(
    header: &[&str],
    rate_hz: f64,
    seconds: f64,
    first_row: usize,
    values: &str,
) -> String {
    let mut text = header.join(",") + "\n";
    let rows = (seconds * rate_hz).round() as usize + 1;
    for k in 0..rows {
        let t = (k + first_row) as f64 / rate_hz;
        text += &format!("{t},{values}\n");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    const H: [&str; 3] = ["time", "a", "b"];

    fn parse(text: &str) -> Result<Vec<[f64; 3]>, DatasetError> {
        parse_numeric(Path::new("x/IMU_1.csv"), text, &H)
    }

    #[test]
    fn reads_rows_with_spaces_crlf_and_blank_lines() {
        let rows = parse("time, a ,b\r\n0.0,1,2\r\n\r\n0.5, -3e-1 ,4\n").unwrap();
        assert_eq!(rows, vec![[0.0, 1.0, 2.0], [0.5, -0.3, 4.0]]);
    }

    #[test]
    fn errors_name_file_and_line() {
        let e = parse("time,a,b\n0,1,2\n0.1,x,2\n").unwrap_err();
        assert_eq!(e.to_string(), "x/IMU_1.csv:3: a = \"x\": not a number");
        let e = parse("time,a,b\n0,1\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "x/IMU_1.csv:2: 2 fields, expected 3 (missing b)"
        );
        let e = parse("time,a,b\n0,1,2,3\n").unwrap_err();
        assert_eq!(e.to_string(), "x/IMU_1.csv:2: 4 fields, expected 3");
        let e = parse("time,a,b\n0,1,NaN\n").unwrap_err();
        assert!(e.to_string().starts_with("x/IMU_1.csv:2: b = NaN"), "{e}");
        let e = parse("time,a,c\n").unwrap_err();
        assert!(e.to_string().starts_with("x/IMU_1.csv:1: header"), "{e}");
        let e = parse("").unwrap_err();
        assert!(matches!(e, DatasetError::Header { .. }));
    }

    #[test]
    fn gaps_are_read_as_nan_when_allowed() {
        let rows = parse_with(
            Path::new("x"),
            "time,a,b\n0,,inf\n1,NaN,2\n",
            &H,
            Values::GapsAsNan,
        )
        .unwrap();
        assert_eq!(rows[0][0], 0.0);
        assert!(rows[0][1].is_nan() && rows[0][2].is_infinite() && rows[1][1].is_nan());
        assert_eq!(rows[1][2], 2.0);
        let e = parse_with(Path::new("x"), "time,a,b\n0,x,1\n", &H, Values::GapsAsNan);
        assert!(e.is_err());
    }
}
