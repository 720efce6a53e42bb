//! NaveGo parameter files (`imu1_params.txt`, `imu2_params.txt`, `gnss_params.txt`, as
//! written next to the converted NaveGo CSVs): one `name = [v1, v2, …]` per line, `#`
//! comments, values in NaveGo's units (SI, radians). Parsed into typed structs whose field
//! names carry the units.
//!
//! NaveGo's own field documentation (its `ins_gnss` and IMU profile headers) gives the units
//! used here: `arw` rad/s/√Hz (= rad/√s), `vrw` m/s²/√Hz (= m/s/√s), `arrw` rad/s²/√Hz,
//! `vrrw` m/s³/√Hz, `gb_sta`/`gb_dyn`/`g_std` rad/s, `ab_sta`/`ab_dyn`/`a_std` m/s²,
//! `gb_corr`/`ab_corr` s, `gb_psd` rad/s/√Hz, `ab_psd` m/s²/√Hz, `ini_align` and
//! `ini_align_err` rad in the order \[roll, pitch, yaw\]; GNSS `stdm` m in the order
//! \[lat (north), lon (east), h (height)\], `stdv` m/s \[N, E, D\], `larm` m in the body frame
//! (x forward, y right, z down: FRD), `freq` Hz, `zupt_th` m/s, `zupt_win` s, `eps` s, `std`
//! \[rad, rad, m\].
//!
//! Validation: every value finite; standard deviations, noise densities and biases' σ ≥ 0;
//! correlation times and rates > 0; GNSS `stdm`/`stdv` in \[1e-6, 1e6\]; `ini_align` within |roll| ≤ π, |pitch| ≤ π/2,
//! |yaw| ≤ 2π. Each failure is a [`ParamsError`] with file:line:column and the field name.
//! Fields the parser does not know are kept in `other` (name → values) rather than refused.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Why a NaveGo parameter file could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ParamsError {
    /// The file could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// the file
        file: PathBuf,
        /// the cause
        source: std::io::Error,
    },
    /// A line is not `name = [values]`.
    #[error("{}:{line}:{column}: expected `name = [v1, v2, ...]`, found `{found}`", file.display())]
    Syntax {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column
        column: usize,
        /// the text
        found: String,
    },
    /// A value is not a number or not finite.
    #[error("{}:{line}:{column}: field `{field}`: expected a finite number, found `{text}`", file.display())]
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
    /// A field has the wrong number of values.
    #[error("{}:{line}:{column}: field `{field}`: expected {expected} value(s), found {found}", file.display())]
    WrongLength {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// 1-based character column
        column: usize,
        /// field name
        field: String,
        /// values expected
        expected: usize,
        /// values found
        found: usize,
    },
    /// A value is outside its range.
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
    /// A field appears twice.
    #[error("{}:{line}:1: field `{field}` given twice (first on line {first})", file.display())]
    Duplicate {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// line of the first definition
        first: usize,
        /// field name
        field: String,
    },
    /// A required field is missing.
    #[error("{}: missing field `{field}` ({what})", file.display())]
    Missing {
        /// the file
        file: PathBuf,
        /// field name
        field: &'static str,
        /// what it is
        what: &'static str,
    },
}

/// One parsed field: its values, where it was, and where each value starts.
#[derive(Clone, Debug, PartialEq)]
struct Entry {
    line: usize,
    name_column: usize,
    values: Vec<f64>,
    value_columns: Vec<usize>,
}

