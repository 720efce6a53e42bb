//! sdins-sim
