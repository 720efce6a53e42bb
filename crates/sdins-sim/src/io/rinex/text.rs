//! Fixed-column text helpers shared by the RINEX readers.

use super::error::RinexError;

/// The file's bytes as ASCII text: every byte ≥ 0x80 and every control byte other than
/// `\n` and `\r` becomes a space (some receivers write GBK or Latin-1 bytes into header
/// lines, e.g. the program/date line of `01.15o`), so column positions are kept and
/// parsing never meets invalid UTF-8.
pub(crate) fn ascii_text(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|&b| {
            if b >= 0x80 || (b < 0x20 && b != b'\n' && b != b'\r') {
                ' '
            } else {
                b as char
            }
        })
        .collect()
}

/// Columns `[start, end)` of an ASCII line (clamped to the line, never panics).
pub(crate) fn col(line: &str, start: usize, end: usize) -> &str {
    let n = line.len();
    let (s, e) = (start.min(n), end.min(n));
    line.get(s..e).unwrap_or("")
}

/// A reader context: file name and the current 1-based line number, for located errors.
#[derive(Clone, Debug)]
pub(crate) struct Ctx<'a> {
    pub file: &'a str,
}

impl Ctx<'_> {
    pub(crate) fn field_err(
        &self,
        line: usize,
        field: &str,
        problem: impl Into<String>,
    ) -> RinexError {
        RinexError::Field {
            file: self.file.to_string(),
            line,
            field: field.to_string(),
            problem: problem.into(),
        }
    }

    /// An optional floating-point field (Fortran `F`, `E` or `D` format; blank → `None`).
    pub(crate) fn opt_f64(
        &self,
        line_no: usize,
        line: &str,
        start: usize,
        end: usize,
        field: &str,
    ) -> Result<Option<f64>, RinexError> {
        let s = col(line, start, end).trim();
        if s.is_empty() {
            return Ok(None);
        }
        let t: String = s
            .chars()
            .map(|c| if c == 'D' || c == 'd' { 'E' } else { c })
            .collect();
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Some(v)),
            _ => Err(self.field_err(line_no, field, format!("not a number: {s:?}"))),
        }
    }

    /// A required floating-point field.
    pub(crate) fn f64(
        &self,
        line_no: usize,
        line: &str,
        start: usize,
        end: usize,
        field: &str,
    ) -> Result<f64, RinexError> {
        self.opt_f64(line_no, line, start, end, field)?
            .ok_or_else(|| self.field_err(line_no, field, "blank"))
    }

    /// A required integer field.
    pub(crate) fn int(
        &self,
        line_no: usize,
        line: &str,
        start: usize,
        end: usize,
        field: &str,
    ) -> Result<i64, RinexError> {
        let s = col(line, start, end).trim();
        s.parse::<i64>()
            .map_err(|_| self.field_err(line_no, field, format!("not an integer: {s:?}")))
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn non_ascii_bytes_become_spaces_and_fortran_numbers_parse() {
        let t = ascii_text(b"GPB2RIN 2-\xd4\xc2-15\tx\n");
        assert_eq!(t, "GPB2RIN 2-  -15 x\n");
        let c = Ctx { file: "f" };
        assert_eq!(
            c.f64(1, " .264850445000D-03", 0, 19, "af0").unwrap(),
            0.264850445000e-3
        );
        assert_eq!(
            c.f64(1, "-.647979884037D-00", 0, 19, "M0").unwrap(),
            -0.647979884037
        );
        assert_eq!(c.opt_f64(1, "   ", 0, 3, "x").unwrap(), None);
        let e = c.f64(7, "  abc", 0, 5, "Crs").unwrap_err().to_string();
        assert_eq!(e, "f:7: Crs: not a number: \"abc\"");
        assert!(c.f64(1, "nan", 0, 3, "x").is_err());
        assert_eq!(col("abc", 2, 10), "c");
        assert_eq!(col("abc", 5, 10), "");
    }
}
