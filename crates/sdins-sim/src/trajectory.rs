//! Trajectory profiles (placeholder).