/// NaveGo IMU error parameters (from `imuN_params.txt`), per axis X, Y, Z of the body frame.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct NavegoImuParams {
    /// angle random walk `arw` \[rad/√s\]
    pub arw_rad_per_sqrt_s: [f64; 3],
    /// velocity random walk `vrw` \[m/s/√s\]
    pub vrw_mps_per_sqrt_s: [f64; 3],
    /// angle rate random walk `arrw` \[rad/s/√s\], zero if absent
    pub arrw_rps_per_sqrt_s: [f64; 3],
    /// velocity rate random walk `vrrw` \[m/s²/√s\], zero if absent
    pub vrrw_mps2_per_sqrt_s: [f64; 3],
    /// gyro static (turn-on) bias `gb_sta` \[rad/s\]
    pub gb_sta_rps: [f64; 3],
    /// accelerometer static (turn-on) bias `ab_sta` \[m/s²\]
    pub ab_sta_mps2: [f64; 3],
    /// gyro dynamic bias (Gauss–Markov σ) `gb_dyn` \[rad/s\]
    pub gb_dyn_rps: [f64; 3],
    /// accelerometer dynamic bias (Gauss–Markov σ) `ab_dyn` \[m/s²\]
    pub ab_dyn_mps2: [f64; 3],
    /// gyro bias correlation time `gb_corr` \[s\]
    pub gb_corr_s: [f64; 3],
    /// accelerometer bias correlation time `ab_corr` \[s\]
    pub ab_corr_s: [f64; 3],
    /// gyro dynamic-bias root-PSD `gb_psd` \[rad/s/√Hz\], if given
    pub gb_psd_rps_per_sqrt_hz: Option<[f64; 3]>,
    /// accelerometer dynamic-bias root-PSD `ab_psd` \[m/s²/√Hz\], if given
    pub ab_psd_mps2_per_sqrt_hz: Option<[f64; 3]>,
    /// gyro white-noise standard deviation per sample `g_std` \[rad/s\], if given
    pub g_std_rps: Option<[f64; 3]>,
    /// accelerometer white-noise standard deviation per sample `a_std` \[m/s²\], if given
    pub a_std_mps2: Option<[f64; 3]>,
    /// sampling frequency `freq` \[Hz\], if given
    pub freq_hz: Option<f64>,
    /// initial attitude `ini_align` \[roll, pitch, yaw\] \[rad\]
    pub ini_align_rpy_rad: [f64; 3],
    /// initial attitude σ `ini_align_err` \[roll, pitch, yaw\] \[rad\]
    pub ini_align_err_rpy_rad: [f64; 3],
    /// fields not interpreted above (for example `m_std`, a magnetometer σ whose unit
    /// NaveGo does not document), name → values as written
    pub other: BTreeMap<String, Vec<f64>>,
}

/// NaveGo GNSS parameters (from `gnss_params.txt`).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct NavegoGnssParams {
    /// position σ `stdm` \[north, east, down\] \[m\] (NaveGo: \[lat, lon, h\]; σ_D = σ_h)
    pub stdm_ned_m: [f64; 3],
    /// velocity σ `stdv` \[N, E, D\] \[m/s\]
    pub stdv_ned_mps: [f64; 3],
    /// lever arm IMU → antenna `larm`, body FRD \[m\]
    pub larm_frd_m: [f64; 3],
    /// fix rate `freq` \[Hz\]
    pub freq_hz: f64,
    /// ZUPT speed threshold `zupt_th` \[m/s\], if given
    pub zupt_th_mps: Option<f64>,
    /// ZUPT window `zupt_win` \[s\], if given
    pub zupt_win_s: Option<f64>,
    /// IMU-to-GNSS time matching window `eps` \[s\], if given
    pub eps_s: Option<f64>,
    /// position σ in NaveGo's angular form `std` \[lat rad, lon rad, h m\], if given
    pub std_lat_rad_lon_rad_h_m: Option<[f64; 3]>,
    /// fields not interpreted above, name → values as written
    pub other: BTreeMap<String, Vec<f64>>,
}

/// Read `imuN_params.txt`.
pub fn read_navego_imu_params(path: &Path) -> Result<NavegoImuParams, ParamsError> {
    parse_navego_imu_params(path, &read(path)?)
}

/// Read `gnss_params.txt`.
pub fn read_navego_gnss_params(path: &Path) -> Result<NavegoGnssParams, ParamsError> {
    parse_navego_gnss_params(path, &read(path)?)
}

fn read(path: &Path) -> Result<String, ParamsError> {
    let bytes = crate::input::read_capped(path).map_err(|source| ParamsError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    Ok(crate::input::text_lossy(bytes))
}

/// Range class of a field.
#[derive(Clone, Copy)]
enum Range {
    /// ≥ 0 (σ, densities)
    NonNegative,
    /// > 0 (times, rates)
    Positive,
    /// any finite value
    Any,
    /// a measurement σ in \[1e-6, 1e6\] (the GNSS readers' range)
    Sigma,
    /// ini_align: |roll| ≤ π, |pitch| ≤ π/2, |yaw| ≤ 2π
    Attitude,
}

struct Fields<'a> {
    file: &'a Path,
    map: BTreeMap<String, Entry>,
}

