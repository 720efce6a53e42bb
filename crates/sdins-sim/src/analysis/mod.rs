//! Error analysis and statistics: INS error propagation and the Schuler analysis
//! ([`error_analysis`], [`errors_run`]), Monte Carlo ([`montecarlo`]), the fusion Monte
//! Carlo ([`fuse_mc`]) and its consistency criterion ([`consistency`]), and Allan variance
//! ([`allan`]).

pub mod allan;
pub mod consistency;
pub mod detection;
pub mod error_analysis;
pub mod errors_run;
pub mod fuse_mc;
pub mod montecarlo;
pub mod static_check;
