//! `sdins montecarlo`: N seeded realisations of a scenario with its IMU error model,
//! per-epoch error statistics, and a lossless shard state for `sdins merge`.
//!
//! Writes into `--out DIR`:
//! * `mc_stats.csv` — `t_s` and, per channel (position/velocity/attitude error N, E, D),
//!   mean, σ, p05, p50, p95 (see `sdins_sim::analysis::montecarlo::stats`);
//! * `mc_state.json` — the raw accumulator state (every f64 as its IEEE bit pattern), the
//!   input of `sdins merge`.
//!
//! With `--shard i/n` only the blocks of shard i are computed (see `docs/montecarlo.md`);
//! `mc_stats.csv` then covers that shard's runs only.

use crate::args::GradeArg;
use crate::error::CliError;
use crate::output::write_string;
use crate::progress::Progress;
use sdins_sim::analysis::montecarlo;
use sdins_sim::analysis::montecarlo::{McError, McRequest, McState, McStats, Shard};
use sdins_sim::scenario::Scenario;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Arguments of `sdins montecarlo`.
#[derive(clap::Args, Debug, Clone)]
#[command(
    after_help = "Examples:\n  sdins montecarlo mach1-east --grade aviation --runs 1000 --seed 1 --out mc\n  \
    sdins montecarlo my.toml --runs 1000 --seed 1 --shard 0/4 --out mc/shard0 --quiet\n  \
    sdins merge mc/shard0 mc/shard1 mc/shard2 mc/shard3 --out mc/all"
)]
pub struct Args {
    /// built-in scenario name or scenario file (its [imu] grade/errors are the error model)
    pub scenario: String,
    /// number of runs N (all shards must use the same N)
    #[arg(long)]
    pub runs: u64,
    /// seed of the sensor-error streams (default: the scenario's [imu] seed, itself 1 by
    /// default; every shard of one job must use the same seed)
    #[arg(long)]
    pub seed: Option<u64>,
    /// algorithm: savage, songlee, songlee-complete, dualquat
    #[arg(long, default_value = "songlee-complete")]
    pub algo: String,
    /// IMU samples per navigation update (default: the scenario's)
    #[arg(long)]
    pub samples: Option<usize>,
    /// IMU grade preset replacing the scenario's error model
    #[command(flatten)]
    pub grade: GradeArg,
    /// compute shard i of n (0-based, e.g. 2/8); shards are whole blocks of runs
    #[arg(long)]
    pub shard: Option<String>,
    /// output epoch spacing [s]
    #[arg(long, default_value_t = montecarlo::DEFAULT_MC_EVERY_S)]
    pub every_s: f64,
    /// stop after this time [s] (default: whole scenario)
    #[arg(long)]
    pub until_s: Option<f64>,
    /// vertical channel: hold (default for Monte Carlo) or free
    #[arg(long, default_value = "hold")]
    pub vertical: String,
    /// runs per block K (all shards must use the same K)
    #[arg(long, default_value_t = sdins_sim::analysis::montecarlo::DEFAULT_BLOCK)]
    pub block: u64,
    /// worker threads (default: all cores)
    #[arg(long)]
    pub threads: Option<usize>,
    /// output folder (default ./sdins-out/mc-<scenario>)
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// print a JSON summary on stdout
    #[arg(long)]
    pub json: bool,
    /// no progress bar
    #[arg(long)]
    pub quiet: bool,
}

/// Map a library error to the CLI's exit codes.
pub fn mc_err(e: McError) -> CliError {
    match e {
        McError::Interrupted => CliError::Interrupted,
        McError::Config(_)
        | McError::Model(_)
        | McError::Mismatch(_)
        | McError::DuplicateBlock(_)
        | McError::BadState(_) => CliError::bad(e.to_string()),
        other => CliError::Other(other.to_string()),
    }
}

/// Write `mc_stats.csv`, `mc_state.json`, the envelope plot (`envelopes.png`), the
/// report (`report.html`) and `run.toml` into `dir`.
pub fn write_outputs(dir: &Path, state: &McState, stats: &McStats) -> Result<(), CliError> {
    let json = serde_json::to_string(state).map_err(|e| CliError::Other(e.to_string()))?;
    write_string(&dir.join("mc_state.json"), &json)?;
    write_string(&dir.join("mc_stats.csv"), &stats.to_csv())?;
    write_report(dir, state, stats)
}