impl Fields<'_> {
    fn check(&self, name: &str, e: &Entry, range: Range) -> Result<(), ParamsError> {
        use std::f64::consts::PI;
        for (i, (&v, &col)) in e.values.iter().zip(&e.value_columns).enumerate() {
            let (ok, expected) = match range {
                Range::NonNegative => (v >= 0.0, "a value >= 0".to_string()),
                Range::Positive => (v > 0.0, "a value > 0".to_string()),
                Range::Any => (true, String::new()),
                Range::Sigma => (
                    (1e-6..=1e6).contains(&v),
                    "a value in [1e-6, 1e6]".to_string(),
                ),
                Range::Attitude => {
                    let lim = [PI, PI / 2.0, 2.0 * PI][i.min(2)];
                    let axis = ["roll", "pitch", "yaw"][i.min(2)];
                    (v.abs() <= lim, format!("|{axis}| <= {lim} rad"))
                }
            };
            if !ok {
                return Err(ParamsError::OutOfRange {
                    file: self.file.to_path_buf(),
                    line: e.line,
                    column: col,
                    field: name.to_string(),
                    value: v,
                    expected,
                });
            }
        }
        Ok(())
    }

    fn take<const N: usize>(
        &mut self,
        name: &'static str,
        what: &'static str,
        range: Range,
    ) -> Result<[f64; N], ParamsError> {
        self.take_opt::<N>(name, range)?
            .ok_or(ParamsError::Missing {
                file: self.file.to_path_buf(),
                field: name,
                what,
            })
    }

    fn take_opt<const N: usize>(
        &mut self,
        name: &str,
        range: Range,
    ) -> Result<Option<[f64; N]>, ParamsError> {
        let Some(e) = self.map.remove(name) else {
            return Ok(None);
        };
        if e.values.len() != N {
            return Err(ParamsError::WrongLength {
                file: self.file.to_path_buf(),
                line: e.line,
                column: e.name_column,
                field: name.to_string(),
                expected: N,
                found: e.values.len(),
            });
        }
        self.check(name, &e, range)?;
        let mut out = [0.0; N];
        out.copy_from_slice(&e.values);
        Ok(Some(out))
    }

    fn rest(self) -> BTreeMap<String, Vec<f64>> {
        self.map.into_iter().map(|(k, e)| (k, e.values)).collect()
    }
}

/// Parse the text of `imuN_params.txt`; `file` names the file in errors.
pub fn parse_navego_imu_params(file: &Path, text: &str) -> Result<NavegoImuParams, ParamsError> {
    let mut f = Fields {
        file,
        map: parse_entries(file, text)?,
    };
    use Range::*;
    let p = NavegoImuParams {
        arw_rad_per_sqrt_s: f.take("arw", "angle random walk, rad/s/root-Hz", NonNegative)?,
        vrw_mps_per_sqrt_s: f.take("vrw", "velocity random walk, m/s^2/root-Hz", NonNegative)?,
        arrw_rps_per_sqrt_s: f.take_opt("arrw", NonNegative)?.unwrap_or([0.0; 3]),
        vrrw_mps2_per_sqrt_s: f.take_opt("vrrw", NonNegative)?.unwrap_or([0.0; 3]),
        gb_sta_rps: f.take("gb_sta", "gyro static bias, rad/s", Any)?,
        ab_sta_mps2: f.take("ab_sta", "accelerometer static bias, m/s^2", Any)?,
        gb_dyn_rps: f.take("gb_dyn", "gyro dynamic bias, rad/s", NonNegative)?,
        ab_dyn_mps2: f.take("ab_dyn", "accelerometer dynamic bias, m/s^2", NonNegative)?,
        gb_corr_s: f.take("gb_corr", "gyro bias correlation time, s", Positive)?,
        ab_corr_s: f.take(
            "ab_corr",
            "accelerometer bias correlation time, s",
            Positive,
        )?,
        gb_psd_rps_per_sqrt_hz: f.take_opt("gb_psd", NonNegative)?,
        ab_psd_mps2_per_sqrt_hz: f.take_opt("ab_psd", NonNegative)?,
        g_std_rps: f.take_opt("g_std", NonNegative)?,
        a_std_mps2: f.take_opt("a_std", NonNegative)?,
        freq_hz: f.take_opt::<1>("freq", Positive)?.map(|v| v[0]),
        ini_align_rpy_rad: f.take("ini_align", "initial [roll pitch yaw], rad", Attitude)?,
        ini_align_err_rpy_rad: f.take(
            "ini_align_err",
            "initial attitude sigma [roll pitch yaw], rad",
            NonNegative,
        )?,
        other: BTreeMap::new(),
    };
    Ok(NavegoImuParams {
        other: f.rest(),
        ..p
    })
}

