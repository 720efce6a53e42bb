//! Error analysis and statistics: INS error propagation and the Schuler analysis
//! ([`error_analysis`], [`errors_run`]), Monte Carlo ([`montecarlo`]) and Allan variance
//! ([`allan`]).

pub mod allan;
pub mod consistency;
pub mod error_analysis;
pub mod errors_run;
pub mod fuse_mc;
pub mod montecarlo;
