//! Line splitting with character columns, number parsing and the value checks shared by
//! every GNSS reader (each failure is a located [`GnssFileError`]).

use super::{GnssFileError, H_RANGE_M, MAX_SIGMA_M, MAX_SPEED_MPS, MIN_SIGMA_M};
use std::path::{Path, PathBuf};

/// One field of a line: its text and 1-based character column.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Field<'a> {
    pub text: &'a str,
    pub column: usize,
}

/// One non-blank line: 1-based number and text (BOM and `\r` removed).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Line<'a> {
    pub no: usize,
    pub text: &'a str,
}

/// The non-blank lines of `text`; a leading UTF-8 byte-order mark is accepted and removed.
pub(crate) fn lines(text: &str) -> Vec<Line<'_>> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    text.lines()
        .enumerate()
        .map(|(i, l)| Line {
            no: i + 1,
            text: l.trim_end_matches('\r'),
        })
        .filter(|l| !l.text.trim().is_empty())
        .collect()
}

/// Split on commas (if the line has one) or on whitespace, with character columns.
pub(crate) fn split(line: &str) -> Vec<Field<'_>> {
    let comma = line.contains(',');
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    let mut col = 0usize;
    let mut start_col = 0usize;
    let is_sep = |c: char| if comma { c == ',' } else { c.is_whitespace() };
    let bytes_line = line;
    for (b, ch) in line.char_indices() {
        col += 1;
        if is_sep(ch) {
            if let Some(s) = start.take() {
                push(&mut out, &bytes_line[s..b], start_col);
            } else if comma {
                // empty field between two commas
                out.push(Field {
                    text: "",
                    column: col,
                });
            }
        } else if start.is_none() {
            start = Some(b);
            start_col = col;
        }
    }
    if let Some(s) = start {
        push(&mut out, &bytes_line[s..], start_col);
    } else if comma && line.ends_with(',') {
        out.push(Field {
            text: "",
            column: col + 1,
        });
    }
    out
}

/// Push a field, trimmed, keeping the column of its first non-blank character.
fn push<'a>(out: &mut Vec<Field<'a>>, s: &'a str, c: usize) {
    let lead = s.len() - s.trim_start().len();
    let lead_chars = s[..lead].chars().count();
    out.push(Field {
        text: s.trim(),
        column: c + lead_chars,
    });
}

/// Context for located errors.
pub(crate) struct Ctx<'a> {
    pub file: &'a Path,
}

impl Ctx<'_> {
    pub fn f(&self) -> PathBuf {
        self.file.to_path_buf()
    }

    /// A finite number.
    pub fn num(&self, line: usize, fld: Field<'_>, name: &str) -> Result<f64, GnssFileError> {
        match fld.text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(GnssFileError::NonFinite {
                file: self.f(),
                line,
                column: fld.column,
                field: name.to_string(),
                text: fld.text.to_string(),
            }),
            Err(_) => Err(GnssFileError::NotANumber {
                file: self.f(),
                line,
                column: fld.column,
                field: name.to_string(),
                text: fld.text.chars().take(40).collect(),
            }),
        }
    }

    pub fn range(
        &self,
        line: usize,
        fld: Field<'_>,
        name: &str,
        value: f64,
        ok: bool,
        expected: &str,
    ) -> Result<f64, GnssFileError> {
        if ok {
            Ok(value)
        } else {
            Err(GnssFileError::OutOfRange {
                file: self.f(),
                line,
                column: fld.column,
                field: name.to_string(),
                value,
                expected: expected.to_string(),
            })
        }
    }

    /// Latitude in degrees, |lat| ≤ 90.
    pub fn lat_deg(&self, line: usize, fld: Field<'_>, name: &str) -> Result<f64, GnssFileError> {
        let v = self.num(line, fld, name)?;
        self.range(
            line,
            fld,
            name,
            v,
            v.abs() <= 90.0,
            "a latitude within ±90°",
        )
    }

    /// Longitude in degrees, |lon| ≤ 360 (wrapped later).
    pub fn lon_deg(&self, line: usize, fld: Field<'_>, name: &str) -> Result<f64, GnssFileError> {
        let v = self.num(line, fld, name)?;
        self.range(
            line,
            fld,
            name,
            v,
            v.abs() <= 360.0,
            "a longitude within ±360°",
        )
    }

    /// Ellipsoidal height in [`H_RANGE_M`].
    pub fn h_m(&self, line: usize, fld: Field<'_>, name: &str) -> Result<f64, GnssFileError> {
        let v = self.num(line, fld, name)?;
        self.range(
            line,
            fld,
            name,
            v,
            (H_RANGE_M.0..=H_RANGE_M.1).contains(&v),
            &format!("a height within [{}, {}] m", H_RANGE_M.0, H_RANGE_M.1),
        )
    }

    /// A standard deviation in [[`MIN_SIGMA_M`], [`MAX_SIGMA_M`]].
    pub fn sigma(&self, line: usize, fld: Field<'_>, name: &str) -> Result<f64, GnssFileError> {
        let v = self.num(line, fld, name)?;
        self.range(
            line,
            fld,
            name,
            v,
            (MIN_SIGMA_M..=MAX_SIGMA_M).contains(&v),
            &format!("a standard deviation in [{MIN_SIGMA_M:e}, {MAX_SIGMA_M:e}]"),
        )
    }

    /// A velocity component, |v| ≤ [`MAX_SPEED_MPS`].
    pub fn vel(&self, line: usize, fld: Field<'_>, name: &str) -> Result<f64, GnssFileError> {
        let v = self.num(line, fld, name)?;
        self.range(
            line,
            fld,
            name,
            v,
            v.abs() <= MAX_SPEED_MPS,
            &format!("a velocity within ±{MAX_SPEED_MPS} m/s"),
        )
    }

    /// Time strictly after `prev`.
    pub fn increasing(
        &self,
        line: usize,
        fld: Field<'_>,
        prev: Option<f64>,
        t: f64,
    ) -> Result<(), GnssFileError> {
        match prev {
            Some(p) if t <= p => Err(GnssFileError::TimeNotIncreasing {
                file: self.f(),
                line,
                column: fld.column,
                prev_s: p,
                t_s: t,
            }),
            _ => Ok(()),
        }
    }

    /// Check the field count; a short last line of a file without a final newline is
    /// reported as truncated.
    pub fn count(
        &self,
        line: Line<'_>,
        fields: &[Field<'_>],
        expected: &[usize],
        last_unterminated: bool,
    ) -> Result<(), GnssFileError> {
        if expected.contains(&fields.len()) {
            return Ok(());
        }
        let want = expected.iter().copied().max().unwrap_or(0);
        let column = line.text.chars().count() + 1;
        if last_unterminated && fields.len() < want {
            Err(GnssFileError::Truncated {
                file: self.f(),
                line: line.no,
                column,
                expected: want,
                found: fields.len(),
            })
        } else {
            Err(GnssFileError::ColumnCount {
                file: self.f(),
                line: line.no,
                column: fields.last().map_or(1, |f| f.column),
                expected: expected
                    .iter()
                    .map(|n| n.to_string())
                    .collect::<Vec<_>>()
                    .join(" or "),
                found: fields.len(),
            })
        }
    }
}

