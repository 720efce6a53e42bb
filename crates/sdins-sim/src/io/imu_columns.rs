//! IMU records through a column map ([`crate::io::columns`]): any delimited text with a
//! time column and three gyro and three accelerometer columns, rates or increments, in any
//! unit of the vocabulary, any axis order (`axes=`, `mount_deg=`), any time base.
//!
//! Rates become increments by [`RateRule`]: the default trapezoid
//! `Δθ_k = ½(ω_{k−1} + ω_k)(t_k − t_{k−1})` (the rate tagged at the sample end; second-order
//! accurate in the rate's variation over the interval, it loses the coning and sculling
//! content that a real integrating sensor keeps; the first sample only starts the first
//! interval and is dropped), or `hold` (`Δθ_k = ω_k δt`, δt the mean interval, every sample
//! kept: the sdins and NaveGo rate readers' rule). Intervals more than
//! [`GENERIC_DT_TOLERANCE`] from the median, or gaps over [`GAP_FACTOR`] δt, are refused
//! with their line; with `allow_gaps` irregular intervals are accepted (the trapezoid uses
//! each one's own length) and the record is split into segments at each gap.

use crate::io::columns::{
    ColumnMap, ColumnsError, Delimiter, Dim, HeaderMode, InputKind, MapOrigin, RateRule,
};
use crate::io::imu_file::{ImuData, ImuFormat, DT_RANGE_S, MAX_DTHETA_RAD, MAX_SPECIFIC_FORCE_G};
use crate::io::table::{read_text, Table};
use crate::io::time::{ClockScale, RunClock, TimeConverter, TimeSpec};
use sdins_core::coning::Increment;
use sdins_core::math::Vec3;
use std::path::Path;

/// Largest relative deviation of a sample interval from the median (without `allow_gaps`).
pub const GENERIC_DT_TOLERANCE: f64 = 0.10;
/// An interval longer than this many median intervals is a gap.
pub const GAP_FACTOR: f64 = 2.0;

/// Everything needed to read an IMU file through a column map (from `--columns`,
/// `--profile` and the shared options).
#[derive(Clone, Debug, PartialEq)]
pub struct ImuColumns {
    /// the map (columns and settings)
    pub map: ColumnMap,
    /// GPS week of a seconds-of-week file without week column
    pub gps_week: Option<u32>,
    /// constant time offset \[s\]
    pub offset_s: f64,
    /// the g of `_g` and `_mg` \[m/s²\]
    pub g_mps2: f64,
    /// accept irregular intervals and split at gaps
    pub allow_gaps: bool,
}

impl ImuColumns {
    /// A map from its text form with default settings.
    pub fn parse(text: &str, origin: MapOrigin) -> Result<Self, ColumnsError> {
        Ok(Self::new(ColumnMap::parse(InputKind::Imu, text, origin)?))
    }
    /// Default settings around a map.
    pub fn new(map: ColumnMap) -> Self {
        Self {
            map,
            gps_week: None,
            offset_s: 0.0,
            g_mps2: crate::io::columns::G0,
            allow_gaps: false,
        }
    }
    /// The time specification.
    pub fn time_spec(&self) -> TimeSpec {
        TimeSpec {
            kind: self.map.time.unwrap_or_default(),
            gps_week: self.gps_week,
            week_column: self.map.get("week").is_some(),
            offset_s: self.offset_s,
        }
    }
}

/// What reading through a map did: for the summary line and run.toml.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct InputReport {
    /// `imu`, `gnss` or `reference`
    pub kind: &'static str,
    /// the map as given
    pub map_origin: String,
    /// time base name (`relative`, `gps-sow`, `unix`)
    pub time_base: &'static str,
    /// the run's clock
    pub clock: RunClock,
    /// the constant offset added \[s\]
    pub offset_s: f64,
    /// GPS week given (not from a column)
    pub gps_week: Option<u32>,
    /// week rollovers unwrapped
    pub rollovers: usize,
    /// delimiter used
    pub delimiter: &'static str,
    /// whether the file had a header
    pub header: bool,
    /// data rows read
    pub rows: usize,
    /// notes (first sample dropped, segments, …)
    pub notes: Vec<String>,
}

