//! `sdins allan`: overlapping Allan deviation with noise fits (issue 4; to be filled).

use crate::error::CliError;
use std::path::PathBuf;

/// Arguments of `sdins allan`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// IMU file (sdins CSV, PSINS .imu, ...)
    #[arg(long)]
    pub imu: PathBuf,
    /// print a JSON summary on stdout
    #[arg(long)]
    pub json: bool,
}

/// Run the command.
pub fn run(_args: Args) -> Result<(), CliError> {
    Err(CliError::Other("allan: not implemented yet".into()))
}
