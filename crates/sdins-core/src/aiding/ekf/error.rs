//! [`FilterError`]: what the filter refuses to continue with.

use crate::aiding::layout::BlockKind;

/// What the filter refuses to continue with.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum FilterError {
    /// A covariance (P or an innovation covariance S) is not positive definite or not finite.
    NotPositiveDefinite {
        /// filter time \[s\]
        t_s: f64,
        /// which matrix
        what: &'static str,
    },
    /// The navigation state became non-finite.
    NonFiniteState {
        /// filter time \[s\]
        t_s: f64,
    },
    /// A measurement has a non-finite value or a time of validity in the future.
    BadMeasurement {
        /// filter time \[s\]
        t_s: f64,
    },
    /// The layout lacks a block a measurement needs.
    MissingBlock {
        /// filter time \[s\]
        t_s: f64,
        /// the block
        block: BlockKind,
    },
}

impl core::fmt::Display for FilterError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            FilterError::NotPositiveDefinite { t_s, what } => write!(
                f,
                "epoch t = {t_s} s: {what} is not finite or not positive definite"
            ),
            FilterError::NonFiniteState { t_s } => {
                write!(f, "epoch t = {t_s} s: navigation state is not finite")
            }
            FilterError::BadMeasurement { t_s } => write!(
                f,
                "epoch t = {t_s} s: measurement has a non-finite value or a time of validity in the future"
            ),
            FilterError::MissingBlock { t_s, block } => write!(
                f,
                "epoch t = {t_s} s: a measurement needs the state block `{}`",
                block.name()
            ),
        }
    }
}

impl core::error::Error for FilterError {}
