//! One module per command.

pub mod align;
pub mod align_plot;
pub mod allan;
pub mod calibrate;
pub mod demo;
pub mod errors;
pub mod fuse;
pub mod fuse_args;
pub mod fuse_files;
pub mod fuse_mc;
pub mod fuse_out;
pub mod fuse_report;
pub mod gnss_sim;
pub mod merge;
pub mod montecarlo;
pub mod nav;
pub mod run;
pub mod scenarios;
pub mod spp;
pub mod truth;
