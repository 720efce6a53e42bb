//! GNSS solution file readers: every format becomes a `Vec<GnssFix>` (geodetic WGS-84
//! antenna position, NED covariance, optional NED velocity) on the file's own time base,
//! then [`to_imu_time`] maps it to the IMU record's clock and [`clip_to_imu_span`] drops the
//! fixes outside the record. The formats, their headers and units are documented in
//! `docs/gnss-files.md`.
//!
//! | format | flag | time base |
//! |---|---|---|
//! | sdins GNSS CSV (`t_s,lat_deg,lon_deg,h_m,sigma_n_m,…`) | `sdins` | the file's seconds ([`TimeBase::FileSeconds`]) |
//! | NaveGo `gnss.csv` (`t_s,lat_rad,lon_rad,h_m,v_n_mps,v_e_mps,v_d_mps`), σ from `gnss_params.txt` | `navego` | the file's seconds |
//! | KF-GINS GNSS text (`t lat lon h σN σE σD`) | `kfgins` | GPS seconds of week |
//! | RTKLIB `.pos` | `rtklib` | GPS seconds since 1980-01-06 (UTC/JST converted) |
//!
//! Checks (each a located [`GnssFileError`], file:line:column and field): empty file,
//! header without data, wrong field count, a short last line without final newline
//! (truncated), non-numeric or non-finite fields, |latitude| > 90°, heights outside
//! [`H_RANGE_M`], σ below [`MIN_SIGMA_M`] (σ ≤ 0) or above [`MAX_SIGMA_M`], speeds beyond [`MAX_SPEED_MPS`], a
//! non-positive-definite covariance, time not strictly increasing. A UTF-8 byte-order mark
//! is accepted (and skipped).

mod gps_time;
mod kfgins;
mod navego;
mod rows;
mod rtklib;
mod sdins_csv;

pub use gps_time::{gps_minus_utc_s, gps_seconds_from_date, LEAP_SECONDS, SECONDS_PER_WEEK};
pub use navego::NAVEGO_GNSS_HEADER;
pub use sdins_csv::{SDINS_GNSS_HEADER, SDINS_GNSS_VEL_HEADER};

use crate::io::navego_params::{NavegoGnssParams, ParamsError};
use crate::sensors::gnss_fix::GnssFix;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Accepted ellipsoidal height range \[m\] (the truth-file and scenario range).
pub const H_RANGE_M: (f64, f64) = (-1000.0, 100_000.0);
/// Largest accepted position or velocity standard deviation \[m, m/s\].
pub const MAX_SIGMA_M: f64 = 1.0e6;
/// Smallest accepted position or velocity standard deviation \[m, m/s\] (1 µm: below any
/// receiver's claim, and σ² stays far from underflow).
pub const MIN_SIGMA_M: f64 = 1.0e-6;
/// Largest accepted velocity component \[m/s\].
pub const MAX_SPEED_MPS: f64 = 1.0e4;

/// GNSS file format selector.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum GnssFormat {
    /// detect from the content (refuses when more than one format fits)
    Auto,
    /// sdins GNSS CSV
    Sdins,
    /// NaveGo `gnss.csv` as converted (σ from `gnss_params.txt`)
    NaveGo,
    /// KF-GINS GNSS text
    KfGins,
    /// RTKLIB `.pos`
    Rtklib,
    /// any delimited text read through a column map (`crate::io::gnss_columns`); not a
    /// `--gnss-format` value: a column map selects it
    Columns,
}

impl GnssFormat {
    /// The flag names.
    pub const NAMES: [&'static str; 5] = ["auto", "sdins", "navego", "kfgins", "rtklib"];
    /// The flag name.
    pub fn name(self) -> &'static str {
        match self {
            GnssFormat::Auto => "auto",
            GnssFormat::Sdins => "sdins",
            GnssFormat::NaveGo => "navego",
            GnssFormat::KfGins => "kfgins",
            GnssFormat::Rtklib => "rtklib",
            GnssFormat::Columns => "columns",
        }
    }
}

