//! The user's own sensor model (`sdins fuse --sensor-model FILE`, docs/own-data.md
//! §"Your sensor model"): the filter's IMU error model, and optionally the antenna lever
//! arm and the initial σ, from a small TOML file whose keys and units are those of a
//! scenario's `[imu.errors]` ([`crate::sensors::imu_error::ImuErrorModel`]) where they
//! exist, or from a KF-GINS YAML configuration ([`super::kfgins_yaml`], chosen by the
//! extension `.yaml`/`.yml`).
//!
//! ```toml
//! [imu]
//! gyro_arw_dpsh = [0.003, 0.003, 0.003]           # °/√h
//! accel_vrw_mpsph = [0.03, 0.03, 0.03]            # m/s/√h (or accel_vrw_ugpsqrthz, μg/√Hz)
//! gyro_bias_dph = [0, 0, 0]                       # known bias, subtracted, °/h
//! gyro_bias_turn_on_dph = [1, 1, 1]               # turn-on σ, °/h
//! gyro_bias_gm_dph = [0.03, 0.03, 0.03]           # Gauss–Markov σ, °/h
//! gyro_bias_gm_tau_s = [3600, 3600, 3600]         # its correlation time, s
//! # or, from a datasheet: bias instability B and the τ of the Allan floor
//! # gyro_bias_instability_dph = [0.5, 0.5, 0.5]
//! # gyro_bias_instability_tau_s = [100, 100, 100]
//! gyro_rrw_dphpsh = [0, 0, 0]                     # rate random walk, °/h/√h
//! gyro_scale_sigma_ppm = [300, 300, 300]          # scale-factor σ (adds the 6 states)
//! # accel_*: the same with _ug, _ugpsh (μg, μg/√h)
//! [gnss]
//! lever_arm_b_m = [0.136, -0.301, -0.184]         # IMU → antenna, body FRD, m
//! [initial]
//! position_sigma_m = [3, 3, 3]                    # N, E, D (with --init)
//! velocity_sigma_mps = [0.1, 0.1, 0.1]            # N, E, D (with --init)
//! attitude_sigma_deg = [1, 1, 2]                  # roll, pitch, yaw
//! attitude_deg = [0, 0, -15]                      # used when no --init/--attitude-deg/--static-s
//! ```
//!
//! **Bias instability → Gauss–Markov.** The Allan deviation of a first-order
//! Gauss–Markov process of σ, T peaks at ≈ [`GM_ADEV_PEAK`]·σ at τ ≈ [`GM_ADEV_PEAK_TAU`]·T;
//! a datasheet's bias-instability floor is 0.664·B (IEEE Std 952, flicker). Matching the
//! peak to the floor and its averaging time τ_floor gives σ = 0.664·B / 0.618,
//! T = τ_floor / 1.89 ([`bias_instability_to_gm`]; the unit tests derive both constants
//! from the exact Allan variance, [`gm_allan_variance`]).
//!
//! Every value is checked (finite; σ, densities ≥ 0; correlation times and initial σ
//! strictly positive); an unknown key or a bad value is a [`SensorModelError`] naming the file, the
//! line and the key.

