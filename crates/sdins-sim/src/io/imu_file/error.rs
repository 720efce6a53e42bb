//! [`super::ImuFileError`]: why an IMU file could not be read (each variant names the
//! file, line and column).

use std::path::PathBuf;

/// Why a file could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImuFileError {
    /// The file could not be opened or read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// the file
        file: PathBuf,
        /// the cause
        source: std::io::Error,
    },
    /// Nothing in the file.
    #[error("{}: empty file, expected an IMU record", file.display())]
    Empty {
        /// the file
        file: PathBuf,
    },
    /// A header but no data rows.
    #[error("{}:{line}: header only, expected data rows after it", file.display())]
    NoData {
        /// the file
        file: PathBuf,
        /// last line of the header
        line: usize,
    },
    /// Fewer than 2 data rows where the interval comes from a time column.
    #[error("{}: {rows} data row(s), expected at least 2 to get the sample interval", file.display())]
    TooFewRows {
        /// the file
        file: PathBuf,
        /// rows found
        rows: usize,
    },
    /// The format could not be recognized.
    #[error("{}:{line}: cannot detect the IMU format: {why}", file.display())]
    UnknownFormat {
        /// the file
        file: PathBuf,
        /// the line looked at
        line: usize,
        /// why
        why: String,
    },
    /// A header line is not what the format expects.
    #[error("{}:{line}: bad header: expected {expected}, found `{found}`", file.display())]
    Header {
        /// the file
        file: PathBuf,
        /// line number (1-based)
        line: usize,
        /// what the format expects
        expected: String,
        /// what is there
        found: String,
    },
    /// The last line is cut short (the file ends without a newline).
    #[error("{}:{line}: truncated last line: {found} of {expected} fields and no final newline", file.display())]
    Truncated {
        /// the file
        file: PathBuf,
        /// line number (1-based)
        line: usize,
        /// fields expected
        expected: usize,
        /// fields found
        found: usize,
    },
    /// A row has the wrong number of fields.
    #[error("{}:{line}: expected {expected} fields, found {found}", file.display())]
    ColumnCount {
        /// the file
        file: PathBuf,
        /// line number (1-based)
        line: usize,
        /// fields expected
        expected: usize,
        /// fields found
        found: usize,
    },
    /// A field is not a number.
    #[error("{}:{line}: column {column} ({name}): expected a number, found `{text}`", file.display())]
    NotANumber {
        /// the file
        file: PathBuf,
        /// line number (1-based)
        line: usize,
        /// column number (1-based)
        column: usize,
        /// column name
        name: String,
        /// the field
        text: String,
    },
    /// A field is NaN or infinite.
    #[error("{}:{line}: column {column} ({name}): expected a finite number, found `{text}`", file.display())]
    NonFinite {
        /// the file
        file: PathBuf,
        /// line number (1-based)
        line: usize,
        /// column number (1-based)
        column: usize,
        /// column name
        name: String,
        /// the field
        text: String,
    },
    /// The time column does not increase strictly.
    #[error("{}:{line}: column 1 (time): expected a time after {prev_s} s, found {t_s} s", file.display())]
    TimeNotIncreasing {
        /// the file
        file: PathBuf,
        /// line number (1-based)
        line: usize,
        /// previous time \[s\]
        prev_s: f64,
        /// this time \[s\]
        t_s: f64,
    },
    /// A sample interval differs from the median by more than [`DT_TOLERANCE`](super::DT_TOLERANCE).
    #[error("{}:{line}: column 1 (time): sample interval {dt_s} s, expected the median {median_s} s within {tol_pct} %", file.display())]
    IrregularInterval {
        /// the file
        file: PathBuf,
        /// line number (1-based)
        line: usize,
        /// the interval ending on that line \[s\]
        dt_s: f64,
        /// median interval \[s\]
        median_s: f64,
        /// tolerance \[%\]
        tol_pct: f64,
    },
    /// A physically absurd value.
    #[error("{}:{line}: columns {columns}: {what} = {value:e}, expected at most {limit:e}", file.display())]
    Absurd {
        /// the file
        file: PathBuf,
        /// line number (1-based)
        line: usize,
        /// the columns involved
        columns: String,
        /// the quantity
        what: &'static str,
        /// its value
        value: f64,
        /// the limit
        limit: f64,
    },
    /// More than one format fits the content.
    #[error("{}:{line}: ambiguous IMU format: {why}; candidates: {}; give --format", file.display(), candidates.join(", "))]
    Ambiguous {
        /// the file
        file: PathBuf,
        /// the line looked at
        line: usize,
        /// the formats that fit
        candidates: Vec<&'static str>,
        /// why
        why: String,
    },
    /// The sample interval is outside [`DT_RANGE_S`](super::DT_RANGE_S).
    #[error("{}:{line}: column 1 (time): sample interval {dt_s:e} s, expected {min_s:e} .. {max_s} s", file.display())]
    IntervalOutOfRange {
        /// the file
        file: PathBuf,
        /// 1-based line (the header line for PSINS `Ts`)
        line: usize,
        /// the interval \[s\]
        dt_s: f64,
        /// lower limit \[s\]
        min_s: f64,
        /// upper limit \[s\]
        max_s: f64,
    },
    /// The last line (no final newline) ends in a number with fewer decimals than the same
    /// column on the line before (fixed-decimal KF-GINS text): cut inside that number.
    #[error("{}:{line}: column {column}: truncated last line: `{text}` has fewer decimals than the line before and the file has no final newline", file.display())]
    CutNumber {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based field number
        column: usize,
        /// the number as cut
        text: String,
    },
    /// A header value is out of range (non-positive sample interval, …).
    #[error("{}:{line}: column {column} ({name}): {what}", file.display())]
    BadValue {
        /// the file
        file: PathBuf,
        /// line number (1-based)
        line: usize,
        /// column number (1-based)
        column: usize,
        /// column name
        name: String,
        /// what is expected
        what: String,
    },
}
