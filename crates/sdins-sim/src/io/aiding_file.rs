//! Recorded aiding-sensor files (docs/own-data.md §"Aiding sensors"): a TOML file names, per
//! sensor, its record and column map and the sensor's settings (the keys of the scenario
//! tables `[baro]`, `[odometer]`, `[magnetometer]`, `[dual_antenna]`, `[body_velocity]`
//! that describe the sensor: σ, priors, lever arm, mounting), and the records are read
//! through the column-map mechanism ([`crate::io::columns`], input kind `aiding`) onto the
//! run's clock.
//!
//! ```toml
//! [odometer]
//! file = "wheel.csv"                      # relative to this file
//! columns = "t_s=time,speed_mps=speed"    # optional (default: the documented header)
//! sigma_mps = 0.05
//! scale_sigma = 0.01
//! lever_arm_b_m = [-1.2, 0.0, 0.3]
//! nhc_sigma_mps = 0.1
//! ```
//!
//! Default headers: barometer `t_s,h_m`; odometer `t_s,speed_mps`; magnetometer
//! `t_s,m_x_ut,m_y_ut,m_z_ut` (body FRD, or the map's `axes=`/`mount_deg=`); dual antenna
//! `t_s,az_deg,el_deg` (`el` not needed with `heading_only`); body velocity
//! `t_s,v_x_mps,v_y_mps,v_z_mps` (vehicle frame). The simulation-only keys `rate_hz`,
//! `outages_s` and `seed` are refused: a record has its own epochs.

use crate::io::columns::{ColumnMap, ColumnsError, InputKind, MapOrigin, TimeKind};
use crate::io::table::{read_text, Table};
use crate::io::time::{RunClock, TimeConverter, TimeSpec};
use crate::sensors::aiding::sim::c_b_v_from_mount_deg;
use crate::sensors::aiding::AidingConfig;
use sdins_core::aiding::sensors::{
    mag_field_ned_ut, AidingMeas, Baro, BodyVelocity, DualAntenna, Magnetometer, Odometer,
};
use sdins_core::math::{Mat3, Vec3};
use std::path::{Path, PathBuf};

const DEG: f64 = std::f64::consts::PI / 180.0;

/// Why the aiding files cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AidingFileError {
    /// The TOML file is invalid.
    #[error("{file}: {message}")]
    Spec {
        /// the TOML file
        file: PathBuf,
        /// what is wrong
        message: String,
    },
    /// A record cannot be read.
    #[error(transparent)]
    Columns(#[from] ColumnsError),
}

/// One sensor's record.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorRecord {
    /// table name (`baro`, `odometer`, …)
    pub sensor: &'static str,
    /// the record
    pub file: PathBuf,
    /// its column map
    pub map: ColumnMap,
    /// constant offset added to its times \[s\]
    pub time_offset_s: f64,
}

/// The parsed TOML: the sensors' settings and their records.
#[derive(Clone, Debug, PartialEq)]
pub struct AidingSpec {
    /// the settings (the filter's model)
    pub config: AidingConfig,
    /// the records
    pub records: Vec<SensorRecord>,
}

/// The tables in the simulator's order, with their default column maps.
const SENSORS: [(&str, &str); 5] = [
    ("baro", "t_s=t_s,h_m=h_m"),
    ("odometer", "t_s=t_s,speed_mps=speed_mps"),
    (
        "magnetometer",
        "t_s=t_s,m_x_ut=m_x_ut,m_y_ut=m_y_ut,m_z_ut=m_z_ut",
    ),
    ("dual_antenna", "t_s=t_s,az_deg=az_deg,el_deg=el_deg"),
    (
        "body_velocity",
        "t_s=t_s,v_x_mps=v_x_mps,v_y_mps=v_y_mps,v_z_mps=v_z_mps",
    ),
];