use crate::fusion::records::RecordModel;
use crate::fusion::simulated::ScaleFactorPrior;
use crate::sensors::imu_error::{DPH, DPHPSH, DPSH, MPS_PER_SQRT_H, UG, UG_PER_SQRT_H};
use sdins_core::aiding::ekf::NoiseModel;
use sdins_core::math::Vec3;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Allan deviation peak of a first-order Gauss–Markov process, in units of its σ (the
/// usual rounded value; the exact peak is 0.61736).
pub const GM_ADEV_PEAK: f64 = 0.618;
/// τ of that peak, in units of the correlation time T.
pub const GM_ADEV_PEAK_TAU: f64 = 1.89;
/// The Allan floor of flicker bias noise in units of the bias instability B (√(2 ln 2/π)).
pub const FLICKER_FLOOR: f64 = 0.664;

/// The exact Allan variance at averaging time `tau_s` of a first-order Gauss–Markov
/// process of steady-state σ `sigma` and correlation time `t_s` (autocorrelation
/// σ² e^(−|t|/T)): (2σ²T/τ)·[1 − (T/(2τ))(3 − 4e^(−τ/T) + e^(−2τ/T))].
pub fn gm_allan_variance(sigma: f64, t_s: f64, tau_s: f64) -> f64 {
    let x = tau_s / t_s;
    sigma * sigma * (2.0 / x) * (1.0 - (3.0 - 4.0 * (-x).exp() + (-2.0 * x).exp()) / (2.0 * x))
}

/// A bias instability `b` (any unit) with the averaging time of its Allan floor
/// `tau_floor_s` as a Gauss–Markov (σ in the unit of `b`, T \[s\]): σ = 0.664 b / 0.618,
/// T = τ_floor / 1.89.
pub fn bias_instability_to_gm(b: f64, tau_floor_s: f64) -> (f64, f64) {
    (
        FLICKER_FLOOR * b / GM_ADEV_PEAK,
        tau_floor_s / GM_ADEV_PEAK_TAU,
    )
}

/// Why a sensor-model file could not be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SensorModelError {
    /// The file could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// the file
        file: PathBuf,
        /// the cause
        source: std::io::Error,
    },
    /// The file does not parse (syntax, unknown key, wrong type).
    #[error("{}:{line}: {message}", file.display())]
    Syntax {
        /// the file
        file: PathBuf,
        /// 1-based line (0: unknown)
        line: usize,
        /// the parser's message (names the key)
        message: String,
    },
    /// A value is out of range or keys contradict each other.
    #[error("{}:{line}: `{key}`: {what}", file.display())]
    Invalid {
        /// the file
        file: PathBuf,
        /// 1-based line (0: unknown)
        line: usize,
        /// the key
        key: String,
        /// what is wrong
        what: String,
    },
}

/// Which format a sensor-model file is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum SensorModelFormat {
    /// the sdins TOML described in the module documentation
    Toml,
    /// a KF-GINS `kf-gins.yaml`
    KfGinsYaml,
}

impl SensorModelFormat {
    /// Name for run.toml.
    pub fn name(self) -> &'static str {
        match self {
            SensorModelFormat::Toml => "sdins-toml",
            SensorModelFormat::KfGinsYaml => "kf-gins-yaml",
        }
    }
}

/// The initial σ a sensor-model file gives (each `None`: the option's default).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InitialSigma {
    /// position σ N, E, D \[m\]
    pub pos_ned_m: Option<[f64; 3]>,
    /// velocity σ N, E, D \[m/s\]
    pub vel_ned_mps: Option<[f64; 3]>,
    /// attitude σ roll, pitch, yaw \[rad\]
    pub att_rpy_rad: Option<[f64; 3]>,
}

/// A sensor model as the filter uses it (SI units).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SensorModel {
    /// the file read
    pub file: PathBuf,
    /// its format
    pub format: SensorModelFormat,
    /// the filter's IMU model (noise, bias dynamics and prior, known bias)
    pub model: RecordModel,
    /// scale-factor prior σ (adds the scale-factor states), if given
    pub scale_sigma: Option<ScaleFactorPrior>,
    /// antenna lever arm, body FRD \[m\]
    pub lever_arm_b_m: Option<[f64; 3]>,
    /// initial σ
    pub initial_sigma: InitialSigma,
    /// initial attitude roll, pitch, yaw \[rad\] (position and velocity from the first fix)
    pub attitude_rpy_rad: Option<[f64; 3]>,
    /// KF-GINS only: what the YAML gives beyond the model (recorded, not used)
    pub kfgins: Option<super::kfgins_yaml::KfGinsExtras>,
}

