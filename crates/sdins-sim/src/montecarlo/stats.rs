//! The final statistics table of a Monte Carlo state and its CSV form.
//!
//! Per epoch and channel: `mean`, `sigma` = √(M2/(n − 1)) (sample standard deviation,
//! the unbiased variance estimate), and the nearest-rank percentiles `p05`, `p50`, `p95`
//! of the log-binned histogram (within 1.16 % relative of a sample value, see
//! [`super::histogram`]).

use super::state::McState;
use super::{CHANNELS, N_CHANNELS};
use serde::Serialize;
use std::fmt::Write;

/// Statistics of one channel at one epoch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ChannelStats {
    /// sample mean
    pub mean: f64,
    /// sample standard deviation √(M2/(n − 1))
    pub sigma: f64,
    /// 5 % percentile
    pub p05: f64,
    /// median
    pub p50: f64,
    /// 95 % percentile
    pub p95: f64,
}

/// The statistics of all epochs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct McStats {
    /// runs included
    pub runs: u64,
    /// whether every run of the job is included
    pub complete: bool,
    /// epoch times \[s\]
    pub times_s: Vec<f64>,
    /// per epoch, per channel ([`CHANNELS`] order)
    pub cells: Vec<[ChannelStats; N_CHANNELS]>,
}

impl McState {
    /// Statistics of the blocks present (the canonical fold, see [`super::plan`]).
    pub fn statistics(&self) -> McStats {
        let m = self.folded_moments();
        let cells = self
            .times_s
            .iter()
            .enumerate()
            .map(|(e, _)| {
                let mut row = [ChannelStats::default(); N_CHANNELS];
                for (c, cell) in row.iter_mut().enumerate() {
                    let i = e * N_CHANNELS + c;
                    let h = &self.hist[i];
                    *cell = ChannelStats {
                        mean: m[i].mean,
                        sigma: m[i].std_dev(),
                        p05: h.percentile(0.05),
                        p50: h.percentile(0.50),
                        p95: h.percentile(0.95),
                    };
                }
                row
            })
            .collect();
        McStats {
            runs: m.first().map_or(0, |x| x.n),
            complete: self.is_complete(),
            times_s: self.times_s.clone(),
            cells,
        }
    }
}

impl McStats {
    /// CSV text: `t_s` then `<channel>_{mean,sigma,p05,p50,p95}` for every channel;
    /// numbers in Rust's shortest round-trip form (so equal files ⇔ equal bits).
    pub fn to_csv(&self) -> String {
        let mut s = String::new();
        s.push_str(
            "# sdins Monte Carlo statistics; errors = algorithm - truth (NED); attitude: C_alg C_true^T = I + [eps x] (rad); sigma = sqrt(M2/(n-1)); percentiles nearest-rank on log bins (1.16 % rel.)\n",
        );
        s.push_str("t_s");
        for c in CHANNELS {
            for k in ["mean", "sigma", "p05", "p50", "p95"] {
                let _ = write!(s, ",{c}_{k}");
            }
        }
        s.push('\n');
        for (t, row) in self.times_s.iter().zip(&self.cells) {
            let _ = write!(s, "{t}");
            for c in row {
                let _ = write!(s, ",{},{},{},{},{}", c.mean, c.sigma, c.p05, c.p50, c.p95);
            }
            s.push('\n');
        }
        s
    }
}