/// Parse the text of `gnss_params.txt`; `file` names the file in errors.
pub fn parse_navego_gnss_params(file: &Path, text: &str) -> Result<NavegoGnssParams, ParamsError> {
    let mut f = Fields {
        file,
        map: parse_entries(file, text)?,
    };
    use Range::*;
    let stdm: [f64; 3] = f.take("stdm", "position sigma [lat lon h], m", Sigma)?;
    let stdv: [f64; 3] = f.take("stdv", "velocity sigma [N E D], m/s", Sigma)?;
    let p = NavegoGnssParams {
        stdm_ned_m: stdm,
        stdv_ned_mps: stdv,
        larm_frd_m: f.take_opt("larm", Any)?.unwrap_or([0.0; 3]),
        freq_hz: f.take::<1>("freq", "fix rate, Hz", Positive)?[0],
        zupt_th_mps: f.take_opt::<1>("zupt_th", NonNegative)?.map(|v| v[0]),
        zupt_win_s: f.take_opt::<1>("zupt_win", NonNegative)?.map(|v| v[0]),
        eps_s: f.take_opt::<1>("eps", NonNegative)?.map(|v| v[0]),
        std_lat_rad_lon_rad_h_m: f.take_opt("std", Positive)?,
        other: BTreeMap::new(),
    };
    Ok(NavegoGnssParams {
        other: f.rest(),
        ..p
    })
}

/// 1-based character column of byte offset `byte` in `line`.
fn char_col(line: &str, byte: usize) -> usize {
    line[..byte].chars().count() + 1
}