impl SensorModel {
    /// The model as a run.toml table (SI units, names with units).
    pub fn to_toml(&self) -> toml::Table {
        let v = |x: &Vec3| toml::Value::Array(x.iter().map(|&e| e.into()).collect());
        let a = |x: &[f64; 3]| toml::Value::Array(x.iter().map(|&e| e.into()).collect());
        let n = &self.model.noise;
        let mut t = toml::Table::new();
        t.insert("file".into(), self.file.display().to_string().into());
        t.insert("format".into(), self.format.name().into());
        t.insert("arw_rad_per_sqrt_s".into(), v(&n.arw_rad_per_sqrt_s));
        t.insert("vrw_mps_per_sqrt_s".into(), v(&n.vrw_mps_per_sqrt_s));
        t.insert("gyro_bias_gm_rps".into(), v(&n.gyro_bias_gm_rps));
        t.insert("gyro_bias_tau_s".into(), v(&n.gyro_bias_tau_s.map(inf0)));
        t.insert("accel_bias_gm_mps2".into(), v(&n.accel_bias_gm_mps2));
        t.insert("accel_bias_tau_s".into(), v(&n.accel_bias_tau_s.map(inf0)));
        t.insert("gyro_bias_rw".into(), v(&n.gyro_bias_rw));
        t.insert("accel_bias_rw".into(), v(&n.accel_bias_rw));
        t.insert(
            "gyro_bias_prior_sigma_rps".into(),
            v(&self.model.gyro_bias_sigma_rps),
        );
        t.insert(
            "accel_bias_prior_sigma_mps2".into(),
            v(&self.model.accel_bias_sigma_mps2),
        );
        t.insert("gyro_bias_known_rps".into(), v(&self.model.gyro_bias0_rps));
        t.insert(
            "accel_bias_known_mps2".into(),
            v(&self.model.accel_bias0_mps2),
        );
        if let Some(s) = &self.scale_sigma {
            t.insert("gyro_scale_sigma_ppm".into(), a(&s.gyro_ppm));
            t.insert("accel_scale_sigma_ppm".into(), a(&s.accel_ppm));
        }
        if let Some(l) = &self.lever_arm_b_m {
            t.insert("lever_arm_b_m".into(), a(l));
        }
        if let Some(k) = &self.kfgins {
            t.insert("kfgins".into(), k.to_toml().into());
        }
        t
    }
}

