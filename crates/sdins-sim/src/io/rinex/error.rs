//! Typed errors of the RINEX readers.

/// Why a RINEX file could not be read. Every parse error names `file:line` and the field.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RinexError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// path as given
        file: String,
        /// the I/O error
        source: std::io::Error,
    },
    /// A field could not be parsed or is out of range.
    #[error("{file}:{line}: {field}: {problem}")]
    Field {
        /// path as given
        file: String,
        /// 1-based line number
        line: usize,
        /// the RINEX field (header label or record field)
        field: String,
        /// what is wrong, with the offending text
        problem: String,
    },
    /// The file is valid RINEX of a kind these readers do not handle.
    #[error("{file}:{line}: unsupported: {what}")]
    Unsupported {
        /// path as given
        file: String,
        /// 1-based line number
        line: usize,
        /// what is unsupported
        what: String,
    },
    /// The file ends inside the header or a record.
    #[error("{file}:{line}: file ends inside {what}")]
    Truncated {
        /// path as given
        file: String,
        /// 1-based line number of the last line
        line: usize,
        /// the header or record being read
        what: String,
    },
}
