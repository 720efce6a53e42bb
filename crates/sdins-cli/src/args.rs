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

/// The column maps of one's own files (docs/own-data.md): `--imu-columns`,
/// `--gnss-columns`, an input profile and the settings a file cannot carry.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct ColumnsArgs {
    /// read the IMU file through a column map `quantity_unit=COLUMN,…` with settings
    /// (`axes=`, `mount_deg=`, `time=`, `delim=`, `header=`, `rates=`; docs/own-data.md);
    /// replaces --imu-format
    #[arg(long, value_name = "MAP")]
    pub imu_columns: Option<String>,
    /// read the GNSS file through a column map (`t_s=…,lat_deg=…,lon_deg=…,h_m=…` or
    /// `alt_msl_m=…`, optional σ and velocity columns; docs/own-data.md)
    #[arg(long, value_name = "MAP")]
    pub gnss_columns: Option<String>,
    /// input profile: a TOML file with `[imu]` and `[gnss]` maps (docs/own-data.md)
    #[arg(long, value_name = "FILE")]
    pub profile: Option<PathBuf>,
    /// GPS week of `time=gps-sow` files without a week column
    #[arg(long, value_name = "WEEK")]
    pub gps_week: Option<u32>,
    /// σ of fixes whose file has no σ columns: N,E,D[,vN,vE,vD] [m, m/s]
    #[arg(long, value_name = "N,E,D[,vN,vE,vD]")]
    pub gnss_sigma: Option<String>,
    /// geoid undulation N [m] for a GNSS map with `alt_msl_m` (h = H + N)
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub undulation_m: Option<f64>,
}

impl ColumnsArgs {
    /// The IMU and GNSS maps from the options and the profile (a map given both ways is
    /// refused); every error names its option or `profile:line`.
    pub fn resolve(
        &self,
    ) -> Result<
        (
            Option<sdins_sim::io::imu_columns::ImuColumns>,
            Option<sdins_sim::io::gnss_columns::GnssColumns>,
        ),
        crate::error::CliError,
    > {
        use crate::error::CliError;
        use sdins_sim::io::columns::MapOrigin;
        use sdins_sim::io::gnss_columns::{GnssColumns, GnssSigma};
        use sdins_sim::io::imu_columns::ImuColumns;
        let bad = |e: sdins_sim::io::columns::ColumnsError| CliError::bad(e.to_string());
        let (mut imu, mut gnss) = match &self.profile {
            Some(p) => {
                let pr = sdins_sim::io::profile::Profile::read(p).map_err(bad)?;
                (pr.imu, pr.gnss)
            }
            None => (None, None),
        };
        if let Some(text) = &self.imu_columns {
            if imu.is_some() {
                return Err(CliError::bad(
                    "--imu-columns: the profile has an [imu] map too: give one",
                ));
            }
            imu = Some(
                ImuColumns::parse(text, MapOrigin::Option("--imu-columns".into())).map_err(bad)?,
            );
        }
        if let Some(text) = &self.gnss_columns {
            if gnss.is_some() {
                return Err(CliError::bad(
                    "--gnss-columns: the profile has a [gnss] map too: give one",
                ));
            }
            gnss = Some(
                GnssColumns::parse(text, MapOrigin::Option("--gnss-columns".into()))
                    .map_err(bad)?,
            );
        }
        if let Some(w) = self.gps_week {
            if imu.is_none() && gnss.is_none() {
                return Err(CliError::bad(
                    "--gps-week applies to files read through a column map (--imu-columns, --gnss-columns or --profile)",
                ));
            }
            if let Some(c) = imu.as_mut() {
                c.gps_week = Some(w);
            }
            if let Some(c) = gnss.as_mut() {
                c.gps_week = Some(w);
            }
        }
        let need_gnss = |opt: &str| {
            CliError::bad(format!(
                "{opt} applies to a GNSS file read through a column map (--gnss-columns or a profile's [gnss])"
            ))
        };
        if let Some(s) = &self.gnss_sigma {
            let c = gnss.as_mut().ok_or_else(|| need_gnss("--gnss-sigma"))?;
            c.sigma =
                Some(GnssSigma::parse(s).map_err(|e| CliError::bad(format!("--gnss-sigma: {e}")))?);
        }
        if let Some(n) = self.undulation_m {
            let c = gnss.as_mut().ok_or_else(|| need_gnss("--undulation-m"))?;
            c.undulation_m = Some(n);
        }
        Ok((imu, gnss))
    }
}
