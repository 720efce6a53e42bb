//! Monte Carlo of the INS/GNSS filter on a scenario (`sdins fuse SCENARIO --runs N`,
//! `sdins.fuse_montecarlo`): per output epoch, the mergeable moments (count, mean, M2) of
//! the NEES of every state block whose truth the simulation knows (position, velocity,
//! attitude, the IMU biases' constant part, the scale factors) and of the NIS of every
//! measurement kind, for the consistency criterion of [`super::consistency`].
//!
//! Exactness is that of [`super::montecarlo`] and uses its machinery: runs in blocks of K
//! reduced in run order ([`super::montecarlo::moments::Moments`], Welford), the blocks of a
//! shard computed on the rayon pool and kept unfolded, the statistics folded in block
//! order (Chan) — the same seed gives the same bits for any thread count and any shard
//! split ([`super::montecarlo::plan`](mod@super::montecarlo::plan)). The seed replaces both the scenario's `[imu] seed`
//! and its `[gnss] seed` (their random streams are disjoint by construction).
//!
//! With [`FuseMcOptions::draw_scale_factors`] each run's true scale factors are drawn
//! from the filter's prior (stream `2⁶² + run` of the seed; disjoint from the IMU streams
//! `6·run + channel` and the GNSS streams `2⁶³ + 16·run + channel`).
//!
//! NIS cells: the updates of a kind applied after the previous output row and up to this
//! one (so with rows at the covariance epochs and 1 Hz fixes, one NIS per run at the fix
//! epochs and none elsewhere; a cell's count says how many).

use super::consistency::{check, Consistency};
use super::montecarlo::moments::Moments;
use super::montecarlo::plan::{block_count, block_runs, shard_blocks, Shard};
use super::montecarlo::state::{fnv1a_hex, BlockResult};
use crate::cancel::CancelToken;
use crate::fusion::request::{
    request_scenario, scenario_options, FuseData, FuseRequest, FuseRunError,
};
use crate::fusion::simulated::{
    fuse_scenario_with, scenario_truth, FuseEpoch, FuseEvent, FuseOptions,
};
use crate::scenario::Scenario;
use crate::sensors::gnss::GnssConfig;
use rand::SeedableRng;
use rand_chacha::ChaCha20Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use sdins_core::aiding::layout::{BlockKind, StateLayout};
use sdins_core::aiding::meas::MeasKind;
use serde::{Deserialize, Serialize};

/// Format tag of the state files.
pub const FORMAT: &str = "sdins-fuse-montecarlo-state-1";

/// Largest number of runs of one job.
pub const MAX_RUNS: u64 = 10_000_000;

/// The blocks whose truth a scenario run knows.
const KNOWN: [BlockKind; 7] = [
    BlockKind::Position,
    BlockKind::Velocity,
    BlockKind::Attitude,
    BlockKind::AccelBias,
    BlockKind::GyroBias,
    BlockKind::AccelScale,
    BlockKind::GyroScale,
];

/// Options of a fusion Monte Carlo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuseMcOptions {
    /// runs N
    pub runs: u64,
    /// seed of the IMU and GNSS error streams
    pub seed: u64,
    /// block size K
    pub block: u64,
    /// with scale-factor states: draw each run's true accelerometer and gyro scale
    /// factors from the filter's prior (normal, σ of the prior per axis; a stream of the
    /// seed per run), replacing the scenario's, so that the truth is distributed as the
    /// filter assumes
    pub draw_scale_factors: bool,
}

/// Why a fusion Monte Carlo stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FuseMcError {
    /// Bad configuration.
    #[error("fuse Monte Carlo: {0}")]
    Config(String),
    /// A run failed.
    #[error("fuse Monte Carlo run {run}: {source}")]
    Run {
        /// the run
        run: u64,
        /// why
        source: FuseRunError,
    },
    /// The states to merge belong to different jobs.
    #[error("cannot merge: {0}")]
    Mismatch(String),
    /// The same block twice.
    #[error("cannot merge: block {0} is present twice (overlapping shards)")]
    DuplicateBlock(u64),
    /// A malformed state.
    #[error("bad fuse Monte Carlo state: {0}")]
    BadState(String),
    /// Stopped by the caller.
    #[error("interrupted")]
    Interrupted,
}

