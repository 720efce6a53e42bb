//! GNSS solutions through a column map ([`crate::io::columns`]): time, latitude,
//! longitude, a stated height datum, optional σ and velocity columns.
//!
//! * Height: `h_m` (ellipsoidal), or `alt_msl_m` (above mean sea level) with the geoid
//!   undulation N from a column `undulation_m=COL` or a constant (`--undulation-m`,
//!   profile `undulation_m`): `h = H + N`. A mean-sea-level height without N is refused.
//! * Velocity: `v_n_mps, v_e_mps` with `v_d_mps` (NED) or `v_u_mps` (ENU, `v_d = −v_u`).
//! * σ: `sigma_n_m, sigma_e_m, sigma_d_m` (or `sigma_u_m`) columns, or, when the file has
//!   none, `--gnss-sigma N,E,D[,vN,vE,vD]` (m, m/s); the covariance is diagonal.

use crate::io::columns::{ColumnMap, ColumnsError, HeaderMode, InputKind, MapOrigin};
use crate::io::gnss_file::{
    GnssData, GnssFormat, GnssReadReport, TimeBase, H_RANGE_M, MAX_SIGMA_M, MAX_SPEED_MPS,
    MIN_SIGMA_M,
};
use crate::io::imu_columns::{delim_name, InputReport};
use crate::io::table::{read_text, Table};
use crate::io::time::{RunClock, TimeConverter, TimeSpec};
use crate::sensors::gnss_fix::GnssFix;
use sdins_core::math::{Mat3, Vec3};
use std::path::Path;

/// σ of fixes whose file has none: position N, E, D \[m\] and velocity N, E, D \[m/s\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssSigma {
    /// position σ north, east, down \[m\]
    pub pos_ned_m: [f64; 3],
    /// velocity σ north, east, down \[m/s\]
    pub vel_ned_mps: Option<[f64; 3]>,
}

impl GnssSigma {
    /// Parse `N,E,D[,vN,vE,vD]`; each in \[[`MIN_SIGMA_M`], [`MAX_SIGMA_M`]\].
    pub fn parse(text: &str) -> Result<Self, String> {
        let v: Vec<f64> = text
            .split(',')
            .map(|s| {
                s.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("`{}` is not a number", s.trim()))
            })
            .collect::<Result<_, _>>()?;
        Self::from_slice(&v)
    }
    /// From 3 or 6 values.
    pub fn from_slice(v: &[f64]) -> Result<Self, String> {
        if v.len() != 3 && v.len() != 6 {
            return Err(format!(
                "expected N,E,D (m) or N,E,D,vN,vE,vD (m, m/s): 3 or 6 values, found {}",
                v.len()
            ));
        }
        if let Some(x) = v
            .iter()
            .find(|x| !(x.is_finite() && (MIN_SIGMA_M..=MAX_SIGMA_M).contains(*x)))
        {
            return Err(format!(
                "σ {x} is outside {MIN_SIGMA_M:e} .. {MAX_SIGMA_M:e}"
            ));
        }
        Ok(Self {
            pos_ned_m: [v[0], v[1], v[2]],
            vel_ned_mps: (v.len() == 6).then(|| [v[3], v[4], v[5]]),
        })
    }
}

/// Everything needed to read a GNSS file through a column map.
#[derive(Clone, Debug, PartialEq)]
pub struct GnssColumns {
    /// the map
    pub map: ColumnMap,
    /// GPS week of a seconds-of-week file without week column
    pub gps_week: Option<u32>,
    /// constant time offset \[s\]
    pub offset_s: f64,
    /// constant geoid undulation N \[m\] for `alt_msl_m`
    pub undulation_m: Option<f64>,
    /// σ when the file has no σ columns
    pub sigma: Option<GnssSigma>,
}

impl GnssColumns {
    /// A map from its text form with default settings.
    pub fn parse(text: &str, origin: MapOrigin) -> Result<Self, ColumnsError> {
        Ok(Self::new(ColumnMap::parse(InputKind::Gnss, text, origin)?))
    }
    /// Default settings around a map.
    pub fn new(map: ColumnMap) -> Self {
        Self {
            map,
            gps_week: None,
            offset_s: 0.0,
            undulation_m: None,
            sigma: None,
        }
    }
}