/// Read the TOML file of the aiding sensors.
pub fn read_aiding_spec(path: &Path) -> Result<AidingSpec, AidingFileError> {
    let spec_err = |message: String| AidingFileError::Spec {
        file: path.into(),
        message,
    };
    let text = read_text(path)?;
    let doc: toml::Table = text.parse().map_err(|e| spec_err(format!("{e}")))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut config = AidingConfig::default();
    let mut records = Vec::new();
    for (name, v) in &doc {
        let Some((sensor, default_map)) = SENSORS.iter().find(|(s, _)| s == name) else {
            return Err(spec_err(format!(
                "unknown table `[{name}]` (expected {})",
                SENSORS.map(|s| s.0).join(", ")
            )));
        };
        let Some(t) = v.as_table() else {
            return Err(spec_err(format!("`{name}` must be a table `[{name}]`")));
        };
        let mut t = t.clone();
        for k in ["rate_hz", "outages_s", "seed"] {
            if t.contains_key(k) {
                return Err(spec_err(format!(
                    "[{name}] {k}: a simulation key; a record has its own epochs"
                )));
            }
        }
        let file = match t.remove("file") {
            Some(toml::Value::String(f)) => dir.join(f),
            _ => {
                return Err(spec_err(format!(
                    "[{name}] file: give the record's path (a string)"
                )))
            }
        };
        let map_text = match t.remove("columns") {
            Some(toml::Value::String(c)) => c,
            None => default_map.to_string(),
            Some(_) => {
                return Err(spec_err(format!(
                    "[{name}] columns: a string `quantity_unit=COLUMN,…`"
                )))
            }
        };
        let time_offset_s = match t.remove("time_offset_s") {
            None => 0.0,
            Some(v) => v
                .as_float()
                .or_else(|| v.as_integer().map(|i| i as f64))
                .filter(|x| x.is_finite())
                .ok_or_else(|| spec_err(format!("[{name}] time_offset_s: a finite number")))?,
        };
        let origin = MapOrigin::Option(format!("{}: [{name}] columns", path.display()));
        let map = ColumnMap::parse(InputKind::Aiding, &map_text, origin)?;
        let bad = |e: toml::de::Error| spec_err(format!("[{name}] {}", e.message()));
        let val = toml::Value::Table(t);
        match *sensor {
            "baro" => config.baro = Some(val.try_into().map_err(bad)?),
            "odometer" => config.odometer = Some(val.try_into().map_err(bad)?),
            "magnetometer" => config.magnetometer = Some(val.try_into().map_err(bad)?),
            "dual_antenna" => config.dual_antenna = Some(val.try_into().map_err(bad)?),
            _ => config.body_velocity = Some(val.try_into().map_err(bad)?),
        }
        records.push(SensorRecord {
            sensor,
            file,
            map,
            time_offset_s,
        });
    }
    config.validate().map_err(|e| spec_err(e.to_string()))?;
    Ok(AidingSpec { config, records })
}

/// Read every record of `spec` onto `clock` (the IMU's), merged in time order (equal
/// times in the order barometer, odometer, magnetometer, dual antenna, body velocity).
pub fn read_aiding_records(
    spec: &AidingSpec,
    clock: &RunClock,
) -> Result<Vec<AidingMeas>, AidingFileError> {
    // in the simulator's sensor order, so that equal times keep it (stable sort)
    let mut all = Vec::new();
    for (name, _) in SENSORS {
        for r in spec.records.iter().filter(|r| r.sensor == name) {
            all.extend(read_record(spec, r, clock)?);
        }
    }
    all.sort_by(|a, b| {
        use sdins_core::aiding::meas::Measurement;
        a.t_valid_s().total_cmp(&b.t_valid_s())
    });
    Ok(all)
}