/// Identity of a job.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FuseMcJob {
    /// scenario name
    pub scenario: String,
    /// FNV-1a of the scenario, GNSS settings and filter options (seeds replaced)
    pub fingerprint: String,
    /// runs N
    pub runs: u64,
    /// seed
    pub seed: u64,
    /// block size K
    pub block: u64,
    /// the true scale factors drawn per run from the prior
    pub draw_scale_factors: bool,
    /// statistics: `nees_<block>` then `nis_<kind>`
    pub columns: Vec<String>,
    /// their degrees of freedom
    pub dof: Vec<u32>,
}

/// The accumulator state of a job or shard.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FuseMcState {
    /// [`FORMAT`]
    pub format: String,
    /// the job
    pub job: FuseMcJob,
    /// output epoch times \[s\]
    #[serde(with = "super::montecarlo::bits::vec")]
    pub times_s: Vec<f64>,
    /// blocks present, ascending, moments row-major (epoch, column)
    pub blocks: Vec<BlockResult>,
}

/// One column's statistics at every epoch.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ColumnStats {
    /// column name
    pub name: String,
    /// degrees of freedom
    pub dof: u32,
    /// per epoch: count, mean, sample σ
    pub n: Vec<u64>,
    /// means
    pub mean: Vec<f64>,
    /// sample standard deviations √(M2/(n − 1))
    pub sd: Vec<f64>,
}

/// The statistics of a state.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FuseMcStats {
    /// runs included
    pub runs: u64,
    /// all blocks present
    pub complete: bool,
    /// epoch times \[s\]
    pub times_s: Vec<f64>,
    /// per column
    pub columns: Vec<ColumnStats>,
}

/// The columns and their dof for a layout and the GNSS settings.
pub fn columns(layout: &StateLayout, gnss: &GnssConfig) -> (Vec<String>, Vec<u32>) {
    let (mut c, mut d) = (Vec::new(), Vec::new());
    for b in layout.blocks() {
        if KNOWN.contains(&b.kind) {
            c.push(format!("nees_{}", b.kind.name()));
            d.push(b.dim as u32);
        }
    }
    for k in MeasKind::ALL {
        c.push(format!("nis_{}", k.name()));
        d.push(match k {
            MeasKind::Gnss if gnss.sigma_vel_ned_mps.iter().all(|x| *x > 0.0) => 6,
            MeasKind::Gnss => 3,
            MeasKind::Zupt => 3,
            MeasKind::Nhc => 2,
            MeasKind::Baro => 1,
            // speed + the two vehicle-frame NHC rows; 1 when the odometer's NHC is off (the
            // column keeps the larger dof)
            MeasKind::Odometer => 3,
            MeasKind::Magnetometer => 3,
            // azimuth + elevation; 1 heading-only (the column keeps the larger dof)
            MeasKind::DualAntenna => 2,
            MeasKind::BodyVelocity => 3,
            _ => 0,
        });
    }
    (c, d)
}

/// The scenario, GNSS settings and options of a request's Monte Carlo (seeds replaced).
fn setup(
    req: &FuseRequest,
    mc: &FuseMcOptions,
) -> Result<(Scenario, GnssConfig, FuseOptions, FuseMcJob), FuseMcError> {
    let FuseData::Scenario(d) = &req.data else {
        return Err(FuseMcError::Config(
            "a Monte Carlo needs a scenario (recorded data have one realisation)".into(),
        ));
    };
    if d.in_motion {
        return Err(FuseMcError::Config(
            "in-motion alignment starts each run at its own time: the runs' epochs would differ"
                .into(),
        ));
    }
    if mc.runs == 0 || mc.runs > MAX_RUNS || mc.block == 0 {
        return Err(FuseMcError::Config(format!(
            "runs = {} (expected 1 … {MAX_RUNS}), block = {} (≥ 1)",
            mc.runs, mc.block
        )));
    }
    let bad = |e: FuseRunError| FuseMcError::Config(e.to_string());
    let mut scn = request_scenario(req, d).map_err(bad)?;
    let opts = scenario_options(req, d, &scn).map_err(bad)?;
    scn.imu.seed = mc.seed;
    let mut gnss = scn.gnss.clone().unwrap_or_default();
    gnss.seed = mc.seed;
    let mut layout = crate::fusion::simulated::noise_from_model(&scn.imu.model)
        .0
        .layout();
    if opts.scale_factors.is_some() {
        layout = layout
            .with_scale_factors()
            .map_err(|e| FuseMcError::Config(e.to_string()))?;
    }
    let (columns, dof) = columns(&layout, &gnss);
    let job = FuseMcJob {
        scenario: scn.name.clone(),
        fingerprint: fnv1a_hex(&format!("{scn:?}|{gnss:?}|{opts:?}")),
        runs: mc.runs,
        seed: mc.seed,
        block: mc.block,
        draw_scale_factors: mc.draw_scale_factors && opts.scale_factors.is_some(),
        columns,
        dof,
    };
    Ok((scn, gnss, opts, job))
}

