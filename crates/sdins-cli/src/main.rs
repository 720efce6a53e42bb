//! `sdins`: strapdown inertial navigation simulator and toolkit.
//!
//! Every command prints `--help` with an example; bad input exits with code 2 and a
//! one-line message naming the file, line and field.

// doc comments of the clap arguments are the --help text: units in [brackets] stay plain
#![allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]

// first: its macros (outln!, out!) are in scope for the modules below
#[macro_use]
mod stdout;
mod args;
mod cmd;
mod csv_out;
#[allow(dead_code)]
mod error;
mod output;
mod plot;
mod progress;
mod provenance;
mod report;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// sdins: exact strapdown inertial navigation simulation, algorithms and analysis.
#[derive(Parser, Debug)]
#[command(
    name = "sdins",
    version,
    about = "sdins: exact strapdown inertial navigation simulation, algorithms and analysis",
    long_about = None
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run the built-in showcase (the papers' comparisons) and print the tables.
    Demo(cmd::demo::Args),
    /// List the built-in scenarios, or print one as a scenario file.
    Scenarios(cmd::scenarios::Args),
    /// Write the exact truth trajectory and IMU increments of a scenario.
    Truth(cmd::truth::Args),
    /// Run one navigation algorithm over a recorded IMU file.
    Nav(cmd::nav::Args),
    /// Truth → IMU → navigation → errors for one or more algorithms side by side.
    Run(cmd::run::Args),
    /// Allan deviation of an IMU file with noise-parameter fits.
    Allan(cmd::allan::Args),
    /// Analytic INS error propagation: closed form, linear model, Schuler share.
    Errors(cmd::errors::Args),
    /// Initial alignment: coarse 1-/2-step, Kalman fine, multi-heading; observability.
    Align(cmd::align::Args),
    /// Turntable calibration: bias, scale factor and misalignment least squares with 1σ.
    Calibrate(cmd::calibrate::Args),
    /// Monte Carlo: N seeded runs with the scenario's IMU errors, per-epoch statistics.
    Montecarlo(cmd::montecarlo::Args),
    /// INS/GNSS Kalman filter on a scenario: errors with ±3σ, innovations, bias estimates.
    Fuse(Box<cmd::fuse::Args>),
    /// Merge Monte Carlo shard states exactly into the statistics of the whole job.
    Merge(cmd::merge::Args),
    /// GNSS single-point positioning and Doppler velocity from RINEX observation and navigation files.
    Spp(cmd::spp::Args),
    /// Raw GNSS simulation: a scenario's [raw_gnss] measurements as RINEX 3.04 observation and navigation files.
    GnssSim(cmd::gnss_sim::Args),
}

fn main() -> ExitCode {
    args::warn_deprecated(&std::env::args_os().collect::<Vec<_>>());
    let cli = Cli::parse();
    progress::install_signal_handlers();
    // SIGPIPE stays ignored (Rust's default): a closed stdout is an EPIPE error of the
    // checked writer (stdout.rs), which unwinds here; so does a panic. Either way the
    // staging folders go and the output folder keeps its previous contents.
    let result =
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| dispatch(cli.command))) {
            Ok(r) => r,
            Err(payload) => {
                output::abort_all();
                return ExitCode::from(stdout::exit_code_of(payload.as_ref()).unwrap_or(101));
            }
        };
    // a run's outputs all or none: swap the staged files in only if the command succeeded
    let result = output::finish(result);
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sdins: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

/// Run one command.
fn dispatch(command: Command) -> Result<(), error::CliError> {
    match command {
        Command::Demo(a) => cmd::demo::run(a),
        Command::Scenarios(a) => cmd::scenarios::run(a),
        Command::Truth(a) => cmd::truth::run(a),
        Command::Run(a) => cmd::run::run(a),
        Command::Nav(a) => cmd::nav::run(a),
        Command::Allan(a) => cmd::allan::run(a),
        Command::Errors(a) => cmd::errors::run(a),
        Command::Align(a) => cmd::align::run(a),
        Command::Calibrate(a) => cmd::calibrate::run(a),
        Command::Montecarlo(a) => cmd::montecarlo::run(a),
        Command::Merge(a) => cmd::merge::run(a),
        Command::Fuse(a) => cmd::fuse::run(*a),
        Command::Spp(a) => cmd::spp::run(a),
        Command::GnssSim(a) => cmd::gnss_sim::run(a),
    }
}
