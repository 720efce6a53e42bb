//! `sdins fuse --imu FILE --gnss FILE` as one library function: read the IMU record, the
//! GNSS fixes (mapped to the IMU clock and clipped to its span, the dropped ones
//! counted), the filter's sensor model and the initial state, run
//! [`crate::fusion::records::fuse_records`] and, with a reference trajectory, compare the
//! forward and smoothed solutions with it.

use crate::cancel::CancelToken;
use crate::fusion::records::{
    fuse_records, RecordEvent, RecordInit, RecordModel, RecordOptions, RecordSummary,
    TruthComparison,
};
use crate::fusion::sensor_model::{read_sensor_model, SensorModel};
use crate::fusion::simulated::{FuseError, InitSigma};
use crate::io::columns::{ColumnsError, InputKind, MapOrigin};
use crate::io::gnss_columns::{read_gnss_columns, GnssColumns, GnssSigma};
use crate::io::gnss_file::TimeBase;
use crate::io::gnss_file::{
    clip_to_imu_span, imu_span_s, read_gnss_file, to_imu_time, GnssFileError, GnssFormat,
    GnssReadOptions, GnssReadReport, ImuClock,
};
use crate::io::imu_columns::{read_imu_record, ImuColumns, InputReport};
use crate::io::imu_file::{read_imu_file, ImuFileError, ImuFormat};
use crate::io::navego_params::{read_navego_imu_params, NavegoImuParams, ParamsError};
use crate::io::reference_file::{
    parse_generic_on, ColumnMap as ReferenceColumns, ReferenceFileError,
};
use crate::io::time::{ClockScale, RunClock};
use crate::io::truth_file::{read_truth, TruthFileError};
use crate::sensors::imu_error::ImuErrorModel;
use sdins_core::nav::InitialState;
use std::path::{Path, PathBuf};

/// Where the filter's sensor model comes from.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SensorModelSource {
    /// an sdins IMU error model (a grade preset or `[imu]` keys)
    Model(Box<ImuErrorModel>),
    /// a NaveGo `imuN_params.txt`
    NavegoParams(PathBuf),
    /// a sensor-model file (sdins TOML or KF-GINS YAML, [`crate::fusion::sensor_model`]),
    /// already read
    File(Box<SensorModel>),
}

/// Where the initial state comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum InitSource {
    /// a full state and its σ
    Given(InitialState, InitSigma),
    /// the first fix and an attitude (roll, pitch, yaw) with σ \[rad\]
    FirstFix([f64; 3], [f64; 3]),
    /// the first fix and NaveGo's `ini_align` with σ `ini_align_err` (needs
    /// [`SensorModelSource::NavegoParams`])
    FirstFixNavegoAttitude,
    /// at rest for the given seconds: coarse alignment
    StaticCoarse(f64),
}

impl SensorModelSource {
    /// From the three user options (a grade preset name, a NaveGo parameter file, a
    /// sensor-model file): exactly one must be given. The message names the options
    /// (`--grade`, `--navego-params`, `--sensor-model`). A sensor-model file is read here.
    pub fn from_options(
        grade: Option<&str>,
        navego_params: Option<&Path>,
        sensor_model: Option<&Path>,
    ) -> Result<Self, String> {
        let given: Vec<&str> = [
            ("--grade", grade.is_some()),
            ("--navego-params", navego_params.is_some()),
            ("--sensor-model", sensor_model.is_some()),
        ]
        .iter()
        .filter(|(_, g)| *g)
        .map(|(n, _)| *n)
        .collect();
        if given.len() > 1 {
            return Err(format!(
                "give either {} or {}, not both (each sets the filter's IMU model)",
                given[0], given[1]
            ));
        }
        match (grade, navego_params, sensor_model) {
            (None, Some(p), None) => Ok(SensorModelSource::NavegoParams(p.to_path_buf())),
            (Some(g), None, None) => crate::sensors::imu_error::presets::preset(g)
                .map(|m| SensorModelSource::Model(Box::new(m)))
                .map_err(|e| format!("--grade: {e}")),
            (None, None, Some(p)) => read_sensor_model(p)
                .map(|m| SensorModelSource::File(Box::new(m)))
                .map_err(|e| format!("--sensor-model: {e}")),
            _ => Err(
                "the filter needs the IMU's error model: give --grade NAME, --navego-params FILE or --sensor-model FILE"
                    .into(),
            ),
        }
    }

