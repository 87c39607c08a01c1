//! MATLAB level 5 MAT-files, read with the `matfile` crate, and the one view of a variable the
//! conversions need: a real numeric matrix with every class widened to `f64`.
//!
//! `matfile` reads numeric matrices, uncompressed or zlib-compressed (`-v7`, SciPy's
//! `do_compression=True`). It skips variables of other classes (character, cell, struct,
//! sparse), so those read as absent here. Files are checked first for what the parser would
//! pass over or report without a reason: the header, the byte order (little-endian, as MATLAB
//! and SciPy write on every common machine) and whether the variables fill the file.

use matfile::{MatFile, NumericData};
use thiserror::Error;

/// Why a MAT-file could not be read.
#[derive(Debug, Error, PartialEq, Eq)]
#[error("not a readable MATLAB level 5 MAT-file: {0}")]
pub struct MatError(String);

/// Length of the text-and-version header in front of the variables.
const HEADER_LEN: usize = 128;
/// How the header's text begins.
const HEADER_TEXT: &[u8] = b"MATLAB 5.0 MAT-file";

/// Element type of an uncompressed variable.
const MI_MATRIX: u32 = 14;
/// Element type of a zlib-compressed variable, the one not padded to 8 bytes.
const MI_COMPRESSED: u32 = 15;

/// Checks that the top-level elements (8-byte tag: type, byte count; data; padding to 8 bytes
/// unless compressed) tile the file after the header. The parser stops at the first variable it
/// cannot read and keeps the ones before it, so a truncated file would otherwise lose its last
/// variables silently. Only variables stand at the top level; the parser would print a line to
/// standard output for anything else.
fn check_elements(bytes: &[u8]) -> Result<(), MatError> {
    let mut at = HEADER_LEN;
    while at < bytes.len() {
        let word = |k: usize| {
            bytes
                .get(at + k..at + k + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        };
        let (Some(kind), Some(len)) = (word(0), word(4)) else {
            return Err(MatError(format!("truncated: a partial tag at byte {at}")));
        };
        if kind != MI_MATRIX && kind != MI_COMPRESSED {
            return Err(MatError(format!(
                "the element at byte {at} is of type {kind}, not a variable \
                 ({MI_MATRIX}, or {MI_COMPRESSED} compressed)"
            )));
        }
        let end = at + 8 + len as usize;
        if end > bytes.len() {
            return Err(MatError(format!(
                "truncated: the variable at byte {at} holds {len} bytes, {} remain",
                bytes.len() - at - 8
            )));
        }
        at = if kind == MI_COMPRESSED {
            end
        } else {
            end.next_multiple_of(8).min(bytes.len())
        };
    }
    Ok(())
}

/// Every numeric variable of a little-endian MAT-file.
pub fn parse_mat(bytes: &[u8]) -> Result<MatFile, MatError> {
    // The parser's own errors do not say why; these are the common cases.
    if bytes.len() < HEADER_LEN {
        return Err(MatError(format!(
            "{} bytes, shorter than the {HEADER_LEN}-byte header",
            bytes.len()
        )));
    }
    if !bytes.starts_with(HEADER_TEXT) {
        return Err(MatError(
            "the header does not start with \"MATLAB 5.0 MAT-file\"".into(),
        ));
    }
    if bytes[HEADER_LEN - 2..HEADER_LEN] != *b"IM" {
        return Err(MatError(
            "not little-endian (endian indicator is not \"IM\")".into(),
        ));
    }
    check_elements(bytes)?;
    MatFile::parse(bytes).map_err(|e| match &e {
        matfile::Error::ParseError(kind) => MatError(format!("{e}: {kind:?}")),
        _ => MatError(e.to_string()),
    })
}

/// A real numeric matrix, column by column.
#[derive(Debug, Clone, PartialEq)]
pub struct Matrix {
    /// Its dimensions (rows, columns, ...).
    pub dims: Vec<usize>,
    /// Its values, column by column.
    pub values: Vec<f64>,
}

impl Matrix {
    /// Rows, the first dimension.
    pub fn rows(&self) -> usize {
        self.dims.first().copied().unwrap_or(0)
    }

    /// The product of the dimensions after the first.
    pub fn cols(&self) -> usize {
        self.dims.iter().skip(1).product()
    }

    /// The number of elements.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether it has no elements.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Element (row, column).
    pub fn at(&self, row: usize, col: usize) -> Option<f64> {
        if row < self.rows() && col < self.cols() {
            self.values.get(col * self.rows() + row).copied()
        } else {
            None
        }
    }
}

/// Why a variable is not a real numeric matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NotReal {
    /// No numeric variable of that name (absent, or of a class that is not read).
    Absent,
    /// It has an imaginary part.
    Complex,
    /// Its values do not fill its dimensions.
    Inconsistent,
}

