//! One module per command.

pub mod align;
pub mod allan;
pub mod demo;
pub mod errors;
pub mod run;
pub mod scenarios;
pub mod truth;