    /// The sensor-model file, if that is the source.
    pub fn file(&self) -> Option<&SensorModel> {
        match self {
            SensorModelSource::File(m) => Some(m),
            _ => None,
        }
    }
}

impl InitSource {
    /// From the user options (at most one of `init` (the `--init` text), `attitude_deg`
    /// with its optional σ (default 1, 1, 2°), `static_s`); none given: NaveGo's
    /// `ini_align` when `navego` is true, else an error. Messages name the options.
    pub fn from_options(
        init: Option<&str>,
        attitude_deg: Option<[f64; 3]>,
        attitude_sigma_deg: Option<[f64; 3]>,
        static_s: Option<f64>,
        navego: bool,
    ) -> Result<Self, String> {
        match (init, attitude_deg, static_s) {
            (Some(s), None, None) => crate::io::initial::parse_initial_state(s)
                .map(|st| InitSource::Given(st, InitSigma::default()))
                .map_err(|e| format!("--init: {e}")),
            (None, Some(a), None) => {
                let sig = attitude_sigma_deg.unwrap_or([1.0, 1.0, 2.0]);
                if sig.iter().any(|x| !(x.is_finite() && *x > 0.0 && *x <= 10.0)) {
                    return Err("--attitude-sigma-deg: each σ must be in (0, 10] deg (the linearised filter's limit)".into());
                }
                if a.iter().any(|x| !x.is_finite()) || a[1].abs() >= 90.0 {
                    return Err("--attitude-deg: roll, pitch, yaw must be finite and |pitch| < 90°".into());
                }
                Ok(InitSource::FirstFix(
                    a.map(f64::to_radians),
                    sig.map(f64::to_radians),
                ))
            }
            (None, None, Some(w)) => {
                if !(w.is_finite() && w > 0.0 && w <= 3600.0) {
                    return Err(format!("--static-s: must be in (0, 3600] s, got {w}"));
                }
                Ok(InitSource::StaticCoarse(w))
            }
            (None, None, None) if navego => Ok(InitSource::FirstFixNavegoAttitude),
            (None, None, None) => Err("the initial state: give --init, --attitude-deg (position and velocity from the first fix) or --static-s (coarse alignment at rest)".into()),
            _ => Err("give only one of --init, --attitude-deg, --static-s".into()),
        }
    }
}

/// The inputs of a fused run on files.
#[derive(Clone, Debug, PartialEq)]
pub struct FilesInput {
    /// IMU file and format
    pub imu: (PathBuf, ImuFormat),
    /// GNSS file and format
    pub gnss: (PathBuf, GnssFormat),
    /// reader options of the GNSS file
    pub gnss_options: GnssReadOptions,
    /// clock relation of the two files
    pub clock: ImuClock,
    /// the filter's sensor model
    pub sensor: SensorModelSource,
    /// initial state
    pub init: InitSource,
    /// optional reference trajectory (sdins truth.csv, PSINS avp, NaveGo ref.csv)
    pub truth: Option<PathBuf>,
    /// compare with the reference after this many seconds from the navigation start
    /// (the ±3σ fractions) \[s\]
    pub check_after_s: f64,
    /// column maps of the IMU and GNSS files (each `None`: the file's fixed format)
    pub columns: InputColumns,
    /// the aiding sensors' TOML file (docs/own-data.md §"Aiding sensors"), if any
    pub aiding: Option<PathBuf>,
}

/// Column maps of a fused run's files (`crate::io::columns`; docs/own-data.md).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InputColumns {
    /// the IMU file's map (its format is then ignored)
    pub imu: Option<ImuColumns>,
    /// the GNSS file's map (its format is then ignored)
    pub gnss: Option<GnssColumns>,
    /// the reference trajectory's map (it needs the velocity columns)
    pub truth: Option<ReferenceColumns>,
}

