//! Plain-text XYZ point files: one point per line, `x y z` or `x y z intensity`.
//!
//! # Reading
//! * Values are separated by whitespace or by commas (a line with a comma is split at commas,
//!   and the fields are trimmed; an empty field is an error).
//! * Blank lines and comments (from `#` to the end of the line) are skipped.
//! * Every data line has the same number of columns as the first one: 3 (`x y z`) or 4
//!   (`x y z intensity`). Anything else is an error naming the line.
//! * Numbers are parsed as by Rust's `f64::from_str` (`1`, `-2.5`, `3e-4`, `nan`, `inf`). A
//!   point with a NaN or infinite coordinate fails with [`ErrorKind::NonFinite`] unless
//!   [`ReadOptions::skip_non_finite`] is set, which drops it.
//!
//! # Writing
//! `x y z` per point, plus the intensity as a fourth column when the cloud has one, separated
//! by single spaces. Numbers are printed in the shortest form that parses back to the same
//! value (scientific notation for very large or small magnitudes), so a write–read round trip
//! is exact. Normals, labels, rings, extra fields, the grid and the sensor pose are not written.

use super::{Error, ErrorKind, Format, Position, ReadOptions};
use crate::{Point3, PointCloud};
use std::fmt;
use std::io::{BufRead, Write};

const FORMAT: Format = Format::Xyz;

/// Reads an XYZ text file (see the [module docs](self) for the rules).
pub fn read_xyz(reader: impl BufRead, options: &ReadOptions) -> Result<PointCloud, Error> {
    let mut lines = TextLines::new(reader, FORMAT);
    let mut positions = Vec::new();
    let mut intensity = Vec::new();
    let mut columns = None;
    let mut point_index = 0u64;
    while let Some((line_no, line)) = lines.next_line()? {
        let at = Position::Line(line_no);
        let data = strip_comment(line);
        if data.trim().is_empty() {
            continue;
        }
        let mut values = [""; 4];
        let mut n = 0;
        for field in split_fields(data) {
            let field = field.map_err(|e| Error::at(FORMAT, at, e))?;
            if let Some(slot) = values.get_mut(n) {
                *slot = field;
            }
            n += 1;
        }
        match columns {
            None if n == 3 || n == 4 => columns = Some(n),
            None => {
                return Err(Error::at(
                    FORMAT,
                    at,
                    ErrorKind::BadValue(format!(
                        "expected 3 (x y z) or 4 (x y z intensity) columns, found {n}"
                    )),
                ));
            }
            Some(c) if c != n => {
                return Err(Error::at(
                    FORMAT,
                    at,
                    ErrorKind::BadValue(format!(
                        "found {n} columns, but the first data line has {c}"
                    )),
                ));
            }
            Some(_) => {}
        }
        let x = parse_f64(values[0], FORMAT, at)?;
        let y = parse_f64(values[1], FORMAT, at)?;
        let z = parse_f64(values[2], FORMAT, at)?;
        let i = if n == 4 { Some(parse_f32(values[3], FORMAT, at)?) } else { None };
        let index = point_index;
        point_index += 1;
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            if options.skip_non_finite {
                continue;
            }
            return Err(Error::at(FORMAT, at, ErrorKind::NonFinite { point: index }));
        }
        positions.push(Point3::new(x, y, z));
        if let Some(i) = i {
            intensity.push(i);
        }
    }
    let mut cloud = PointCloud::from_positions(positions).map_err(|e| Error::new(FORMAT, e))?;
    if columns == Some(4) {
        cloud.set_intensity(Some(intensity)).map_err(|e| Error::new(FORMAT, e))?;
    }
    Ok(cloud)
}

/// Writes `cloud` as XYZ text: `x y z` per line, with the intensity as a fourth column when the
/// cloud has one. Only positions and intensity are written.
pub fn write_xyz(writer: impl Write, cloud: &PointCloud) -> Result<(), Error> {
    let mut w = std::io::BufWriter::new(writer);
    let io = |e: std::io::Error| Error::new(FORMAT, e);
    let intensity = cloud.intensity();
    for (k, p) in cloud.positions().iter().enumerate() {
        write!(w, "{} {} {}", Real(p.x), Real(p.y), Real(p.z)).map_err(io)?;
        if let Some(i) = intensity {
            write!(w, " {}", Real32(i[k])).map_err(io)?;
        }
        w.write_all(b"\n").map_err(io)?;
    }
    w.flush().map_err(io)
}

