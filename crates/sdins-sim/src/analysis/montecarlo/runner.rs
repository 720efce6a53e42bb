//! Running the realisations: rayon over blocks, each block reduced in run order.
//!
//! A run is one pass of [`crate::nav::pipeline::run`] with `sensor_run = Some(r)` and the
//! Monte Carlo seed in place of the scenario's `[imu] seed`. The blocks of a shard are
//! computed in parallel on the current rayon pool (`par_iter().map().collect()` keeps
//! block order); see [`super::plan`] for why the result does not depend on the pool.

use super::histogram::LogHistogram;
use super::moments::Moments;
use super::plan::{block_count, block_runs, shard_blocks, Shard};
use super::state::{fnv1a_hex, BlockResult, McJob, McState, FORMAT};
use super::truth_cache::{worth_caching, TruthCache};
use super::{McError, N_CHANNELS};
use crate::nav::pipeline::{run as run_pipeline, NavError, RunOptions};
use crate::scenario::Scenario;
use rayon::prelude::*;
use sdins_core::nav::AlgorithmSpec;

/// Options of a Monte Carlo job.
#[derive(Clone, Debug, PartialEq)]
pub struct McOptions {
    /// number of runs N (≥ 1)
    pub runs: u64,
    /// seed of the sensor-error streams (replaces the scenario's `[imu] seed`)
    pub seed: u64,
    /// the algorithm
    pub algo: AlgorithmSpec,
    /// output epoch spacing \[s\]: the rows are the updates nearest to `k·every_s`
    /// ([`crate::nav::epochs`])
    pub every_s: f64,
    /// stop time \[s\] (None: whole scenario)
    pub until_s: Option<f64>,
    /// block size K (≥ 1; default [`super::DEFAULT_BLOCK`])
    pub block: u64,
    /// vertical channel held to the truth (default for Monte Carlo: true)
    pub vertical_hold: bool,
}

/// The errors of one run as channel rows: (epoch times, rows).
fn channels(e: &NavError) -> [f64; N_CHANNELS] {
    let (p, v, a) = (e.pos_err_ned_m, e.vel_err_ned_mps, e.att_err_rad);
    [p[0], p[1], p[2], v[0], v[1], v[2], a[0], a[1], a[2]]
}

/// Largest number of runs of one job (the per-epoch moments are exact far beyond it; the
/// cap keeps block and shard arithmetic and run-time estimates sane).
pub const MAX_RUNS: u64 = 100_000_000;

/// One realisation: the errors at every output epoch.
pub fn run_one(scn: &Scenario, opts: &McOptions, run: u64) -> Result<Vec<NavError>, McError> {
    let ropts = RunOptions {
        algos: vec![opts.algo],
        vertical_hold: opts.vertical_hold,
        every_s: Some(opts.every_s),
        until_s: opts.until_s,
        sensor_run: Some(run),
    };
    let mut out = Vec::new();
    run_pipeline(scn, &ropts, |_, _, _, e| out.push(*e), |_, _| {})
        .map_err(|e| McError::Config(e.to_string()))?;
    Ok(out)
}

