//! Recorded trajectories from files (`sdins truth --from-reference`; docs/scenarios.md
//! §"Recorded trajectories"); `crate::scenario::from_reference` turns one into a scenario.
//!
//! Formats: the sdins `truth.csv`, a PSINS `avp` CSV, NaveGo's `ref.csv` (read by
//! [`crate::io::truth_file`], converted to sdins conventions there), and any CSV with a header
//! through a [`ColumnMap`] (NED velocity, body FRD, ZYX Euler angles).

use crate::io::truth_file::TruthFileError;
use crate::truth::reference::{ReferenceError, ReferenceSample};
use sdins_core::math::{euler_from_c_b_n, Euler, Vec3};
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

/// Angle unit of a generic column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AngleUnit {
    /// degrees (`*_deg` key)
    Deg,
    /// radians (`*_rad` key)
    Rad,
}

/// Which header names of a generic CSV hold which quantity: the text form is
/// `t_s=COL,lat_deg=COL,lon_deg=COL,h_m=COL,roll_deg=COL,pitch_deg=COL,yaw_deg=COL` with
/// `_rad` instead of `_deg` for radians and, optionally, `v_n_mps=COL,v_e_mps=COL,v_d_mps=COL`
/// (the file's own velocity, compared with the interpolant's).
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnMap {
    /// time \[s\]
    pub t: String,
    /// latitude, longitude, height
    pub pos: [(String, AngleUnit); 2],
    /// height \[m\]
    pub h: String,
    /// roll, pitch, yaw
    pub att: [(String, AngleUnit); 3],
    /// NED velocity columns \[m/s\]
    pub vel: Option<[String; 3]>,
}

impl ColumnMap {
    /// Parse the text form (see [`ColumnMap`]).
    pub fn parse(s: &str) -> Result<Self, ReferenceFileError> {
        let bad = |m: String| ReferenceFileError::Columns { message: m };
        let mut got: Vec<(String, String)> = Vec::new();
        for item in s.split(',').map(str::trim).filter(|x| !x.is_empty()) {
            let Some((k, v)) = item.split_once('=') else {
                return Err(bad(format!("`{item}`: expected KEY=COLUMN")));
            };
            let (k, v) = (k.trim(), v.trim());
            if v.is_empty() {
                return Err(bad(format!("`{item}`: empty column name")));
            }
            if got.iter().any(|(g, _)| g == k) {
                return Err(bad(format!("`{k}` given twice")));
            }
            got.push((k.to_string(), v.to_string()));
        }
        const KEYS: [&str; 13] = [
            "t_s",
            "lat_deg",
            "lat_rad",
            "lon_deg",
            "lon_rad",
            "h_m",
            "roll_deg",
            "roll_rad",
            "pitch_deg",
            "pitch_rad",
            "yaw_deg",
            "yaw_rad",
            "v_n_mps",
        ];
        for (k, _) in &got {
            if !KEYS.contains(&k.as_str()) && k != "v_e_mps" && k != "v_d_mps" {
                return Err(bad(format!("unknown key `{k}`: expected t_s, lat_deg|lat_rad, lon_deg|lon_rad, h_m, roll_deg|roll_rad, pitch_deg|pitch_rad, yaw_deg|yaw_rad and optionally v_n_mps, v_e_mps, v_d_mps")));
            }
        }
        let one = |k: &str| got.iter().find(|(g, _)| g == k).map(|(_, v)| v.clone());
        let need = |k: &str| one(k).ok_or_else(|| bad(format!("missing `{k}=COLUMN`")));
        let angle = |q: &str| -> Result<(String, AngleUnit), ReferenceFileError> {
            match (one(&format!("{q}_deg")), one(&format!("{q}_rad"))) {
                (Some(c), None) => Ok((c, AngleUnit::Deg)),
                (None, Some(c)) => Ok((c, AngleUnit::Rad)),
                (Some(_), Some(_)) => Err(bad(format!("give `{q}_deg` or `{q}_rad`, not both"))),
                (None, None) => Err(bad(format!("missing `{q}_deg=COLUMN` (or `{q}_rad`)"))),
            }
        };
        let vel = match (one("v_n_mps"), one("v_e_mps"), one("v_d_mps")) {
            (Some(n), Some(e), Some(d)) => Some([n, e, d]),
            (None, None, None) => None,
            _ => return Err(bad("give all of v_n_mps, v_e_mps, v_d_mps or none".into())),
        };
        Ok(Self {
            t: need("t_s")?,
            pos: [angle("lat")?, angle("lon")?],
            h: need("h_m")?,
            att: [angle("roll")?, angle("pitch")?, angle("yaw")?],
            vel,
        })
    }
}