/// The column-map options as the user gives them (CLI `--imu-columns`, …; Python
/// `imu_columns=`, …): maps as text, a profile, and the values a file cannot carry.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ColumnOptions {
    /// IMU map text
    pub imu_columns: Option<String>,
    /// GNSS map text
    pub gnss_columns: Option<String>,
    /// reference map text
    pub truth_columns: Option<String>,
    /// TOML input profile with `[imu]`, `[gnss]`, `[reference]` maps
    pub profile: Option<PathBuf>,
    /// GPS week of `time=gps-sow` files without a week column
    pub gps_week: Option<u32>,
    /// σ of fixes without σ columns: `N,E,D[,vN,vE,vD]` \[m, m/s\]
    pub gnss_sigma: Option<String>,
    /// geoid undulation \[m\] for `alt_msl_m` maps
    pub undulation_m: Option<f64>,
}

impl ColumnOptions {
    /// Whether any option is given.
    pub fn any(&self) -> bool {
        *self != Self::default()
    }
    /// The maps of the options and the profile (a map given both ways is refused). `name`
    /// spells an option for messages (`imu_columns` → `--imu-columns` on the CLI).
    pub fn resolve(&self, name: &dyn Fn(&str) -> String) -> Result<InputColumns, ColumnsError> {
        let opt = |o: &str, m: String| ColumnsError::map(&MapOrigin::Option(name(o)), m);
        let mut c = match &self.profile {
            Some(p) => {
                let pr = crate::io::profile::Profile::read(p)?;
                InputColumns {
                    imu: pr.imu,
                    gnss: pr.gnss,
                    truth: pr.reference,
                }
            }
            None => InputColumns::default(),
        };
        let both = |o: &str, t: &str| opt(o, format!("the profile has a [{t}] map too: give one"));
        if let Some(text) = &self.imu_columns {
            if c.imu.is_some() {
                return Err(both("imu_columns", "imu"));
            }
            c.imu = Some(ImuColumns::parse(
                text,
                MapOrigin::Option(name("imu_columns")),
            )?);
        }
        if let Some(text) = &self.gnss_columns {
            if c.gnss.is_some() {
                return Err(both("gnss_columns", "gnss"));
            }
            c.gnss = Some(GnssColumns::parse(
                text,
                MapOrigin::Option(name("gnss_columns")),
            )?);
        }
        if let Some(text) = &self.truth_columns {
            if c.truth.is_some() {
                return Err(both("truth_columns", "reference"));
            }
            c.truth = Some(ReferenceColumns::new(crate::io::columns::ColumnMap::parse(
                InputKind::Reference,
                text,
                MapOrigin::Option(name("truth_columns")),
            )?));
        }
        if let Some(w) = self.gps_week {
            if c.imu.is_none() && c.gnss.is_none() && c.truth.is_none() {
                return Err(opt(
                    "gps_week",
                    "applies to files read through a column map".into(),
                ));
            }
            if let Some(m) = c.imu.as_mut() {
                m.gps_week = Some(w);
            }
            if let Some(m) = c.gnss.as_mut() {
                m.gps_week = Some(w);
            }
            if let Some(m) = c.truth.as_mut() {
                m.gps_week = Some(w);
            }
        }
        let need_gnss = |o: &str| {
            opt(
                o,
                format!(
                    "applies to a GNSS file read through a column map ({} or a profile's [gnss])",
                    name("gnss_columns")
                ),
            )
        };
        if let Some(s) = &self.gnss_sigma {
            let m = c.gnss.as_mut().ok_or_else(|| need_gnss("gnss_sigma"))?;
            m.sigma = Some(GnssSigma::parse(s).map_err(|e| opt("gnss_sigma", e))?);
        }
        if let Some(n) = self.undulation_m {
            if c.gnss.is_none() && c.truth.is_none() {
                return Err(need_gnss("undulation_m"));
            }
            if let Some(m) = c.gnss.as_mut() {
                m.undulation_m = Some(n);
            }
            if let Some(m) = c.truth.as_mut() {
                m.undulation_m = Some(n);
            }
        }
        Ok(c)
    }
}

