//! Truth generator (placeholder).