/// Why a reference file could not be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReferenceFileError {
    /// A reader of a known format failed.
    #[error(transparent)]
    File(#[from] TruthFileError),
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

/// Read a generic CSV through `map`.
pub fn parse_generic(
    path: &Path,
    text: &str,
    map: &ColumnMap,
) -> Result<Vec<ReferenceSample>, ReferenceFileError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut rd = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(text.as_bytes());
    let bad = |line: u64, field: &str, message: String| {
        ReferenceFileError::File(TruthFileError::Invalid {
            file: path.into(),
            line: line as usize,
            field: field.into(),
            message,
        })
    };
    let header = rd
        .headers()
        .map_err(|e| bad(1, "(header)", e.to_string()))?
        .clone();
    let idx = |name: &str| -> Result<usize, ReferenceFileError> {
        header.iter().position(|h| h == name).ok_or_else(|| {
            bad(
                1,
                name,
                format!(
                    "no such column in the header `{}`",
                    header.iter().collect::<Vec<_>>().join(",")
                ),
            )
        })
    };
    let unit = |u: AngleUnit| {
        if u == AngleUnit::Deg {
            1f64.to_radians()
        } else {
            1.0
        }
    };
    let cols = [
        (idx(&map.t)?, 1.0, map.t.as_str()),
        (
            idx(&map.pos[0].0)?,
            unit(map.pos[0].1),
            map.pos[0].0.as_str(),
        ),
        (
            idx(&map.pos[1].0)?,
            unit(map.pos[1].1),
            map.pos[1].0.as_str(),
        ),
        (idx(&map.h)?, 1.0, map.h.as_str()),
        (
            idx(&map.att[0].0)?,
            unit(map.att[0].1),
            map.att[0].0.as_str(),
        ),
        (
            idx(&map.att[1].0)?,
            unit(map.att[1].1),
            map.att[1].0.as_str(),
        ),
        (
            idx(&map.att[2].0)?,
            unit(map.att[2].1),
            map.att[2].0.as_str(),
        ),
    ];
    let vel = match &map.vel {
        Some(v) => Some([idx(&v[0])?, idx(&v[1])?, idx(&v[2])?]),
        None => None,
    };
    let mut out: Vec<ReferenceSample> = Vec::new();
    for rec in rd.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            bad(line, "(row)", e.to_string())
        })?;
        let line = rec.position().map_or(0, |p| p.line());
        let num = |i: usize, name: &str| -> Result<f64, ReferenceFileError> {
            let f = rec.get(i).ok_or_else(|| {
                bad(
                    line,
                    name,
                    format!("missing (the row has {} fields)", rec.len()),
                )
            })?;
            let v: f64 = f
                .parse()
                .map_err(|_| bad(line, name, format!("`{f}` is not a number")))?;
            if !v.is_finite() {
                return Err(bad(line, name, format!("`{f}` is not finite")));
            }
            Ok(v)
        };
        let mut x = [0.0; 7];
        for (k, &(i, scale, name)) in cols.iter().enumerate() {
            x[k] = num(i, name)? * scale;
        }
        if let Some(prev) = out.last() {
            if x[0] <= prev.t_s {
                return Err(bad(
                    line,
                    &map.t,
                    format!(
                        "{} s does not increase on the previous row's {} s",
                        x[0], prev.t_s
                    ),
                ));
            }
        }
        if x[1].abs() > 89.99f64.to_radians() {
            return Err(bad(line, &map.pos[0].0, format!("latitude {:.4} deg is beyond ±89.99 deg (the NED mechanization is singular at the poles)", x[1].to_degrees())));
        }
        let v_n_mps = match vel {
            Some([a, b, c]) => {
                let names = map
                    .vel
                    .as_ref()
                    .map_or(["", "", ""], |v| [&v[0], &v[1], &v[2]].map(|s| s.as_str()));
                Some(Vec3::new(
                    num(a, names[0])?,
                    num(b, names[1])?,
                    num(c, names[2])?,
                ))
            }
            None => None,
        };
        out.push(ReferenceSample {
            t_s: x[0],
            lat_rad: x[1],
            lon_rad: x[2],
            h_m: x[3],
            euler: Euler::new(x[4], x[5], x[6]),
            v_n_mps,
        });
    }
    Ok(out)
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
        assert_eq!(m.t, "time");
        assert_eq!(m.att[2], ("y".to_string(), AngleUnit::Deg));
        assert!(m.vel.is_none());
        for (bad, what) in [
            ("t_s=time", "missing `lat_deg"),
            (&format!("{MAP},lat_rad=x"), "not both"),
            (&format!("{MAP},v_n_mps=a"), "all of"),
            (&format!("{MAP},speed=a"), "unknown key `speed`"),
            (&format!("{MAP},t_s=b"), "twice"),
            ("t_s", "KEY=COLUMN"),
        ] {
            let e = ColumnMap::parse(bad).unwrap_err().to_string();
            assert!(e.contains(what), "{bad}: {e}");
        }
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
                "r.csv:1: y: no such column",
            ),
            (
                "time,lat,lon,alt,r,p,y\n0,45,7,10,1,2,3\n0,45,7,10,1,2,x\n",
                "r.csv:3: y: `x` is not a number",
            ),
            (
                "time,lat,lon,alt,r,p,y\n0,45,7,10,1,2,3\n0,45,7,10,1,2,3\n",
                "r.csv:3: time: 0 s does not increase",
            ),
            (
                "time,lat,lon,alt,r,p,y\n0,45,7,10,1,2,NaN\n",
                "r.csv:2: y: `NaN` is not finite",
            ),
            (
                "time,lat,lon,alt,r,p,y\n0,90,7,10,1,2,3\n",
                "r.csv:2: lat: latitude",
            ),
            ("time,lat,lon,alt,r,p,y\n0,45,7\n", "r.csv:2: alt: missing"),
        ] {
            let e = parse_generic(p, text, &m).unwrap_err().to_string();
            assert!(e.contains(needle), "{e}");
        }
    }
}
