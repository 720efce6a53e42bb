//! Delimited text tables for column maps: comma, whitespace or semicolon separated fields,
//! comment lines (`#`, `%`, `//`), an optional header line, blank lines skipped, a UTF-8
//! byte-order mark accepted. Rows are kept as line slices and split on demand.

use crate::io::columns::{Column, ColumnRef, ColumnsError, Delimiter, HeaderMode};
use std::path::{Path, PathBuf};

/// Prefixes of comment lines.
pub const COMMENT_PREFIXES: [&str; 3] = ["#", "%", "//"];

/// The lines of a table, split into its header and data lines.
#[derive(Clone, Debug)]
pub struct Table<'a> {
    file: PathBuf,
    /// the delimiter used (never `Auto`)
    pub delim: Delimiter,
    /// the header line's number and names, if the file has one
    pub header: Option<(usize, Vec<String>)>,
    /// data lines with their 1-based numbers
    pub lines: Vec<(usize, &'a str)>,
    /// fields of the first data line (every row must have as many)
    pub width: usize,
    /// whether the text ends with a newline
    pub ends_with_newline: bool,
}

fn is_comment(l: &str) -> bool {
    let t = l.trim_start();
    COMMENT_PREFIXES.iter().any(|p| t.starts_with(p))
}

/// Split one line.
pub fn split_line<'b>(line: &'b str, delim: Delimiter, out: &mut Vec<&'b str>) {
    out.clear();
    match delim {
        Delimiter::Comma => out.extend(line.split(',').map(str::trim)),
        Delimiter::Semicolon => out.extend(line.split(';').map(str::trim)),
        _ => out.extend(line.split_whitespace()),
    }
}

impl<'a> Table<'a> {
    /// Split `text` (of `file`, for messages) into header and data lines.
    pub fn new(
        file: &Path,
        text: &'a str,
        delim: Delimiter,
        header: HeaderMode,
    ) -> Result<Self, ColumnsError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines: Vec<(usize, &str)> = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
            .filter(|(_, l)| !l.trim().is_empty() && !is_comment(l))
            .collect();
        let Some(&(first_no, first)) = lines.first() else {
            return Err(ColumnsError::Data {
                file: file.into(),
                line: 1,
                field: "(file)".into(),
                message: "empty file (no data line outside comments)".into(),
            });
        };
        let delim = match delim {
            Delimiter::Auto if first.contains(',') => Delimiter::Comma,
            Delimiter::Auto if first.contains(';') => Delimiter::Semicolon,
            Delimiter::Auto => Delimiter::Whitespace,
            d => d,
        };
        let mut f = Vec::new();
        split_line(first, delim, &mut f);
        let is_header = match header {
            HeaderMode::Yes => true,
            HeaderMode::No => false,
            _ => f.iter().any(|x| x.parse::<f64>().is_err()),
        };
        let header = if is_header {
            lines.remove(0);
            Some((
                first_no,
                f.iter()
                    .map(|s| s.trim_matches('"').to_string())
                    .collect::<Vec<String>>(),
            ))
        } else {
            None
        };
        let Some(&(_, first_data)) = lines.first() else {
            return Err(ColumnsError::Data {
                file: file.into(),
                line: first_no,
                field: "(header)".into(),
                message: "header only, expected data rows after it".into(),
            });
        };
        split_line(first_data, delim, &mut f);
        let width = header.as_ref().map_or(f.len(), |h| h.1.len());
        Ok(Self {
            file: file.into(),
            delim,
            header,
            lines,
            width,
            ends_with_newline: text.ends_with('\n'),
        })
    }

    /// 0-based field index of a mapped column.
    pub fn index(&self, c: &Column) -> Result<usize, ColumnsError> {
        match &c.column {
            ColumnRef::Index(i) if *i <= self.width => Ok(i - 1),
            ColumnRef::Index(i) => Err(ColumnsError::Data {
                file: self.file.clone(),
                line: self
                    .header
                    .as_ref()
                    .map_or_else(|| self.lines[0].0, |h| h.0),
                field: c.key.clone(),
                message: format!(
                    "column {i} does not exist: the rows have {} fields",
                    self.width
                ),
            }),
            ColumnRef::Name(n) => {
                let Some((line, names)) = &self.header else {
                    return Err(ColumnsError::Data {
                        file: self.file.clone(),
                        line: self.lines[0].0,
                        field: c.key.clone(),
                        message: format!(
                            "column `{n}` by name, but the file has no header: give its 1-based index"
                        ),
                    });
                };
                names
                    .iter()
                    .position(|h| h == n)
                    .ok_or_else(|| ColumnsError::Data {
                        file: self.file.clone(),
                        line: *line,
                        field: c.key.clone(),
                        message: format!("no column `{n}` in the header `{}`", names.join(",")),
                    })
            }
        }
    }

    /// Split data line `k` into `out`, checking its field count.
    pub fn row<'b>(&'b self, k: usize, out: &mut Vec<&'a str>) -> Result<usize, ColumnsError> {
        let (line, text) = self.lines[k];
        split_line(text, self.delim, out);
        if out.len() != self.width {
            let last = k + 1 == self.lines.len();
            let message = if last && !self.ends_with_newline && out.len() < self.width {
                format!(
                    "truncated last line: {} of {} fields and no final newline",
                    out.len(),
                    self.width
                )
            } else {
                format!("expected {} fields, found {}", self.width, out.len())
            };
            return Err(ColumnsError::Data {
                file: self.file.clone(),
                line,
                field: "(row)".into(),
                message,
            });
        }
        Ok(line)
    }

    /// A finite number from field `i` of a split row.
    pub fn num(
        &self,
        line: usize,
        fields: &[&str],
        i: usize,
        key: &str,
    ) -> Result<f64, ColumnsError> {
        let f = fields.get(i).copied().unwrap_or("");
        let v: f64 = f.parse().map_err(|_| ColumnsError::Data {
            file: self.file.clone(),
            line,
            field: key.into(),
            message: format!("`{f}` is not a number"),
        })?;
        if !v.is_finite() {
            return Err(ColumnsError::Data {
                file: self.file.clone(),
                line,
                field: key.into(),
                message: format!("`{f}` is not finite"),
            });
        }
        Ok(v)
    }

    /// An error at `line` in column `key`.
    pub fn err(&self, line: usize, key: &str, message: String) -> ColumnsError {
        ColumnsError::Data {
            file: self.file.clone(),
            line,
            field: key.into(),
            message,
        }
    }

    /// Warnings for the record (a last line without final newline).
    pub fn warnings(&self) -> Vec<String> {
        if self.ends_with_newline {
            Vec::new()
        } else {
            vec!["the file does not end with a newline: its last line may have been cut inside its last number".into()]
        }
    }
}

