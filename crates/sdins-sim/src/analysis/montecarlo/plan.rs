//! The canonical reduction plan: runs → blocks → shards.
//!
//! * Runs `0 … N−1` are cut into **blocks** of `K` consecutive runs (the last block may
//!   be shorter): block `b` holds runs `b·K … min((b+1)·K, N) − 1`.
//! * A block is reduced **in run-index order** (Welford, one run after the other); its
//!   result does not depend on which thread computes it.
//! * The Monte Carlo result is the fold of the block results **in block order** with
//!   Chan's merge, `((B₀ ⊕ B₁) ⊕ B₂) ⊕ …`, always starting from block 0.
//! * A **shard** is a contiguous range of whole blocks. Shard `i` of `n` holds blocks
//!   `⌊i·B/n⌋ … ⌊(i+1)·B/n⌋ − 1` of the `B = ⌈N/K⌉` blocks. A shard stores its block
//!   results individually (not folded), so merging shards re-creates exactly the list of
//!   block results of a single run and the fold gives the same bits.
//!
//! Threads only change *who* computes a block, never the order of any floating-point
//! operation, hence: same seed → same bits for any thread count and any sharding.

use super::McError;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Default block size K.
pub const DEFAULT_BLOCK: u64 = 16;

/// Shard `index` of `count` (0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// 0-based shard index
    pub index: u64,
    /// number of shards
    pub count: u64,
}

impl Shard {
    /// The whole job as one shard.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Parse `i/n` (0 ≤ i < n).
    pub fn parse(s: &str) -> Result<Shard, McError> {
        let bad = || McError::Config(format!("shard `{s}`: expected i/n with 0 ≤ i < n"));
        let (a, b) = s.split_once('/').ok_or_else(bad)?;
        let index: u64 = a.trim().parse().map_err(|_| bad())?;
        let count: u64 = b.trim().parse().map_err(|_| bad())?;
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

/// Number of blocks `⌈runs/K⌉`.
pub fn block_count(runs: u64, block: u64) -> u64 {
    runs.div_ceil(block.max(1))
}

/// Runs of block `b` (saturating: total for every input, empty past the last block).
pub fn block_runs(b: u64, runs: u64, block: u64) -> Range<u64> {
    let k = block.max(1);
    b.saturating_mul(k).min(runs)..b.saturating_add(1).saturating_mul(k).min(runs)
}

/// Blocks of a shard: `⌊i·B/n⌋ … ⌊(i+1)·B/n⌋`.
pub fn shard_blocks(shard: Shard, runs: u64, block: u64) -> Range<u64> {
    let nb = block_count(runs, block) as u128;
    let (i, n) = (shard.index as u128, shard.count.max(1) as u128);
    ((i * nb / n) as u64)..(((i + 1) * nb / n) as u64)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_blocks_and_blocks_partition_runs() {
        for runs in [1, 15, 16, 17, 100, 1000] {
            for n in 1..=7 {
                let mut next_block = 0;
                for i in 0..n {
                    let r = shard_blocks(Shard { index: i, count: n }, runs, 16);
                    assert_eq!(r.start, next_block);
                    next_block = r.end;
                }
                assert_eq!(next_block, block_count(runs, 16));
            }
            let mut next_run = 0;
            for b in 0..block_count(runs, 16) {
                let r = block_runs(b, runs, 16);
                assert_eq!(r.start, next_run);
                assert!(!r.is_empty());
                next_run = r.end;
            }
            assert_eq!(next_run, runs);
        }
        assert_eq!(Shard::parse("2/4").unwrap(), Shard { index: 2, count: 4 });
        assert!(Shard::parse("4/4").is_err());
        assert!(Shard::parse("1").is_err());
        assert!(Shard::parse("0/0").is_err());
    }
}