impl fmt::Display for GnssFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for GnssFormat {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "auto" => Ok(GnssFormat::Auto),
            "sdins" => Ok(GnssFormat::Sdins),
            "navego" => Ok(GnssFormat::NaveGo),
            "kfgins" => Ok(GnssFormat::KfGins),
            "rtklib" => Ok(GnssFormat::Rtklib),
            _ => Err(format!(
                "unknown GNSS format `{s}` (expected one of {})",
                GnssFormat::NAMES.join(", ")
            )),
        }
    }
}

/// What the `t_s` of the fixes returned by a reader count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum TimeBase {
    /// the file's own seconds (sdins, NaveGo): assumed to be the IMU file's clock
    FileSeconds,
    /// GPS seconds of week (KF-GINS); a week rollover inside the file is unwrapped, so
    /// values continue past 604 800 s
    GpsSecondsOfWeek,
    /// GPS seconds since the GPS epoch 1980-01-06 00:00:00 GPST (RTKLIB)
    GpsSecondsSinceEpoch,
}

/// Reader options.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct GnssReadOptions {
    /// NaveGo σ and rate; when `None`, [`read_gnss_file`] loads `gnss_params.txt` from the
    /// data file's folder
    pub navego: Option<NavegoGnssParams>,
    /// RTKLIB: keep only fixes with quality flag `1 <= Q <= max` (1 fix, 2 float, 3 SBAS,
    /// 4 DGPS, 5 single, 6 PPP); `None` keeps all
    pub rtklib_max_q: Option<u8>,
    /// RTKLIB: geoid undulation N \[m\] used to turn geodetic (mean-sea-level) heights into
    /// ellipsoidal ones, h = H + N; without it such files are refused
    pub geoid_undulation_m: Option<f64>,
}

impl GnssReadOptions {
    /// Use these NaveGo parameters.
    pub fn with_navego(mut self, p: NavegoGnssParams) -> Self {
        self.navego = Some(p);
        self
    }
    /// RTKLIB quality filter (keep `1 <= Q <= max_q`).
    pub fn with_rtklib_max_q(mut self, max_q: u8) -> Self {
        self.rtklib_max_q = Some(max_q);
        self
    }
    /// Constant geoid undulation \[m\] for geodetic heights.
    pub fn with_geoid_undulation_m(mut self, n_m: f64) -> Self {
        self.geoid_undulation_m = Some(n_m);
        self
    }
}

/// What a reader did besides returning fixes.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct GnssReadReport {
    /// data rows read
    pub rows: usize,
    /// rows dropped by the RTKLIB quality filter
    pub skipped_quality: usize,
    /// how auto-detection decided (`None` when the format was given)
    pub detection: Option<String>,
    /// time system of the file as written (RTKLIB `GPST`, `UTC`, `JST`; others `GPST` or
    /// `file seconds`)
    pub time_system: String,
    /// notes that do not stop reading (for example a last line without final newline)
    pub warnings: Vec<String>,
}

/// A GNSS file read into fixes.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct GnssData {
    /// the format actually read (never `Auto`)
    pub format: GnssFormat,
    /// the fixes, `t_s` on `time_base`, strictly increasing
    pub fixes: Vec<GnssFix>,
    /// what `t_s` counts
    pub time_base: TimeBase,
    /// what the reader did
    pub report: GnssReadReport,
}