impl InputReport {
    /// As a run.toml table.
    pub fn to_toml(&self) -> toml::Table {
        let mut t = toml::Table::new();
        t.insert("map".into(), self.map_origin.clone().into());
        t.insert("time_base".into(), self.time_base.into());
        t.insert("clock".into(), self.clock.scale.name().into());
        t.insert("clock_origin_s".into(), self.clock.origin_s.into());
        t.insert("time_offset_s".into(), self.offset_s.into());
        if let Some(w) = self.gps_week {
            t.insert("gps_week".into(), i64::from(w).into());
        }
        t.insert("week_rollovers".into(), (self.rollovers as i64).into());
        t.insert("delimiter".into(), self.delimiter.into());
        t.insert("header".into(), self.header.into());
        t.insert("rows".into(), (self.rows as i64).into());
        if !self.notes.is_empty() {
            t.insert(
                "notes".into(),
                toml::Value::Array(self.notes.iter().map(|n| n.clone().into()).collect()),
            );
        }
        t
    }
    /// One line for stderr: the time base, clock origin and offset.
    pub fn summary(&self) -> String {
        let origin = match self.clock.scale {
            ClockScale::File => "the file's own seconds".to_string(),
            s => format!("{} {} s + t", s.name(), self.clock.origin_s),
        };
        format!(
            "{}: {} rows, time {} on {origin}, offset {} s{}",
            self.kind,
            self.rows,
            self.time_base,
            self.offset_s,
            if self.rollovers > 0 {
                format!(", {} week rollover(s) unwrapped", self.rollovers)
            } else {
                String::new()
            }
        )
    }
}

/// An IMU file read through a map.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct ImuColumnsData {
    /// the record (the first segment when `allow_gaps` split it)
    pub data: ImuData,
    /// every segment (one unless `allow_gaps` split the record at gaps)
    pub segments: Vec<ImuData>,
    /// what was done
    pub report: InputReport,
}

pub(crate) fn delim_name(d: Delimiter) -> &'static str {
    match d {
        Delimiter::Comma => "comma",
        Delimiter::Semicolon => "semicolon",
        _ => "whitespace",
    }
}

/// Read `path` through `cols`; `clock` the run's clock when another input set it.
pub fn read_imu_columns(
    path: &Path,
    cols: &ImuColumns,
    clock: Option<&RunClock>,
) -> Result<ImuColumnsData, ColumnsError> {
    let text = read_text(path)?;
    parse_imu_columns(path, &text, cols, clock)
}

/// Read `path` through `cols` as one continuous record (a record split at gaps by
/// `allow_gaps` is refused: cut the file at the gap), with its report.
pub fn read_imu_record(
    path: &Path,
    cols: &ImuColumns,
    clock: Option<&RunClock>,
) -> Result<(ImuData, InputReport), ColumnsError> {
    let d = read_imu_columns(path, cols, clock)?;
    if d.segments.len() > 1 {
        return Err(ColumnsError::Data {
            file: path.to_path_buf(),
            line: 1,
            field: "(time)".into(),
            message: format!(
                "the record has {} segments split at gaps: this runs on one continuous record (cut the file at the gap)",
                d.segments.len()
            ),
        });
    }
    Ok((d.data, d.report))
}

/// An IMU file read through `cols` when given, else in its format; with the map's report.
pub fn read_imu_any(
    path: &Path,
    format: crate::io::imu_file::ImuFormat,
    cols: Option<&ImuColumns>,
) -> Result<(ImuData, Option<InputReport>), String> {
    match cols {
        Some(c) => {
            if format != crate::io::imu_file::ImuFormat::Auto {
                return Err(format!(
                    "{}: the IMU file is read through a column map: give either it or an IMU format",
                    c.map.origin
                ));
            }
            read_imu_record(path, c, None)
                .map(|(d, r)| (d, Some(r)))
                .map_err(|e| e.to_string())
        }
        None => crate::io::imu_file::read_imu_file(path, format)
            .map(|d| (d, None))
            .map_err(|e| e.to_string()),
    }
}

