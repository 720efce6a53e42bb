//! `sdins merge`: combine the shard states written by `sdins montecarlo --shard i/n` into
//! the statistics of the whole job, bit-identical to a single unsharded run (the block
//! results are kept per block and folded in block order, see
//! `sdins_sim::analysis::montecarlo::plan`).

use super::montecarlo::{mc_err, print_summary, summary_json, write_outputs};
use crate::error::CliError;
use sdins_sim::analysis::montecarlo::McState;
use std::path::{Path, PathBuf};

/// Arguments of `sdins merge`.
#[derive(clap::Args, Debug, Clone)]
#[command(
    after_help = "Example:\n  sdins merge mc/shard0 mc/shard1 mc/shard2 mc/shard3 --out mc/all\n\
    Each input is a folder holding mc_state.json (or the state file itself)."
)]
pub struct Args {
    /// shard output folders (or mc_state.json files)
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// output folder for the merged mc_stats.csv and mc_state.json
    #[arg(long)]
    pub out: PathBuf,
    /// accept an incomplete set of shards (statistics of the runs present)
    #[arg(long)]
    pub allow_partial: bool,
    /// print a JSON summary on stdout
    #[arg(long)]
    pub json: bool,
    /// no messages on stderr
    #[arg(long)]
    pub quiet: bool,
}

fn read_state(p: &Path) -> Result<McState, CliError> {
    let file = if p.is_dir() {
        p.join("mc_state.json")
    } else {
        p.to_path_buf()
    };
    let text = std::fs::read_to_string(&file).map_err(|source| CliError::Io {
        path: file.clone(),
        source,
    })?;
    let st: McState = serde_json::from_str(&text)
        .map_err(|e| CliError::bad(format!("{}: not a Monte Carlo state: {e}", file.display())))?;
    st.validate()
        .map_err(|e| CliError::bad(format!("{}: {e}", file.display())))?;
    Ok(st)
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let states = args
        .inputs
        .iter()
        .map(|p| read_state(p))
        .collect::<Result<Vec<_>, _>>()?;
    let merged = McState::merge(&states).map_err(mc_err)?;
    let missing = merged.missing_blocks();
    if !missing.is_empty() {
        let msg = format!(
            "{} of {} blocks missing (first missing block {}; runs {}..): give every shard",
            missing.len(),
            sdins_sim::analysis::montecarlo::plan::block_count(merged.job.runs, merged.job.block),
            missing[0],
            missing[0] * merged.job.block
        );
        if !args.allow_partial {
            return Err(CliError::bad(format!("{msg}, or --allow-partial")));
        }
        if !args.quiet {
            eprintln!("sdins: warning: {msg}");
        }
    }
    crate::output::claim(&args.out)?;
    let stats = merged.statistics();
    write_outputs(&args.out, &merged, &stats)?;
    if args.json {
        let v = summary_json(&merged, &stats, &args.out);
        outln!(
            "{}",
            serde_json::to_string_pretty(&v).map_err(|e| CliError::Other(e.to_string()))?
        );
    } else {
        print_summary(&merged, &stats, &args.out);
    }
    Ok(())
}