/// Why a GNSS file could not be read or used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GnssFileError {
    /// The file could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// the file
        file: PathBuf,
        /// the cause
        source: std::io::Error,
    },
    /// Nothing in the file.
    #[error("{}: empty file, expected GNSS fixes", file.display())]
    Empty {
        /// the file
        file: PathBuf,
    },
    /// A header but no data rows.
    #[error("{}:{line}: header only, expected data rows after it", file.display())]
    NoData {
        /// the file
        file: PathBuf,
        /// last header line
        line: usize,
    },
    /// No format fits.
    #[error("{}:{line}: cannot detect the GNSS format: {why}", file.display())]
    UnknownFormat {
        /// the file
        file: PathBuf,
        /// the line looked at
        line: usize,
        /// why
        why: String,
    },
    /// More than one format fits.
    #[error("{}:{line}: ambiguous GNSS format: {why}; candidates: {}; give the format", file.display(), candidates.join(", "))]
    Ambiguous {
        /// the file
        file: PathBuf,
        /// the line looked at
        line: usize,
        /// the formats that fit
        candidates: Vec<&'static str>,
        /// why
        why: String,
    },
    /// A header is not what the format expects.
    #[error("{}:{line}:{column}: bad header: expected {expected}, found `{found}`", file.display())]
    Header {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column
        column: usize,
        /// what the format expects
        expected: String,
        /// what is there
        found: String,
    },
    /// The last line is cut short (no final newline).
    #[error("{}:{line}:{column}: truncated last line: {found} of {expected} fields and no final newline", file.display())]
    Truncated {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column (end of the line)
        column: usize,
        /// fields expected
        expected: usize,
        /// fields found
        found: usize,
    },
    /// The last line (no final newline) ends in a number with fewer decimals than the
    /// same column on the line before: cut inside that number.
    #[error("{}:{line}:{column}: truncated last line: `{text}` has fewer decimals than the {expected_decimals} of this column on the line before, and the file has no final newline", file.display())]
    CutNumber {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column
        column: usize,
        /// the number as cut
        text: String,
        /// decimals on the line before
        expected_decimals: usize,
    },
    /// The quality filter left no fix.
    #[error("{}: all {skipped} fixes have a quality flag Q outside 1..={max_q}", file.display())]
    AllFiltered {
        /// the file
        file: PathBuf,
        /// rows dropped
        skipped: usize,
        /// the filter
        max_q: u8,
    },
    /// Wrong number of fields.
    #[error("{}:{line}:{column}: expected {expected} fields, found {found}", file.display())]
    ColumnCount {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column of the last field
        column: usize,
        /// fields expected (for example `7` or `13 or 16`)
        expected: String,
        /// fields found
        found: usize,
    },
    /// A field is not a number.
    #[error("{}:{line}:{column}: field `{field}`: expected a number, found `{text}`", file.display())]
    NotANumber {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column
        column: usize,
        /// field name
        field: String,
        /// the text
        text: String,
    },
    /// A field is NaN or infinite.
    #[error("{}:{line}:{column}: field `{field}`: expected a finite number, found `{text}`", file.display())]
    NonFinite {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column
        column: usize,
        /// field name
        field: String,
        /// the text
        text: String,
    },
    /// A value is outside its range (latitude, height, σ, speed, …).
    #[error("{}:{line}:{column}: field `{field}`: {value} is out of range, expected {expected}", file.display())]
    OutOfRange {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column
        column: usize,
        /// field name
        field: String,
        /// the value
        value: f64,
        /// the accepted range
        expected: String,
    },
    /// Time not strictly increasing.
    #[error("{}:{line}:{column}: field `time`: expected a time after {prev_s} s, found {t_s} s", file.display())]
    TimeNotIncreasing {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column
        column: usize,
        /// previous time \[s\]
        prev_s: f64,
        /// this time \[s\]
        t_s: f64,
    },
    /// A covariance built from the file is not positive definite.
    #[error("{}:{line}:{column}: fields `{fields}`: the covariance they give is not positive definite", file.display())]
    NotPositiveDefinite {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column of the first of the fields
        column: usize,
        /// the fields
        fields: String,
    },
    /// Something the reader does not support (a time system, a height type, a layout).
    #[error("{}:{line}:{column}: {what}", file.display())]
    Unsupported {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column
        column: usize,
        /// what and what to do
        what: String,
    },
    /// The NaveGo parameter file is missing or bad.
    #[error("{0}")]
    Params(#[from] ParamsError),
    /// The GNSS time base cannot be mapped to the IMU clock asked for.
    #[error("{}: GNSS times are {have}, cannot map them to an IMU clock in {want}", file.display())]
    TimeBaseMismatch {
        /// the file
        file: PathBuf,
        /// the GNSS file's time base
        have: &'static str,
        /// the IMU clock asked for
        want: &'static str,
    },
    /// No fix falls inside the IMU record.
    #[error("{}: none of the {n_fixes} fixes (t = {gnss_first_s} .. {gnss_last_s} s) falls inside the IMU record (t = {imu_first_s} .. {imu_last_s} s); check the time bases", file.display())]
    NoOverlap {
        /// the file
        file: PathBuf,
        /// fixes in the file
        n_fixes: usize,
        /// first fix time \[s\]
        gnss_first_s: f64,
        /// last fix time \[s\]
        gnss_last_s: f64,
        /// IMU record start \[s\]
        imu_first_s: f64,
        /// IMU record end \[s\]
        imu_last_s: f64,
    },
}

