//! Scenario files (placeholder).

/// Scenario error.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ScenarioError {
    /// placeholder
    #[error("{0}")]
    Invalid(String),
}
