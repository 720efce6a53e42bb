//! Recorded trajectories from files (`sdins truth --from-reference`; docs/scenarios.md
//! §"Recorded trajectories"); `crate::scenario::from_reference` turns one into a scenario.
//!
//! Formats: the sdins `truth.csv`, a PSINS `avp` CSV, NaveGo's `ref.csv` (read by
//! [`crate::io::truth_file`], converted to sdins conventions there), and any CSV with a header
//! through a [`ColumnMap`] (NED velocity, body FRD, ZYX Euler angles).

use crate::io::columns::{ColumnsError, HeaderMode, InputKind, MapOrigin, YawConvention};
use crate::io::gnss_columns::{height, velocity};
use crate::io::imu_columns::{delim_name, InputReport};
use crate::io::table::Table;
use crate::io::time::{RunClock, TimeConverter, TimeSpec};
use crate::io::truth_file::TruthFileError;
use crate::truth::reference::{ReferenceError, ReferenceSample};
use sdins_core::math::{c_b_n_from_euler, euler_from_c_b_n, Euler, Mat3, Vec3};
use std::path::{Path, PathBuf};

/// Which reader a reference file needs.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ReferenceFormat {
    /// told apart by the header (sdins, PSINS avp or NaveGo)
    Auto,
    /// a CSV with a header, columns named by the map
    Generic(Box<ColumnMap>),
}

/// Which columns of a generic CSV hold which quantity: a reference map of the one
/// column-map mechanism ([`crate::io::columns`]): `t_s=COL,lat_deg=COL,lon_deg=COL,h_m=COL,
/// roll_deg=COL,pitch_deg=COL,yaw_deg=COL` with any unit of the vocabulary (`_rad`, `t_ms`,
/// …), the height datum (`h_m` ellipsoidal, or `alt_msl_m` with `undulation_m=COL` or
/// [`Self::undulation_m`]), optional velocity `v_n_mps,v_e_mps` with `v_d_mps` (NED) or
/// `v_u_mps` (ENU), the attitude convention `yaw=ned|enu|enu-east`, the time base
/// `time=relative|gps-sow|unix`, `delim=`, `header=`.
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnMap {
    /// the map
    pub map: crate::io::columns::ColumnMap,
    /// GPS week of a seconds-of-week file without week column
    pub gps_week: Option<u32>,
    /// constant time offset \[s\]
    pub offset_s: f64,
    /// constant geoid undulation \[m\] for `alt_msl_m`
    pub undulation_m: Option<f64>,
}

impl ColumnMap {
    /// Parse the text form (see [`ColumnMap`]); messages name `--columns`.
    pub fn parse(s: &str) -> Result<Self, ReferenceFileError> {
        Ok(Self::new(crate::io::columns::ColumnMap::parse(
            InputKind::Reference,
            s,
            MapOrigin::default(),
        )?))
    }
    /// Default settings around a map.
    pub fn new(map: crate::io::columns::ColumnMap) -> Self {
        Self {
            map,
            gps_week: None,
            offset_s: 0.0,
            undulation_m: None,
        }
    }
}

/// `C_b^n` (FRD→NED) from a file's roll, pitch, yaw \[rad\] in its convention.
pub fn c_b_n_from_convention(conv: YawConvention, roll: f64, pitch: f64, yaw: f64) -> Mat3 {
    match conv {
        YawConvention::Enu => crate::io::truth_file::c_b_n_from_psins(pitch, roll, yaw),
        YawConvention::EnuEast => {
            // C(FLU→ENU) = Rz(yaw) Ry(pitch) Rx(roll); ENU→NED swaps x, y and negates z,
            // FRD→FLU negates y and z
            let c = c_b_n_from_euler(&Euler::new(roll, pitch, yaw));
            let q_n = Mat3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
            let q_b = Mat3::from_diagonal(&Vec3::new(1.0, -1.0, -1.0));
            q_n * c * q_b
        }
        _ => c_b_n_from_euler(&Euler::new(roll, pitch, yaw)),
    }
}