/// A triad: its three columns' indices, SI factors and whether they are increments.
struct Triad {
    idx: [usize; 3],
    scale: [f64; 3],
    keys: [String; 3],
    inc: bool,
}

fn triad(
    t: &Table<'_>,
    cols: &ImuColumns,
    names: [&str; 3],
    alt: [&str; 3],
    accel: bool,
) -> Result<Triad, ColumnsError> {
    let m = &cols.map;
    let mut idx = [0; 3];
    let mut scale = [0.0; 3];
    let mut keys: [String; 3] = Default::default();
    let mut inc = None;
    for i in 0..3 {
        let c = match (m.get(names[i]), m.get(alt[i])) {
            (Some(a), Some(b)) => {
                return Err(ColumnsError::map(
                    &m.origin,
                    format!("`{}` and `{}` map the same axis: give one", a.key, b.key),
                ))
            }
            (Some(c), None) | (None, Some(c)) => c,
            (None, None) => {
                let what = if accel {
                    "specific force: _mps2, _g, _mg, or increments _mps_inc"
                } else {
                    "angular rate: _radps, _dps, _dph, or increments _rad_inc, _deg_inc"
                };
                return Err(ColumnsError::map(
                    &m.origin,
                    format!("missing `{}_UNIT=COLUMN` ({what})", names[i]),
                ));
            }
        };
        let is_inc = matches!(
            c.unit.dim,
            Dim::AngleInc | Dim::VelInc | Dim::Angle | Dim::Speed
        );
        if inc.is_some_and(|x| x != is_inc) {
            return Err(ColumnsError::map(
                &m.origin,
                format!(
                    "`{}`: the three axes must all be rates or all increments",
                    c.key
                ),
            ));
        }
        inc = Some(is_inc);
        idx[i] = t.index(c)?;
        scale[i] = match c.unit.suffix {
            "g" => cols.g_mps2,
            "mg" => 1e-3 * cols.g_mps2,
            _ => c.unit.to_si,
        };
        keys[i] = c.key.clone();
    }
    Ok(Triad {
        idx,
        scale,
        keys,
        inc: inc.unwrap_or(false),
    })
}

