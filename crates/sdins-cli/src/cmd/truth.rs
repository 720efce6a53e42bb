//! `sdins truth` (placeholder).

use crate::error::CliError;

/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Run the command.
pub fn run(_args: Args) -> Result<(), CliError> {
    Err(CliError::Other("truth: not implemented yet".into()))
}
