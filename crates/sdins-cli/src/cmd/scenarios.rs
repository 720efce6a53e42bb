//! `sdins scenarios`: list the built-in scenarios, print one as a file to start from, or
//! import a gnss-ins-sim motion-definition file (`sdins scenarios import FILE`).

use crate::error::CliError;
use sdins_sim::scenario::{builtin, BUILTINS};

/// Arguments of `sdins scenarios`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  sdins scenarios\n  sdins scenarios mach1-east > my.toml\n  sdins scenarios import motion_def-3d.csv --mode 1.0,0.5,2.0 > my.toml"
)]
pub struct Args {
    /// print this built-in scenario as a TOML file, or `import` to translate FILE
    pub name: Option<String>,
    /// with `import`: a gnss-ins-sim motion-definition CSV
    /// (docs/scenarios.md §"Importing gnss-ins-sim motion files")
    pub file: Option<std::path::PathBuf>,
    /// with `import`: gnss-ins-sim `mode` = max acceleration [m/s²], max angular
    /// acceleration [deg/s²], max angular rate [deg/s]
    #[arg(long, value_delimiter = ',', default_values_t = [1.0, 0.5, 2.0])]
    pub mode: Vec<f64>,
    /// with `import`: IMU rate of the scenario [Hz] (command durations must be whole samples)
    #[arg(long, default_value_t = 100.0)]
    pub rate_hz: f64,
}

fn import(args: &Args) -> Result<(), CliError> {
    use sdins_sim::io::gnss_ins_sim::{import_file, limits_from_mode, ImportOptions};
    let Some(file) = &args.file else {
        return Err(CliError::bad(
            "scenarios import: give the motion-definition file: sdins scenarios import FILE",
        ));
    };
    let mode: [f64; 3] = match args.mode.as_slice() {
        [a, b, c] => [*a, *b, *c],
        _ => return Err(CliError::bad("--mode: expected three numbers a,b,c")),
    };
    let limits = limits_from_mode(mode).map_err(|e| CliError::bad(format!("--{e}")))?;
    if !(args.rate_hz.is_finite() && args.rate_hz > 0.0 && args.rate_hz <= 100_000.0) {
        return Err(CliError::bad(format!(
            "--rate-hz: {} must be a finite number in (0, 100000]",
            args.rate_hz
        )));
    }
    let opts = ImportOptions {
        limits,
        rate_hz: args.rate_hz,
    };
    let toml = import_file(file, &opts).map_err(|e| CliError::bad(e.to_string()))?;
    // validate the result as every scenario is (envelope check included)
    sdins_sim::scenario::Scenario::from_toml(&toml, &file.display().to_string())
        .map_err(|e| CliError::bad(e.to_string()))?;
    out!("{toml}");
    Ok(())
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.name.as_deref() == Some("import") {
        return import(&args);
    }
    if args.file.is_some() {
        return Err(CliError::bad(
            "scenarios: a second argument is only for `sdins scenarios import FILE`",
        ));
    }
    match args.name {
        None => {
            outln!("built-in scenarios (print one with `sdins scenarios NAME`):");
            for b in BUILTINS {
                outln!("  {:<12} {}", b.name, b.summary);
            }
            Ok(())
        }
        Some(n) => match builtin(&n) {
            Some(b) => {
                out!("{}", b.toml);
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
