//! The lossless, mergeable accumulator state of a Monte Carlo job (or of a shard of it).
//!
//! Every `f64` is stored as its bit pattern (`u64`), so writing a state to JSON and
//! reading it back gives the same bits. A state holds:
//! * the job identity ([`McJob`]): scenario name and fingerprint, algorithm, runs, seed,
//!   block size, epoch spacing, vertical mode — merging requires them to be equal;
//! * the output epochs' times;
//! * one [`BlockResult`] per computed block (moments per epoch and channel, **not**
//!   folded, see [`super::plan`](mod@super::plan));
//! * one [`LogHistogram`] per epoch and channel (integer counts: merging is exact in any
//!   order).

use super::histogram::LogHistogram;
use super::moments::Moments;
use super::plan::{block_count, block_runs};
use super::{McError, N_CHANNELS};
use serde::{Deserialize, Serialize};

/// Format tag of the state files.
pub const FORMAT: &str = "sdins-montecarlo-state-2";

/// Identity of a Monte Carlo job.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct McJob {
    /// scenario name
    pub scenario: String,
    /// FNV-1a 64 hash of the scenario's full description (hex), seed included
    pub fingerprint: String,
    /// algorithm CLI name
    pub algo: String,
    /// samples per navigation update
    pub samples: usize,
    /// total number of runs N
    pub runs: u64,
    /// seed of the sensor-error streams
    pub seed: u64,
    /// block size K
    pub block: u64,
    /// output epoch spacing \[s\]: rows at the updates nearest to `k·every_s`
    /// ([`crate::nav::epochs`]; format 2, format 1 held a count of updates)
    #[serde(with = "super::bits")]
    pub every_s: f64,
    /// stop time \[s\] (None: whole scenario)
    #[serde(with = "super::bits::opt")]
    pub until_s: Option<f64>,
    /// vertical channel held to the truth
    pub vertical_hold: bool,
}

/// The moments of one block of runs, per epoch and channel (`epoch·9 + channel`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BlockResult {
    /// block index
    pub index: u64,
    /// moments, row-major (epoch, channel)
    pub moments: Vec<Moments>,
}

/// Accumulator state of a job or shard.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct McState {
    /// format tag ([`FORMAT`])
    pub format: String,
    /// the job
    pub job: McJob,
    /// output epoch times \[s\]
    #[serde(with = "super::bits::vec")]
    pub times_s: Vec<f64>,
    /// computed blocks, ascending index
    pub blocks: Vec<BlockResult>,
    /// histograms, row-major (epoch, channel)
    pub hist: Vec<LogHistogram>,
}

/// FNV-1a 64-bit hash of a string, as 16 hex digits.
pub fn fnv1a_hex(s: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in s.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

impl McState {
    /// Check internal consistency (sizes, block order, indices in range).
    pub fn validate(&self) -> Result<(), McError> {
        if self.format != FORMAT {
            return Err(McError::BadState(format!(
                "format `{}`, expected `{FORMAT}`",
                self.format
            )));
        }
        let cells = self.times_s.len() * N_CHANNELS;
        if self.hist.len() != cells {
            return Err(McError::BadState(format!(
                "{} histograms for {cells} cells",
                self.hist.len()
            )));
        }
        let nb = block_count(self.job.runs, self.job.block);
        let mut prev: Option<u64> = None;
        for b in &self.blocks {
            if b.moments.len() != cells {
                return Err(McError::BadState(format!(
                    "block {}: {} moments for {cells} cells",
                    b.index,
                    b.moments.len()
                )));
            }
            if b.index >= nb || prev.is_some_and(|p| p >= b.index) {
                return Err(McError::BadState(format!(
                    "block {} out of range or out of order",
                    b.index
                )));
            }
            prev = Some(b.index);
            // moment invariants: every cell counts the block's runs, finite mean, m2 ≥ 0
            let runs = block_runs(b.index, self.job.runs, self.job.block);
            let want = runs.end - runs.start;
            for (c, m) in b.moments.iter().enumerate() {
                if m.n != want || !m.mean.is_finite() || !m.m2.is_finite() || m.m2 < 0.0 {
                    return Err(McError::BadState(format!(
                        "block {} cell {c}: n = {} (expected {want}), mean = {}, m2 = {} (finite, ≥ 0 expected)",
                        b.index, m.n, m.mean, m.m2
                    )));
                }
            }
        }
        if self.times_s.iter().any(|t| !t.is_finite()) {
            return Err(McError::BadState("non-finite epoch time".into()));
        }
        // the histograms count every run of the state's blocks, once per cell
        let runs: u64 = self
            .blocks
            .iter()
            .map(|b| {
                let r = block_runs(b.index, self.job.runs, self.job.block);
                r.end - r.start
            })
            .sum();
        if let Some((c, h)) = self
            .hist
            .iter()
            .enumerate()
            .find(|(_, h)| h.total() != runs)
        {
            return Err(McError::BadState(format!(
                "histogram of cell {c} counts {} values for {runs} runs",
                h.total()
            )));
        }
        Ok(())
    }

    /// Merge shard states of one job into one state (blocks re-sorted by index,
    /// histograms added). The result equals, bit for bit, the state a single process
    /// would have computed for the union of the shards.
    pub fn merge(states: &[McState]) -> Result<McState, McError> {
        let first = states
            .first()
            .ok_or_else(|| McError::Mismatch("nothing to merge".into()))?;
        first.validate()?;
        let mut out = McState {
            format: FORMAT.to_string(),
            job: first.job.clone(),
            times_s: first.times_s.clone(),
            blocks: Vec::new(),
            hist: vec![LogHistogram::default(); first.hist.len()],
        };
        for s in states {
            s.validate()?;
            if s.job != first.job {
                return Err(McError::Mismatch(format!(
                    "different jobs: {:?} vs {:?}",
                    s.job, first.job
                )));
            }
            if s.times_s.len() != first.times_s.len()
                || s.times_s
                    .iter()
                    .zip(&first.times_s)
                    .any(|(a, b)| a.to_bits() != b.to_bits())
            {
                return Err(McError::Mismatch("different output epochs".into()));
            }
            out.blocks.extend(s.blocks.iter().cloned());
            for (h, o) in out.hist.iter_mut().zip(&s.hist) {
                h.merge(o);
            }
        }
        out.blocks.sort_by_key(|b| b.index);
        for w in out.blocks.windows(2) {
            if w[0].index == w[1].index {
                return Err(McError::DuplicateBlock(w[0].index));
            }
        }
        Ok(out)
    }

    /// Indices of the blocks not present (empty when the job is complete).
    pub fn missing_blocks(&self) -> Vec<u64> {
        let have: std::collections::BTreeSet<u64> = self.blocks.iter().map(|b| b.index).collect();
        (0..block_count(self.job.runs, self.job.block))
            .filter(|b| !have.contains(b))
            .collect()
    }

    /// Whether every block of the job is present.
    pub fn is_complete(&self) -> bool {
        self.missing_blocks().is_empty()
    }

    /// The canonical fold: moments of every cell, blocks merged in ascending block order.
    pub fn folded_moments(&self) -> Vec<Moments> {
        let mut acc = vec![Moments::default(); self.times_s.len() * N_CHANNELS];
        for b in &self.blocks {
            for (a, m) in acc.iter_mut().zip(&b.moments) {
                *a = a.merged(m);
            }
        }
        acc
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn fnv_is_stable() {
        assert_eq!(fnv1a_hex(""), "cbf29ce484222325");
        assert_eq!(fnv1a_hex("a"), "af63dc4c8601ec8c");
    }
}