/// Parse the text of an IMU file through `cols` (`path` for messages).
pub fn parse_imu_columns(
    path: &Path,
    text: &str,
    cols: &ImuColumns,
    clock: Option<&RunClock>,
) -> Result<ImuColumnsData, ColumnsError> {
    let m = &cols.map;
    if !(cols.g_mps2.is_finite() && cols.g_mps2 > 0.0) {
        return Err(ColumnsError::map(
            &m.origin,
            format!("g = {} m/s² must be positive", cols.g_mps2),
        ));
    }
    let c_s_b = m.c_s_b()?;
    let tcol = m.need("t", "t_s, t_ms, t_us or t_ns")?.clone();
    let t = Table::new(
        path,
        text,
        m.delim.unwrap_or_default(),
        m.header.unwrap_or(HeaderMode::Auto),
    )?;
    let ti = t.index(&tcol)?;
    let wi = match m.get("week") {
        Some(c) => Some(t.index(c)?),
        None => None,
    };
    let g = triad(
        &t,
        cols,
        ["gyro_x", "gyro_y", "gyro_z"],
        ["dtheta_x", "dtheta_y", "dtheta_z"],
        false,
    )?;
    let a = triad(
        &t,
        cols,
        ["accel_x", "accel_y", "accel_z"],
        ["dv_x", "dv_y", "dv_z"],
        true,
    )?;
    let mut conv = TimeConverter::new(&cols.time_spec(), clock)
        .map_err(|e| ColumnsError::map(&m.origin, e))?;
    let n = t.lines.len();
    let (mut ts, mut lines) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut gv, mut av) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mut f = Vec::with_capacity(t.width);
    for k in 0..n {
        let line = t.row(k, &mut f)?;
        let week = match wi {
            Some(i) => Some(t.num(line, &f, i, "week")?),
            None => None,
        };
        let tk = conv
            .convert(f[ti], tcol.unit.time_exp10, week)
            .map_err(|e| t.err(line, &tcol.key, e))?;
        let vec = |tr: &Triad| -> Result<Vec3, ColumnsError> {
            let mut v = [0.0; 3];
            for (i, vi) in v.iter_mut().enumerate() {
                *vi = t.num(line, &f, tr.idx[i], &tr.keys[i])? * tr.scale[i];
            }
            Ok(c_s_b * Vec3::from(v))
        };
        gv.push(vec(&g)?);
        av.push(vec(&a)?);
        ts.push(tk);
        lines.push(line);
    }
    let rule = m.rates.unwrap_or_default();
    let any_rate = !g.inc || !a.inc;
    let bounds = segment_bounds(&t, &ts, &lines, &tcol.key, cols.allow_gaps)?;
    let mut segments = Vec::with_capacity(bounds.len());
    for &(s, e) in &bounds {
        segments.push(segment(
            &t,
            &ts[s..e],
            &lines[s..e],
            &gv[s..e],
            &av[s..e],
            &g,
            &a,
            rule,
        )?);
    }
    let mut notes = Vec::new();
    if any_rate && rule == RateRule::Trapezoid {
        notes.push(format!(
            "rates integrated by the trapezoid rule; the first sample (line {}) starts the first interval and is dropped",
            lines[0]
        ));
    }
    if bounds.len() > 1 {
        let starts: Vec<String> = bounds[1..]
            .iter()
            .map(|&(s, _)| format!("line {}", lines[s]))
            .collect();
        notes.push(format!(
            "{} segments split at gaps (new segments start at {})",
            bounds.len(),
            starts.join(", ")
        ));
    }
    let clock = conv
        .clock()
        .ok_or_else(|| t.err(lines[0], &tcol.key, "no time".into()))?;
    let report = InputReport {
        kind: "imu",
        map_origin: m.origin.to_string(),
        time_base: m.time.unwrap_or_default().name(),
        clock,
        offset_s: cols.offset_s,
        gps_week: cols.gps_week,
        rollovers: conv.rollovers,
        delimiter: delim_name(t.delim),
        header: t.header.is_some(),
        rows: n,
        notes,
    };
    let mut data = segments[0].clone();
    data.warnings.extend(t.warnings());
    Ok(ImuColumnsData {
        data,
        segments,
        report,
    })
}

/// Check the time column and split it into segments `[start, end)` at gaps.
fn segment_bounds(
    t: &Table<'_>,
    ts: &[f64],
    lines: &[usize],
    key: &str,
    allow_gaps: bool,
) -> Result<Vec<(usize, usize)>, ColumnsError> {
    if ts.len() < 2 {
        return Err(t.err(
            lines[0],
            key,
            format!(
                "{} data row(s), expected at least 2 to get the sample interval",
                ts.len()
            ),
        ));
    }
    for k in 1..ts.len() {
        if ts[k] <= ts[k - 1] {
            return Err(t.err(
                lines[k],
                key,
                format!("expected a time after {} s, found {} s", ts[k - 1], ts[k]),
            ));
        }
    }
    let mut d: Vec<f64> = ts.windows(2).map(|w| w[1] - w[0]).collect();
    d.sort_by(f64::total_cmp);
    let median = d[d.len() / 2];
    let mut bounds = Vec::new();
    let mut start = 0;
    for k in 1..ts.len() {
        let dk = ts[k] - ts[k - 1];
        let gap = dk > GAP_FACTOR * median;
        if !allow_gaps && (gap || (dk - median).abs() > GENERIC_DT_TOLERANCE * median) {
            let what = if gap {
                "a gap"
            } else {
                "an irregular interval"
            };
            return Err(t.err(
                lines[k],
                key,
                format!(
                    "sample interval {dk} s is {what}: the median is {median} s (accepted: within {} %, gaps over {GAP_FACTOR} intervals split the record with --allow-gaps)",
                    GENERIC_DT_TOLERANCE * 100.0
                ),
            ));
        }
        if gap {
            bounds.push((start, k));
            start = k;
        }
    }
    bounds.push((start, ts.len()));
    for &(s, e) in &bounds {
        if e - s < 3 {
            return Err(t.err(
                lines[s],
                key,
                format!(
                    "a segment of {} row(s) between gaps: too short to use",
                    e - s
                ),
            ));
        }
    }
    Ok(bounds)
}