/// The variable `name` of `file` as a real matrix.
pub fn real_matrix(file: &MatFile, name: &str) -> Result<Matrix, NotReal> {
    let array = file.find_by_name(name).ok_or(NotReal::Absent)?;
    fn widen<T: Copy>(real: &[T], imag: &Option<Vec<T>>, f: impl Fn(T) -> f64) -> Option<Vec<f64>> {
        imag.is_none().then(|| real.iter().map(|&x| f(x)).collect())
    }
    // 64-bit integers beyond 2^53 lose their last bits: the recordings hold labels and counts.
    let values = match array.data() {
        NumericData::Int8 { real, imag } => widen(real, imag, f64::from),
        NumericData::UInt8 { real, imag } => widen(real, imag, f64::from),
        NumericData::Int16 { real, imag } => widen(real, imag, f64::from),
        NumericData::UInt16 { real, imag } => widen(real, imag, f64::from),
        NumericData::Int32 { real, imag } => widen(real, imag, f64::from),
        NumericData::UInt32 { real, imag } => widen(real, imag, f64::from),
        NumericData::Int64 { real, imag } => widen(real, imag, |x| x as f64),
        NumericData::UInt64 { real, imag } => widen(real, imag, |x| x as f64),
        NumericData::Single { real, imag } => widen(real, imag, f64::from),
        NumericData::Double { real, imag } => widen(real, imag, |x| x),
    }
    .ok_or(NotReal::Complex)?;
    let dims = array.size().clone();
    let count = dims.iter().try_fold(1usize, |n, &d| n.checked_mul(d));
    if count != Some(values.len()) {
        return Err(NotReal::Inconsistent);
    }
    Ok(Matrix { dims, values })
}

/// Test fixtures: MAT-files written the way MATLAB and SciPy write them.
#[cfg(test)]
pub(crate) mod fixture {
    /// One element: tag and data padded to 8 bytes.
    pub fn element(kind: u32, data: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        out.extend_from_slice(&kind.to_le_bytes());
        out.extend_from_slice(&(data.len() as u32).to_le_bytes());
        out.extend_from_slice(data);
        out.resize(out.len().next_multiple_of(8), 0);
        out
    }

    /// A small element (data of at most 4 bytes packed in the tag).
    pub fn small(kind: u32, data: &[u8]) -> Vec<u8> {
        let mut out = (((data.len() as u32) << 16) | kind).to_le_bytes().to_vec();
        out.extend_from_slice(data);
        out.resize(8, 0);
        out
    }

    fn matrix(class_and_flags: u32, name: &str, dims: &[i32], parts: Vec<u8>) -> Vec<u8> {
        let mut body = element(6, &[class_and_flags.to_le_bytes(), [0; 4]].concat());
        let dim_bytes: Vec<u8> = dims.iter().flat_map(|d| d.to_le_bytes()).collect();
        body.extend(element(5, &dim_bytes));
        body.extend(if name.len() <= 4 {
            small(1, name.as_bytes())
        } else {
            element(1, name.as_bytes())
        });
        body.extend(parts);
        element(14, &body)
    }

    fn column_major(rows_of: &[&[f64]]) -> (Vec<i32>, Vec<u8>) {
        let rows = rows_of.len();
        let cols = rows_of.first().map_or(0, |r| r.len());
        let mut data = Vec::new();
        for c in 0..cols {
            for r in rows_of {
                data.extend_from_slice(&r[c].to_le_bytes());
            }
        }
        (vec![rows as i32, cols as i32], data)
    }

    /// A double matrix `rows` x `cols` from its rows.
    pub fn doubles(name: &str, rows_of: &[&[f64]]) -> Vec<u8> {
        let (dims, data) = column_major(rows_of);
        matrix(6, name, &dims, element(9, &data))
    }

    /// A complex double matrix whose real and imaginary parts are both `rows_of`.
    pub fn complex_doubles(name: &str, rows_of: &[&[f64]]) -> Vec<u8> {
        let (dims, data) = column_major(rows_of);
        let parts = [element(9, &data), element(9, &data)].concat();
        matrix(6 | 0x800, name, &dims, parts)
    }

    /// A 1 x n character matrix stored as UTF-8, as SciPy writes it.
    pub fn chars(name: &str, text: &str) -> Vec<u8> {
        let real = if text.len() <= 4 {
            small(16, text.as_bytes())
        } else {
            element(16, text.as_bytes())
        };
        matrix(4, name, &[1, text.len() as i32], real)
    }

    /// A 1 x n int64 vector, as SciPy writes integer arrays.
    pub fn int64s(name: &str, values: &[i64]) -> Vec<u8> {
        let data: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        matrix(14, name, &[1, values.len() as i32], element(12, &data))
    }

