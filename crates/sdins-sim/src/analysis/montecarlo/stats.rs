//! The final statistics table of a Monte Carlo state and its CSV form.
//!
//! Per epoch and channel: `mean`, `sigma` = √(M2/(n − 1)) (sample standard deviation,
//! the unbiased variance estimate), and the nearest-rank percentiles `p05`, `p50`, `p95`
//! of the log-binned histogram (within 1.16 % relative of a sample value, see
//! [`super::histogram`]).

use super::state::McState;
use super::{CHANNELS, N_CHANNELS};
use serde::Serialize;

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
    /// Statistics of the blocks present (the canonical fold, see [`super::plan`](mod@super::plan)).
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
    /// written by the csv crate, numbers in their shortest round-trip form (so equal files
    /// ⇔ equal bits).
    pub fn to_csv(&self) -> String {
        let mut out = String::from(
            "# sdins Monte Carlo statistics; errors = algorithm - truth (NED); attitude: C_alg C_true^T = I + [eps x] (rad); sigma = sqrt(M2/(n-1)); percentiles nearest-rank on log bins (1.16 % rel.)\n",
        );
        let mut header = vec!["t_s".to_string()];
        for c in CHANNELS {
            for k in ["mean", "sigma", "p05", "p50", "p95"] {
                header.push(format!("{c}_{k}"));
            }
        }
        let mut w = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(Vec::new());
        // in memory, every record of the header's length: cannot fail
        let _ = w.write_record(&header);
        for (t, row) in self.times_s.iter().zip(&self.cells) {
            let mut rec = Vec::with_capacity(1 + 5 * row.len());
            rec.push(*t);
            for c in row {
                rec.extend([c.mean, c.sigma, c.p05, c.p50, c.p95]);
            }
            let _ = w.serialize(&rec);
        }
        if let Ok(bytes) = w.into_inner() {
            out.push_str(&String::from_utf8_lossy(&bytes));
        }
        out
    }
}