/// Read a GNSS file. For NaveGo without parameters in `opts`, `gnss_params.txt` is read
/// from the same folder.
pub fn read_gnss_file(
    path: &Path,
    format: GnssFormat,
    opts: &GnssReadOptions,
) -> Result<GnssData, GnssFileError> {
    let bytes = crate::input::read_capped(path).map_err(|source| GnssFileError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    let text = crate::input::text_lossy(bytes);
    let resolved = match format {
        GnssFormat::Auto => detect(path, &text)?.0,
        f => f,
    };
    if resolved == GnssFormat::NaveGo && opts.navego.is_none() {
        let params = path
            .parent()
            .unwrap_or_else(|| Path::new("."))
            .join("gnss_params.txt");
        let p = crate::io::navego_params::read_navego_gnss_params(&params)?;
        let opts = opts.clone().with_navego(p);
        return parse_gnss_str(path, &text, format, &opts);
    }
    parse_gnss_str(path, &text, format, opts)
}

/// Parse the text of a GNSS file; `file` names it in errors. NaveGo needs
/// `opts.navego` (its CSV has no σ columns).
pub fn parse_gnss_str(
    file: &Path,
    text: &str,
    format: GnssFormat,
    opts: &GnssReadOptions,
) -> Result<GnssData, GnssFileError> {
    let (format, detection) = match format {
        GnssFormat::Auto => {
            let (f, why) = detect(file, text)?;
            (f, Some(why))
        }
        f => (f, None),
    };
    let mut data = match format {
        GnssFormat::NaveGo => {
            let Some(p) = &opts.navego else {
                return Err(GnssFileError::Params(ParamsError::Missing {
                    file: file.to_path_buf(),
                    field: "stdm",
                    what: "NaveGo GNSS parameters (gnss_params.txt) are needed for the σ",
                }));
            };
            navego::parse(file, text, p)?
        }
        GnssFormat::Sdins => sdins_csv::parse(file, text)?,
        GnssFormat::KfGins => kfgins::parse(file, text)?,
        GnssFormat::Rtklib | GnssFormat::Auto => rtklib::parse(file, text, opts)?,
        GnssFormat::Columns => {
            return Err(GnssFileError::UnknownFormat {
                file: file.to_path_buf(),
                line: 1,
                why: "a column map is read by `io::gnss_columns::read_gnss_columns`".into(),
            })
        }
    };
    data.report.detection = detection;
    Ok(data)
}

/// Decide the format from the content: returns the format and the reason, or
/// [`GnssFileError::Ambiguous`] with the candidates when more than one fits.
pub fn detect(file: &Path, text: &str) -> Result<(GnssFormat, String), GnssFileError> {
    let lines = rows::lines(text);
    let Some(first) = lines.first() else {
        return Err(GnssFileError::Empty {
            file: file.to_path_buf(),
        });
    };
    let t = first.text.trim_start();
    if t.starts_with('%') {
        return Ok((
            GnssFormat::Rtklib,
            "rtklib: the file starts with an RTKLIB `%` header".into(),
        ));
    }
    let names: Vec<String> = rows::split(first.text)
        .iter()
        .map(|f| f.text.trim_matches('"').to_string())
        .collect();
    if names.first().map(String::as_str) == Some("t_s") {
        if names.get(1).map(String::as_str) == Some("lat_deg") {
            return Ok((
                GnssFormat::Sdins,
                "sdins: header starts `t_s,lat_deg`".into(),
            ));
        }
        if names.get(1).map(String::as_str) == Some("lat_rad") {
            return Ok((
                GnssFormat::NaveGo,
                "navego: header starts `t_s,lat_rad`".into(),
            ));
        }
    }
    let fields = rows::split(first.text);
    let nums: Vec<f64> = fields
        .iter()
        .filter_map(|f| f.text.parse::<f64>().ok())
        .collect();
    if rtklib::looks_like_data(first.text) {
        return Ok((
            GnssFormat::Rtklib,
            "rtklib: headerless lines of an RTKLIB solution (date or week/seconds, then lat lon height Q ns)".into(),
        ));
    }
    if nums.len() == 7 && fields.len() == 7 {
        // 7 numbers: KF-GINS `t lat lon h σN σE σD` (degrees), or a headerless NaveGo
        // `t lat lon h vN vE vD` (radians). Latitude or longitude beyond the radian range
        // decides for degrees; σ ≤ 0 rules KF-GINS out.
        let deg =
            nums[1].abs() > std::f64::consts::FRAC_PI_2 || nums[2].abs() > std::f64::consts::PI;
        let sig_pos = nums[4..7].iter().all(|&s| s > 0.0);
        return match (deg, sig_pos) {
            (true, true) => Ok((
                GnssFormat::KfGins,
                format!("kfgins: 7 numbers per line, latitude/longitude {}/{} are degrees, σ columns positive", nums[1], nums[2]),
            )),
            (false, true) => Err(GnssFileError::Ambiguous {
                file: file.to_path_buf(),
                line: first.no,
                candidates: vec!["kfgins", "navego"],
                why: format!("7 numbers per line; latitude {} and longitude {} fit both degrees (KF-GINS) and radians (NaveGo without header)", nums[1], nums[2]),
            }),
            (_, false) => Err(GnssFileError::UnknownFormat {
                file: file.to_path_buf(),
                line: first.no,
                why: "7 numbers per line but the last three (KF-GINS σN σE σD) are not all positive; a NaveGo gnss.csv needs its `t_s,lat_rad,...` header".into(),
            }),
        };
    }
    Err(GnssFileError::UnknownFormat {
        file: file.to_path_buf(),
        line: first.no,
        why: format!(
            "first line `{}` is neither an sdins/NaveGo CSV header, an RTKLIB `%` header or solution line, nor 7 numbers (KF-GINS)",
            first.text.chars().take(80).collect::<String>()
        ),
    })
}

/// The clock of the IMU record the fixes are to be used with.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum ImuClock {
    /// the IMU file counts the same seconds as the GNSS file (NaveGo, sdins pairs)
    SameAsGnss,
    /// `t_imu = t_gnss + t_imu_minus_t_gnss_s` (a known constant offset)
    Offset {
        /// the offset \[s\]
        t_imu_minus_t_gnss_s: f64,
    },
    /// the IMU file counts GPS seconds of week (KF-GINS IMU files); GPS times since the
    /// epoch are reduced to the week of the first fix, later weeks continuing past
    /// 604 800 s
    GpsSecondsOfWeek,
}