/// Why a reference file could not be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReferenceFileError {
    /// A reader of a known format failed.
    #[error(transparent)]
    File(#[from] TruthFileError),
    /// A column map or a file read through one.
    #[error(transparent)]
    Map(#[from] ColumnsError),
    /// The column map.
    #[error("--columns: {message}")]
    Columns {
        /// what is wrong
        message: String,
    },
    /// The rows cannot be interpolated.
    #[error("{}: {source}", file.display())]
    Reference {
        /// the file
        file: PathBuf,
        /// cause
        source: ReferenceError,
    },
    /// An option.
    #[error("{option}: {message}")]
    Option {
        /// the option
        option: &'static str,
        /// what is wrong
        message: String,
    },
    /// The interpolated motion leaves the kinematic envelope.
    #[error("{}: {message}", file.display())]
    Envelope {
        /// the file
        file: PathBuf,
        /// the envelope check's message
        message: String,
    },
}

/// Read a generic CSV through `map` (times on the file's own clock for relative time,
/// else seconds after the first row's whole GPST second).
pub fn parse_generic(
    path: &Path,
    text: &str,
    map: &ColumnMap,
) -> Result<Vec<ReferenceSample>, ReferenceFileError> {
    Ok(parse_generic_on(path, text, map, None)?.0)
}

/// [`parse_generic`] on a run's clock (`None`: the file sets it), with the report.
pub fn parse_generic_on(
    path: &Path,
    text: &str,
    cm: &ColumnMap,
    clock: Option<&RunClock>,
) -> Result<(Vec<ReferenceSample>, InputReport), ReferenceFileError> {
    let m = &cm.map;
    let need = |q: &str, hint: &str| m.need(q, hint).cloned();
    let tcol = need("t", "t_s, t_ms, t_us or t_ns")?;
    let lat = need("lat", "lat_deg or lat_rad")?;
    let lon = need("lon", "lon_deg or lon_rad")?;
    let att = [
        need("roll", "roll_deg or roll_rad")?,
        need("pitch", "pitch_deg or pitch_rad")?,
        need("yaw", "yaw_deg or yaw_rad")?,
    ];
    let t = Table::new(
        path,
        text,
        m.delim.unwrap_or_default(),
        m.header.unwrap_or(HeaderMode::Auto),
    )?;
    let (ti, lai, loi) = (t.index(&tcol)?, t.index(&lat)?, t.index(&lon)?);
    let ai = [t.index(&att[0])?, t.index(&att[1])?, t.index(&att[2])?];
    let wi = match m.get("week") {
        Some(c) => Some(t.index(c)?),
        None => None,
    };
    let hgt = height(&t, m, cm.undulation_m)?;
    let vel = velocity(&t, m)?;
    let conv_yaw = m.yaw.unwrap_or_default();
    let spec = TimeSpec {
        kind: m.time.unwrap_or_default(),
        gps_week: cm.gps_week,
        week_column: wi.is_some(),
        offset_s: cm.offset_s,
    };
    let mut conv = TimeConverter::new(&spec, clock).map_err(|e| ColumnsError::map(&m.origin, e))?;
    let mut out: Vec<ReferenceSample> = Vec::with_capacity(t.lines.len());
    let mut f = Vec::with_capacity(t.width);
    for k in 0..t.lines.len() {
        let line = t.row(k, &mut f)?;
        let week = match wi {
            Some(i) => Some(t.num(line, &f, i, "week")?),
            None => None,
        };
        let tk = conv
            .convert(f[ti], tcol.unit.time_exp10, week)
            .map_err(|e| t.err(line, &tcol.key, e))?;
        if let Some(prev) = out.last() {
            if tk <= prev.t_s {
                return Err(t
                    .err(
                        line,
                        &tcol.key,
                        format!(
                            "{tk} s does not increase on the previous row's {} s",
                            prev.t_s
                        ),
                    )
                    .into());
            }
        }
        let la = t.num(line, &f, lai, &lat.key)? * lat.unit.to_si;
        if la.abs() > 89.99f64.to_radians() {
            return Err(t.err(line, &lat.key, format!("latitude {:.4} deg is beyond ±89.99 deg (the NED mechanization is singular at the poles)", la.to_degrees())).into());
        }
        let lo = t.num(line, &f, loi, &lon.key)? * lon.unit.to_si;
        let h = hgt.value(&t, line, &f)?;
        let mut e = [0.0; 3];
        for i in 0..3 {
            e[i] = t.num(line, &f, ai[i], &att[i].key)? * att[i].unit.to_si;
        }
        let euler = if conv_yaw == YawConvention::Ned {
            Euler::new(e[0], e[1], e[2])
        } else {
            euler_from_c_b_n(&c_b_n_from_convention(conv_yaw, e[0], e[1], e[2]))
        };
        let v_n_mps = match &vel {
            Some(vc) => {
                let mut v = [0.0; 3];
                for (i, vi) in v.iter_mut().enumerate() {
                    *vi = t.num(line, &f, vc.idx[i], &vc.keys[i])?;
                }
                if vc.up {
                    v[2] = -v[2];
                }
                Some(Vec3::from(v))
            }
            None => None,
        };
        out.push(ReferenceSample {
            t_s: tk,
            lat_rad: la,
            lon_rad: lo,
            h_m: h,
            euler,
            v_n_mps,
        });
    }
    let clock = conv
        .clock()
        .ok_or_else(|| t.err(t.lines[0].0, &tcol.key, "no time".into()))?;
    let report = InputReport {
        kind: "reference",
        map_origin: m.origin.to_string(),
        time_base: spec.kind.name(),
        clock,
        offset_s: cm.offset_s,
        gps_week: cm.gps_week,
        rollovers: conv.rollovers,
        delimiter: delim_name(t.delim),
        header: t.header.is_some(),
        rows: out.len(),
        notes: Vec::new(),
    };
    Ok((out, report))
}

/// Read a reference file in `format`.
pub fn read_reference(
    path: &Path,
    format: &ReferenceFormat,
) -> Result<Vec<ReferenceSample>, ReferenceFileError> {
    match format {
        ReferenceFormat::Auto => {
            let rows = crate::io::truth_file::read_truth(path)?;
            Ok(rows
                .iter()
                .map(|s| ReferenceSample {
                    t_s: s.t_s,
                    lat_rad: s.lat_rad,
                    lon_rad: s.lon_rad,
                    h_m: s.h_m,
                    euler: euler_from_c_b_n(&s.c_b_n),
                    v_n_mps: Some(s.v_n_mps),
                })
                .collect())
        }
        ReferenceFormat::Generic(map) => {
            let bytes = crate::input::read_capped(path).map_err(|source| TruthFileError::Io {
                file: path.into(),
                source,
            })?;
            parse_generic(path, &crate::input::text_lossy(bytes), map)
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    const MAP: &str = "t_s=time,lat_deg=lat,lon_deg=lon,h_m=alt,roll_deg=r,pitch_deg=p,yaw_deg=y";

    #[test]
    fn column_map_parses_and_rejects() {
        let m = ColumnMap::parse(MAP).unwrap();
        assert_eq!(
            m.map.get("t").unwrap().column,
            crate::io::columns::ColumnRef::Name("time".into())
        );
        assert_eq!(m.map.get("yaw").unwrap().unit.suffix, "deg");
        assert!(m.map.get("v_n").is_none());
        for (bad, what) in [
            (format!("{MAP},lat_rad=x"), "map the same quantity"),
            (format!("{MAP},speed=a"), "unknown key `speed`"),
            (format!("{MAP},t_s=b"), "twice"),
            ("t_s".to_string(), "KEY=COLUMN"),
        ] {
            let e = ColumnMap::parse(&bad).unwrap_err().to_string();
            assert!(
                e.starts_with("--columns: ") && e.contains(what),
                "{bad}: {e}"
            );
        }
        let p = Path::new("r.csv");
        let ok = "time,lat,lon,alt,r,p,y\n0,45,7,10,1,2,3\n";
        for (bad, what) in [
            ("t_s=time".to_string(), "missing `lat_UNIT"),
            (format!("{MAP},v_n_mps=a"), "all velocity columns"),
        ] {
            let e = parse_generic(p, ok, &ColumnMap::parse(&bad).unwrap())
                .unwrap_err()
                .to_string();
            assert!(e.contains(what), "{bad}: {e}");
        }
    }

    #[test]
    fn yaw_conventions_agree() {
        // a level vehicle heading 30° east of north
        let ned = c_b_n_from_convention(YawConvention::Ned, 0.0, 0.0, 30f64.to_radians());
        let enu = c_b_n_from_convention(YawConvention::Enu, 0.0, 0.0, -30f64.to_radians());
        let east = c_b_n_from_convention(YawConvention::EnuEast, 0.0, 0.0, 60f64.to_radians());
        assert!((ned - enu).abs().max() < 1e-15);
        assert!((ned - east).abs().max() < 1e-15);
        // nose up 10°, right wing down 5°: KITTI's pitch is positive nose down
        let ned = c_b_n_from_convention(YawConvention::Ned, 0.1, 0.2, 0.3);
        let e = euler_from_c_b_n(&ned);
        let east = c_b_n_from_convention(
            YawConvention::EnuEast,
            e.roll_rad,
            -e.pitch_rad,
            std::f64::consts::FRAC_PI_2 - e.yaw_rad,
        );
        assert!((ned - east).abs().max() < 1e-15);
    }

    #[test]
    fn generic_rows_are_located() {
        let m = ColumnMap::parse(MAP).unwrap();
        let p = Path::new("r.csv");
        let ok = "time,lat,lon,alt,r,p,y\n0,45,7,10,1,2,3\n0.1,45,7,10,1,2,3\n";
        let rows = parse_generic(p, ok, &m).unwrap();
        assert_eq!(rows.len(), 2);
        assert!((rows[0].lat_rad - 45f64.to_radians()).abs() < 1e-15);
        assert!((rows[1].euler.yaw_rad - 3f64.to_radians()).abs() < 1e-15);
        for (text, needle) in [
            (
                "time,lat,lon,alt,r,p\n0,45,7,10,1,2\n",
                "r.csv:1: yaw_deg: no column `y`",
            ),
            (
                "time,lat,lon,alt,r,p,y\n0,45,7,10,1,2,3\n1,45,7,10,1,2,x\n",
                "r.csv:3: yaw_deg: `x` is not a number",
            ),
            (
                "time,lat,lon,alt,r,p,y\n0,45,7,10,1,2,3\n0,45,7,10,1,2,3\n",
                "r.csv:3: t_s: 0 s does not increase",
            ),
            (
                "time,lat,lon,alt,r,p,y\n0,45,7,10,1,2,NaN\n",
                "r.csv:2: yaw_deg: `NaN` is not finite",
            ),
            (
                "time,lat,lon,alt,r,p,y\n0,90,7,10,1,2,3\n",
                "r.csv:2: lat_deg: latitude",
            ),
            (
                "time,lat,lon,alt,r,p,y\n0,45,7\n",
                "r.csv:2: (row): expected 7 fields, found 3",
            ),
        ] {
            let e = parse_generic(p, text, &m).unwrap_err().to_string();
            assert!(e.contains(needle), "{e}");
        }
    }
}