/// Envelopes of every channel the statistics hold: position, velocity and attitude
/// error (rows) in N, E, D (columns), each with the mean over the runs (line), mean ± σ
/// (shaded band) and the 5th and 95th percentiles (dashed). A channel that is exactly
/// zero in every run says so on its panel: with the vertical channel held (`--vertical
/// hold`, the Monte Carlo default) the down position and velocity errors are zero by
/// construction. Attitude errors in μrad (the unit of free-inertial attitude errors in
/// every report, docs/user-guide.md).
fn envelope_figure(stats: &McStats, vertical_hold: bool) -> crate::plot::Figure {
    use crate::plot::{Band, Figure, Panel, Series};
    let groups = [
        ("position error", "δp", "m", 0, 1.0),
        ("velocity error", "δv", "m/s", 3, 1.0),
        ("attitude error", "ε", "μrad", 6, 1e6),
    ];
    let mut panels = Vec::new();
    for (what, sym, unit, first, scale) in groups {
        for (k, axis) in ["N", "E", "D"].iter().enumerate() {
            let c = first + k;
            let rows = || stats.times_s.iter().zip(&stats.cells);
            let pick = |f: fn(&montecarlo::ChannelStats) -> f64| -> Vec<(f64, f64)> {
                rows().map(|(t, row)| (*t, f(&row[c]) * scale)).collect()
            };
            let zero = rows().all(|(_, row)| {
                let x = &row[c];
                [x.mean, x.sigma, x.p05, x.p50, x.p95]
                    .iter()
                    .all(|v| *v == 0.0)
            });
            let note = match (zero, vertical_hold && k == 2 && first < 6) {
                (false, _) => String::new(),
                (true, true) => "≡ 0: vertical channel held (--vertical hold)".to_string(),
                (true, false) => "≡ 0 in every run".to_string(),
            };
            panels.push(Panel {
                title: format!("{what}, {axis}"),
                x_label: "time [s]".into(),
                y_label: format!("{sym}_{axis} [{unit}]"),
                min_y_span: if zero { 1.0 } else { 0.0 },
                series: vec![
                    Series::line("mean", pick(|x| x.mean)),
                    Series::dashed("p05, p95", pick(|x| x.p05)).colored_as("mean"),
                    Series::dashed("p05, p95", pick(|x| x.p95)).colored_as("mean"),
                ],
                bands: vec![Band {
                    name: "mean ± σ".into(),
                    color_of: "mean".into(),
                    points: rows()
                        .map(|(t, row)| {
                            let x = &row[c];
                            (*t, (x.mean - x.sigma) * scale, (x.mean + x.sigma) * scale)
                        })
                        .collect(),
                    outline: false,
                }],
                note,
                ..Panel::default()
            });
        }
    }
    Figure {
        panels,
        cols: 3,
        size: (1500, 1150),
    }
}

fn write_report(dir: &Path, state: &McState, stats: &McStats) -> Result<(), CliError> {
    let job = &state.job;
    let mut r = crate::report::Report::new(&format!("sdins montecarlo: {}", job.scenario));
    r.para(&format!(
        "{} runs ({} included{}), algorithm {} with {} samples per update, seed {}, vertical channel {}.",
        job.runs,
        stats.runs,
        if stats.complete { "" } else { ", partial" },
        job.algo,
        job.samples,
        job.seed,
        if job.vertical_hold { "held" } else { "free" }
    ));
    if let (Some(t), Some(row)) = (stats.times_s.last(), stats.cells.last()) {
        let rows: Vec<Vec<String>> = sdins_sim::analysis::montecarlo::CHANNELS
            .iter()
            .zip(row.iter())
            .map(|(n, c)| {
                vec![
                    n.to_string(),
                    format!("{:.4e}", c.mean),
                    format!("{:.4e}", c.sigma),
                    format!("{:.4e}", c.p05),
                    format!("{:.4e}", c.p50),
                    format!("{:.4e}", c.p95),
                ]
            })
            .collect();
        r.para(&format!("Statistics at the last epoch, t = {t} s:"));
        r.table(&["channel", "mean", "σ", "p05", "p50", "p95"], &rows);
    }
    let fig = envelope_figure(stats, job.vertical_hold);
    r.figure_file(&fig, dir, "envelopes", "Error envelopes over the runs, position, velocity and attitude in N, E, D: mean (line), mean ± σ (band), 5th and 95th percentiles (dashed); all statistics in the table and mc_stats.csv.")?;
    r.write(&dir.join("report.html"))?;
    let mut t = toml::Table::new();
    t.insert("scenario".into(), job.scenario.clone().into());
    t.insert(
        "scenario_fingerprint".into(),
        job.fingerprint.clone().into(),
    );
    t.insert("algo".into(), job.algo.clone().into());
    // u64 values as strings: TOML integers are i64
    t.insert("runs".into(), job.runs.to_string().into());
    t.insert("seed".into(), job.seed.to_string().into());
    crate::report::write_run_toml(dir, t)
}