/// Map the fixes to the IMU clock.
pub fn to_imu_time(
    file: &Path,
    data: &GnssData,
    clock: ImuClock,
) -> Result<Vec<GnssFix>, GnssFileError> {
    let shift = match (clock, data.time_base) {
        (ImuClock::SameAsGnss, _) => 0.0,
        (
            ImuClock::Offset {
                t_imu_minus_t_gnss_s,
            },
            _,
        ) if t_imu_minus_t_gnss_s.is_finite() => t_imu_minus_t_gnss_s,
        (ImuClock::Offset { .. }, _) => {
            return Err(GnssFileError::TimeBaseMismatch {
                file: file.to_path_buf(),
                have: "on any base",
                want: "a non-finite offset",
            })
        }
        (ImuClock::GpsSecondsOfWeek, TimeBase::GpsSecondsOfWeek) => 0.0,
        (ImuClock::GpsSecondsOfWeek, TimeBase::GpsSecondsSinceEpoch) => {
            let t0 = data.fixes.first().map_or(0.0, |f| f.t_s);
            -(t0 / SECONDS_PER_WEEK).floor() * SECONDS_PER_WEEK
        }
        (ImuClock::GpsSecondsOfWeek, TimeBase::FileSeconds) => {
            return Err(GnssFileError::TimeBaseMismatch {
                file: file.to_path_buf(),
                have: "file seconds without a GPS reference",
                want: "GPS seconds of week",
            })
        }
    };
    Ok(data
        .fixes
        .iter()
        .map(|f| GnssFix {
            t_s: f.t_s + shift,
            ..*f
        })
        .collect())
}

