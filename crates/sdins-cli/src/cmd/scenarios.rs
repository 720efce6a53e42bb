//! `sdins scenarios`: list the built-in scenarios or print one as a file to start from.

use crate::error::CliError;
use sdins_sim::scenario::{builtin, BUILTINS};

/// Arguments of `sdins scenarios`.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  sdins scenarios\n  sdins scenarios mach1-east > my.toml")]
pub struct Args {
    /// print this built-in scenario as a TOML file
    pub name: Option<String>,
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    match args.name {
        None => {
            println!("built-in scenarios (print one with `sdins scenarios NAME`):");
            for b in BUILTINS {
                println!("  {:<12} {}", b.name, b.summary);
            }
            Ok(())
        }
        Some(n) => match builtin(&n) {
            Some(b) => {
                print!("{}", b.toml);
                Ok(())
            }
            None => Err(CliError::bad(format!(
                "unknown scenario `{n}` (built-ins: {})",
                BUILTINS
                    .iter()
                    .map(|b| b.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ))),
        },
    }
}