/// The height datum of a GNSS or reference map: the column of `h` or `alt_msl`, and the
/// undulation's column or constant.
pub(crate) enum Height {
    Ellipsoidal(usize, String),
    Msl(usize, String, Undulation),
}

pub(crate) enum Undulation {
    Column(usize, String),
    Const(f64),
}

pub(crate) fn height(
    t: &Table<'_>,
    m: &ColumnMap,
    undulation_m: Option<f64>,
) -> Result<Height, ColumnsError> {
    let und_col = m.get("undulation");
    if let Some(n) = undulation_m {
        if !(n.is_finite() && n.abs() <= 200.0) {
            return Err(ColumnsError::map(
                &m.origin,
                format!("geoid undulation {n} m: expected |N| ≤ 200 m"),
            ));
        }
    }
    match (m.get("h"), m.get("alt_msl")) {
        (Some(_), Some(_)) => Err(ColumnsError::map(
            &m.origin,
            "give `h_m` (ellipsoidal) or `alt_msl_m` (mean sea level), not both",
        )),
        (Some(c), None) => {
            if und_col.is_some() || undulation_m.is_some() {
                return Err(ColumnsError::map(&m.origin, "an undulation with `h_m` (already ellipsoidal): use `alt_msl_m` for heights above mean sea level"));
            }
            Ok(Height::Ellipsoidal(t.index(c)?, c.key.clone()))
        }
        (None, Some(c)) => {
            let und = match (und_col, undulation_m) {
                (Some(u), None) => Undulation::Column(t.index(u)?, u.key.clone()),
                (None, Some(n)) => Undulation::Const(n),
                (Some(_), Some(_)) => return Err(ColumnsError::map(&m.origin, "an undulation column and a constant undulation: give one")),
                (None, None) => return Err(ColumnsError::map(&m.origin, "`alt_msl_m` is a height above mean sea level: give the geoid undulation N as a column (`undulation_m=COL`) or a constant (--undulation-m, profile `undulation_m`), h = H + N")),
            };
            Ok(Height::Msl(t.index(c)?, c.key.clone(), und))
        }
        (None, None) => Err(ColumnsError::map(
            &m.origin,
            "missing the height: state its datum, `h_m=COL` (ellipsoidal) or `alt_msl_m=COL` with the geoid undulation",
        )),
    }
}

impl Height {
    pub(crate) fn value(
        &self,
        t: &Table<'_>,
        line: usize,
        f: &[&str],
    ) -> Result<f64, ColumnsError> {
        let h = match self {
            Height::Ellipsoidal(i, k) => t.num(line, f, *i, k)?,
            Height::Msl(i, k, u) => {
                let n = match u {
                    Undulation::Column(j, kk) => {
                        let n = t.num(line, f, *j, kk)?;
                        if n.abs() > 200.0 {
                            return Err(t.err(
                                line,
                                kk,
                                format!("geoid undulation {n} m: expected |N| ≤ 200 m"),
                            ));
                        }
                        n
                    }
                    Undulation::Const(n) => *n,
                };
                t.num(line, f, *i, k)? + n
            }
        };
        if !(H_RANGE_M.0..=H_RANGE_M.1).contains(&h) {
            let k = match self {
                Height::Ellipsoidal(_, k) | Height::Msl(_, k, _) => k,
            };
            return Err(t.err(
                line,
                k,
                format!(
                    "ellipsoidal height {h} m is outside {} .. {} m",
                    H_RANGE_M.0, H_RANGE_M.1
                ),
            ));
        }
        Ok(h)
    }
}

/// Velocity columns: indices, keys, and whether the third is up (ENU).
pub(crate) struct VelCols {
    pub idx: [usize; 3],
    pub keys: [String; 3],
    pub up: bool,
}