/// Why a fused run on files failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FilesError {
    /// the IMU file
    #[error(transparent)]
    Imu(#[from] ImuFileError),
    /// the GNSS file
    #[error(transparent)]
    Gnss(#[from] GnssFileError),
    /// the NaveGo parameters
    #[error(transparent)]
    Params(#[from] ParamsError),
    /// the reference trajectory
    #[error(transparent)]
    Truth(#[from] TruthFileError),
    /// a column map or a file read through one
    #[error(transparent)]
    Columns(#[from] ColumnsError),
    /// a reference trajectory read through a column map
    #[error(transparent)]
    Reference(#[from] ReferenceFileError),
    /// the filter or an option
    #[error(transparent)]
    Fuse(#[from] FuseError),
    /// the aiding sensors' files
    #[error(transparent)]
    Aiding(#[from] crate::io::aiding_file::AidingFileError),
}

/// What a fused run on files did.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct FilesResult {
    /// the filter run
    pub summary: RecordSummary,
    /// IMU format read, samples, interval \[s\]
    pub imu_format: ImuFormat,
    /// IMU samples
    pub imu_samples: usize,
    /// IMU sample interval \[s\]
    pub imu_dt_s: f64,
    /// IMU reader warnings
    pub imu_warnings: Vec<String>,
    /// GNSS format read
    pub gnss_format: GnssFormat,
    /// GNSS reader report
    pub gnss_report: GnssReadReport,
    /// fixes inside the IMU record
    pub fixes_in_span: usize,
    /// fixes dropped before / after the IMU record
    pub fixes_outside: (usize, usize),
    /// comparison of the forward solution with the reference
    pub forward: Option<TruthComparison>,
    /// comparison of the smoothed solution with the reference
    pub smoothed: Option<TruthComparison>,
    /// what the column maps did (time base, clock origin, offsets), IMU first
    pub inputs: Vec<InputReport>,
    /// the sensor-model file used, if that was the source (for run.toml)
    pub sensor_model: Option<SensorModel>,
}

/// Run it; `observe` sees every forward and smoothed point and every update, with the
/// point's errors against the reference (roll, pitch, yaw \[rad\], v_N, v_E, v_D \[m/s\],
/// N, E, D \[m\]) when one is given and matches the point's time.
pub fn fuse_files(
    input: &FilesInput,
    opts: &RecordOptions,
    cancel: &CancelToken,
    mut observe: impl FnMut(RecordEvent<'_>, Option<&[f64; 9]>),
) -> Result<FilesResult, FilesError> {
    let mut inputs = Vec::new();
    let imu = match &input.columns.imu {
        Some(c) => {
            let (d, rep) = read_imu_record(&input.imu.0, c, None)?;
            inputs.push(rep);
            d
        }
        None => read_imu_file(&input.imu.0, input.imu.1)?,
    };
    let gnss = match &input.columns.gnss {
        Some(c) => {
            // on the IMU map's clock; alone, on its own scale from origin 0 (GPS seconds
            // since the epoch or of week), which the fixed IMU formats' clocks understand
            let alone = |scale| RunClock { scale, origin_s: 0 };
            let (clock, base) = match inputs.first() {
                Some(r) => (r.clock, TimeBase::FileSeconds),
                None => match c.map.time.unwrap_or_default() {
                    crate::io::columns::TimeKind::Relative => {
                        (alone(ClockScale::File), TimeBase::FileSeconds)
                    }
                    crate::io::columns::TimeKind::GpsSow
                        if c.gps_week.is_none() && c.map.get("week").is_none() =>
                    {
                        (
                            alone(ClockScale::GpsWeekUnknown),
                            TimeBase::GpsSecondsOfWeek,
                        )
                    }
                    _ => (alone(ClockScale::Gpst), TimeBase::GpsSecondsSinceEpoch),
                },
            };
            let (mut d, rep) = read_gnss_columns(&input.gnss.0, c, Some(&clock))?;
            d.time_base = base;
            inputs.push(rep);
            d
        }
        None => read_gnss_file(&input.gnss.0, input.gnss.1, &input.gnss_options)?,
    };
    let on_imu = to_imu_time(&input.gnss.0, &gnss, input.clock)?;
    let (first, last) = imu_span_s(&imu);
    let clip = clip_to_imu_span(&input.gnss.0, &on_imu, first, last)?;
    let mut navego: Option<NavegoImuParams> = None;
    let model = match &input.sensor {
        SensorModelSource::Model(m) => RecordModel::from_error_model(m),
        SensorModelSource::NavegoParams(p) => {
            let prm = read_navego_imu_params(p)?;
            let m = RecordModel::from_navego(&prm);
            navego = Some(prm);
            m
        }
        SensorModelSource::File(m) => m.model,
    };
    let init = match input.init {
        InitSource::Given(state, sigma) => RecordInit::Given { state, sigma },
        InitSource::FirstFix(rpy_rad, rpy_sigma_rad) => RecordInit::FirstFix {
            rpy_rad,
            rpy_sigma_rad,
        },
        InitSource::FirstFixNavegoAttitude => {
            let Some(p) = &navego else {
                return Err(FuseError::Option(
                    "init",
                    "NaveGo's ini_align needs NaveGo IMU parameters (--navego-params)".into(),
                )
                .into());
            };
            RecordInit::FirstFix {
                rpy_rad: p.ini_align_rpy_rad,
                rpy_sigma_rad: p.ini_align_err_rpy_rad,
            }
        }
        InitSource::StaticCoarse(w) => RecordInit::StaticCoarse { window_s: w },
    };
    let truth = match (&input.truth, &input.columns.truth) {
        (Some(p), Some(m)) => {
            let (t, rep) = read_truth_columns(p, m, inputs.first().map(|r| r.clock))?;
            inputs.push(rep);
            Some(t)
        }
        (Some(p), None) => Some(read_truth(p)?),
        (None, Some(m)) => {
            return Err(ColumnsError::map(
                &m.map.origin,
                "a reference map needs a reference file (--truth FILE / truth=)",
            )
            .into())
        }
        (None, None) => None,
    };
    // the comparison starts counting ±3σ after the navigation start + check_after_s;
    // the start is known only inside fuse_records: use the later of the first fix and
    // the record start (the two possible starts)
    let t0 = match init {
        RecordInit::FirstFix { .. } => clip.fixes.first().map_or(first, |f| f.t_s.max(first)),
        _ => first,
    };
    let t_check = t0 + input.check_after_s;
    let mut fwd = truth
        .clone()
        .map(|t| TruthComparison::new(opts.earth, t, t_check));
    let mut smo = if opts.smooth {
        truth.map(|t| TruthComparison::new(opts.earth, t, t_check))
    } else {
        None
    };
    // the aiding sensors' records, on the IMU map's clock (or the fixed format's seconds)
    let aided;
    let opts = match &input.aiding {
        Some(p) => {
            let spec = crate::io::aiding_file::read_aiding_spec(p)?;
            let clock = inputs.first().map_or(
                RunClock {
                    scale: ClockScale::File,
                    origin_s: 0,
                },
                |r| r.clock,
            );
            let meas = crate::io::aiding_file::read_aiding_records(&spec, &clock)?;
            aided = RecordOptions {
                aiding: crate::fusion::records::AidingRecord {
                    config: spec.config,
                    meas,
                },
                ..opts.clone()
            };
            &aided
        }
        None => opts,
    };
    let summary = fuse_records(&imu, &clip.fixes, &model, &init, opts, cancel, |ev| {
        let err = match ev {
            RecordEvent::Forward(p) => fwd.as_mut().and_then(|c| c.add(p)),
            RecordEvent::Smoothed(p) => smo.as_mut().and_then(|c| c.add(p)),
            _ => None,
        };
        observe(ev, err.as_ref());
    })?;
    Ok(FilesResult {
        summary,
        imu_format: imu.format,
        imu_samples: imu.increments.len(),
        imu_dt_s: imu.dt_s,
        imu_warnings: imu.warnings,
        gnss_format: gnss.format,
        gnss_report: gnss.report,
        fixes_in_span: clip.fixes.len(),
        fixes_outside: (clip.before, clip.after),
        forward: fwd,
        smoothed: smo,
        inputs,
        sensor_model: input.sensor.file().cloned(),
    })
}

/// A reference trajectory read through a map, as truth samples on the run's clock (the
/// IMU map's, else the file's own). The comparison needs the velocity: a map without
/// `v_n`/`v_e` columns is refused.
fn read_truth_columns(
    path: &Path,
    m: &ReferenceColumns,
    clock: Option<RunClock>,
) -> Result<(Vec<crate::truth::TruthSample>, InputReport), FilesError> {
    let bytes = crate::input::read_capped(path).map_err(|source| TruthFileError::Io {
        file: path.into(),
        source,
    })?;
    let text = crate::input::text_lossy(bytes);
    let (rows, rep) = parse_generic_on(path, &text, m, clock.as_ref())?;
    let mut out = Vec::with_capacity(rows.len());
    for r in rows {
        let Some(v) = r.v_n_mps else {
            return Err(ColumnsError::map(
                &m.map.origin,
                "the comparison with the reference needs its velocity: map v_n, v_e and v_d (or v_u)",
            )
            .into());
        };
        out.push(crate::truth::TruthSample::new(
            r.t_s,
            Default::default(),
            r.lat_rad,
            r.lon_rad,
            r.h_m,
            v,
            sdins_core::math::c_b_n_from_euler(&r.euler),
        ));
    }
    Ok((out, rep))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    const IMU: &str =
        "t_s=time,gyro_x_dps=gx,gyro_y_dps=gy,gyro_z_dps=gz,accel_x_g=ax,accel_y_g=ay,accel_z_g=az";
    const GNSS: &str = "t_s=time,lat_deg=lat,lon_deg=lon,alt_msl_m=alt";

    fn cli(n: &str) -> String {
        format!("--{}", n.replace('_', "-"))
    }

    #[test]
    fn column_options_resolve_and_name_the_caller_s_option() {
        let o = ColumnOptions {
            imu_columns: Some(IMU.into()),
            gnss_columns: Some(GNSS.into()),
            gnss_sigma: Some("1,1,2".into()),
            undulation_m: Some(30.0),
            gps_week: Some(2300),
            ..Default::default()
        };
        let c = o.resolve(&cli).unwrap();
        let g = c.gnss.unwrap();
        assert_eq!(g.undulation_m, Some(30.0));
        assert_eq!(g.gps_week, Some(2300));
        assert!(g.sigma.is_some());
        assert_eq!(c.imu.unwrap().gps_week, Some(2300));
        assert!(!ColumnOptions::default().any() && o.any());
        // σ without a GNSS map; a bad σ; a reflection: each names the option as spelled
        let e = ColumnOptions {
            gnss_sigma: Some("1,1,2".into()),
            ..Default::default()
        }
        .resolve(&|n: &str| n.to_string())
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("gnss_sigma: ") && e.contains("gnss_columns"),
            "{e}"
        );
        let e = ColumnOptions {
            gnss_sigma: Some("1,1".into()),
            ..o.clone()
        }
        .resolve(&cli)
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("--gnss-sigma: "), "{e}");
        let e = ColumnOptions {
            imu_columns: Some(format!("{IMU},axes=x:+y,y:+x,z:+z")),
            ..Default::default()
        }
        .resolve(&cli)
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("--imu-columns: ") && e.contains("reflection"),
            "{e}"
        );
    }

    #[test]
    fn a_map_in_the_profile_and_an_option_is_refused() {
        let dir = std::env::temp_dir().join(format!("sdins-colopt-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("p.toml");
        std::fs::write(&p, format!("[imu]\ncolumns = \"{IMU}\"\n")).unwrap();
        let from_profile = ColumnOptions {
            profile: Some(p.clone()),
            ..Default::default()
        };
        assert!(from_profile.resolve(&cli).unwrap().imu.is_some());
        let e = ColumnOptions {
            imu_columns: Some(IMU.into()),
            ..from_profile
        }
        .resolve(&cli)
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("--imu-columns: the profile has a [imu] map"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