/// The job identity and the per-run scenario (seed replaced).
pub fn job(scn: &Scenario, opts: &McOptions) -> Result<(McJob, Scenario), McError> {
    if scn.mounting.imu.is_some() {
        return Err(McError::Config(
            "the scenario's [mounting] places the IMU away from the vehicle reference point; the Monte Carlo compares with the truth at the reference point and does not model the lever arm: remove imu_lever_arm_m / imu_mount_deg (sdins truth and run support them)".into(),
        ));
    }
    if opts.runs == 0 || opts.runs > MAX_RUNS {
        return Err(McError::Config(format!(
            "runs = {}: expected 1 … {MAX_RUNS}",
            opts.runs
        )));
    }
    if opts.block == 0 {
        return Err(McError::Config("block size must be ≥ 1".into()));
    }
    if !(opts.every_s.is_finite() && opts.every_s > 0.0) {
        return Err(McError::Config(format!(
            "epoch spacing {} s must be > 0",
            opts.every_s
        )));
    }
    crate::nav::pipeline::check_algorithms(std::slice::from_ref(&opts.algo))
        .map_err(|e| McError::Config(e.to_string()))?;
    if let Some(u) = opts.until_s {
        if !(u.is_finite() && u > 0.0) {
            return Err(McError::Config(format!("until_s = {u}: expected > 0")));
        }
    }
    scn.imu
        .model
        .validate()
        .map_err(|e| McError::Model(e.to_string()))?;
    let mut s = scn.clone();
    s.imu.seed = opts.seed;
    let fingerprint = fnv1a_hex(&format!("{s:?}|{:?}", opts.algo));
    Ok((
        McJob {
            scenario: s.name.clone(),
            fingerprint,
            algo: opts.algo.kind.name().to_string(),
            samples: opts.algo.samples,
            runs: opts.runs,
            seed: opts.seed,
            block: opts.block,
            every_s: opts.every_s,
            until_s: opts.until_s,
            vertical_hold: opts.vertical_hold,
        },
        s,
    ))
}

/// Number of runs in a shard.
pub fn shard_runs(opts: &McOptions, shard: Shard) -> u64 {
    let b = shard_blocks(shard, opts.runs, opts.block);
    let start = block_runs(b.start, opts.runs, opts.block).start;
    let end = if b.is_empty() {
        start
    } else {
        block_runs(b.end - 1, opts.runs, opts.block).end
    };
    end - start
}