/// One run: epoch times and, per epoch, the NEES columns and the NIS values `(column,
/// value)` binned to it.
type RunRows = (Vec<f64>, Vec<f64>, Vec<Vec<(usize, f64)>>);

fn one_run(
    scn: &Scenario,
    truth: Option<&[crate::truth::TruthSample]>,
    gnss: &GnssConfig,
    opts: &FuseOptions,
    job: &FuseMcJob,
    run: u64,
) -> Result<RunRows, FuseMcError> {
    let n_nees = job
        .columns
        .iter()
        .filter(|c| c.starts_with("nees_"))
        .count();
    let drawn;
    let scn = match (&opts.scale_factors, job.draw_scale_factors) {
        (Some(sp), true) => {
            let mut rng = ChaCha20Rng::seed_from_u64(job.seed);
            rng.set_stream((1u64 << 62) | run);
            let mut s = scn.clone();
            for i in 0..3 {
                let (wa, wg): (f64, f64) = (
                    StandardNormal.sample(&mut rng),
                    StandardNormal.sample(&mut rng),
                );
                s.imu.model.accel_scale_ppm[i] = sp.accel_ppm[i] * wa;
                s.imu.model.gyro_scale_ppm[i] = sp.gyro_ppm[i] * wg;
            }
            drawn = s;
            &drawn
        }
        _ => scn,
    };
    let mut times = Vec::new();
    let mut nees = Vec::new();
    let mut nis: Vec<Vec<(usize, f64)>> = Vec::new();
    let mut pending: Vec<(usize, f64)> = Vec::new();
    let kinds: Vec<(BlockKind, usize)> = KNOWN
        .iter()
        .filter_map(|k| {
            job.columns
                .iter()
                .position(|c| *c == format!("nees_{}", k.name()))
                .map(|i| (*k, i))
        })
        .collect();
    let nees_of = |e: &FuseEpoch| {
        let mut v = vec![0.0; n_nees];
        for (k, i) in &kinds {
            v[*i] = e.nees(*k).unwrap_or(f64::NAN);
        }
        v
    };
    fuse_scenario_with(
        scn,
        truth,
        gnss,
        opts,
        run,
        &CancelToken::new(),
        |ev| match ev {
            FuseEvent::Epoch(e) => {
                times.push(e.t_s);
                nees.extend(nees_of(e));
                nis.push(std::mem::take(&mut pending));
            }
            FuseEvent::Update(u) if u.accepted => {
                pending.push((n_nees + u.kind.index(), u.nis));
            }
            _ => {}
        },
    )
    .map_err(|e| FuseMcError::Run {
        run,
        source: FuseRunError::Fuse(e),
    })?;
    Ok((times, nees, nis))
}