    /// `variable` as a compressed element (`miCOMPRESSED`, a zlib stream, no padding after it),
    /// as MATLAB `-v7` and SciPy's `do_compression=True` write it. The stream holds one stored
    /// deflate block (no compression), which a reader inflates like any other, so no compressor
    /// is needed to write it.
    pub fn compressed(variable: &[u8]) -> Vec<u8> {
        let len = u16::try_from(variable.len()).expect("a fixture variable under 64 KiB");
        let mut z = vec![0x78, 0x01, 0x01];
        z.extend_from_slice(&len.to_le_bytes());
        z.extend_from_slice(&(!len).to_le_bytes());
        z.extend_from_slice(variable);
        let (mut a, mut b) = (1u32, 0u32);
        for &byte in variable {
            a = (a + u32::from(byte)) % 65521;
            b = (b + a) % 65521;
        }
        z.extend_from_slice(&((b << 16) | a).to_be_bytes());
        let mut out = 15u32.to_le_bytes().to_vec();
        out.extend_from_slice(&(z.len() as u32).to_le_bytes());
        out.extend(z);
        out
    }

    /// A whole file of these variables.
    pub fn file(variables: &[Vec<u8>]) -> Vec<u8> {
        let mut header = b"MATLAB 5.0 MAT-file Platform: posix".to_vec();
        header.resize(116, b' ');
        header.resize(124, 0);
        header.extend_from_slice(&0x0100u16.to_le_bytes());
        header.extend_from_slice(b"IM");
        header.extend(variables.iter().flatten());
        header
    }
}

#[cfg(test)]
mod tests {
    use super::fixture::{chars, complex_doubles, compressed, doubles, file, int64s};
    use super::*;

    #[test]
    fn reads_doubles_column_by_column_and_widens_integers() {
        let bytes = file(&[
            doubles("imu", &[&[1.0, 2.0, 3.0], &[4.0, 5.0, 6.0]]),
            chars("best_detector", "shoe"),
            chars("label", "vicon room"),
            int64s("zv", &[1, 0, -1]),
        ]);
        let mat = parse_mat(&bytes).unwrap();
        let imu = real_matrix(&mat, "imu").unwrap();
        assert_eq!((imu.rows(), imu.cols(), imu.len()), (2, 3, 6));
        assert_eq!(imu.at(1, 0), Some(4.0));
        assert_eq!(imu.at(0, 2), Some(3.0));
        assert_eq!(imu.at(2, 0), None);
        assert_eq!(
            real_matrix(&mat, "zv").unwrap().values,
            vec![1.0, 0.0, -1.0]
        );
        // Character matrices are skipped, and do not hide the variables after them.
        assert_eq!(real_matrix(&mat, "best_detector"), Err(NotReal::Absent));
        assert_eq!(real_matrix(&mat, "nope"), Err(NotReal::Absent));
    }

    #[test]
    fn reads_compressed_variables_and_refuses_complex_ones() {
        let bytes = file(&[
            compressed(&doubles("ts", &[&[0.005, 0.01]])),
            compressed(&complex_doubles("gt", &[&[1.0, 2.0]])),
        ]);
        let mat = parse_mat(&bytes).unwrap();
        let ts = real_matrix(&mat, "ts").unwrap();
        assert_eq!(
            (ts.dims.as_slice(), ts.values.as_slice()),
            (&[1, 2][..], &[0.005, 0.01][..])
        );
        assert_eq!(real_matrix(&mat, "gt"), Err(NotReal::Complex));
    }

    #[test]
    fn refuses_what_is_not_a_mat_file_with_the_reason() {
        assert_eq!(
            parse_mat(b"short").unwrap_err().to_string(),
            "not a readable MATLAB level 5 MAT-file: 5 bytes, shorter than the 128-byte header"
        );
        let mut not_mat = file(&[]);
        not_mat[..6].copy_from_slice(b"HDF5 f");
        assert!(
            parse_mat(&not_mat)
                .unwrap_err()
                .to_string()
                .contains("does not start with")
        );
        let mut bad_version = file(&[]);
        bad_version[124..126].copy_from_slice(&[0x00, 0x02]);
        assert!(parse_mat(&bad_version).is_err());
        let mut big_endian = file(&[]);
        big_endian[126..128].copy_from_slice(b"MI");
        assert!(
            parse_mat(&big_endian)
                .unwrap_err()
                .to_string()
                .contains("not little-endian")
        );
        // A truncated last variable fails the file rather than going missing.
        let whole = file(&[
            doubles("ts", &[&[1.0]]),
            compressed(&doubles("gt", &[&[1.0, 2.0]])),
        ]);
        let e = parse_mat(&whole[..whole.len() - 12]).unwrap_err();
        assert!(
            e.to_string()
                .contains("truncated: the variable at byte 192 holds 83 bytes, 71 remain"),
            "{e}"
        );
        assert!(parse_mat(&whole[..whole.len() - 60]).is_err());
        let mut stray = file(&[doubles("ts", &[&[1.0]])]);
        stray.extend(super::fixture::element(9, &1.0f64.to_le_bytes()));
        assert_eq!(
            parse_mat(&stray).unwrap_err().to_string(),
            "not a readable MATLAB level 5 MAT-file: the element at byte 192 is of type 9, \
             not a variable (14, or 15 compressed)"
        );
    }
}