fn read_record(
    spec: &AidingSpec,
    r: &SensorRecord,
    clock: &RunClock,
) -> Result<Vec<AidingMeas>, AidingFileError> {
    let m = &r.map;
    let text = read_text(&r.file)?;
    let t = Table::new(
        &r.file,
        &text,
        m.delim.unwrap_or_default(),
        m.header.unwrap_or(crate::io::columns::HeaderMode::Auto),
    )?;
    let tcol = m.need("t", "t_s, t_ms, t_us or t_ns")?.clone();
    let ti = t.index(&tcol)?;
    let wi = match m.get("week") {
        Some(c) => Some(t.index(c)?),
        None => None,
    };
    let col = |q: &str, hint: &str| -> Result<(usize, f64, String), ColumnsError> {
        let c = m.need(q, hint)?;
        Ok((t.index(c)?, c.unit.to_si, c.key.clone()))
    };
    let mut conv = TimeConverter::new(
        &TimeSpec {
            kind: m.time.unwrap_or(TimeKind::Relative),
            gps_week: None,
            week_column: wi.is_some(),
            offset_s: r.time_offset_s,
        },
        Some(clock),
    )
    .map_err(|e| ColumnsError::map(&m.origin, e))?;
    let c = &spec.config;
    let c_s_b = m.c_s_b()?;
    enum Kind {
        Baro(usize, f64, String, f64),
        Odo([(usize, f64, String); 1], Odometer),
        Mag([(usize, f64, String); 3], Vec3, f64),
        Dual(
            (usize, f64, String),
            Option<(usize, f64, String)>,
            DualAntenna,
        ),
        Dvl([(usize, f64, String); 3], BodyVelocity),
    }
    let kind = match r.sensor {
        "baro" => {
            let (i, s, k) = col("h", "h_m")?;
            Kind::Baro(i, s, k, c.baro.as_ref().map_or(1.0, |b| b.sigma_m))
        }
        "odometer" => {
            let o = c.odometer.clone().unwrap_or_default();
            Kind::Odo(
                [col("speed", "speed_mps")?],
                Odometer {
                    t_s: 0.0,
                    speed_mps: 0.0,
                    sigma_mps: o.speed_var().sqrt(),
                    c_b_v: c_b_v_from_mount_deg(&o.mount_deg),
                    lever_arm_b_m: Vec3::from(o.lever_arm_b_m),
                    nhc_sigma_mps: (o.nhc_sigma_mps > 0.0).then_some(o.nhc_sigma_mps),
                    nhc_v_mps: [0.0; 2],
                },
            )
        }
        "magnetometer" => {
            let g = c.magnetometer.clone().unwrap_or_default();
            Kind::Mag(
                [
                    col("m_x", "m_x_ut")?,
                    col("m_y", "m_y_ut")?,
                    col("m_z", "m_z_ut")?,
                ],
                mag_field_ned_ut(
                    g.declination_deg * DEG,
                    g.inclination_deg * DEG,
                    g.intensity_ut,
                ),
                g.sigma_ut,
            )
        }
        "dual_antenna" => {
            let d = c.dual_antenna.clone().unwrap_or_default();
            let el = if d.heading_only {
                None
            } else {
                Some(col("el", "el_deg")?)
            };
            Kind::Dual(
                col("az", "az_deg")?,
                el,
                DualAntenna {
                    t_s: 0.0,
                    az_rad: 0.0,
                    el_rad: 0.0,
                    baseline_b_m: Vec3::from(d.baseline_b_m),
                    sigma_rel_m: d.sigma_rel_m,
                    heading_only: d.heading_only,
                },
            )
        }
        _ => {
            let b = c.body_velocity.clone().unwrap_or_default();
            let s = Vec3::from(b.sigma_mps);
            Kind::Dvl(
                [
                    col("v_x", "v_x_mps")?,
                    col("v_y", "v_y_mps")?,
                    col("v_z", "v_z_mps")?,
                ],
                BodyVelocity {
                    t_s: 0.0,
                    v_v_mps: Vec3::zeros(),
                    cov_mps2: Mat3::from_diagonal(&s.component_mul(&s)),
                    c_b_v: c_b_v_from_mount_deg(&b.mount_deg),
                    lever_arm_b_m: Vec3::from(b.lever_arm_b_m),
                },
            )
        }
    };
    let mut out = Vec::with_capacity(t.lines.len());
    let mut f = Vec::with_capacity(t.width);
    let mut prev: Option<f64> = None;
    for k in 0..t.lines.len() {
        let line = t.row(k, &mut f)?;
        let week = match wi {
            Some(i) => Some(t.num(line, &f, i, "week")?),
            None => None,
        };
        let ts = conv
            .convert(f[ti], tcol.unit.time_exp10, week)
            .map_err(|e| t.err(line, &tcol.key, e))?;
        if prev.is_some_and(|p| ts <= p) {
            return Err(t
                .err(
                    line,
                    &tcol.key,
                    format!(
                        "expected a time after {} s, found {ts} s",
                        prev.unwrap_or(ts)
                    ),
                )
                .into());
        }
        prev = Some(ts);
        let num = |c: &(usize, f64, String)| t.num(line, &f, c.0, &c.2).map(|v| v * c.1);
        out.push(match &kind {
            Kind::Baro(i, s, key, sigma) => AidingMeas::Baro(Baro {
                t_s: ts,
                h_baro_m: t.num(line, &f, *i, key)? * s,
                sigma_m: *sigma,
            }),
            Kind::Odo([sp], o) => AidingMeas::Odometer(Odometer {
                t_s: ts,
                speed_mps: num(sp)?,
                ..*o
            }),
            Kind::Mag(cols, m_n, sigma) => {
                let m_s = Vec3::new(num(&cols[0])?, num(&cols[1])?, num(&cols[2])?);
                AidingMeas::Magnetometer(Magnetometer {
                    t_s: ts,
                    m_b_ut: c_s_b * m_s,
                    m_n_ut: *m_n,
                    sigma_ut: *sigma,
                })
            }
            Kind::Dual(az, el, d) => AidingMeas::DualAntenna(DualAntenna {
                t_s: ts,
                az_rad: num(az)?,
                el_rad: match el {
                    Some(e) => num(e)?,
                    None => 0.0,
                },
                ..*d
            }),
            Kind::Dvl(cols, b) => AidingMeas::BodyVelocity(BodyVelocity {
                t_s: ts,
                v_v_mps: Vec3::new(num(&cols[0])?, num(&cols[1])?, num(&cols[2])?),
                ..*b
            }),
        });
    }
    Ok(out)
}