pub(crate) fn velocity(t: &Table<'_>, m: &ColumnMap) -> Result<Option<VelCols>, ColumnsError> {
    let (n, e, d, u) = (m.get("v_n"), m.get("v_e"), m.get("v_d"), m.get("v_u"));
    let third = match (d, u) {
        (Some(_), Some(_)) => {
            return Err(ColumnsError::map(
                &m.origin,
                "give `v_d_mps` (NED) or `v_u_mps` (ENU), not both",
            ))
        }
        (Some(c), None) => Some((c, false)),
        (None, Some(c)) => Some((c, true)),
        (None, None) => None,
    };
    match (n, e, third) {
        (Some(n), Some(e), Some((z, up))) => Ok(Some(VelCols {
            idx: [t.index(n)?, t.index(e)?, t.index(z)?],
            keys: [n.key.clone(), e.key.clone(), z.key.clone()],
            up,
        })),
        (None, None, None) => Ok(None),
        _ => Err(ColumnsError::map(
            &m.origin,
            "give all velocity columns, v_n_mps, v_e_mps and v_d_mps (NED) or v_u_mps (ENU), or none",
        )),
    }
}

pub(crate) fn wrap_lon_rad(lon: f64) -> f64 {
    use std::f64::consts::PI;
    if lon.abs() <= PI {
        return lon;
    }
    let mut l = lon % (2.0 * PI);
    if l > PI {
        l -= 2.0 * PI;
    } else if l <= -PI {
        l += 2.0 * PI;
    }
    l
}

/// Three columns' indices and keys.
type ThreeCols = ([usize; 3], [String; 3]);

/// Three σ columns (`sigma_{n,e,d|u}` or `sigma_{vn,ve,vd|vu}`), all or none.
fn sigma_cols(
    t: &Table<'_>,
    m: &ColumnMap,
    names: [&str; 4],
) -> Result<Option<ThreeCols>, ColumnsError> {
    let z = match (m.get(names[2]), m.get(names[3])) {
        (Some(_), Some(_)) => {
            return Err(ColumnsError::map(
                &m.origin,
                format!("give `{}` or `{}`, not both", names[2], names[3]),
            ))
        }
        (a, b) => a.or(b),
    };
    match (m.get(names[0]), m.get(names[1]), z) {
        (Some(a), Some(b), Some(c)) => Ok(Some((
            [t.index(a)?, t.index(b)?, t.index(c)?],
            [a.key.clone(), b.key.clone(), c.key.clone()],
        ))),
        (None, None, None) => Ok(None),
        _ => Err(ColumnsError::map(
            &m.origin,
            format!(
                "give all of {}, {}, {} (or {}) or none",
                names[0], names[1], names[2], names[3]
            ),
        )),
    }
}

/// Read `path` through `cols`; `clock` the run's clock (the IMU record's) when set.
pub fn read_gnss_columns(
    path: &Path,
    cols: &GnssColumns,
    clock: Option<&RunClock>,
) -> Result<(GnssData, InputReport), ColumnsError> {
    let text = read_text(path)?;
    parse_gnss_columns(path, &text, cols, clock)
}

