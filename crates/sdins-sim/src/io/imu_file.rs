//! IMU file readers. Every format is converted at the edge to FRD body-frame
//! increments ([`Increment`]: Δθ \[rad\], Δv \[m/s\]) over a constant sample period.
//!
//! | format | flag | layout | frame | content |
//! |---|---|---|---|---|
//! | sdins increments | `sdins` | CSV header `t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps` | FRD | increments, `t_s` = end of the sample |
//! | sdins rates | `sdins` | CSV header `t_s,gyro_x_rps,gyro_y_rps,gyro_z_rps,accel_x_mps2,accel_y_mps2,accel_z_mps2` | FRD | rates (rad/s, m/s²); Δθ = ω·dt |
//! | PSINS trj CSV | `psins-csv` | the sdins increment header | RFU (X-right, Y-forward, Z-up) | increments |
//! | PSINS `.imu` | `psins` | `%` comment lines; 3 header lines; integer pulse counts `gx gy gz ax ay az` | RFU | pulses × weights (arcsec, μg·s) |
//! | KF-GINS | `kfgins` | 7 numbers per line, whitespace or comma separated, no header: `t dθx dθy dθz dvx dvy dvz` | FRD | increments |
//! | NaveGo CSV | `navego` | CSV header `t_s,f_x_mps2,f_y_mps2,f_z_mps2,w_x_radps,w_y_radps,w_z_radps` | FRD | rates (specific force first) |
//!
//! RFU → FRD: `x_frd = y_rfu`, `y_frd = x_rfu`, `z_frd = −z_rfu` (for Δθ and Δv alike).
//! PSINS `.imu` header: line 1 `[pitch0, roll0, yaw0 (deg), VE0, VN0, VU0 (m/s)]`,
//! line 2 `[lat0 (deg), lon0 (deg), h0 (m), t0 (s), Ts (ms), g (m/s²)]`, line 3 gyro
//! pulse weights (arcsec) and accelerometer pulse weights (μg·s); μg·s are converted
//! with the file's own `g` (PSINS: `ug = 1e-6·g0`). Its first sample ends at `t0 + Ts`.
//!
//! Validation (each failure is an [`ImuFileError`] naming file, line, column and what
//! was expected; nothing panics): empty file, header without data, truncated last
//! line (no final newline and too few fields), wrong column count, non-numeric or
//! non-finite field, time not strictly increasing, sample interval off the median by
//! more than [`DT_TOLERANCE`], absurd magnitudes (|Δθ| > π per sample,
//! |f| > [`MAX_SPECIFIC_FORCE_G`] g).

use sdins_core::coning::Increment;
use sdins_core::Vec3;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Largest accepted |Δθ| per sample \[rad\].
pub const MAX_DTHETA_RAD: f64 = core::f64::consts::PI;
/// Largest accepted |f| \[g\].
pub const MAX_SPECIFIC_FORCE_G: f64 = 1000.0;
/// Largest accepted relative deviation of a sample interval from the median.
pub const DT_TOLERANCE: f64 = 0.01;
/// Accepted sample interval range \[s\]: 1 MHz to 1 Hz (a strapdown IMU record outside it is
/// a wrong time unit or a corrupt file).
pub const DT_RANGE_S: (f64, f64) = (1.0e-6, 1.0);
/// |mean specific force along z| \[g\] above which auto-detection tells an FRD (z down:
/// f_z ≈ −g) from an RFU (z up: f_z ≈ +g) increment CSV with the same header.
pub const GRAVITY_SIGN_THRESHOLD_G: f64 = 0.5;
/// Gravity used for the |f| limit \[m/s²\].
const G0: f64 = 9.80665;
/// One arcsecond \[rad\].
const ARCSEC: f64 = core::f64::consts::PI / 180.0 / 3600.0;

/// Column names of the sdins increment CSV (also PSINS trj CSVs).
pub const SDINS_INCREMENT_HEADER: [&str; 7] = [
    "t_s",
    "dtheta_x_rad",
    "dtheta_y_rad",
    "dtheta_z_rad",
    "dv_x_mps",
    "dv_y_mps",
    "dv_z_mps",
];
/// Column names of the sdins rate CSV.
pub const SDINS_RATE_HEADER: [&str; 7] = [
    "t_s",
    "gyro_x_rps",
    "gyro_y_rps",
    "gyro_z_rps",
    "accel_x_mps2",
    "accel_y_mps2",
    "accel_z_mps2",
];
/// Column names of the NaveGo CSV.
pub const NAVEGO_HEADER: [&str; 7] = [
    "t_s",
    "f_x_mps2",
    "f_y_mps2",
    "f_z_mps2",
    "w_x_radps",
    "w_y_radps",
    "w_z_radps",
];
const KFGINS_NAMES: [&str; 7] = [
    "t", "dtheta_x", "dtheta_y", "dtheta_z", "dv_x", "dv_y", "dv_z",
];
const PSINS_NAMES: [&str; 6] = [
    "gyro_x_pulses",
    "gyro_y_pulses",
    "gyro_z_pulses",
    "acc_x_pulses",
    "acc_y_pulses",
    "acc_z_pulses",
];

/// File format selector.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ImuFormat {
    /// detect from the content
    Auto,
    /// sdins CSV (increments or rates, told apart by the header), FRD
    Sdins,
    /// PSINS `.imu` pulse file, RFU
    Psins,
    /// PSINS trj CSV (sdins increment header, RFU)
    PsinsCsv,
    /// KF-GINS 7-column text, FRD
    KfGins,
    /// NaveGo CSV (rates, FRD)
    NaveGo,
    /// any delimited text read through a column map (`crate::io::imu_columns`); not a
    /// `--imu-format` value: `--columns` or `--profile` selects it
    Columns,
}

