//! `sdins fuse SCENARIO --runs N` (the fusion Monte Carlo: NEES per state block and NIS
//! per measurement kind at every output epoch, `sdins_sim::analysis::fuse_mc`) and
//! `sdins fuse --merge DIR...` (its shards merged bit for bit). Writes
//! `fuse_mc_stats.csv`, `fuse_mc_state.json` and `run.toml`; prints the consistency
//! criterion (`sdins_sim::analysis::consistency`) of every column after 30 s.

use super::fuse_args::Args;
use crate::error::CliError;
use crate::output::write_string;
use crate::progress::Progress;
use sdins_sim::analysis::fuse_mc::{run_shard, FuseMcError, FuseMcOptions, FuseMcState};
use sdins_sim::analysis::montecarlo::plan::{block_count, block_runs, shard_blocks};
use sdins_sim::analysis::montecarlo::Shard;
use sdins_sim::fusion::request::{FuseData, FuseRequest};
use std::path::Path;
use std::sync::Mutex;

/// Consistency is judged after this time \[s\] (convergence).
const AFTER_S: f64 = 30.0;

fn mc_err(e: FuseMcError) -> CliError {
    match e {
        FuseMcError::Interrupted => CliError::Interrupted,
        other => CliError::bad(other.to_string()),
    }
}

/// Run a shard (or the whole job) of the Monte Carlo of a scenario request.
pub fn run(args: &Args, req: &FuseRequest) -> Result<(), CliError> {
    let FuseData::Scenario(d) = &req.data else {
        return Err(CliError::bad("--runs applies to scenarios"));
    };
    let runs = args.runs.unwrap_or(1);
    let mc = FuseMcOptions {
        runs,
        seed: args.seed.unwrap_or(d.scenario.imu.seed),
        block: args.block,
        draw_scale_factors: args.draw_scale_factors,
    };
    let shard = match &args.shard {
        None => Shard::ALL,
        Some(s) => Shard::parse(s).map_err(|e| CliError::bad(format!("--shard: {e}")))?,
    };
    if let Some(t) = args.threads {
        if !(1..=1024).contains(&t) {
            return Err(CliError::bad(format!("--threads {t}: expected 1 … 1024")));
        }
    }
    let name = &d.scenario.name;
    let out = args.out.clone().unwrap_or_else(|| match args.shard {
        None => crate::output::default_dir("fuse-mc-", name),
        Some(_) => crate::output::default_dir("fuse-mc-", &format!("{name}-shard{}", shard.index)),
    });
    crate::output::claim(&out)?;
    let blocks = shard_blocks(shard, runs, mc.block);
    let total: u64 = blocks
        .map(|b| {
            let r = block_runs(b, runs, mc.block);
            r.end - r.start
        })
        .sum();
    let bar = Mutex::new((Progress::new(total, "runs", args.quiet), 0_u64));
    let on_run = || {
        if let Ok(mut g) = bar.lock() {
            g.1 += 1;
            let done = g.1;
            g.0.set(done);
        }
    };
    let cancelled = crate::progress::interrupted;
    let compute = || run_shard(req, &mc, shard, &on_run, &cancelled);
    let result = match args.threads {
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .map_err(|e| CliError::Other(e.to_string()))?
            .install(compute),
        None => compute(),
    };
    if let Ok(g) = bar.lock() {
        g.0.finish();
    }
    finish(args, &out, &result.map_err(mc_err)?)
}

/// Merge shard states (`--merge DIR...`).
pub fn merge(args: &Args) -> Result<(), CliError> {
    let Some(out) = args.out.clone() else {
        return Err(CliError::bad("--merge needs --out DIR"));
    };
    let states = args
        .merge
        .iter()
        .map(|p| read_state(p))
        .collect::<Result<Vec<_>, _>>()?;
    let merged = FuseMcState::merge(&states).map_err(mc_err)?;
    let missing = merged.missing_blocks();
    if !missing.is_empty() {
        let msg = format!(
            "{} of {} blocks missing (first missing block {})",
            missing.len(),
            block_count(merged.job.runs, merged.job.block),
            missing[0]
        );
        if !args.allow_partial {
            return Err(CliError::bad(format!(
                "{msg}: give every shard, or --allow-partial"
            )));
        }
        if !args.quiet {
            eprintln!("sdins: warning: {msg}");
        }
    }
    crate::output::claim(&out)?;
    finish(args, &out, &merged)
}

fn read_state(p: &Path) -> Result<FuseMcState, CliError> {
    let file = if p.is_dir() {
        p.join("fuse_mc_state.json")
    } else {
        p.to_path_buf()
    };
    let text = std::fs::read_to_string(&file).map_err(|source| CliError::Io {
        path: file.clone(),
        source,
    })?;
    let st: FuseMcState = serde_json::from_str(&text).map_err(|e| {
        CliError::bad(format!(
            "{}: not a fuse Monte Carlo state: {e}",
            file.display()
        ))
    })?;
    st.validate()
        .map_err(|e| CliError::bad(format!("{}: {e}", file.display())))?;
    Ok(st)
}

fn finish(args: &Args, out: &Path, state: &FuseMcState) -> Result<(), CliError> {
    let stats = state.statistics();
    let json = serde_json::to_string(state).map_err(|e| CliError::Other(e.to_string()))?;
    write_string(&out.join("fuse_mc_state.json"), &json)?;
    write_string(&out.join("fuse_mc_stats.csv"), &stats.to_csv())?;
    let mut f = toml::Table::new();
    f.insert("scenario".into(), state.job.scenario.clone().into());
    f.insert("runs".into(), (state.job.runs as i64).into());
    f.insert("seed".into(), (state.job.seed as i64).into());
    f.insert("block".into(), (state.job.block as i64).into());
    f.insert("fingerprint".into(), state.job.fingerprint.clone().into());
    crate::report::write_run_toml(out, f)?;
    let verdicts: Vec<_> = stats
        .columns
        .iter()
        .filter_map(|c| stats.consistency(&c.name, AFTER_S, 1))
        .filter(|c| c.epochs > 0)
        .collect();
    if args.json {
        let v = serde_json::json!({
            "scenario": state.job.scenario,
            "runs": stats.runs,
            "complete": stats.complete,
            "epochs": stats.times_s.len(),
            "consistency_after_s": AFTER_S,
            "consistency": verdicts,
            "out": out.display().to_string(),
        });
        outln!("{v:#}");
    } else {
        outln!(
            "sdins fuse {}: {} runs ({}), {} epochs; wrote {}",
            state.job.scenario,
            stats.runs,
            if stats.complete {
                "complete"
            } else {
                "partial"
            },
            stats.times_s.len(),
            out.display()
        );
        for c in &verdicts {
            outln!("  {c}");
        }
    }
    Ok(())
}
