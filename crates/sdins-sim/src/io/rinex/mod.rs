//! RINEX observation and navigation files for GPS: readers of versions 2.10/2.11 and 3.0x
//! (non-ASCII header bytes read as spaces), RINEX 3.04 writers that the readers and RTKLIB
//! read back (docs/theory/gnss.md). The processing is `crate::nav::spp`.
//!
//! ```no_run
//! use sdins_sim::cancel::CancelToken;
//! use sdins_sim::io::rinex::{read_nav, read_obs};
//! use sdins_sim::nav::spp::{run_spp, SppMode, SppRunOptions};
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
mod nav;
mod obs;
mod raw_out;
mod text;
mod write;

pub use error::RinexError;
pub use nav::{parse_nav, read_nav, NavFile};
pub use obs::{parse_obs, read_obs, ObsCode, ObsEpoch, ObsFile, ObsHeader, ObsValue, SatObs};
pub use write::{fmt_d, nav_to_rinex3, obs_to_rinex3};