impl ImuFormat {
    /// The flag names.
    pub const NAMES: [&'static str; 6] =
        ["auto", "sdins", "psins", "psins-csv", "kfgins", "navego"];
    /// The flag name.
    pub fn name(self) -> &'static str {
        match self {
            ImuFormat::Auto => "auto",
            ImuFormat::Sdins => "sdins",
            ImuFormat::Psins => "psins",
            ImuFormat::PsinsCsv => "psins-csv",
            ImuFormat::KfGins => "kfgins",
            ImuFormat::NaveGo => "navego",
            ImuFormat::Columns => "columns",
        }
    }
}

impl fmt::Display for ImuFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ImuFormat {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "auto" => Ok(ImuFormat::Auto),
            "sdins" => Ok(ImuFormat::Sdins),
            "psins" => Ok(ImuFormat::Psins),
            "psins-csv" => Ok(ImuFormat::PsinsCsv),
            "kfgins" => Ok(ImuFormat::KfGins),
            "navego" => Ok(ImuFormat::NaveGo),
            _ => Err(format!(
                "unknown IMU format `{s}` (expected one of {})",
                ImuFormat::NAMES.join(", ")
            )),
        }
    }
}

/// Header of a PSINS `.imu` file (values as written, PSINS conventions: ENU, body RFU).
#[derive(Clone, Debug, PartialEq)]
pub struct PsinsHeader {
    /// initial \[pitch, roll, yaw\] \[deg\] (PSINS: yaw counter-clockwise from north; "maybe inaccurate")
    pub att0_deg: [f64; 3],
    /// initial velocity \[VE, VN, VU\] \[m/s\]
    pub vel0_enu_mps: [f64; 3],
    /// latitude \[deg\]
    pub lat_deg: f64,
    /// longitude \[deg\]
    pub lon_deg: f64,
    /// height \[m\]
    pub h_m: f64,
    /// start time \[s\]
    pub t0_s: f64,
    /// sample interval \[s\]
    pub ts_s: f64,
    /// local gravity stated by the file \[m/s²\]
    pub g_mps2: f64,
    /// gyro pulse weights (RFU axes) \[arcsec\]
    pub gyro_weight_arcsec: [f64; 3],
    /// accelerometer pulse weights (RFU axes) \[μg·s\]
    pub accel_weight_ugs: [f64; 3],
}

/// An IMU record converted to FRD increments.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuData {
    /// the format actually read (never `Auto`)
    pub format: ImuFormat,
    /// sample period \[s\] (mean interval `(t_last − t_0)/(n − 1)` for files with a time
    /// column, after every interval was checked against the median)
    pub dt_s: f64,
    /// time stamp of the first sample as given by the file \[s\]
    pub t0_s: f64,
    /// the samples, FRD
    pub increments: Vec<Increment>,
    /// PSINS `.imu` header, if that was the format
    pub psins: Option<PsinsHeader>,
    /// how auto-detection picked the format (`None` when the format was given)
    pub detection: Option<String>,
    /// notes that did not stop reading (for example a last line without final newline)
    pub warnings: Vec<String>,
}

mod error;
pub use error::ImuFileError;

/// Read an IMU file (see the module docs for formats and checks).
pub fn read_imu_file(path: &Path, format: ImuFormat) -> Result<ImuData, ImuFileError> {
    // the format is told by line 1: checked before the rest is read
    let check = |first: &str| {
        let first = first.strip_prefix('\u{feff}').unwrap_or(first);
        match format {
            ImuFormat::Auto if !first.trim().is_empty() => detect(path, 1, first).map(|_| ()),
            _ => Ok(()),
        }
    };
    let bytes = crate::input::read_capped_with(path, check).map_err(|e| match e {
        crate::input::Refused::Io(source) => ImuFileError::Io {
            file: path.to_path_buf(),
            source,
        },
        crate::input::Refused::Header(e) => e,
    })?;
    let text = crate::input::text_lossy(bytes);
    parse_imu_str(path, &text, format)
}

/// Parse the text of an IMU file; `file` is only used in error messages.
pub fn parse_imu_str(file: &Path, text: &str, format: ImuFormat) -> Result<ImuData, ImuFileError> {
    // a UTF-8 byte-order mark is accepted and skipped
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let p = Parser {
        file,
        ends_with_newline: text.ends_with('\n'),
        lines: numbered_lines(text),
    };
    let Some(&(first_no, first)) = p.lines.first() else {
        return Err(ImuFileError::Empty {
            file: file.to_path_buf(),
        });
    };
    let given = format;
    let format = match format {
        ImuFormat::Auto => detect(file, first_no, first)?,
        // `psins` names the conventions (RFU body): a PSINS trajectory exported as CSV with
        // the sdins increment header is read as `psins-csv`
        ImuFormat::Psins if first.trim_start().starts_with("t_s,") => ImuFormat::PsinsCsv,
        f => f,
    };
    // a logger killed mid-write cuts its last line: dropped with a warning (reliability
    // issue, class 10)
    let mut p = p;
    let cut = p.drop_cut_last_line(format == ImuFormat::KfGins);
    let mut data = match format {
        ImuFormat::Psins => p.psins()?,
        ImuFormat::KfGins => p.kfgins()?,
        ImuFormat::Columns => {
            return Err(ImuFileError::UnknownFormat {
                file: file.to_path_buf(),
                line: first_no,
                why: "a column map is read by `io::imu_columns::read_imu_columns` (give --columns or --profile)".into(),
            })
        }
        ImuFormat::Sdins | ImuFormat::PsinsCsv | ImuFormat::NaveGo | ImuFormat::Auto => {
            p.csv(format)?
        }
    };
    if given == ImuFormat::Auto {
        let why = match data.format {
            ImuFormat::Psins => "a `%` PSINS header".to_string(),
            ImuFormat::KfGins => "7 numbers per line without header (KF-GINS)".to_string(),
            ImuFormat::NaveGo => "the NaveGo CSV header".to_string(),
            _ if header_fields(first) == SDINS_RATE_HEADER => {
                "the sdins rate CSV header".to_string()
            }
            _ => {
                // the increment header is shared by sdins (FRD) and PSINS trj CSVs (RFU):
                // gravity's sign on z decides (FRD z down: f_z ≈ −g; RFU z up: f_z ≈ +g)
                let fz = mean_fz_g(&data.increments, data.dt_s);
                let (f, w) = if fz < -GRAVITY_SIGN_THRESHOLD_G {
                    (ImuFormat::Sdins, "FRD: z down")
                } else if fz > GRAVITY_SIGN_THRESHOLD_G {
                    (ImuFormat::PsinsCsv, "RFU: z up")
                } else {
                    return Err(ImuFileError::Ambiguous {
                        file: file.to_path_buf(),
                        line: first_no,
                        candidates: vec!["sdins", "psins-csv"],
                        why: format!(
                            "the increment header is used by sdins (FRD) and PSINS trajectory CSVs (RFU), and the mean specific force along z, {fz:.3} g, is within ±{GRAVITY_SIGN_THRESHOLD_G} g, so gravity does not tell them apart"
                        ),
                    });
                };
                if f == ImuFormat::PsinsCsv {
                    data = p.csv(ImuFormat::PsinsCsv)?;
                }
                format!(
                    "the increment CSV header and a mean specific force along z of {fz:.3} g ({w})"
                )
            }
        };
        data.detection = Some(format!("read as `{}`: {why}", data.format));
    }
    if let Some(w) = cut {
        data.warnings.push(w);
    } else if !p.ends_with_newline {
        data.warnings.push(
            "the file does not end with a newline: its last line may have been cut inside its last number".into(),
        );
    }
    Ok(data)
}

