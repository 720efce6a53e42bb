//! CLI error type: bad input (exit 2) versus internal/IO failure (exit 1).

use std::path::PathBuf;

/// Error returned by a command.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The user's input is wrong (file content, option value). Exit code 2.
    #[error("{0}")]
    BadInput(String),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
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
}

impl CliError {
    /// Process exit code for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::BadInput(_) => 2,
            CliError::Io { .. } | CliError::Other(_) => 1,
            CliError::Interrupted => crate::progress::cancel_exit_code(),
        }
    }
    /// Shorthand for a bad-input error.
    pub fn bad(msg: impl Into<String>) -> Self {
        CliError::BadInput(msg.into())
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
