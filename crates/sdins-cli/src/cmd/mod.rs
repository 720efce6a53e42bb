//! One module per command.

pub mod allan;
pub mod demo;
pub mod errors;
pub mod merge;
pub mod montecarlo;
pub mod run;
pub mod scenarios;
pub mod truth;