/// Time span covered by an IMU record: from the start of its first sample interval
/// (`t0_s − dt_s`, the sample stamps mark interval ends) to its last stamp.
pub fn imu_span_s(imu: &crate::io::imu_file::ImuData) -> (f64, f64) {
    let n = imu.increments.len();
    (
        imu.t0_s - imu.dt_s,
        imu.t0_s + imu.dt_s * n.saturating_sub(1) as f64,
    )
}

/// The fixes inside an IMU record, and how many were dropped on each side.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SpanClip {
    /// fixes with `first <= t_s <= last`
    pub fixes: Vec<GnssFix>,
    /// dropped before the record
    pub before: usize,
    /// dropped after the record
    pub after: usize,
}

/// Keep the fixes with `imu_first_s <= t_s <= imu_last_s`, counting the others; an error
/// only if none is left.
pub fn clip_to_imu_span(
    file: &Path,
    fixes: &[GnssFix],
    imu_first_s: f64,
    imu_last_s: f64,
) -> Result<SpanClip, GnssFileError> {
    let before = fixes.iter().filter(|f| f.t_s < imu_first_s).count();
    let after = fixes.iter().filter(|f| f.t_s > imu_last_s).count();
    let kept: Vec<GnssFix> = fixes
        .iter()
        .filter(|f| f.t_s >= imu_first_s && f.t_s <= imu_last_s)
        .copied()
        .collect();
    if kept.is_empty() {
        return Err(GnssFileError::NoOverlap {
            file: file.to_path_buf(),
            n_fixes: fixes.len(),
            gnss_first_s: fixes.first().map_or(f64::NAN, |f| f.t_s),
            gnss_last_s: fixes.last().map_or(f64::NAN, |f| f.t_s),
            imu_first_s,
            imu_last_s,
        });
    }
    Ok(SpanClip {
        fixes: kept,
        before,
        after,
    })
}

/// Shared tail of the readers: the "no data" and "no final newline" checks.
pub(crate) fn finish(
    file: &Path,
    text: &str,
    header_line: Option<usize>,
    fixes: Vec<GnssFix>,
    format: GnssFormat,
    time_base: TimeBase,
    mut report: GnssReadReport,
) -> Result<GnssData, GnssFileError> {
    if fixes.is_empty() && report.skipped_quality == 0 {
        return match header_line {
            Some(line) => Err(GnssFileError::NoData {
                file: file.to_path_buf(),
                line,
            }),
            None => Err(GnssFileError::Empty {
                file: file.to_path_buf(),
            }),
        };
    }
    if !text.ends_with('\n') && !text.trim().is_empty() {
        report.warnings.push(
            "the file does not end with a newline: its last line may have been cut inside its last number".into(),
        );
    }
    Ok(GnssData {
        format,
        fixes,
        time_base,
        report,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests;