/// Mean specific force along body z over the record \[g\], in the file's own axes.
fn mean_fz_g(incs: &[Increment], dt_s: f64) -> f64 {
    if incs.is_empty() || dt_s.is_nan() || dt_s <= 0.0 {
        return 0.0;
    }
    let s: f64 = incs.iter().map(|i| i.dv_b_mps[2]).sum();
    s / (incs.len() as f64 * dt_s * G0)
}

/// Non-blank lines with their 1-based numbers (trailing `\r` removed).
fn numbered_lines(text: &str) -> Vec<(usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .filter(|(_, l)| !l.trim().is_empty())
        .collect()
}

fn split_fields(line: &str) -> Vec<&str> {
    if line.contains(',') {
        line.split(',').map(str::trim).collect()
    } else {
        line.split_whitespace().collect()
    }
}

fn header_fields(line: &str) -> Vec<String> {
    split_fields(line)
        .iter()
        .map(|s| s.trim_matches('"').to_string())
        .collect()
}

fn detect(file: &Path, line_no: usize, first: &str) -> Result<ImuFormat, ImuFileError> {
    if first.trim_start().starts_with('%') {
        return Ok(ImuFormat::Psins);
    }
    let h = header_fields(first);
    if h == SDINS_INCREMENT_HEADER || h == SDINS_RATE_HEADER {
        return Ok(ImuFormat::Sdins);
    }
    if h == NAVEGO_HEADER {
        return Ok(ImuFormat::NaveGo);
    }
    if h.len() == 7 && h.iter().all(|f| f.parse::<f64>().is_ok()) {
        return Ok(ImuFormat::KfGins);
    }
    Err(ImuFileError::UnknownFormat {
        file: file.to_path_buf(),
        line: line_no,
        why: format!(
            "first line `{}` is neither a PSINS `%` header, an sdins/NaveGo CSV header nor 7 numbers (KF-GINS); give --format",
            first.chars().take(80).collect::<String>()
        ),
    })
}

/// RFU → FRD.
fn rfu_to_frd(v: Vec3) -> Vec3 {
    Vec3::new(v[1], v[0], -v[2])
}

struct Parser<'a> {
    file: &'a Path,
    ends_with_newline: bool,
    lines: Vec<(usize, &'a str)>,
}