/// Parse the text of a GNSS file through `cols` (`path` for messages).
pub fn parse_gnss_columns(
    path: &Path,
    text: &str,
    cols: &GnssColumns,
    clock: Option<&RunClock>,
) -> Result<(GnssData, InputReport), ColumnsError> {
    let m = &cols.map;
    let tcol = m.need("t", "t_s, t_ms, t_us or t_ns")?.clone();
    let lat = m.need("lat", "lat_deg or lat_rad")?.clone();
    let lon = m.need("lon", "lon_deg or lon_rad")?.clone();
    let t = Table::new(
        path,
        text,
        m.delim.unwrap_or_default(),
        m.header.unwrap_or(HeaderMode::Auto),
    )?;
    let (ti, lai, loi) = (t.index(&tcol)?, t.index(&lat)?, t.index(&lon)?);
    let wi = match m.get("week") {
        Some(c) => Some(t.index(c)?),
        None => None,
    };
    let hgt = height(&t, m, cols.undulation_m)?;
    let vel = velocity(&t, m)?;
    let sp = sigma_cols(&t, m, ["sigma_n", "sigma_e", "sigma_d", "sigma_u"])?;
    let sv = sigma_cols(&t, m, ["sigma_vn", "sigma_ve", "sigma_vd", "sigma_vu"])?;
    let bad = |s: &str| ColumnsError::map(&m.origin, s.to_string());
    let pos_sigma = match (&sp, cols.sigma) {
        (Some(_), Some(_)) => return Err(bad("the file has σ columns and --gnss-sigma is given: give one")),
        (None, None) => return Err(bad("the file has no position σ columns (sigma_n_m, sigma_e_m, sigma_d_m): give --gnss-sigma N,E,D[,vN,vE,vD] (m, m/s)")),
        (None, Some(s)) => Some(s.pos_ned_m),
        (Some(_), None) => None,
    };
    let vel_sigma = match (&vel, &sv, cols.sigma.and_then(|s| s.vel_ned_mps)) {
        (None, Some(_), _) => return Err(bad("velocity σ columns without velocity columns")),
        (Some(_), None, None) => return Err(bad("the file has velocity columns but no velocity σ: add sigma_vn_mps, sigma_ve_mps, sigma_vd_mps or give --gnss-sigma N,E,D,vN,vE,vD")),
        (Some(_), Some(_), Some(_)) => return Err(bad("the file has velocity σ columns and --gnss-sigma gives them too: give one")),
        (_, _, s) => s,
    };
    let sq = |s: [f64; 3]| Mat3::from_diagonal(&Vec3::new(s[0] * s[0], s[1] * s[1], s[2] * s[2]));
    let mut conv = TimeConverter::new(
        &TimeSpec {
            kind: m.time.unwrap_or_default(),
            gps_week: cols.gps_week,
            week_column: m.get("week").is_some(),
            offset_s: cols.offset_s,
        },
        clock,
    )
    .map_err(|e| ColumnsError::map(&m.origin, e))?;
    let mut fixes: Vec<GnssFix> = Vec::with_capacity(t.lines.len());
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
        if let Some(p) = fixes.last() {
            if tk <= p.t_s {
                return Err(t.err(
                    line,
                    &tcol.key,
                    format!("expected a time after {} s, found {tk} s", p.t_s),
                ));
            }
        }
        let la = t.num(line, &f, lai, &lat.key)? * lat.unit.to_si;
        if la.abs() > std::f64::consts::FRAC_PI_2 {
            return Err(t.err(
                line,
                &lat.key,
                format!("latitude {} deg is beyond ±90 deg", la.to_degrees()),
            ));
        }
        let lo = t.num(line, &f, loi, &lon.key)? * lon.unit.to_si;
        if lo.abs() > 2.0 * std::f64::consts::PI {
            return Err(t.err(
                line,
                &lon.key,
                format!("longitude {} deg is beyond ±360 deg", lo.to_degrees()),
            ));
        }
        let h = hgt.value(&t, line, &f)?;
        let three = |idx: [usize; 3],
                     keys: &[String; 3],
                     lo: f64,
                     hi: f64,
                     what: &str|
         -> Result<[f64; 3], ColumnsError> {
            let mut v = [0.0; 3];
            for i in 0..3 {
                v[i] = t.num(line, &f, idx[i], &keys[i])?;
                if !(lo..=hi).contains(&v[i].abs()) {
                    return Err(t.err(
                        line,
                        &keys[i],
                        format!("{what} {} outside {lo:e} .. {hi:e}", v[i]),
                    ));
                }
            }
            Ok(v)
        };
        let pos_cov = match (&sp, pos_sigma) {
            (Some((idx, keys)), _) => sq(three(*idx, keys, MIN_SIGMA_M, MAX_SIGMA_M, "σ")?),
            (None, Some(s)) => sq(s),
            (None, None) => Mat3::identity(),
        };
        let v = match &vel {
            Some(vc) => {
                let mut v = three(vc.idx, &vc.keys, 0.0, MAX_SPEED_MPS, "speed")?;
                if vc.up {
                    v[2] = -v[2];
                }
                let cov = match (&sv, vel_sigma) {
                    (Some((idx, keys)), _) => sq(three(*idx, keys, MIN_SIGMA_M, MAX_SIGMA_M, "σ")?),
                    (None, Some(s)) => sq(s),
                    (None, None) => Mat3::identity(),
                };
                Some((Vec3::from(v), cov))
            }
            None => None,
        };
        fixes.push(GnssFix {
            t_s: tk,
            lat_rad: la,
            lon_rad: wrap_lon_rad(lo),
            h_m: h,
            pos_cov_ned_m2: pos_cov,
            vel: v,
        });
    }
    let clock = conv
        .clock()
        .ok_or_else(|| t.err(t.lines[0].0, &tcol.key, "no time".into()))?;
    let report = InputReport {
        kind: "gnss",
        map_origin: m.origin.to_string(),
        time_base: m.time.unwrap_or_default().name(),
        clock,
        offset_s: cols.offset_s,
        gps_week: cols.gps_week,
        rollovers: conv.rollovers,
        delimiter: delim_name(t.delim),
        header: t.header.is_some(),
        rows: fixes.len(),
        notes: Vec::new(),
    };
    let data = GnssData {
        format: GnssFormat::Columns,
        fixes,
        time_base: TimeBase::FileSeconds,
        report: GnssReadReport {
            rows: report.rows,
            time_system: clock.scale.name().into(),
            warnings: t.warnings(),
            ..GnssReadReport::default()
        },
    };
    Ok((data, report))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn read(text: &str, map: &str, f: impl Fn(&mut GnssColumns)) -> Result<GnssData, ColumnsError> {
        let mut c = GnssColumns::parse(map, MapOrigin::default())?;
        f(&mut c);
        parse_gnss_columns(Path::new("g.txt"), text, &c, None).map(|x| x.0)
    }

    #[test]
    fn datum_velocity_frame_and_sigma() {
        let text = "t lat lon alt n ve vn vu\n0 45 7 100 30 1 2 3\n1 45 7 100 30 1 2 3\n";
        let base = "t_s=t,lat_deg=lat,lon_deg=lon,v_e_mps=ve,v_n_mps=vn,v_u_mps=vu";
        let d = read(text, &format!("{base},alt_msl_m=alt,undulation_m=n"), |c| {
            c.sigma = Some(GnssSigma::parse("1,2,3,0.1,0.2,0.3").unwrap())
        })
        .unwrap();
        let fx = d.fixes[0];
        assert_eq!(fx.h_m, 130.0);
        let (v, cv) = fx.vel.unwrap();
        assert_eq!([v.x, v.y, v.z], [2.0, 1.0, -3.0]);
        assert_eq!(cv[(2, 2)], 0.09);
        assert_eq!(fx.pos_cov_ned_m2[(1, 1)], 4.0);
        let d = read(text, &format!("{base},alt_msl_m=alt"), |c| {
            c.undulation_m = Some(-10.0);
            c.sigma = Some(GnssSigma::parse("1,2,3,0.1,0.2,0.3").unwrap())
        })
        .unwrap();
        assert_eq!(d.fixes[1].h_m, 90.0);
        for (map, what) in [
            (format!("{base},alt_msl_m=alt"), "give the geoid undulation"),
            (base.to_string(), "state its datum"),
            (format!("{base},h_m=alt,alt_msl_m=alt"), "not both"),
            (format!("{base},h_m=alt,v_d_mps=vu"), "not both"),
            (
                format!("{base},h_m=alt,undulation_m=n"),
                "already ellipsoidal",
            ),
        ] {
            let e = read(text, &map, |c| {
                c.sigma = Some(GnssSigma::parse("1,2,3,0.1,0.2,0.3").unwrap())
            })
            .unwrap_err()
            .to_string();
            assert!(
                e.starts_with("--columns: ") && e.contains(what),
                "{map}: {e}"
            );
        }
        let e = read(text, &format!("{base},h_m=alt"), |_| {})
            .unwrap_err()
            .to_string();
        assert!(e.contains("--gnss-sigma"), "{e}");
        let e = read(text, &format!("{base},h_m=alt"), |c| {
            c.sigma = Some(GnssSigma::parse("1,2,3").unwrap())
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("no velocity σ"), "{e}");
        assert!(GnssSigma::parse("1,2").is_err());
        assert!(GnssSigma::parse("1,2,0").is_err());
        assert!(GnssSigma::parse("1,2,x").is_err());
    }
}