fn parse_entries(file: &Path, text: &str) -> Result<BTreeMap<String, Entry>, ParamsError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut map: BTreeMap<String, Entry> = BTreeMap::new();
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = raw.trim_end_matches('\r');
        let body = match line.find('#') {
            Some(k) => &line[..k],
            None => line,
        };
        if body.trim().is_empty() {
            continue;
        }
        let syntax = |at: usize| ParamsError::Syntax {
            file: file.to_path_buf(),
            line: line_no,
            column: char_col(line, at),
            found: line.trim().chars().take(80).collect(),
        };
        let Some(eq) = body.find('=') else {
            return Err(syntax(body.len() - body.trim_start().len()));
        };
        let name = body[..eq].trim();
        let name_start = body.len() - body.trim_start().len();
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(syntax(name_start));
        }
        let rhs = &body[eq + 1..];
        let rhs_trim = rhs.trim();
        // byte offset of the values inside `line`
        let (vals, vals_off) = if let Some(inner) = rhs_trim.strip_prefix('[') {
            let Some(inner) = inner.strip_suffix(']') else {
                return Err(syntax(eq + 1 + rhs.len() - rhs.trim_start().len()));
            };
            let off = eq + 1 + (rhs.len() - rhs.trim_start().len()) + 1;
            (inner, off)
        } else {
            (rhs, eq + 1)
        };
        let mut values = Vec::new();
        let mut value_columns = Vec::new();
        let mut k = 0;
        let bytes = vals.as_bytes();
        while k < bytes.len() {
            if bytes[k] == b',' || bytes[k] == b';' || bytes[k].is_ascii_whitespace() {
                k += 1;
                continue;
            }
            let start = k;
            while k < bytes.len()
                && !(bytes[k] == b',' || bytes[k] == b';' || bytes[k].is_ascii_whitespace())
            {
                k += 1;
            }
            let tok = &vals[start..k];
            let col = char_col(line, vals_off + start);
            match tok.parse::<f64>() {
                Ok(v) if v.is_finite() => {
                    values.push(v);
                    value_columns.push(col);
                }
                _ => {
                    return Err(ParamsError::NotANumber {
                        file: file.to_path_buf(),
                        line: line_no,
                        column: col,
                        field: name.to_string(),
                        text: tok.to_string(),
                    })
                }
            }
        }
        if let Some(prev) = map.get(name) {
            return Err(ParamsError::Duplicate {
                file: file.to_path_buf(),
                line: line_no,
                first: prev.line,
                field: name.to_string(),
            });
        }
        map.insert(
            name.to_string(),
            Entry {
                line: line_no,
                name_column: char_col(line, name_start),
                values,
                value_columns,
            },
        );
    }
    Ok(map)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    const IMU: &str = "# comment\nvrw = [0.1, 0.1, 0.1]\narw = [1e-3 1e-3 1e-3]\n\
        ab_dyn = [1, 2, 3]\ngb_dyn = [4, 5, 6]\nab_corr = [100., 100., 100.]\n\
        gb_corr = [100., 100., 100.]\nab_sta = [-0.5, 0.5, 0.5]\ngb_sta = [0.05, 0.05, 0.05]\n\
        m_std = [1, 2, 3]\nini_align_err = [0.01 , 0.01 , 0.03]\n\
        ini_align = [ 0.                , -0.                , -0.26]\n";

    fn p(t: &str) -> Result<NavegoImuParams, ParamsError> {
        parse_navego_imu_params(Path::new("imu.txt"), t)
    }

    #[test]
    fn imu_fields_and_units() {
        let q = p(IMU).unwrap();
        assert_eq!(q.vrw_mps_per_sqrt_s, [0.1; 3]);
        assert_eq!(q.arw_rad_per_sqrt_s, [1e-3; 3]);
        assert_eq!(q.ab_sta_mps2, [-0.5, 0.5, 0.5]);
        assert_eq!(q.ini_align_rpy_rad, [0.0, 0.0, -0.26]);
        assert_eq!(q.arrw_rps_per_sqrt_s, [0.0; 3]);
        assert_eq!(q.gb_psd_rps_per_sqrt_hz, None);
        assert_eq!(q.other.get("m_std"), Some(&vec![1.0, 2.0, 3.0]));
    }

    #[test]
    fn imu_errors_are_located() {
        let e = p(&IMU.replace("arw = [1e-3 1e-3 1e-3]", "arw = [1e-3 nan 1e-3]")).unwrap_err();
        assert!(
            e.to_string().starts_with("imu.txt:3:13: field `arw`"),
            "{e}"
        );
        let e =
            p(&IMU.replace("gb_corr = [100., 100., 100.]", "gb_corr = [100., 0, 1]")).unwrap_err();
        assert!(
            matches!(
                e,
                ParamsError::OutOfRange {
                    line: 7,
                    column: 18,
                    ..
                }
            ),
            "{e}"
        );
        let e = p(&IMU.replace("vrw = [0.1, 0.1, 0.1]", "vrw = [0.1, 0.1]")).unwrap_err();
        assert!(
            matches!(
                e,
                ParamsError::WrongLength {
                    line: 2,
                    column: 1,
                    expected: 3,
                    found: 2,
                    ..
                }
            ),
            "{e}"
        );
        let e = p(&IMU.replace("vrw = [0.1, 0.1, 0.1]\n", "")).unwrap_err();
        assert!(
            matches!(e, ParamsError::Missing { field: "vrw", .. }),
            "{e}"
        );
        let e = p(&format!("{IMU}arw = [1, 1, 1]\n")).unwrap_err();
        assert!(
            matches!(
                e,
                ParamsError::Duplicate {
                    line: 13,
                    first: 3,
                    ..
                }
            ),
            "{e}"
        );
        let e = p(&format!("{IMU}what is this\n")).unwrap_err();
        assert!(matches!(e, ParamsError::Syntax { line: 13, .. }), "{e}");
        let e = p(&format!("{IMU}x = [1, 2\n")).unwrap_err();
        assert!(matches!(e, ParamsError::Syntax { line: 13, .. }), "{e}");
        let e = p(&IMU.replace("-0.26]", "7.0]")).unwrap_err();
        assert!(matches!(e, ParamsError::OutOfRange { line: 12, .. }), "{e}");
        assert!(matches!(p("").unwrap_err(), ParamsError::Missing { .. }));
        // BOM accepted
        assert!(p(&format!("\u{feff}{IMU}")).is_ok());
    }

    #[test]
    fn gnss_fields() {
        let t = "stdm = [5, 5, 10]   # m\nstdv = [0.05, 0.05, 0.05]\nlarm = [0, 0, 0]\nfreq = [5]\neps = [0.001]\n";
        let g = parse_navego_gnss_params(Path::new("g.txt"), t).unwrap();
        assert_eq!(g.stdm_ned_m, [5.0, 5.0, 10.0]);
        assert_eq!(g.freq_hz, 5.0);
        assert_eq!(g.eps_s, Some(0.001));
        let e =
            parse_navego_gnss_params(Path::new("g.txt"), &t.replace("[5, 5, 10]", "[5, 0, 10]"))
                .unwrap_err();
        assert!(e.to_string().starts_with("g.txt:1:12: field `stdm`"), "{e}");
    }
}