/// Run the blocks of `shard` on the current rayon thread pool. `on_run()` is called after
/// every finished run (from worker threads); when `cancelled()` turns true, the
/// remaining runs are skipped and [`McError::Interrupted`] is returned.
pub fn run_shard(
    scn: &Scenario,
    opts: &McOptions,
    shard: Shard,
    on_run: &(dyn Fn() + Sync),
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Result<McState, McError> {
    let (job, s) = job(scn, opts)?;
    if shard.count == 0 || shard.index >= shard.count {
        return Err(McError::Config(format!(
            "shard {}/{}: expected 0 ≤ i < n",
            shard.index, shard.count
        )));
    }
    let nb = block_count(opts.runs, opts.block);
    if shard.count > nb {
        return Err(McError::Config(format!(
            "{} shards for {nb} blocks of {} runs: every shard needs at least one block",
            shard.count, opts.block
        )));
    }
    // epoch times from a run-free pass would cost a whole run; take them from the runs and
    // check that every run has the same epochs
    let blocks: Vec<u64> = shard_blocks(shard, opts.runs, opts.block).collect();
    // the truth is the same for every run: generate it once where that is expensive
    let cache = worth_caching(&s, opts.algo.samples, opts.until_s)
        .then(|| TruthCache::build(&s, opts.algo.samples, job.every_s, opts.until_s));
    type Block = (BlockResult, Vec<LogHistogram>, Vec<f64>);
    let results: Vec<Result<Block, McError>> = blocks
        .par_iter()
        .map(|&b| {
            let mut moments: Vec<Moments> = Vec::new();
            let mut hist: Vec<LogHistogram> = Vec::new();
            let mut times: Vec<f64> = Vec::new();
            for r in block_runs(b, opts.runs, opts.block) {
                if cancelled() {
                    return Err(McError::Interrupted);
                }
                let errs = match &cache {
                    Some(c) => c.run(&s.imu.model, s.imu.seed, r, &opts.algo, opts.vertical_hold),
                    None => run_one(&s, opts, r)?,
                };
                if times.is_empty() {
                    times = errs.iter().map(|e| e.t_s).collect();
                    moments = vec![Moments::default(); times.len() * N_CHANNELS];
                    hist = vec![LogHistogram::default(); times.len() * N_CHANNELS];
                } else if errs.len() != times.len() {
                    return Err(McError::Config(format!(
                        "run {r} produced {} epochs, run 0 of its block {}",
                        errs.len(),
                        times.len()
                    )));
                }
                for (ei, e) in errs.iter().enumerate() {
                    for (c, x) in channels(e).into_iter().enumerate() {
                        moments[ei * N_CHANNELS + c].push(x);
                        hist[ei * N_CHANNELS + c].push(x);
                    }
                }
                on_run();
            }
            Ok((BlockResult { index: b, moments }, hist, times))
        })
        .collect();
    let mut state = McState {
        format: FORMAT.to_string(),
        job,
        times_s: Vec::new(),
        blocks: Vec::with_capacity(results.len()),
        hist: Vec::new(),
    };
    for r in results {
        let (block, hist, times) = r?;
        if state.blocks.is_empty() {
            state.times_s = times;
            state.hist = hist;
        } else {
            if times.len() != state.times_s.len() {
                return Err(McError::Config("blocks produced different epochs".into()));
            }
            for (a, h) in state.hist.iter_mut().zip(&hist) {
                a.merge(h);
            }
        }
        state.blocks.push(block);
    }
    if state.times_s.is_empty() {
        return Err(McError::Config(
            "no output epoch (scenario shorter than one epoch?)".into(),
        ));
    }
    Ok(state)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::analysis::montecarlo::DEFAULT_BLOCK;

    /// 60 s stationary, aviation grade, 100 Hz: fast enough for the default test run.
    pub(crate) fn small_scenario() -> Scenario {
        Scenario::from_toml(
            r#"
name = "mc-small"
[start]
lat_deg = 37.5
lon_deg = 127.0
yaw_deg = 30.0
[imu]
rate_hz = 100.0
grade = "aviation"
[nav]
samples = 2
[[segment]]
type = "static"
duration_s = 60.0
"#,
            "mc-small",
        )
        .unwrap()
    }

    fn opts(runs: u64) -> McOptions {
        McOptions {
            runs,
            seed: 42,
            algo: AlgorithmSpec::from_name("songlee-complete", 2).unwrap(),
            every_s: 10.0,
            until_s: None,
            block: DEFAULT_BLOCK,
            vertical_hold: true,
        }
    }

    fn in_pool(threads: usize, f: impl FnOnce() -> McState + Send) -> McState {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(f)
    }

    #[test]
    fn tampered_states_are_refused() {
        let scn = small_scenario();
        let o = opts(9);
        let st = run_shard(&scn, &o, Shard::ALL, &|| {}, &|| false).unwrap();
        st.validate().unwrap();
        let tamper = |f: &dyn Fn(&mut McState)| {
            let mut t = st.clone();
            f(&mut t);
            McState::merge(&[t]).unwrap_err().to_string()
        };
        assert!(tamper(&|t| t.blocks[0].moments[0].n += 1).contains("n = "));
        assert!(tamper(&|t| t.blocks[0].moments[3].m2 = -1.0).contains("m2"));
        assert!(tamper(&|t| t.blocks[0].moments[1].mean = f64::NAN).contains("mean"));
        assert!(tamper(&|t| t.times_s[0] = f64::INFINITY).contains("epoch"));
        assert!(tamper(&|t| t.hist[2] = Default::default()).contains("histogram"));
    }

    #[test]
    fn bit_identical_for_threads_and_shards() {
        let scn = small_scenario();
        let o = opts(61); // 4 blocks, the last one partial
        let none = || {};
        let go = || false;
        let one = in_pool(1, || run_shard(&scn, &o, Shard::ALL, &none, &go).unwrap());
        let two = in_pool(2, || run_shard(&scn, &o, Shard::ALL, &none, &go).unwrap());
        assert_eq!(one, two);
        let shards: Vec<McState> = (0..4)
            .map(|i| {
                in_pool(2, || {
                    run_shard(&scn, &o, Shard { index: i, count: 4 }, &none, &go).unwrap()
                })
            })
            .collect();
        assert!(!shards[0].is_complete());
        // merge in a scrambled order, through a JSON round trip
        let json: Vec<McState> = [3, 1, 0, 2]
            .iter()
            .map(|&i| {
                let s = serde_json::to_string(&shards[i]).unwrap();
                serde_json::from_str(&s).unwrap()
            })
            .collect();
        let merged = McState::merge(&json).unwrap();
        assert_eq!(merged, one);
        let (a, b) = (one.statistics(), merged.statistics());
        assert_eq!(a.to_csv(), b.to_csv());
        assert!(a.complete);
        assert_eq!(a.runs, 61);
        assert_eq!(a.times_s, [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0]);
        // bit equality of every number
        for (ra, rb) in a.cells.iter().zip(&b.cells) {
            for (x, y) in ra.iter().zip(rb) {
                assert_eq!(x.sigma.to_bits(), y.sigma.to_bits());
                assert_eq!(x.mean.to_bits(), y.mean.to_bits());
            }
        }
        // the sensor errors are really there, and the vertical channel is held
        let last = a.cells.last().unwrap();
        assert!(last[0].sigma > 0.01 && last[6].sigma > 1e-7);
        assert_eq!(last[2].sigma, 0.0);
        // p05 ≤ p50 ≤ p95
        assert!(last[0].p05 <= last[0].p50 && last[0].p50 <= last[0].p95);
        // overlapping shards and different jobs are refused
        assert!(matches!(
            McState::merge(&[shards[1].clone(), shards[1].clone()]),
            Err(McError::DuplicateBlock(_))
        ));
        let other = run_shard(
            &scn,
            &McOptions {
                seed: 7,
                ..opts(61)
            },
            Shard { index: 0, count: 4 },
            &none,
            &go,
        )
        .unwrap();
        assert!(matches!(
            McState::merge(&[other, shards[1].clone()]),
            Err(McError::Mismatch(_))
        ));
    }

    /// The cached truth replays the streaming pipeline bit for bit (dq-paper: integrated truth,
    /// coning overlay; aviation-grade errors; 41 s with a partial last epoch).
    #[test]
    fn cached_truth_run_equals_pipeline_run() {
        let b = crate::scenario::builtin("dq-paper").unwrap();
        let text = b.toml.replace("[imu]", "[imu]\ngrade = \"aviation\"");
        let scn = Scenario::from_toml(&text, "dq").unwrap();
        assert!(worth_caching(&scn, 2, Some(41.0)));
        let o = McOptions {
            until_s: Some(41.0),
            ..opts(1)
        };
        let (job, s) = job(&scn, &o).unwrap();
        let cache = TruthCache::build(&s, 2, job.every_s, o.until_s);
        for hold in [true, false] {
            let o = McOptions {
                vertical_hold: hold,
                ..o.clone()
            };
            for r in [0, 5] {
                let a = run_one(&s, &o, r).unwrap();
                let c = cache.run(&s.imu.model, s.imu.seed, r, &o.algo, hold);
                assert_eq!(a.len(), 6); // 0, 10, 20, 30, 40 and the last update, 41 s
                assert_eq!(a, c);
            }
        }
    }

    #[test]
    fn bad_options_and_cancel() {
        let scn = small_scenario();
        let none = || {};
        let go = || false;
        assert!(run_shard(&scn, &opts(0), Shard::ALL, &none, &go).is_err());
        assert!(run_shard(&scn, &opts(16), Shard { index: 0, count: 2 }, &none, &go).is_err());
        let stop = || true;
        assert_eq!(
            run_shard(&scn, &opts(2), Shard::ALL, &none, &stop),
            Err(McError::Interrupted)
        );
        assert_eq!(shard_runs(&opts(61), Shard { index: 3, count: 4 }), 13);
    }
}