/// 0 for an infinite correlation time (TOML has no infinity in our run files' readers).
fn inf0(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// Read a sensor model: `.yaml`/`.yml` as KF-GINS, anything else as the sdins TOML.
pub fn read_sensor_model(path: &Path) -> Result<SensorModel, SensorModelError> {
    let bytes = crate::input::read_capped(path).map_err(|source| SensorModelError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    let text = crate::input::text_lossy(bytes);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("yaml" | "yml") => super::kfgins_yaml::parse_kfgins_yaml(path, &text),
        _ => parse_sensor_model_toml(path, &text),
    }
}

type V3 = Option<Spanned<[f64; 3]>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    imu: Option<ImuRaw>,
    gnss: Option<GnssRaw>,
    initial: Option<InitialRaw>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct ImuRaw {
    gyro_arw_dpsh: V3,
    accel_vrw_ugpsqrthz: V3,
    accel_vrw_mpsph: V3,
    gyro_bias_dph: V3,
    accel_bias_ug: V3,
    gyro_bias_turn_on_dph: V3,
    accel_bias_turn_on_ug: V3,
    gyro_bias_gm_dph: V3,
    gyro_bias_gm_tau_s: V3,
    accel_bias_gm_ug: V3,
    accel_bias_gm_tau_s: V3,
    gyro_bias_instability_dph: V3,
    gyro_bias_instability_tau_s: V3,
    accel_bias_instability_ug: V3,
    accel_bias_instability_tau_s: V3,
    gyro_rrw_dphpsh: V3,
    accel_rrw_ugpsh: V3,
    gyro_scale_sigma_ppm: V3,
    accel_scale_sigma_ppm: V3,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GnssRaw {
    lever_arm_b_m: V3,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InitialRaw {
    position_sigma_m: V3,
    velocity_sigma_mps: V3,
    attitude_sigma_deg: V3,
    attitude_deg: V3,
}

/// 1-based line of byte `offset` in `text`.
pub(super) fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// Value ranges.
#[derive(Clone, Copy)]
pub(super) enum Range {
    /// finite
    Finite,
    /// finite and ≥ 0
    NonNegative,
    /// finite and > 0
    Positive,
}

/// Check `v` against `range`; the error names `key` at `line`.
pub(super) fn check(
    file: &Path,
    line: usize,
    key: &str,
    v: &[f64],
    range: Range,
) -> Result<(), SensorModelError> {
    for &x in v {
        let (ok, what) = match range {
            Range::Finite => (x.is_finite(), "must be finite"),
            Range::NonNegative => (x.is_finite() && x >= 0.0, "must be finite and >= 0"),
            Range::Positive => (x.is_finite() && x > 0.0, "must be finite and > 0"),
        };
        if !ok {
            return Err(SensorModelError::Invalid {
                file: file.to_path_buf(),
                line,
                key: key.to_string(),
                what: format!("{what}, got {x}"),
            });
        }
    }
    Ok(())
}

struct Ctx<'a> {
    file: &'a Path,
    text: &'a str,
}

impl Ctx<'_> {
    fn get(
        &self,
        section: &str,
        key: &str,
        v: &V3,
        range: Range,
    ) -> Result<Option<[f64; 3]>, SensorModelError> {
        let Some(s) = v else { return Ok(None) };
        let line = line_of(self.text, s.span().start);
        check(
            self.file,
            line,
            &format!("{section}.{key}"),
            s.get_ref(),
            range,
        )?;
        Ok(Some(*s.get_ref()))
    }

    fn line(&self, v: &V3) -> usize {
        v.as_ref().map_or(0, |s| line_of(self.text, s.span().start))
    }
}

/// One sensor's bias terms in SI (σ's and the correlation time).
struct Bias {
    gm: [f64; 3],
    tau_s: [f64; 3],
}

/// The Gauss–Markov part of one sensor: `gm`/`gm_tau` or `instability`/`instability_tau`
/// (not both), converted with `unit`.
#[allow(clippy::too_many_arguments)]
fn gm_part(
    c: &Ctx<'_>,
    names: [&str; 4],
    gm: &V3,
    gm_tau: &V3,
    inst: &V3,
    inst_tau: &V3,
    unit: f64,
) -> Result<Bias, SensorModelError> {
    use Range::*;
    let g = c.get("imu", names[0], gm, NonNegative)?;
    let gt = c.get("imu", names[1], gm_tau, Positive)?;
    let b = c.get("imu", names[2], inst, NonNegative)?;
    let bt = c.get("imu", names[3], inst_tau, Positive)?;
    let invalid = |line: usize, key: &str, what: String| SensorModelError::Invalid {
        file: c.file.to_path_buf(),
        line,
        key: format!("imu.{key}"),
        what,
    };
    match (g, b) {
        (Some(_), Some(_)) => Err(invalid(
            c.line(inst),
            names[2],
            format!(
                "give either {} (with {}) or {} (with {}), not both",
                names[0], names[1], names[2], names[3]
            ),
        )),
        (Some(g), None) => {
            let tau = match gt {
                Some(t) => t,
                None if g.iter().all(|&x| x == 0.0) => [f64::INFINITY; 3],
                None => {
                    return Err(invalid(
                        c.line(gm),
                        names[0],
                        format!("needs {} (the correlation time, s)", names[1]),
                    ))
                }
            };
            Ok(Bias {
                gm: g.map(|x| x * unit),
                tau_s: std::array::from_fn(|i| if g[i] > 0.0 { tau[i] } else { f64::INFINITY }),
            })
        }
        (None, Some(b)) => {
            let Some(t) = bt else {
                return Err(invalid(
                    c.line(inst),
                    names[2],
                    format!(
                        "needs {} (the averaging time of the Allan floor, s)",
                        names[3]
                    ),
                ));
            };
            let mut gm = [0.0; 3];
            let mut tau = [f64::INFINITY; 3];
            for i in 0..3 {
                if b[i] > 0.0 {
                    let (s, tt) = bias_instability_to_gm(b[i] * unit, t[i]);
                    gm[i] = s;
                    tau[i] = tt;
                }
            }
            Ok(Bias { gm, tau_s: tau })
        }
        (None, None) => Ok(Bias {
            gm: [0.0; 3],
            tau_s: [f64::INFINITY; 3],
        }),
    }
}

/// Parse the sdins sensor-model TOML; `file` names the file in errors.
pub fn parse_sensor_model_toml(file: &Path, text: &str) -> Result<SensorModel, SensorModelError> {
    let raw: Raw = toml::from_str(text).map_err(|e| SensorModelError::Syntax {
        file: file.to_path_buf(),
        line: e.span().map_or(0, |s| line_of(text, s.start)),
        message: e.message().trim().to_string(),
    })?;
    let c = Ctx { file, text };
    use Range::*;
    let im = raw.imu.unwrap_or_default();
    let z = |o: Option<[f64; 3]>| o.unwrap_or([0.0; 3]);
    let arw = z(c.get("imu", "gyro_arw_dpsh", &im.gyro_arw_dpsh, NonNegative)?);
    let vrw_a = z(c.get(
        "imu",
        "accel_vrw_ugpsqrthz",
        &im.accel_vrw_ugpsqrthz,
        NonNegative,
    )?);
    let vrw_b = z(c.get("imu", "accel_vrw_mpsph", &im.accel_vrw_mpsph, NonNegative)?);
    let bg0 = z(c.get("imu", "gyro_bias_dph", &im.gyro_bias_dph, Finite)?);
    let ba0 = z(c.get("imu", "accel_bias_ug", &im.accel_bias_ug, Finite)?);
    let bg_on = z(c.get(
        "imu",
        "gyro_bias_turn_on_dph",
        &im.gyro_bias_turn_on_dph,
        NonNegative,
    )?);
    let ba_on = z(c.get(
        "imu",
        "accel_bias_turn_on_ug",
        &im.accel_bias_turn_on_ug,
        NonNegative,
    )?);
    let g = gm_part(
        &c,
        [
            "gyro_bias_gm_dph",
            "gyro_bias_gm_tau_s",
            "gyro_bias_instability_dph",
            "gyro_bias_instability_tau_s",
        ],
        &im.gyro_bias_gm_dph,
        &im.gyro_bias_gm_tau_s,
        &im.gyro_bias_instability_dph,
        &im.gyro_bias_instability_tau_s,
        DPH,
    )?;
    let a = gm_part(
        &c,
        [
            "accel_bias_gm_ug",
            "accel_bias_gm_tau_s",
            "accel_bias_instability_ug",
            "accel_bias_instability_tau_s",
        ],
        &im.accel_bias_gm_ug,
        &im.accel_bias_gm_tau_s,
        &im.accel_bias_instability_ug,
        &im.accel_bias_instability_tau_s,
        UG,
    )?;
    let g_rrw = z(c.get("imu", "gyro_rrw_dphpsh", &im.gyro_rrw_dphpsh, NonNegative)?);
    let a_rrw = z(c.get("imu", "accel_rrw_ugpsh", &im.accel_rrw_ugpsh, NonNegative)?);
    let gs = c.get(
        "imu",
        "gyro_scale_sigma_ppm",
        &im.gyro_scale_sigma_ppm,
        NonNegative,
    )?;
    let as_ = c.get(
        "imu",
        "accel_scale_sigma_ppm",
        &im.accel_scale_sigma_ppm,
        NonNegative,
    )?;
    let scale_sigma = scale_prior(&c, gs, as_, &im)?;
    let v = |x: [f64; 3], u: f64| Vec3::new(x[0] * u, x[1] * u, x[2] * u);
    let vrw_a = v(vrw_a, UG);
    let vrw_b = v(vrw_b, MPS_PER_SQRT_H);
    let hyp = |x: Vec3, y: Vec3| Vec3::from_fn(|i, _| x[i].hypot(y[i]));
    let noise = NoiseModel {
        arw_rad_per_sqrt_s: v(arw, DPSH),
        vrw_mps_per_sqrt_s: hyp(vrw_a, vrw_b),
        accel_bias_gm_mps2: Vec3::from(a.gm),
        accel_bias_tau_s: Vec3::from(a.tau_s),
        gyro_bias_gm_rps: Vec3::from(g.gm),
        gyro_bias_tau_s: Vec3::from(g.tau_s),
        accel_bias_rw: v(a_rrw, UG_PER_SQRT_H),
        gyro_bias_rw: v(g_rrw, DPHPSH),
    };
    let model = RecordModel {
        noise,
        accel_bias_sigma_mps2: hyp(v(ba_on, UG), Vec3::from(a.gm)),
        gyro_bias_sigma_rps: hyp(v(bg_on, DPH), Vec3::from(g.gm)),
        accel_bias0_mps2: v(ba0, UG),
        gyro_bias0_rps: v(bg0, DPH),
    };
    let lever_arm_b_m = match &raw.gnss {
        Some(gn) => c.get("gnss", "lever_arm_b_m", &gn.lever_arm_b_m, Finite)?,
        None => None,
    };
    let (initial_sigma, attitude_rpy_rad) = match &raw.initial {
        None => (InitialSigma::default(), None),
        Some(i) => initial(&c, i)?,
    };
    Ok(SensorModel {
        file: file.to_path_buf(),
        format: SensorModelFormat::Toml,
        model,
        scale_sigma,
        lever_arm_b_m,
        initial_sigma,
        attitude_rpy_rad,
        kfgins: None,
    })
}

fn scale_prior(
    c: &Ctx<'_>,
    gs: Option<[f64; 3]>,
    as_: Option<[f64; 3]>,
    im: &ImuRaw,
) -> Result<Option<ScaleFactorPrior>, SensorModelError> {
    if gs.is_none() && as_.is_none() {
        return Ok(None);
    }
    let p = ScaleFactorPrior {
        accel_ppm: as_.unwrap_or([0.0; 3]),
        gyro_ppm: gs.unwrap_or([0.0; 3]),
    };
    if p.validate().is_err() {
        let (key, v) = if gs.is_some_and(|g| g.iter().any(|&x| x > 1e5)) {
            ("gyro_scale_sigma_ppm", &im.gyro_scale_sigma_ppm)
        } else {
            ("accel_scale_sigma_ppm", &im.accel_scale_sigma_ppm)
        };
        return Err(SensorModelError::Invalid {
            file: c.file.to_path_buf(),
            line: c.line(v),
            key: format!("imu.{key}"),
            what: "must be in [0, 100000] ppm".into(),
        });
    }
    Ok(Some(p))
}

fn initial(
    c: &Ctx<'_>,
    i: &InitialRaw,
) -> Result<(InitialSigma, Option<[f64; 3]>), SensorModelError> {
    use Range::*;
    let s = InitialSigma {
        pos_ned_m: c.get("initial", "position_sigma_m", &i.position_sigma_m, Positive)?,
        vel_ned_mps: c.get(
            "initial",
            "velocity_sigma_mps",
            &i.velocity_sigma_mps,
            Positive,
        )?,
        att_rpy_rad: c
            .get(
                "initial",
                "attitude_sigma_deg",
                &i.attitude_sigma_deg,
                Positive,
            )?
            .map(|a| a.map(f64::to_radians)),
    };
    let att = c.get("initial", "attitude_deg", &i.attitude_deg, Finite)?;
    if let Some(a) = att {
        if a[1].abs() >= 90.0 {
            return Err(SensorModelError::Invalid {
                file: c.file.to_path_buf(),
                line: c.line(&i.attitude_deg),
                key: "initial.attitude_deg".into(),
                what: format!("|pitch| must be < 90 deg, got {}", a[1]),
            });
        }
    }
    Ok((s, att.map(|a| a.map(f64::to_radians))))
}

#[cfg(test)]
#[path = "sensor_model_tests.rs"]
mod tests;
