//! Raw GNSS files and single-point processing: RINEX observation and navigation readers
//! (2.10/2.11 and 3.0x, GPS), RINEX 3.04 writers, and the file-level SPP/Doppler driver
//! over the `sdins_core::gnss` mathematics (docs/theory/gnss.md).
//!
//! ```no_run
//! use sdins_sim::cancel::CancelToken;
//! use sdins_sim::raw_gnss::{read_nav, read_obs, run_spp, SppMode, SppRunOptions};
//! use std::path::Path;
//! let obs = read_obs(Path::new("abpo0080.15o"))?;
//! let nav = read_nav(Path::new("abpo0080.15n"))?;
//! let opts = SppRunOptions { mode: SppMode::IonoFree, every: 10, ..SppRunOptions::default() };
//! let run = run_spp(&obs, &nav, &opts, &CancelToken::new())?;
//! if let Some(s) = run.summary {
//!     println!("horizontal RMS {:.2} m over {} epochs", s.horizontal_rms_m, s.n_solutions);
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod error;
mod rinex_nav;
mod rinex_obs;
mod rinex_write;
mod spp;
mod text;

pub use error::{RinexError, SppRunError};
pub use rinex_nav::{parse_nav, read_nav, NavFile};
pub use rinex_obs::{parse_obs, read_obs, ObsCode, ObsEpoch, ObsFile, ObsHeader, ObsValue, SatObs};
pub use rinex_write::{fmt_d, nav_to_rinex3, obs_to_rinex3};
pub use spp::{
    run_spp, SppEpoch, SppFailure, SppMode, SppRun, SppRunOptions, SppSummary, SISRE_GPS_M,
};
