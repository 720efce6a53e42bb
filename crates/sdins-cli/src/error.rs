//! CLI error type: bad input (exit 2) versus internal/IO failure (exit 1).

use std::path::PathBuf;

/// Error returned by a command.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The user's input is wrong (file content, option value). Exit code 2.
    #[error("{0}")]
    BadInput(String),
    /// Reading or writing a file failed. Exit code 2 when the path the user gave is the
    /// cause (missing, a name too long, a folder under a file, …; [`user_io_cause`]), else 1.
    #[error("{}: {}", path.display(), describe_io(source))]
    Io {
        /// the file
        path: PathBuf,
        /// the cause
        source: std::io::Error,
    },
    /// Anything else. Exit code 1.
    #[error("{0}")]
    Other(String),
    /// Stopped by SIGINT/SIGTERM through the cancellation token. Exit code 130 or 143.
    #[error("interrupted: no output written")]
    Interrupted,
    /// The inputs were valid but the result failed its own checks (the fusion health
    /// verdict); the outputs are written. Exit code 3.
    #[error("{0}")]
    ResultFailedChecks(String),
}

impl CliError {
    /// Process exit code for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::BadInput(_) => 2,
            CliError::Io { source, .. } if user_io_cause(source).is_some() => 2,
            CliError::Io { .. } | CliError::Other(_) => 1,
            CliError::Interrupted => crate::progress::cancel_exit_code(),
            CliError::ResultFailedChecks(_) => 3,
        }
    }
    /// Shorthand for a bad-input error.
    pub fn bad(msg: impl Into<String>) -> Self {
        CliError::BadInput(msg.into())
    }
}

/// The user-facing cause of an I/O error the user's path provoked, in sdins's words, or
/// None for a system failure (full disk, I/O error: exit 1).
pub fn user_io_cause(e: &std::io::Error) -> Option<&'static str> {
    Some(match e.raw_os_error()? {
        libc::ENOENT => "no such file or folder",
        libc::ENOTDIR => "a part of this path is a file, not a folder",
        libc::EISDIR => "is a folder, not a file",
        libc::ENAMETOOLONG => "name too long for the file system",
        libc::EACCES | libc::EPERM => "permission denied",
        libc::EROFS => "on a read-only file system",
        libc::ELOOP => "too many levels of symbolic links",
        libc::EEXIST => "already exists",
        _ => return None,
    })
}

/// An I/O error in sdins's words where the cause is the user's path, else the OS message.
fn describe_io(e: &std::io::Error) -> String {
    match user_io_cause(e) {
        Some(s) => s.to_string(),
        None => e.to_string(),
    }
}

impl From<sdins_sim::cancel::Cancelled> for CliError {
    fn from(_: sdins_sim::cancel::Cancelled) -> Self {
        CliError::Interrupted
    }
}

impl From<sdins_sim::nav::pipeline::PipelineError> for CliError {
    fn from(e: sdins_sim::nav::pipeline::PipelineError) -> Self {
        match e {
            sdins_sim::nav::pipeline::PipelineError::Cancelled(_) => CliError::Interrupted,
            other => CliError::BadInput(other.to_string()),
        }
    }
}

impl From<sdins_sim::scenario::ScenarioError> for CliError {
    fn from(e: sdins_sim::scenario::ScenarioError) -> Self {
        match e {
            sdins_sim::scenario::ScenarioError::Cancelled => CliError::Interrupted,
            other => CliError::BadInput(other.to_string()),
        }
    }
}
