//! A recorded trajectory as a scenario (`sdins truth --from-reference`; docs/scenarios.md
//! §"Recorded trajectories"): the rows read by [`crate::io::reference_file`], the C²
//! interpolant of [`crate::truth::reference`], an ideal IMU at the chosen rate.

use super::{EarthChoice, ImuConfig, Mounting, NavConfig, Scenario, Start};
use crate::io::reference_file::{read_reference, ColumnMap, ReferenceFileError, ReferenceFormat};
use crate::truth::reference::{ReferenceTrack, VelocityComparison};
use crate::truth::trajectory::Trajectory;
use sdins_core::math::euler_from_c_b_n;
use std::path::Path;

/// How a recorded trajectory becomes a scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceOptions {
    /// the reader
    pub format: ReferenceFormat,
    /// IMU sample rate \[Hz\]
    pub rate_hz: f64,
    /// earth model of truth and navigation
    pub earth: EarthChoice,
}

impl ReferenceOptions {
    /// Options from their command-line / Python spellings: `columns` the text form of a
    /// [`ColumnMap`] (`None`: a known format told apart by the header), `earth` `wgs84` or
    /// `psins` (a recorded trajectory needs an ellipsoid).
    pub fn from_names(
        rate_hz: f64,
        columns: Option<&str>,
        earth: &str,
    ) -> Result<Self, ReferenceFileError> {
        let earth = match earth {
            "wgs84" => EarthChoice::Wgs84,
            "psins" => EarthChoice::Psins,
            other => {
                let message = format!("`{other}`: expected wgs84 or psins (an ellipsoid)");
                return Err(ReferenceFileError::Option {
                    option: "--earth",
                    message,
                });
            }
        };
        let format = match columns {
            Some(m) => ReferenceFormat::Generic(Box::new(ColumnMap::parse(m)?)),
            None => ReferenceFormat::Auto,
        };
        Ok(Self {
            format,
            rate_hz,
            earth,
        })
    }
}

impl Default for ReferenceOptions {
    fn default() -> Self {
        Self {
            format: ReferenceFormat::Auto,
            rate_hz: 100.0,
            earth: EarthChoice::Wgs84,
        }
    }
}

/// What [`scenario_from_reference`] built, besides the scenario.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceSummary {
    /// rows read
    pub rows: usize,
    /// reference time of the first row (truth time 0) \[s\]
    pub t0_s: f64,
    /// the file's span \[s\]
    pub span_s: f64,
    /// the truth's duration: the span cut to whole IMU samples \[s\]
    pub duration_s: f64,
    /// the file's velocity against the interpolant's, if the file has velocity
    pub velocity: Option<VelocityComparison>,
}

/// A scenario whose trajectory is the C² interpolant of a recorded trajectory
/// ([`crate::truth::reference`]): start at the first row, ideal IMU at `opts.rate_hz`, the
/// default navigation set-up; checked against the kinematic envelope.
pub fn scenario_from_reference(
    path: &Path,
    opts: &ReferenceOptions,
) -> Result<(Scenario, ReferenceSummary), ReferenceFileError> {
    if !(opts.rate_hz.is_finite() && opts.rate_hz > 0.0 && opts.rate_hz <= 100_000.0) {
        return Err(ReferenceFileError::Option {
            option: "--rate-hz",
            message: format!("{}: expected a rate in (0, 100000] Hz", opts.rate_hz),
        });
    }
    let rows = read_reference(path, &opts.format)?;
    let earth = opts.earth.model();
    let track =
        ReferenceTrack::new(&rows, &earth).map_err(|source| ReferenceFileError::Reference {
            file: path.into(),
            source,
        })?;
    let dt = 1.0 / opts.rate_hz;
    let span = track.duration_s();
    let n = (span / dt * (1.0 + 1e-12)).floor();
    if n < 1.0 {
        return Err(ReferenceFileError::Option {
            option: "--rate-hz",
            message: format!(
                "the reference spans {span} s, less than one sample at {} Hz",
                opts.rate_hz
            ),
        });
    }
    let duration = n * dt;
    let summary = ReferenceSummary {
        rows: rows.len(),
        t0_s: track.t0_s(),
        span_s: span,
        duration_s: duration,
        velocity: track.velocity_comparison(),
    };
    let p0 = track.at(0.0, 0.0);
    let e0 = euler_from_c_b_n(&p0.kin.c_b_n);
    let v0 = p0.kin.v_n_mps;
    let start = Start {
        lat_rad: p0.lat_rad,
        lon_rad: p0.lon_rad,
        h_m: p0.h_m,
        speed_mps: v0.x.hypot(v0.y),
        climb_rate_mps: -v0.z,
        euler: e0,
    };
    let trajectory = Trajectory::from_reference(track, duration, Vec::new());
    if let Err(e) = crate::truth::envelope::check_trajectory(
        &trajectory,
        crate::truth::envelope::StartPosition {
            lat_rad: start.lat_rad,
            h_m: start.h_m,
        },
        dt,
        &crate::truth::envelope::Envelope::DEFAULT,
    ) {
        return Err(ReferenceFileError::Envelope {
            file: path.into(),
            message: format!(
                "{e} (trajectory time, reference time minus {} s)",
                summary.t0_s
            ),
        });
    }
    let mut nav = NavConfig {
        earth: opts.earth,
        ..NavConfig::default()
    };
    nav.substeps = crate::truth::auto_substeps(dt, &trajectory);
    let name = path
        .file_stem()
        .map_or_else(|| "reference".into(), |s| s.to_string_lossy().into_owned());
    let scn = Scenario {
        description: format!(
            "recorded trajectory {} at {} Hz",
            path.display(),
            opts.rate_hz
        ),
        name,
        start,
        imu: ImuConfig {
            rate_hz: opts.rate_hz,
            seed: 1,
            grade: None,
            errors: None,
            model: crate::sensors::imu_error::ImuErrorModel::ideal(),
        },
        nav,
        trajectory,
        gnss: None,
        aiding: Default::default(),
        raw_gnss: None,
        source_toml: format!(
            "# sdins truth --from-reference {} --rate-hz {}\n",
            path.display(),
            opts.rate_hz
        ),
        mounting: Mounting::default(),
        vibration: Vec::new(),
        route: None,
    };
    Ok((scn, summary))
}
