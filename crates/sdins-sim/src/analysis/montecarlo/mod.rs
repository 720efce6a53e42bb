//! Monte Carlo: N seeded realisations of a scenario with its IMU error model,
//! one navigation algorithm, and per-epoch statistics of the navigation errors in
//! mergeable accumulators.
//!
//! * Run `r` (0-based) corrupts the exact truth increments with the scenario's
//!   [`ImuErrorModel`](crate::sensors::imu_error::ImuErrorModel) seeded by (seed, r, channel)
//!   ([`crate::sensors::imu_error::ImuErrorState`]), navigates with one algorithm (default
//!   `songlee-complete`) and records the errors of [`crate::nav::pipeline::nav_error`] every
//!   output epoch. Long runs with sensor errors use the vertical channel **held** to the
//!   truth (the free inertial vertical channel diverges, docs/theory/error-analysis.md
//!   §"Full stationary closed form"), so the horizontal channels are the ones to compare; the down
//!   channels are then zero.
//! * Channels ([`CHANNELS`]): position error N, E, D \[m\], velocity error N, E, D \[m/s\],
//!   attitude error ε N, E, D \[rad\] (convention G, `C_alg C_trueᵀ = I + [ε×]`).
//! * Statistics per epoch and channel: mean, sample σ = √(M2/(n − 1)), and the 5/50/95 %
//!   percentiles ([`histogram`]).
//! * Exactness: the canonical reduction of [`plan`](mod@plan) (blocks of K runs reduced in run
//!   order, blocks folded in block order with Chan's merge, shards of whole blocks that
//!   keep their block results) makes the statistics bit-identical for any number of
//!   threads and for one shard versus any number of merged shards.
//!
//! Files: [`moments`] (Welford/Chan), [`histogram`] (percentiles), [`plan`](mod@plan) (blocks and
//! shards), [`state`] (the lossless, mergeable accumulator state), [`runner`] (rayon over
//! blocks), [`stats`] (the final table and its CSV), [`truth_cache`] (the truth computed
//! once for all runs).

pub mod histogram;
pub mod moments;
pub mod options;
pub mod plan;
pub mod runner;
pub mod state;
pub mod stats;
pub mod truth_cache;

pub use options::{mc_options, plan, McChoice, McPlan, McRequest, DEFAULT_MC_EVERY_S};
pub use plan::{Shard, DEFAULT_BLOCK};
pub use runner::{run_shard, McOptions};
pub use state::{BlockResult, McJob, McState};
pub use stats::{ChannelStats, McStats};

/// Number of error channels.
pub const N_CHANNELS: usize = 9;

/// Channel names (CSV column prefixes), in storage order.
pub const CHANNELS: [&str; N_CHANNELS] = [
    "pos_n_m",
    "pos_e_m",
    "pos_d_m",
    "vel_n_mps",
    "vel_e_mps",
    "vel_d_mps",
    "att_n_rad",
    "att_e_rad",
    "att_d_rad",
];

/// Monte Carlo error.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum McError {
    /// Invalid options (runs, block size, shard, epoch spacing, algorithm).
    #[error("Monte Carlo configuration: {0}")]
    Config(String),
    /// The scenario's IMU error model is invalid.
    #[error("IMU error model: {0}")]
    Model(String),
    /// Two states to merge belong to different jobs.
    #[error("cannot merge: {0}")]
    Mismatch(String),
    /// The same block appears in two states.
    #[error("cannot merge: block {0} is present twice (overlapping shards)")]
    DuplicateBlock(u64),
    /// A state file is malformed.
    #[error("bad Monte Carlo state: {0}")]
    BadState(String),
    /// Stopped by the caller.
    #[error("interrupted")]
    Interrupted,
}

/// Serde helpers storing `f64` losslessly as its IEEE-754 bit pattern (`u64`).
pub mod bits {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Serialize `x` as `x.to_bits()`.
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        x.to_bits().serialize(s)
    }
    /// Deserialize from the bit pattern.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        u64::deserialize(d).map(f64::from_bits)
    }

    /// The same for `Vec<f64>`.
    pub mod vec {
        use serde::{Deserialize, Deserializer, Serialize, Serializer};
        /// Serialize as a list of bit patterns.
        pub fn serialize<S: Serializer>(x: &[f64], s: S) -> Result<S::Ok, S::Error> {
            let v: Vec<u64> = x.iter().map(|a| a.to_bits()).collect();
            v.serialize(s)
        }
        /// Deserialize from bit patterns.
        pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
            Vec::<u64>::deserialize(d).map(|v| v.into_iter().map(f64::from_bits).collect())
        }
    }

    /// The same for `Option<f64>`.
    pub mod opt {
        use serde::{Deserialize, Deserializer, Serialize, Serializer};
        /// Serialize as an optional bit pattern.
        pub fn serialize<S: Serializer>(x: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
            x.map(f64::to_bits).serialize(s)
        }
        /// Deserialize from an optional bit pattern.
        pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
            Option::<u64>::deserialize(d).map(|v| v.map(f64::from_bits))
        }
    }
}