impl Parser<'_> {
    fn f(&self) -> PathBuf {
        self.file.to_path_buf()
    }

    /// Parse `lines[from..]` as rows of `names.len()` numbers into a flat vector.
    fn rows(&self, from: usize, names: &[&str]) -> Result<Vec<f64>, ImuFileError> {
        let n = names.len();
        let total = self.lines.len();
        let mut out = Vec::with_capacity((total - from) * n);
        for (idx, &(line, text)) in self.lines.iter().enumerate().skip(from) {
            let fields = split_fields(text);
            if fields.len() != n {
                if idx + 1 == total && !self.ends_with_newline && fields.len() < n {
                    return Err(ImuFileError::Truncated {
                        file: self.f(),
                        line,
                        expected: n,
                        found: fields.len(),
                    });
                }
                return Err(ImuFileError::ColumnCount {
                    file: self.f(),
                    line,
                    expected: n,
                    found: fields.len(),
                });
            }
            for (col, s) in fields.iter().enumerate() {
                let v: f64 = s.parse().map_err(|_| ImuFileError::NotANumber {
                    file: self.f(),
                    line,
                    column: col + 1,
                    name: names[col].to_string(),
                    text: s.to_string(),
                })?;
                if !v.is_finite() {
                    return Err(ImuFileError::NonFinite {
                        file: self.f(),
                        line,
                        column: col + 1,
                        name: names[col].to_string(),
                        text: s.to_string(),
                    });
                }
                out.push(v);
            }
        }
        Ok(out)
    }

    /// A last line without final newline that is cut (fewer fields than the line before;
    /// with `fixed_decimals`, a number with fewer decimals than the same column on the
    /// line before) is removed; the warning that says so, or None.
    fn drop_cut_last_line(&mut self, fixed_decimals: bool) -> Option<String> {
        let n = self.lines.len();
        if self.ends_with_newline || n < 2 {
            return None;
        }
        let (line, last) = self.lines[n - 1];
        let (fl, fp) = (split_fields(last), split_fields(self.lines[n - 2].1));
        let dec = |s: &str| {
            if s.contains(['e', 'E']) {
                None
            } else {
                Some(s.find('.').map_or(0, |k| s.len() - k - 1))
            }
        };
        let why = if fl.len() < fp.len() {
            format!("{} of {} fields", fl.len(), fp.len())
        } else if let Some(b) = fixed_decimals
            .then(|| {
                fp.iter()
                    .zip(&fl)
                    .find_map(|(a, b)| match (dec(a), dec(b)) {
                        (Some(da), Some(db)) if db < da => Some(*b),
                        _ => None,
                    })
            })
            .flatten()
        {
            format!("`{b}` has fewer decimals than the line before")
        } else {
            return None;
        };
        self.lines.pop();
        Some(format!(
            "line {line}: the last line is cut ({why}) and the file does not end with a newline (a logger stopped mid-write): dropped"
        ))
    }

    /// Line number of data row `k` when the data starts at `lines[from]`.
    fn line_of(&self, from: usize, k: usize) -> usize {
        self.lines.get(from + k).map_or(0, |l| l.0)
    }

    /// Check the time column (strictly increasing, regular) and return (t0, median dt).
    fn times(&self, from: usize, t: &[f64]) -> Result<(f64, f64), ImuFileError> {
        if t.len() < 2 {
            return Err(ImuFileError::TooFewRows {
                file: self.f(),
                rows: t.len(),
            });
        }
        for k in 1..t.len() {
            if t[k] <= t[k - 1] {
                return Err(ImuFileError::TimeNotIncreasing {
                    file: self.f(),
                    line: self.line_of(from, k),
                    prev_s: t[k - 1],
                    t_s: t[k],
                });
            }
        }
        let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let mut sorted = d.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[sorted.len() / 2];
        for (k, dk) in d.iter_mut().enumerate() {
            if (*dk - median).abs() > DT_TOLERANCE * median {
                return Err(ImuFileError::IrregularInterval {
                    file: self.f(),
                    line: self.line_of(from, k + 1),
                    dt_s: *dk,
                    median_s: median,
                    tol_pct: DT_TOLERANCE * 100.0,
                });
            }
        }
        // the mean interval: more accurate than the median of rounded differences
        let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
        if !(DT_RANGE_S.0..=DT_RANGE_S.1).contains(&dt) {
            return Err(ImuFileError::IntervalOutOfRange {
                file: self.f(),
                line: self.line_of(from, 1),
                dt_s: dt,
                min_s: DT_RANGE_S.0,
                max_s: DT_RANGE_S.1,
            });
        }
        Ok((t[0], dt))
    }

    /// Magnitude checks on one converted sample.
    fn check_sample(
        &self,
        line: usize,
        inc: &Increment,
        dt: f64,
        cols: (&str, &str),
    ) -> Result<(), ImuFileError> {
        let a = inc.dtheta_b_rad.norm();
        if a > MAX_DTHETA_RAD {
            return Err(ImuFileError::Absurd {
                file: self.f(),
                line,
                columns: cols.0.to_string(),
                what: "|Δθ| per sample [rad]",
                value: a,
                limit: MAX_DTHETA_RAD,
            });
        }
        let f = inc.dv_b_mps.norm() / dt;
        if f > MAX_SPECIFIC_FORCE_G * G0 {
            return Err(ImuFileError::Absurd {
                file: self.f(),
                line,
                columns: cols.1.to_string(),
                what: "|f| [m/s²]",
                value: f,
                limit: MAX_SPECIFIC_FORCE_G * G0,
            });
        }
        Ok(())
    }

    /// Rows with a time column: (t, a, b) with a, b the two 3-vectors in file order.
    fn timed(
        &self,
        from: usize,
        names: &[&str],
    ) -> Result<(Vec<[Vec3; 2]>, f64, f64), ImuFileError> {
        if from >= self.lines.len() {
            return Err(ImuFileError::NoData {
                file: self.f(),
                line: self.line_of(0, from.saturating_sub(1)),
            });
        }
        let flat = self.rows(from, names)?;
        let t: Vec<f64> = flat.chunks_exact(7).map(|r| r[0]).collect();
        let v: Vec<[Vec3; 2]> = flat
            .chunks_exact(7)
            .map(|r| [Vec3::new(r[1], r[2], r[3]), Vec3::new(r[4], r[5], r[6])])
            .collect();
        let (t0, dt) = self.times(from, &t)?;
        Ok((v, t0, dt))
    }

    fn csv(&self, format: ImuFormat) -> Result<ImuData, ImuFileError> {
        let (line_no, first) = self.lines[0];
        let h = header_fields(first);
        let expect = |names: &[&str]| ImuFileError::Header {
            file: self.f(),
            line: line_no,
            expected: format!("the {format} CSV header `{}`", names.join(",")),
            found: first.chars().take(120).collect(),
        };
        let (rates, gyro_first, rfu, names): (bool, bool, bool, &[&str]) = match format {
            ImuFormat::NaveGo if h == NAVEGO_HEADER => (true, false, false, &NAVEGO_HEADER),
            ImuFormat::NaveGo => return Err(expect(&NAVEGO_HEADER)),
            ImuFormat::PsinsCsv if h == SDINS_INCREMENT_HEADER => {
                (false, true, true, &SDINS_INCREMENT_HEADER)
            }
            ImuFormat::PsinsCsv => return Err(expect(&SDINS_INCREMENT_HEADER)),
            _ if h == SDINS_INCREMENT_HEADER => (false, true, false, &SDINS_INCREMENT_HEADER),
            _ if h == SDINS_RATE_HEADER => (true, true, false, &SDINS_RATE_HEADER),
            _ => {
                return Err(ImuFileError::Header {
                    file: self.f(),
                    line: line_no,
                    expected: format!(
                        "the sdins CSV header `{}` (increments) or `{}` (rates)",
                        SDINS_INCREMENT_HEADER.join(","),
                        SDINS_RATE_HEADER.join(",")
                    ),
                    found: first.chars().take(120).collect(),
                })
            }
        };
        if self.lines.len() < 2 {
            return Err(ImuFileError::NoData {
                file: self.f(),
                line: line_no,
            });
        }
        let (v, t0, dt) = self.timed(1, names)?;
        let cols = if gyro_first {
            ("2-4", "5-7")
        } else {
            ("5-7", "2-4")
        };
        let mut incs = Vec::with_capacity(v.len());
        for (k, [a, b]) in v.into_iter().enumerate() {
            let (g, f) = if gyro_first { (a, b) } else { (b, a) };
            let (mut dth, mut dv) = if rates { (g * dt, f * dt) } else { (g, f) };
            if rfu {
                dth = rfu_to_frd(dth);
                dv = rfu_to_frd(dv);
            }
            let inc = Increment::new(dth, dv);
            self.check_sample(self.line_of(1, k), &inc, dt, cols)?;
            incs.push(inc);
        }
        Ok(ImuData {
            format,
            dt_s: dt,
            t0_s: t0,
            increments: incs,
            psins: None,
            detection: None,
            warnings: Vec::new(),
        })
    }

    fn kfgins(&self) -> Result<ImuData, ImuFileError> {
        let (v, t0, dt) = self.timed(0, &KFGINS_NAMES)?;
        let mut incs = Vec::with_capacity(v.len());
        for (k, [g, f]) in v.into_iter().enumerate() {
            let inc = Increment::new(g, f);
            self.check_sample(self.line_of(0, k), &inc, dt, ("2-4", "5-7"))?;
            incs.push(inc);
        }
        Ok(ImuData {
            format: ImuFormat::KfGins,
            dt_s: dt,
            t0_s: t0,
            increments: incs,
            psins: None,
            detection: None,
            warnings: Vec::new(),
        })
    }

    fn psins(&self) -> Result<ImuData, ImuFileError> {
        let start = self
            .lines
            .iter()
            .position(|(_, l)| !l.trim_start().starts_with('%'))
            .unwrap_or(self.lines.len());
        const H1: [&str; 6] = [
            "pitch0_deg",
            "roll0_deg",
            "yaw0_deg",
            "ve0_mps",
            "vn0_mps",
            "vu0_mps",
        ];
        const H2: [&str; 6] = ["lat0_deg", "lon0_deg", "h0_m", "t0_s", "ts_ms", "g_mps2"];
        const H3: [&str; 6] = [
            "gyro_x_arcsec",
            "gyro_y_arcsec",
            "gyro_z_arcsec",
            "acc_x_ugs",
            "acc_y_ugs",
            "acc_z_ugs",
        ];
        let mut hdr = [[0.0; 6]; 3];
        for (i, names) in [H1, H2, H3].iter().enumerate() {
            let Some(&(line, text)) = self.lines.get(start + i) else {
                let line = self.lines.last().map_or(0, |l| l.0);
                return Err(ImuFileError::Header {
                    file: self.f(),
                    line,
                    expected: format!("PSINS header line {} `{}`", i + 1, names.join(" ")),
                    found: "end of file".into(),
                });
            };
            let fields = split_fields(text);
            if fields.len() != 6 {
                return Err(ImuFileError::Header {
                    file: self.f(),
                    line,
                    expected: format!(
                        "PSINS header line {} with 6 numbers `{}`",
                        i + 1,
                        names.join(" ")
                    ),
                    found: text.chars().take(120).collect(),
                });
            }
            for (c, s) in fields.iter().enumerate() {
                let v: f64 = s.parse().map_err(|_| ImuFileError::NotANumber {
                    file: self.f(),
                    line,
                    column: c + 1,
                    name: names[c].to_string(),
                    text: s.to_string(),
                })?;
                if !v.is_finite() {
                    return Err(ImuFileError::NonFinite {
                        file: self.f(),
                        line,
                        column: c + 1,
                        name: names[c].to_string(),
                        text: s.to_string(),
                    });
                }
                hdr[i][c] = v;
            }
        }
        let l2 = self.lines[start + 1].0;
        let l3 = self.lines[start + 2].0;
        let positive = |v: f64, line: usize, col: usize, name: &str| {
            if v > 0.0 {
                Ok(())
            } else {
                Err(ImuFileError::BadValue {
                    file: self.f(),
                    line,
                    column: col + 1,
                    name: name.to_string(),
                    what: format!("expected a positive value, found {v}"),
                })
            }
        };
        positive(hdr[1][4], l2, 4, H2[4])?;
        positive(hdr[1][5], l2, 5, H2[5])?;
        for c in 0..6 {
            positive(hdr[2][c], l3, c, H3[c])?;
        }
        let header = PsinsHeader {
            att0_deg: [hdr[0][0], hdr[0][1], hdr[0][2]],
            vel0_enu_mps: [hdr[0][3], hdr[0][4], hdr[0][5]],
            lat_deg: hdr[1][0],
            lon_deg: hdr[1][1],
            h_m: hdr[1][2],
            t0_s: hdr[1][3],
            ts_s: hdr[1][4] * 1e-3,
            g_mps2: hdr[1][5],
            gyro_weight_arcsec: [hdr[2][0], hdr[2][1], hdr[2][2]],
            accel_weight_ugs: [hdr[2][3], hdr[2][4], hdr[2][5]],
        };
        if !(DT_RANGE_S.0..=DT_RANGE_S.1).contains(&header.ts_s) {
            return Err(ImuFileError::IntervalOutOfRange {
                file: self.f(),
                line: l2,
                dt_s: header.ts_s,
                min_s: DT_RANGE_S.0,
                max_s: DT_RANGE_S.1,
            });
        }
        let from = start + 3;
        if from >= self.lines.len() {
            return Err(ImuFileError::NoData {
                file: self.f(),
                line: l3,
            });
        }
        let flat = self.rows(from, &PSINS_NAMES)?;
        let gw = Vec3::from(header.gyro_weight_arcsec) * ARCSEC;
        let aw = Vec3::from(header.accel_weight_ugs) * (1e-6 * header.g_mps2);
        let dt = header.ts_s;
        let mut incs = Vec::with_capacity(flat.len() / 6);
        for (k, r) in flat.chunks_exact(6).enumerate() {
            let g = Vec3::new(r[0], r[1], r[2]).component_mul(&gw);
            let a = Vec3::new(r[3], r[4], r[5]).component_mul(&aw);
            let inc = Increment::new(rfu_to_frd(g), rfu_to_frd(a));
            self.check_sample(self.line_of(from, k), &inc, dt, ("1-3", "4-6"))?;
            incs.push(inc);
        }
        Ok(ImuData {
            format: ImuFormat::Psins,
            dt_s: dt,
            t0_s: header.t0_s + dt,
            increments: incs,
            psins: Some(header),
            detection: None,
            warnings: Vec::new(),
        })
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    const INC_H: &str = "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n";

    fn parse(text: &str, f: ImuFormat) -> Result<ImuData, ImuFileError> {
        parse_imu_str(Path::new("test.csv"), text, f)
    }

    fn good_rows(n: usize) -> String {
        (0..n)
            .map(|k| {
                format!(
                    "{},1e-4,2e-4,3e-4,0.01,0.02,-0.098\n",
                    0.01 * (k + 1) as f64
                )
            })
            .collect()
    }

    #[test]
    fn sdins_increments_and_rates() {
        let d = parse(&format!("{INC_H}{}", good_rows(5)), ImuFormat::Auto).unwrap();
        assert_eq!(d.format, ImuFormat::Sdins);
        assert_eq!(d.increments.len(), 5);
        assert!((d.dt_s - 0.01).abs() < 1e-12);
        assert_eq!(d.t0_s, 0.01);
        assert_eq!(d.increments[2].dtheta_b_rad, Vec3::new(1e-4, 2e-4, 3e-4));
        let rates = "t_s,gyro_x_rps,gyro_y_rps,gyro_z_rps,accel_x_mps2,accel_y_mps2,accel_z_mps2\n0,0.1,0.2,0.3,1,2,-9.8\n0.5,0.1,0.2,0.3,1,2,-9.8\n";
        let d = parse(rates, ImuFormat::Sdins).unwrap();
        assert!((d.increments[0].dtheta_b_rad - Vec3::new(0.05, 0.1, 0.15)).norm() < 1e-15);
        assert!((d.increments[1].dv_b_mps - Vec3::new(0.5, 1.0, -4.9)).norm() < 1e-15);
    }

    #[test]
    fn psins_csv_is_rfu() {
        let d = parse(&format!("{INC_H}{}", good_rows(3)), ImuFormat::PsinsCsv).unwrap();
        assert_eq!(d.increments[0].dtheta_b_rad, Vec3::new(2e-4, 1e-4, -3e-4));
        assert_eq!(d.increments[0].dv_b_mps, Vec3::new(0.02, 0.01, 0.098));
    }

    #[test]
    fn navego_and_kfgins() {
        let nav = "t_s,f_x_mps2,f_y_mps2,f_z_mps2,w_x_radps,w_y_radps,w_z_radps\n0,1,2,-9.8,0.1,0.2,0.3\n0.005,1,2,-9.8,0.1,0.2,0.3\n";
        let d = parse(nav, ImuFormat::Auto).unwrap();
        assert_eq!(d.format, ImuFormat::NaveGo);
        assert!((d.increments[0].dtheta_b_rad - Vec3::new(0.1, 0.2, 0.3) * 0.005).norm() < 1e-15);
        assert!((d.increments[0].dv_b_mps - Vec3::new(1.0, 2.0, -9.8) * 0.005).norm() < 1e-15);
        let kf = "100.000 1e-5 2e-5 3e-5 0.001 0.002 -0.0490\n100.005  1e-5 2e-5 3e-5 0.001 0.002 -0.0490\n";
        let d = parse(kf, ImuFormat::Auto).unwrap();
        assert_eq!(d.format, ImuFormat::KfGins);
        assert_eq!(d.t0_s, 100.0);
        assert_eq!(d.increments[1].dv_b_mps, Vec3::new(0.001, 0.002, -0.049));
    }

    #[test]
    fn psins_imu_pulses() {
        let txt = "% comment\n% more\n\n1 2 -90.6 0 0 0\n34.2 108.9 380 0 10 9.78\n0.1 0.1 0.2 125 125 100\n1 2 3 4 5 80\n0 0 0 0 0 80\n";
        let d = parse(txt, ImuFormat::Auto).unwrap();
        assert_eq!(d.format, ImuFormat::Psins);
        let h = d.psins.clone().unwrap();
        assert_eq!(h.att0_deg, [1.0, 2.0, -90.6]);
        assert_eq!(h.lat_deg, 34.2);
        assert!((d.dt_s - 0.01).abs() < 1e-15);
        assert!((d.t0_s - 0.01).abs() < 1e-15);
        let i = d.increments[0];
        // RFU (1, 2, 3) pulses × (0.1, 0.1, 0.2)" → FRD (0.2", 0.1", −0.6")
        assert!((i.dtheta_b_rad - Vec3::new(0.2, 0.1, -0.6) * ARCSEC).norm() < 1e-18);
        // accel RFU (4·125, 5·125, 80·100) μg·s → FRD (625, 500, −8000) μg·s
        assert!((i.dv_b_mps - Vec3::new(625.0, 500.0, -8000.0) * 1e-6 * 9.78).norm() < 1e-15);
    }

    fn err(text: &str, f: ImuFormat) -> ImuFileError {
        parse(text, f).unwrap_err()
    }

    #[test]
    fn validation_classes() {
        assert!(matches!(
            err("", ImuFormat::Auto),
            ImuFileError::Empty { .. }
        ));
        assert!(matches!(
            err("\n  \n", ImuFormat::Sdins),
            ImuFileError::Empty { .. }
        ));
        assert!(matches!(
            err(INC_H, ImuFormat::Auto),
            ImuFileError::NoData { line: 1, .. }
        ));
        let one = format!("{INC_H}{}", good_rows(1));
        assert!(matches!(
            err(&one, ImuFormat::Auto),
            ImuFileError::TooFewRows { rows: 1, .. }
        ));
        // truncated last line (no final newline): dropped with a warning that names it
        let mut t = format!("{INC_H}{}", good_rows(3));
        t.push_str("0.04,1e-4,2e-4");
        let d = parse(&t, ImuFormat::Auto).unwrap();
        assert_eq!(d.increments.len(), 3);
        assert!(
            d.warnings.iter().any(|w| w.contains("line 5")
                && w.contains("3 of 7 fields")
                && w.contains("dropped")),
            "{:?}",
            d.warnings
        );
        // wrong column count in the middle
        let t = format!("{INC_H}0.01,1,2,3,4,5\n{}", good_rows(3));
        let e = err(&t, ImuFormat::Auto);
        assert!(
            matches!(
                e,
                ImuFileError::ColumnCount {
                    line: 2,
                    expected: 7,
                    found: 6,
                    ..
                }
            ),
            "{e}"
        );
        // non-numeric
        let t = format!(
            "{INC_H}{}0.04,1e-4,abc,3e-4,0.01,0.02,-0.098\n",
            good_rows(3)
        );
        let e = err(&t, ImuFormat::Auto);
        assert!(
            matches!(&e, ImuFileError::NotANumber { line: 5, column: 3, name, .. } if name == "dtheta_y_rad"),
            "{e}"
        );
        assert!(
            e.to_string()
                .contains("test.csv:5: column 3 (dtheta_y_rad): expected a number, found `abc`"),
            "{e}"
        );
        // NaN / inf
        for bad in ["NaN", "inf", "-inf"] {
            let t = format!(
                "{INC_H}{}0.04,1e-4,2e-4,3e-4,{bad},0.02,-0.098\n",
                good_rows(3)
            );
            let e = err(&t, ImuFormat::Auto);
            assert!(
                matches!(
                    e,
                    ImuFileError::NonFinite {
                        line: 5,
                        column: 5,
                        ..
                    }
                ),
                "{e}"
            );
        }
        // time backwards, time repeating
        let t = format!(
            "{INC_H}{}0.02,1e-4,2e-4,3e-4,0.01,0.02,-0.098\n",
            good_rows(3)
        );
        assert!(matches!(
            err(&t, ImuFormat::Auto),
            ImuFileError::TimeNotIncreasing { line: 5, .. }
        ));
        let t = format!(
            "{INC_H}{}0.03,1e-4,2e-4,3e-4,0.01,0.02,-0.098\n",
            good_rows(3)
        );
        assert!(matches!(
            err(&t, ImuFormat::Auto),
            ImuFileError::TimeNotIncreasing { line: 5, .. }
        ));
        // irregular interval: 2 % off the median
        let t = format!(
            "{INC_H}{}0.0402,1e-4,2e-4,3e-4,0.01,0.02,-0.098\n",
            good_rows(3)
        );
        assert!(matches!(
            err(&t, ImuFormat::Auto),
            ImuFileError::IrregularInterval { line: 5, .. }
        ));
        // ... but 0.5 % is accepted
        let t = format!(
            "{INC_H}{}0.04005,1e-4,2e-4,3e-4,0.01,0.02,-0.098\n",
            good_rows(3)
        );
        assert!(parse(&t, ImuFormat::Auto).is_ok());
        // absurd: |Δθ| > π per sample, |f| > 1000 g
        let t = format!("{INC_H}{}0.04,3.2,0,0,0.01,0.02,-0.098\n", good_rows(3));
        assert!(matches!(
            err(&t, ImuFormat::Auto),
            ImuFileError::Absurd { line: 5, .. }
        ));
        let t = format!("{INC_H}{}0.04,0,0,0,0,0,-98.1\n", good_rows(3));
        let e = err(&t, ImuFormat::Auto);
        assert!(matches!(e, ImuFileError::Absurd { line: 5, .. }), "{e}");
        // a plain 1000 g is still fine at 0.01 s: Δv = 98.0665 m/s
        let t = format!("{INC_H}{}0.04,0,0,0,0,0,-98.0\n", good_rows(3));
        assert!(parse(&t, ImuFormat::Auto).is_ok());
        // wrong header for a forced format, unknown format
        assert!(matches!(
            err(&format!("{INC_H}{}", good_rows(3)), ImuFormat::NaveGo),
            ImuFileError::Header { line: 1, .. }
        ));
        assert!(matches!(
            err("a,b,c\n1,2,3\n", ImuFormat::Auto),
            ImuFileError::UnknownFormat { .. }
        ));
        // PSINS: header cut short, bad interval, truncated pulses
        let e = err("% x\n0 0 0 0 0 0\n34 108 380 0 10 9.78\n", ImuFormat::Psins);
        assert!(matches!(e, ImuFileError::Header { .. }), "{e}");
        let e = err(
            "% x\n0 0 0 0 0 0\n34 108 380 0 0 9.78\n0.1 0.1 0.1 125 125 125\n1 2 3 4 5 6\n",
            ImuFormat::Psins,
        );
        assert!(
            matches!(
                e,
                ImuFileError::BadValue {
                    line: 3,
                    column: 5,
                    ..
                }
            ),
            "{e}"
        );
        let e = err(
            "% x\n0 0 0 0 0 0\n34 108 380 0 10 9.78\n0.1 0.1 0.1 125 125 125\n",
            ImuFormat::Psins,
        );
        assert!(matches!(e, ImuFileError::NoData { line: 4, .. }), "{e}");
        let d = parse(
            "% x\n0 0 0 0 0 0\n34 108 380 0 10 9.78\n0.1 0.1 0.1 125 125 125\n1 2 3 4 5 6\n1 2 3 4 5 6\n1 2",
            ImuFormat::Psins,
        )
        .unwrap();
        assert_eq!(d.increments.len(), 2);
        assert!(d.warnings[0].contains("line 7"), "{:?}", d.warnings);
        // I/O error names the file
        let e = read_imu_file(Path::new("/nonexistent/x.imu"), ImuFormat::Auto).unwrap_err();
        assert!(
            e.to_string().starts_with("/nonexistent/x.imu: cannot read"),
            "{e}"
        );
        assert_eq!("psins-csv".parse::<ImuFormat>(), Ok(ImuFormat::PsinsCsv));
        assert!("foo".parse::<ImuFormat>().is_err());
    }

    #[test]
    fn intervals_bom_cut_lines_and_detection() {
        // absurd sample intervals: a 1e298 s step (regular, so only the range catches it)
        let t = format!(
            "{INC_H}0,1e-4,2e-4,3e-4,0.01,0.02,-0.098\n1e298,1e-4,2e-4,3e-4,0.01,0.02,-0.098\n2e298,1e-4,2e-4,3e-4,0.01,0.02,-0.098\n"
        );
        let e = err(&t, ImuFormat::Auto);
        assert!(
            matches!(e, ImuFileError::IntervalOutOfRange { line: 3, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("sample interval 1e298 s"), "{e}");
        let t = "100 1e-5 2e-5 3e-5 0.001 0.002 -0.049\n100.0000000001 1e-5 2e-5 3e-5 0.001 0.002 -0.049\n";
        assert!(matches!(
            err(t, ImuFormat::KfGins),
            ImuFileError::IntervalOutOfRange { .. }
        ));
        let e = err(
            "% x\n0 0 0 0 0 0\n34 108 380 0 1e300 9.78\n0.1 0.1 0.1 125 125 125\n1 2 3 4 5 6\n",
            ImuFormat::Psins,
        );
        assert!(
            matches!(e, ImuFileError::IntervalOutOfRange { line: 3, .. }),
            "{e}"
        );
        // byte-order mark accepted
        let d = parse(&format!("\u{feff}{INC_H}{}", good_rows(3)), ImuFormat::Auto).unwrap();
        assert_eq!(d.increments.len(), 3);
        // last line cut inside its last number, no final newline: KF-GINS (fixed decimals)
        let row = |t: f64| format!("{t:.3} 1.0e-5 2e-5 3e-5 0.00100 0.00200 -0.04900\n");
        let kf = format!(
            "{}{}{}100.015 1e-5 2e-5 3e-5 0.00100 0.00200 -0.049",
            row(100.0),
            row(100.005),
            row(100.01)
        );
        let d = parse(&kf, ImuFormat::Auto).unwrap();
        assert_eq!(d.increments.len(), 3);
        assert!(
            d.warnings[0].contains("line 4")
                && d.warnings[0].contains("`-0.049` has fewer decimals"),
            "{:?}",
            d.warnings
        );
        // ... and in the middle of the line: too few fields
        let d = parse(
            &format!("{INC_H}{}0.04,1e-4,2e", good_rows(3)),
            ImuFormat::Auto,
        )
        .unwrap();
        assert_eq!(d.increments.len(), 3);
        assert!(d.warnings[0].contains("line 5"), "{:?}", d.warnings);
        // a complete last line without newline: read, with a warning
        let t = format!("{INC_H}{}", good_rows(3));
        let d = parse(t.trim_end(), ImuFormat::Auto).unwrap();
        assert_eq!((d.increments.len(), d.warnings.len()), (3, 1));
        // detection reported; the increment header shared by sdins (FRD) and PSINS CSV (RFU)
        let d = parse(&t, ImuFormat::Auto).unwrap();
        assert_eq!(d.format, ImuFormat::Sdins);
        assert!(
            d.detection.as_deref().unwrap().contains("FRD"),
            "{:?}",
            d.detection
        );
        assert_eq!(parse(&t, ImuFormat::Sdins).unwrap().detection, None);
        // a PSINS trajectory CSV (z up: +g) is read as psins-csv, not as FRD
        let rfu: String = (0..5)
            .map(|k| format!("{},1e-4,2e-4,3e-4,0.01,0.02,0.098\n", 0.01 * (k + 1) as f64))
            .collect();
        let d = parse(&format!("{INC_H}{rfu}"), ImuFormat::Auto).unwrap();
        assert_eq!(d.format, ImuFormat::PsinsCsv);
        assert_eq!(d.increments[0].dv_b_mps, Vec3::new(0.02, 0.01, -0.098));
        // no gravity on z (free fall, or z horizontal): refused, candidates listed
        let zero: String = (0..5)
            .map(|k| format!("{},1e-4,2e-4,3e-4,0.01,0.02,0.0\n", 0.01 * (k + 1) as f64))
            .collect();
        let e = err(&format!("{INC_H}{zero}"), ImuFormat::Auto);
        match &e {
            ImuFileError::Ambiguous {
                candidates,
                line: 1,
                ..
            } => {
                assert_eq!(candidates, &vec!["sdins", "psins-csv"])
            }
            _ => panic!("{e}"),
        }
        assert!(
            e.to_string().contains("candidates: sdins, psins-csv"),
            "{e}"
        );
    }
}
