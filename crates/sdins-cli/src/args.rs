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
    /// read the IMU file through a column map `quantity_unit=COLUMN,…` with settings
    /// (`axes=`, `mount_deg=`, `time=`, `delim=`, `header=`, `rates=`; docs/own-data.md);
    /// replaces --imu-format
    #[arg(long, value_name = "MAP")]
    pub imu_columns: Option<String>,
    /// input profile: a TOML file whose `[imu]` map reads the IMU file (docs/own-data.md)
    #[arg(long, value_name = "FILE")]
    pub profile: Option<PathBuf>,
}

impl ImuFormatArg {
    /// `--imu-format auto` and no map.
    #[cfg(test)]
    pub fn auto() -> Self {
        Self {
            imu_format: ImuFormat::Auto,
            imu_columns: None,
            profile: None,
        }
    }
    /// The IMU map of `--imu-columns` or the profile's `[imu]` (errors name the option or
    /// `profile:line`; exit 2).
    pub fn columns(
        &self,
    ) -> Result<Option<sdins_sim::io::imu_columns::ImuColumns>, crate::error::CliError> {
        let o = sdins_sim::fusion::files::ColumnOptions {
            imu_columns: self.imu_columns.clone(),
            profile: self.profile.clone(),
            ..Default::default()
        };
        let c = o
            .resolve(&flag_name)
            .map_err(|e| crate::error::CliError::bad(e.to_string()))?;
        if self.profile.is_some() && c.imu.is_none() {
            return Err(crate::error::CliError::bad(
                "--profile: the profile has no [imu] map",
            ));
        }
        Ok(c.imu)
    }
    /// Read the IMU file in the format or through the map; the map's summary goes to
    /// stderr and is returned for run.toml.
    pub fn read(
        &self,
        path: &std::path::Path,
    ) -> Result<
        (
            sdins_sim::io::imu_file::ImuData,
            Option<sdins_sim::io::imu_columns::InputReport>,
        ),
        crate::error::CliError,
    > {
        let cols = self.columns()?;
        let (d, rep) =
            sdins_sim::io::imu_columns::read_imu_any(path, self.imu_format, cols.as_ref())
                .map_err(crate::error::CliError::bad)?;
        if let Some(r) = &rep {
            eprintln!("{}", r.summary());
        }
        Ok((d, rep))
    }
}

/// `[inputs.imu]` of run.toml: what the IMU column map did (time base, clock, offsets).
pub fn inputs_toml(toml: &mut toml::Table, rep: Option<&sdins_sim::io::imu_columns::InputReport>) {
    if let Some(r) = rep {
        let mut t = toml::Table::new();
        t.insert(r.kind.to_string(), r.to_toml().into());
        toml.insert("inputs".into(), t.into());
    }
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
/// `--gnss-columns`, `--truth-columns`, an input profile and the settings a file cannot
/// carry.
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
    /// read the --truth file through a column map (time, position, attitude and velocity
    /// columns; `yaw=ned|enu|enu-east`; docs/own-data.md)
    #[arg(long, value_name = "MAP")]
    pub truth_columns: Option<String>,
    /// input profile: a TOML file with `[imu]`, `[gnss]` and `[reference]` maps
    /// (docs/own-data.md)
    #[arg(long, value_name = "FILE")]
    pub profile: Option<PathBuf>,
    /// GPS week of `time=gps-sow` files without a week column
    #[arg(long, value_name = "WEEK")]
    pub gps_week: Option<u32>,
    /// σ of fixes whose file has no σ columns: N,E,D[,vN,vE,vD] [m, m/s]
    #[arg(long, value_name = "N,E,D[,vN,vE,vD]")]
    pub gnss_sigma: Option<String>,
    /// geoid undulation N [m] for a map with `alt_msl_m` (h = H + N)
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub undulation_m: Option<f64>,
}

/// An option name as the command line spells it (`imu_columns` → `--imu-columns`).
pub fn flag_name(name: &str) -> String {
    format!("--{}", name.replace('_', "-"))
}

impl ColumnsArgs {
    /// The library's options.
    pub fn options(&self) -> sdins_sim::fusion::files::ColumnOptions {
        sdins_sim::fusion::files::ColumnOptions {
            imu_columns: self.imu_columns.clone(),
            gnss_columns: self.gnss_columns.clone(),
            truth_columns: self.truth_columns.clone(),
            profile: self.profile.clone(),
            gps_week: self.gps_week,
            gnss_sigma: self.gnss_sigma.clone(),
            undulation_m: self.undulation_m,
        }
    }
    /// The IMU, GNSS and reference maps from the options and the profile (a map given
    /// both ways is refused); every error names its option or `profile:line` (exit 2).
    pub fn resolve(
        &self,
    ) -> Result<sdins_sim::fusion::files::InputColumns, crate::error::CliError> {
        self.options()
            .resolve(&flag_name)
            .map_err(|e| crate::error::CliError::bad(e.to_string()))
    }
}