#[allow(clippy::too_many_arguments)]
fn segment(
    t: &Table<'_>,
    ts: &[f64],
    lines: &[usize],
    gv: &[Vec3],
    av: &[Vec3],
    g: &Triad,
    a: &Triad,
    rule: RateRule,
) -> Result<ImuData, ColumnsError> {
    let n = ts.len();
    let dt_mean = (ts[n - 1] - ts[0]) / (n - 1) as f64;
    if !(DT_RANGE_S.0..=DT_RANGE_S.1).contains(&dt_mean) {
        return Err(t.err(
            lines[1],
            "(time)",
            format!(
                "sample interval {dt_mean:e} s, expected {:e} .. {} s (is the time unit right?)",
                DT_RANGE_S.0, DT_RANGE_S.1
            ),
        ));
    }
    let trapezoid = rule == RateRule::Trapezoid && (!g.inc || !a.inc);
    let first = usize::from(trapezoid);
    let one = |v: &[Vec3], inc: bool, k: usize| -> Vec3 {
        if inc {
            v[k]
        } else if trapezoid {
            (v[k - 1] + v[k]) * (0.5 * (ts[k] - ts[k - 1]))
        } else {
            v[k] * dt_mean
        }
    };
    let mut incs = Vec::with_capacity(n - first);
    for (k, &line_k) in lines.iter().enumerate().take(n).skip(first) {
        let inc = Increment::new(one(gv, g.inc, k), one(av, a.inc, k));
        let dth = inc.dtheta_b_rad.norm();
        if dth > MAX_DTHETA_RAD {
            return Err(t.err(
                line_k,
                &g.keys.join("/"),
                format!("|Δθ| = {dth:e} rad per sample, expected at most π"),
            ));
        }
        let f = inc.dv_b_mps.norm() / dt_mean;
        let lim = MAX_SPECIFIC_FORCE_G * crate::io::columns::G0;
        if f > lim {
            return Err(t.err(
                line_k,
                &a.keys.join("/"),
                format!("|f| = {f:e} m/s², expected at most {lim:e}"),
            ));
        }
        incs.push(inc);
    }
    let dt_s = if first == 1 {
        (ts[n - 1] - ts[1]) / (n - 2).max(1) as f64
    } else {
        dt_mean
    };
    Ok(ImuData {
        format: ImuFormat::Columns,
        dt_s: if n - first >= 2 { dt_s } else { dt_mean },
        t0_s: ts[first],
        increments: incs,
        psins: None,
        detection: None,
        warnings: Vec::new(),
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    const HDR: &str = "t,gx,gy,gz,ax,ay,az\n";

    fn rows(n: usize, dt: f64, w: [f64; 3], f: [f64; 3]) -> String {
        let mut s = String::from(HDR);
        for k in 0..n {
            s += &format!(
                "{},{},{},{},{},{},{}\n",
                k as f64 * dt,
                w[0],
                w[1],
                w[2],
                f[0],
                f[1],
                f[2]
            );
        }
        s
    }

    fn read(text: &str, map: &str) -> Result<ImuColumnsData, ColumnsError> {
        let c = ImuColumns::parse(map, MapOrigin::default())?;
        parse_imu_columns(Path::new("imu.txt"), text, &c, None)
    }

    const RATES: &str =
        "t_s=t,gyro_x_dps=gx,gyro_y_dps=gy,gyro_z_dps=gz,accel_x_g=ax,accel_y_g=ay,accel_z_g=az";

    #[test]
    fn rates_by_trapezoid_and_hold() {
        let text = rows(11, 0.01, [1.0, 2.0, 3.0], [0.0, 0.0, -1.0]);
        let d = read(&text, RATES).unwrap();
        assert_eq!(d.data.increments.len(), 10);
        assert_eq!(d.data.t0_s, 0.01);
        let i = d.data.increments[0];
        assert!((i.dtheta_b_rad.x - 0.01f64.to_radians()).abs() < 1e-17);
        assert!((i.dv_b_mps.z + 0.01 * 9.80665).abs() < 1e-15);
        let h = read(&text, &format!("{RATES},rates=hold")).unwrap();
        assert_eq!(h.data.increments.len(), 11);
        assert_eq!(h.data.t0_s, 0.0);
        assert!(d.report.notes[0].contains("dropped"));
    }

    #[test]
    fn axes_apply_to_both_triads() {
        let text = rows(5, 0.01, [1.0, 2.0, 3.0], [0.1, 0.2, 0.3]);
        let d = read(&text, &format!("{RATES},axes=x:+y,y:+x,z:-z,rates=hold")).unwrap();
        let i = d.data.increments[0];
        assert_eq!(i.dtheta_b_rad.x, 2.0 * crate::io::columns::DEG * 0.01);
        assert_eq!(i.dtheta_b_rad.z, -3.0 * crate::io::columns::DEG * 0.01);
        assert_eq!(i.dv_b_mps.y, 0.1 * 9.80665 * 0.01);
    }

    #[test]
    fn gaps_and_irregular_intervals() {
        let mut text = rows(10, 0.01, [0.0; 3], [0.0, 0.0, -1.0]);
        text += "0.2,0,0,0,0,0,-1\n0.21,0,0,0,0,0,-1\n0.22,0,0,0,0,0,-1\n";
        let e = read(&text, RATES).unwrap_err().to_string();
        assert!(
            e.starts_with("imu.txt:12: t_s: sample interval") && e.contains("a gap"),
            "{e}"
        );
        let c = ImuColumns {
            allow_gaps: true,
            ..ImuColumns::parse(RATES, MapOrigin::default()).unwrap()
        };
        let d = parse_imu_columns(Path::new("imu.txt"), &text, &c, None).unwrap();
        assert_eq!(d.segments.len(), 2);
        assert_eq!(d.segments[1].t0_s, 0.21);
        let mut odd = rows(10, 0.01, [0.0; 3], [0.0, 0.0, -1.0]);
        odd += "0.1015,0,0,0,0,0,-1\n";
        let e = read(&odd, RATES).unwrap_err().to_string();
        assert!(e.contains("irregular"), "{e}");
    }

    #[test]
    fn bad_maps_and_rows_are_located() {
        let text = rows(5, 0.01, [0.0; 3], [0.0, 0.0, -1.0]);
        for (map, what) in [
            ("t_s=t", "--columns: missing `gyro_x_UNIT=COLUMN`"),
            (
                &RATES.replace("gyro_y_dps", "gyro_y_rad_inc"),
                "must all be rates or all increments",
            ),
            (
                &RATES.replace("t_s=t", "t_s=time"),
                "imu.txt:1: t_s: no column `time`",
            ),
            (&RATES.replace("t_s=t,", ""), "missing `t_UNIT=COLUMN`"),
            (&format!("{RATES},axes=x:+x,y:+y,z:-z"), "reflection"),
            (&RATES.replace("t_s=t", "t_us=t"), "sample interval 1e-8 s"),
        ] {
            let e = read(&text, map).unwrap_err().to_string();
            assert!(e.contains(what), "{map}: {e}");
        }
        let bad = text.replace("0.03,0,", "0.03,x,");
        let e = read(&bad, RATES).unwrap_err().to_string();
        assert_eq!(e, "imu.txt:5: gyro_x_dps: `x` is not a number");
        let back = text.replace("0.03,", "0.01,");
        assert!(read(&back, RATES)
            .unwrap_err()
            .to_string()
            .contains("imu.txt:5: t_s: expected a time after"));
    }
}