/// The part of a line before a `#` comment.
pub(crate) fn strip_comment(line: &str) -> &str {
    match line.find('#') {
        Some(i) => &line[..i],
        None => line,
    }
}

/// Splits a data line at commas (if it has one) or at whitespace. Comma-separated fields are
/// trimmed and must not be empty.
pub(crate) fn split_fields(line: &str) -> impl Iterator<Item = Result<&str, ErrorKind>> {
    let commas = line.contains(',');
    let (a, b) = if commas {
        (
            Some(line.split(',').map(|f| {
                let f = f.trim();
                if f.is_empty() {
                    Err(ErrorKind::BadValue("empty field between commas".into()))
                } else {
                    Ok(f)
                }
            })),
            None,
        )
    } else {
        (None, Some(line.split_whitespace().map(Ok)))
    };
    a.into_iter().flatten().chain(b.into_iter().flatten())
}

/// Parses an `f64`, naming the offending text on failure.
pub(crate) fn parse_f64(text: &str, format: Format, at: Position) -> Result<f64, Error> {
    text.parse::<f64>().map_err(|_| bad_number(text, format, at))
}

/// Parses an `f32`, naming the offending text on failure.
pub(crate) fn parse_f32(text: &str, format: Format, at: Position) -> Result<f32, Error> {
    text.parse::<f32>().map_err(|_| bad_number(text, format, at))
}

fn bad_number(text: &str, format: Format, at: Position) -> Error {
    let shown: String = text.chars().take(40).collect();
    let ellipsis = if shown.len() < text.len() { "…" } else { "" };
    Error::at(format, at, ErrorKind::BadValue(format!("`{shown}{ellipsis}` is not a number")))
}

/// Reads a text file line by line, counting lines (1-based) and checking UTF-8.
pub(crate) struct TextLines<R> {
    reader: R,
    buf: Vec<u8>,
    line: u64,
    format: Format,
}

impl<R: BufRead> TextLines<R> {
    pub(crate) fn new(reader: R, format: Format) -> TextLines<R> {
        TextLines { reader, buf: Vec::new(), line: 0, format }
    }

    /// The next line (1-based number, text without `\n` or `\r\n`), or `None` at the end.
    pub(crate) fn next_line(&mut self) -> Result<Option<(u64, &str)>, Error> {
        self.buf.clear();
        let line = self.line + 1;
        let n = self
            .reader
            .read_until(b'\n', &mut self.buf)
            .map_err(|e| Error::at(self.format, Position::Line(line), e))?;
        if n == 0 {
            return Ok(None);
        }
        self.line = line;
        if self.buf.last() == Some(&b'\n') {
            self.buf.pop();
            if self.buf.last() == Some(&b'\r') {
                self.buf.pop();
            }
        }
        let text = std::str::from_utf8(&self.buf).map_err(|_| {
            Error::at(
                self.format,
                Position::Line(line),
                ErrorKind::BadValue("the line is not valid UTF-8 text".into()),
            )
        })?;
        Ok(Some((line, text)))
    }
}

/// Formats an `f64` so that it parses back to the same value: plain decimals for ordinary
/// magnitudes, scientific notation for very large or small ones.
pub(crate) struct Real(pub f64);

impl fmt::Display for Real {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-5..1e16).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// Formats an `f32` so that it parses back (as `f32`) to the same value.
pub(crate) struct Real32(pub f32);

impl fmt::Display for Real32 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-5..1e16).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn real_formatting_round_trips() {
        for v in [0.0, -0.0, 1.0, 0.1, 1e-300, -3.5e300, 123456.789, f64::MIN_POSITIVE, 5e-324] {
            let s = Real(v).to_string();
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
            assert!(s.len() < 30, "{s}");
        }
        for v in [0.0f32, 1.5, 1e-30, 3.4e38] {
            let s = Real32(v).to_string();
            assert_eq!(s.parse::<f32>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
    }

    #[test]
    fn fields_split_at_commas_or_whitespace() {
        let f: Vec<_> = split_fields(" 1 2\t3 ").collect::<Result<_, _>>().unwrap();
        assert_eq!(f, ["1", "2", "3"]);
        let f: Vec<_> = split_fields("1, 2 ,3").collect::<Result<_, _>>().unwrap();
        assert_eq!(f, ["1", "2", "3"]);
        assert!(split_fields("1,,3").any(|f| f.is_err()));
    }
}