/// Read a file (size-capped, line 1 checked first) as text.
pub fn read_text(path: &Path) -> Result<String, ColumnsError> {
    let bytes = crate::input::read_capped(path).map_err(|source| ColumnsError::Io {
        file: path.into(),
        source,
    })?;
    Ok(crate::input::text_lossy(bytes))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::io::columns::{ColumnMap, InputKind, MapOrigin};

    #[test]
    fn delimiters_comments_and_headers() {
        let p = Path::new("x.txt");
        for (text, d, h) in [
            ("# c\na,b\n1,2\n", Delimiter::Comma, true),
            ("% c\n1;2\n3;4\n", Delimiter::Semicolon, false),
            ("// c\n a  b\n1 2\n", Delimiter::Whitespace, true),
            ("\u{feff}1\t2\n", Delimiter::Whitespace, false),
        ] {
            let t = Table::new(p, text, Delimiter::Auto, HeaderMode::Auto).unwrap();
            assert_eq!(t.delim, d, "{text}");
            assert_eq!(t.header.is_some(), h, "{text}");
            assert_eq!(t.width, 2);
        }
        let t = Table::new(p, "a,b\n1,2\n3\n", Delimiter::Auto, HeaderMode::Auto).unwrap();
        let mut f = Vec::new();
        let e = t.row(1, &mut f).unwrap_err().to_string();
        assert_eq!(e, "x.txt:3: (row): expected 2 fields, found 1");
        let t = Table::new(p, "a,b\n1,2\n3", Delimiter::Auto, HeaderMode::Auto).unwrap();
        assert!(t
            .row(1, &mut f)
            .unwrap_err()
            .to_string()
            .contains("truncated"));
        let m = ColumnMap::parse(InputKind::Imu, "t_s=c,week=3", MapOrigin::default()).unwrap();
        let e = t.index(m.get("t").unwrap()).unwrap_err().to_string();
        assert!(e.contains("no column `c` in the header `a,b`"), "{e}");
        let e = t.index(m.get("week").unwrap()).unwrap_err().to_string();
        assert!(e.contains("column 3 does not exist"), "{e}");
        assert!(Table::new(p, "# only\n", Delimiter::Auto, HeaderMode::Auto).is_err());
        assert!(Table::new(p, "a,b\n", Delimiter::Auto, HeaderMode::Auto)
            .unwrap_err()
            .to_string()
            .contains("header only"));
    }
}