/// Summary printed after a run or merge.
pub fn summary_json(state: &McState, stats: &McStats, out: &Path) -> serde_json::Value {
    let last = stats.cells.last();
    serde_json::json!({
        "job": state.job,
        "runs_included": stats.runs,
        "complete": stats.complete,
        "missing_blocks": state.missing_blocks(),
        "epochs": stats.times_s.len(),
        "final_t_s": stats.times_s.last(),
        "final": last.map(|row| {
            sdins_sim::analysis::montecarlo::CHANNELS
                .iter()
                .zip(row.iter())
                .map(|(c, s)| (c.to_string(), serde_json::json!(s)))
                .collect::<serde_json::Map<_, _>>()
        }),
        "out": out.display().to_string(),
    })
}

/// Print a short table of the final epoch.
pub fn print_summary(state: &McState, stats: &McStats, out: &Path) {
    outln!(
        "Monte Carlo {} / {}: {} of {} runs (seed {}, block {}), {} epochs{}",
        state.job.scenario,
        state.job.algo,
        stats.runs,
        state.job.runs,
        state.job.seed,
        state.job.block,
        stats.times_s.len(),
        if stats.complete {
            ""
        } else {
            " — INCOMPLETE (missing blocks)"
        }
    );
    if let (Some(t), Some(row)) = (stats.times_s.last(), stats.cells.last()) {
        outln!("final epoch t = {t} s");
        outln!(
            "{:>10} {:>12} {:>12} {:>12} {:>12} {:>12}",
            "channel",
            "mean",
            "sigma",
            "p05",
            "p50",
            "p95"
        );
        for (c, s) in sdins_sim::analysis::montecarlo::CHANNELS
            .iter()
            .zip(row.iter())
        {
            outln!(
                "{c:>10} {:>12.4e} {:>12.4e} {:>12.4e} {:>12.4e} {:>12.4e}",
                s.mean,
                s.sigma,
                s.p05,
                s.p50,
                s.p95
            );
        }
    }
    outln!("files in {}", out.display());
}

/// The job as the library takes it.
fn request(args: &Args) -> Result<McRequest, CliError> {
    let shard = match &args.shard {
        None => None,
        Some(s) => Some(Shard::parse(s).map_err(|e| CliError::bad(format!("--shard: {e}")))?),
    };
    Ok(McRequest {
        choice: montecarlo::McChoice {
            runs: args.runs,
            seed: args.seed,
            algo: Some(args.algo.clone()),
            samples: args.samples,
            every_s: Some(args.every_s),
            until_s: args.until_s,
            vertical: Some(args.vertical.clone()),
            block: Some(args.block),
        },
        grade: args.grade.grade.clone(),
        shard,
        threads: args.threads,
    })
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let scn = Scenario::load(&args.scenario)?;
    let plan =
        montecarlo::plan(scn, &request(&args)?).map_err(|e| CliError::BadInput(e.to_string()))?;
    let name = &plan.scenario.name;
    if plan.ideal_sensors() && !args.quiet {
        eprintln!(
            "sdins: warning: scenario {name} has ideal sensors (no [imu] grade/errors and no --grade): every run is the same"
        );
    }
    let out = args.out.clone().unwrap_or_else(|| match args.shard {
        None => crate::output::default_dir("mc-", name),
        Some(_) => crate::output::default_dir("mc-", &format!("{name}-shard{}", plan.shard.index)),
    });
    crate::output::check_size("mc_stats.csv", plan.epochs as f64, 400.0, "raise --every-s")?;
    crate::output::claim(&out)?;
    let bar = Mutex::new((Progress::new(plan.runs, "runs", args.quiet), 0_u64));
    let on_run = || {
        if let Ok(mut g) = bar.lock() {
            g.1 += 1;
            let done = g.1;
            g.0.set(done);
        }
    };
    let result = plan.run(&on_run, &crate::progress::interrupted);
    if let Ok(g) = bar.lock() {
        g.0.finish();
    }
    let state = result.map_err(mc_err)?;
    let stats = state.statistics();
    write_outputs(&out, &state, &stats)?;
    if args.json {
        let v = summary_json(&state, &stats, &out);
        outln!(
            "{}",
            serde_json::to_string_pretty(&v).map_err(|e| CliError::Other(e.to_string()))?
        );
    } else {
        print_summary(&state, &stats, &out);
    }
    Ok(())
}
