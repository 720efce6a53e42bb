//! Options shared by several commands, parsed in one place: the IMU file format, the
//! sensor grade, the earth model and the output folder. A command flattens the ones it
//! takes (`#[command(flatten)]`), so a spelling, a default or a help text changes for
//! every command at once.

use sdins_sim::io::imu_file::ImuFormat;
use sdins_sim::sensors::imu_error::presets::GRADE_NAMES;
use std::path::PathBuf;

/// `--imu-format` of every command that reads an IMU file.
#[derive(clap::Args, Debug, Clone)]
pub struct ImuFormatArg {
    /// IMU file format: auto (told apart by the content), sdins, psins, psins-csv, kfgins,
    /// navego (docs/imu-files.md); `--format` is a deprecated alias
    #[arg(long = "imu-format", alias = "format", value_name = "FORMAT", default_value = "auto", value_parser = parse_imu_format)]
    pub imu_format: ImuFormat,
}

fn parse_imu_format(s: &str) -> Result<ImuFormat, String> {
    s.parse()
}

/// `--grade`: on scenario commands the simulated IMU's errors (and, for `fuse`, the
/// filter's model unless a sensor-model file is given); on recorded data the filter's
/// model only.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct GradeArg {
    /// IMU grade preset (docs/imu-errors.md)
    #[arg(long, value_name = "GRADE", value_parser = grade_parser())]
    pub grade: Option<String>,
}

/// The preset names of the grade table, with the aliases `navigation` (aviation) and
/// `automotive` (consumer); `--help` lists exactly the table's names.
fn grade_parser() -> clap::builder::PossibleValuesParser {
    use clap::builder::PossibleValue;
    clap::builder::PossibleValuesParser::new(GRADE_NAMES.map(|n| match n {
        "aviation" => PossibleValue::new(n).alias("navigation"),
        "consumer" => PossibleValue::new(n).alias("automotive"),
        _ => PossibleValue::new(n),
    }))
}

/// `--out DIR`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct OutArg {
    /// output folder (default: ./sdins-out/<command>-<name>); sdins writes only inside it
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

/// Warn on stderr when a deprecated spelling is used (`--format` for `--imu-format`).
pub fn warn_deprecated(args: &[std::ffi::OsString]) {
    let mut seen_end = false;
    for a in args.iter().skip(1) {
        let s = a.to_string_lossy();
        if s == "--" {
            seen_end = true;
        }
        if !seen_end && (s == "--format" || s.starts_with("--format=")) {
            eprintln!("sdins: warning: --format is deprecated; use --imu-format");
            return;
        }
    }
}