/// Digits after the decimal point (0 without a point; `None` with an exponent).
fn decimals(s: &str) -> Option<usize> {
    if s.contains(['e', 'E']) {
        return None;
    }
    Some(s.find('.').map_or(0, |k| s.len() - k - 1))
}

/// Fixed-decimal text formats (KF-GINS, RTKLIB print every column with a fixed number of
/// decimals): a last line without final newline whose field has fewer decimals than the same
/// field on the line before was cut inside that number.
pub(crate) fn check_cut_number(
    ctx: &Ctx<'_>,
    prev: &[Field<'_>],
    last: Line<'_>,
    fields: &[Field<'_>],
    unterminated: bool,
) -> Result<(), GnssFileError> {
    if !unterminated {
        return Ok(());
    }
    for (p, f) in prev.iter().zip(fields) {
        if let (Some(dp), Some(df)) = (decimals(p.text), decimals(f.text)) {
            if df < dp {
                return Err(GnssFileError::CutNumber {
                    file: ctx.f(),
                    line: last.no,
                    column: f.column,
                    text: f.text.to_string(),
                    expected_decimals: dp,
                });
            }
        }
    }
    Ok(())
}

/// Wrap a longitude \[rad\] into (−π, π].
pub(crate) fn wrap_lon_rad(lon: f64) -> f64 {
    use std::f64::consts::PI;
    let mut l = lon % (2.0 * PI);
    if l > PI {
        l -= 2.0 * PI;
    } else if l <= -PI {
        l += 2.0 * PI;
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_columns() {
        let f = split("1, 2 ,,x");
        let t: Vec<_> = f.iter().map(|f| (f.text, f.column)).collect();
        assert_eq!(t, vec![("1", 1), ("2", 4), ("", 7), ("x", 8)]);
        let f = split("  10.0   20  ");
        let t: Vec<_> = f.iter().map(|f| (f.text, f.column)).collect();
        assert_eq!(t, vec![("10.0", 3), ("20", 10)]);
        let f = split("a,");
        assert_eq!(f.len(), 2);
        assert_eq!((f[1].text, f[1].column), ("", 3));
        let l = lines("\u{feff}a\r\n\n b\n");
        assert_eq!((l[0].no, l[0].text), (1, "a"));
        assert_eq!((l[1].no, l[1].text), (3, " b"));
    }

    #[test]
    fn wrap() {
        use std::f64::consts::PI;
        assert!((wrap_lon_rad(1.5 * PI) + 0.5 * PI).abs() < 1e-15);
        assert!((wrap_lon_rad(-1.5 * PI) - 0.5 * PI).abs() < 1e-15);
        assert_eq!(wrap_lon_rad(0.3), 0.3);
    }
}