/// Compute shard `shard` of the Monte Carlo of a (scenario) request on the current rayon
/// pool. `on_run()` after every run; `cancelled()` stops it ([`FuseMcError::Interrupted`]).
pub fn run_shard(
    req: &FuseRequest,
    mc: &FuseMcOptions,
    shard: Shard,
    on_run: &(dyn Fn() + Sync),
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Result<FuseMcState, FuseMcError> {
    let (scn, gnss, opts, job) = setup(req, mc)?;
    let nb = block_count(mc.runs, mc.block);
    if shard.count == 0 || shard.index >= shard.count || shard.count > nb {
        return Err(FuseMcError::Config(format!(
            "shard {}/{} of {nb} blocks: expected 0 ≤ i < n ≤ blocks",
            shard.index, shard.count
        )));
    }
    let len = crate::truth::TruthGenerator::new(&scn.trajectory, scn.truth_config()).len_samples();
    let cached = (len <= 1_000_000).then(|| scenario_truth(&scn));
    let ncol = job.columns.len();
    let n_nees = job
        .columns
        .iter()
        .filter(|c| c.starts_with("nees_"))
        .count();
    let blocks: Vec<u64> = shard_blocks(shard, mc.runs, mc.block).collect();
    let results: Vec<Result<(BlockResult, Vec<f64>), FuseMcError>> = blocks
        .par_iter()
        .map(|&b| {
            let mut moments: Vec<Moments> = Vec::new();
            let mut times: Vec<f64> = Vec::new();
            for r in block_runs(b, mc.runs, mc.block) {
                if cancelled() {
                    return Err(FuseMcError::Interrupted);
                }
                let (t, nees, nis) = one_run(&scn, cached.as_deref(), &gnss, &opts, &job, r)?;
                if times.is_empty() {
                    times = t;
                    moments = vec![Moments::default(); times.len() * ncol];
                } else if t.len() != times.len()
                    || t.iter()
                        .zip(&times)
                        .any(|(a, b)| a.to_bits() != b.to_bits())
                {
                    return Err(FuseMcError::Config(format!(
                        "run {r} has other output epochs than the first run of its block"
                    )));
                }
                for (e, bins) in nis.iter().enumerate() {
                    for c in 0..n_nees {
                        moments[e * ncol + c].push(nees[e * n_nees + c]);
                    }
                    for (c, x) in bins {
                        moments[e * ncol + c].push(*x);
                    }
                }
                on_run();
            }
            Ok((BlockResult { index: b, moments }, times))
        })
        .collect();
    let mut state = FuseMcState {
        format: FORMAT.into(),
        job,
        times_s: Vec::new(),
        blocks: Vec::new(),
    };
    for r in results {
        let (block, times) = r?;
        if state.blocks.is_empty() {
            state.times_s = times;
        } else if times.len() != state.times_s.len() {
            return Err(FuseMcError::Config(
                "blocks produced different epochs".into(),
            ));
        }
        state.blocks.push(block);
    }
    Ok(state)
}

impl FuseMcState {
    /// Check sizes, order and the moments' invariants.
    pub fn validate(&self) -> Result<(), FuseMcError> {
        let bad = |m: String| Err(FuseMcError::BadState(m));
        if self.format != FORMAT {
            return bad(format!("format `{}`, expected `{FORMAT}`", self.format));
        }
        let ncol = self.job.columns.len();
        if ncol == 0 || self.job.dof.len() != ncol {
            return bad("columns and their dof differ in number".into());
        }
        let cells = self.times_s.len() * ncol;
        let nb = block_count(self.job.runs, self.job.block);
        let mut prev = None;
        for b in &self.blocks {
            if b.moments.len() != cells || b.index >= nb || prev.is_some_and(|p| p >= b.index) {
                return bad(format!("block {}: size, range or order", b.index));
            }
            prev = Some(b.index);
            let runs = block_runs(b.index, self.job.runs, self.job.block);
            let want = runs.end - runs.start;
            for (c, m) in b.moments.iter().enumerate() {
                let nees = self.job.columns[c % ncol].starts_with("nees_");
                let n_ok = if nees { m.n == want } else { true };
                if !n_ok || !(m.n == 0 || m.mean.is_finite()) || !m.m2.is_finite() || m.m2 < 0.0 {
                    return bad(format!(
                        "block {} cell {c}: n = {}, mean = {}, m2 = {}",
                        b.index, m.n, m.mean, m.m2
                    ));
                }
            }
        }
        if self.times_s.iter().any(|t| !t.is_finite()) {
            return bad("non-finite epoch time".into());
        }
        Ok(())
    }

    /// Merge shard states of one job (bit-identical to a single run of their union).
    pub fn merge(states: &[FuseMcState]) -> Result<FuseMcState, FuseMcError> {
        let first = states
            .first()
            .ok_or_else(|| FuseMcError::Mismatch("nothing to merge".into()))?;
        let mut out = FuseMcState {
            format: FORMAT.into(),
            job: first.job.clone(),
            times_s: first.times_s.clone(),
            blocks: Vec::new(),
        };
        for s in states {
            s.validate()?;
            if s.job != first.job {
                return Err(FuseMcError::Mismatch(format!(
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
                return Err(FuseMcError::Mismatch("different output epochs".into()));
            }
            out.blocks.extend(s.blocks.iter().cloned());
        }
        out.blocks.sort_by_key(|b| b.index);
        for w in out.blocks.windows(2) {
            if w[0].index == w[1].index {
                return Err(FuseMcError::DuplicateBlock(w[0].index));
            }
        }
        Ok(out)
    }

    /// Block indices not present.
    pub fn missing_blocks(&self) -> Vec<u64> {
        let have: std::collections::BTreeSet<u64> = self.blocks.iter().map(|b| b.index).collect();
        (0..block_count(self.job.runs, self.job.block))
            .filter(|b| !have.contains(b))
            .collect()
    }

    /// The statistics: the blocks folded in ascending order (Chan).
    pub fn statistics(&self) -> FuseMcStats {
        let ncol = self.job.columns.len();
        let mut acc = vec![Moments::default(); self.times_s.len() * ncol];
        for b in &self.blocks {
            for (a, m) in acc.iter_mut().zip(&b.moments) {
                *a = a.merged(m);
            }
        }
        let columns = (0..ncol)
            .map(|c| {
                let cell = |e: usize| acc[e * ncol + c];
                let ne = self.times_s.len();
                ColumnStats {
                    name: self.job.columns[c].clone(),
                    dof: self.job.dof[c],
                    n: (0..ne).map(|e| cell(e).n).collect(),
                    mean: (0..ne).map(|e| cell(e).mean).collect(),
                    sd: (0..ne).map(|e| cell(e).std_dev()).collect(),
                }
            })
            .collect();
        let runs = self
            .blocks
            .iter()
            .map(|b| {
                let r = block_runs(b.index, self.job.runs, self.job.block);
                r.end - r.start
            })
            .sum();
        FuseMcStats {
            runs,
            complete: self.missing_blocks().is_empty(),
            times_s: self.times_s.clone(),
            columns,
        }
    }
}

impl FuseMcStats {
    /// The consistency criterion on a column, over the epochs after `after_s` whose cell
    /// holds one value per run (`tests` judged together: Bonferroni on the grand mean).
    pub fn consistency(&self, column: &str, after_s: f64, tests: usize) -> Option<Consistency> {
        let c = self.columns.iter().find(|c| c.name == column)?;
        let means: Vec<f64> = (0..self.times_s.len())
            .filter(|&e| self.times_s[e] > after_s && c.n[e] == self.runs && self.runs > 0)
            .map(|e| c.mean[e])
            .collect();
        Some(check(
            column,
            &means,
            f64::from(c.dof),
            self.runs as f64,
            tests,
        ))
    }

    /// CSV: `t_s`, then per column `<name>_n`, `<name>_mean`, `<name>_sd` (shortest
    /// round-trip decimals; empty cells have n = 0).
    pub fn to_csv(&self) -> String {
        let mut out = String::from(
            "# sdins fuse Monte Carlo statistics per output epoch: NEES per state block, NIS per measurement kind; sd = sqrt(M2/(n-1))\n",
        );
        let mut header = vec!["t_s".to_string()];
        for c in &self.columns {
            for k in ["n", "mean", "sd"] {
                header.push(format!("{}_{k}", c.name));
            }
        }
        out.push_str(&header.join(","));
        out.push('\n');
        for (e, t) in self.times_s.iter().enumerate() {
            out.push_str(&format!("{t}"));
            for c in &self.columns {
                out.push_str(&format!(",{},{},{}", c.n[e], c.mean[e], c.sd[e]));
            }
            out.push('\n');
        }
        out
    }
}
