//! KF-GINS configuration files (`kf-gins.yaml`, i2Nav-WHU/KF-GINS) as a sensor model
//! (`sdins fuse --sensor-model kf-gins.yaml`: chosen by the extension `.yaml`/`.yml`).
//!
//! Units (KF-GINS's own comments): `initpos` \[deg, deg, m\], `initvel` \[m/s NED\],
//! `initatt` \[deg\] (roll, pitch, yaw), `initgyrbias` \[deg/h\], `initaccbias` \[mGal =
//! 1e-5 m/s²\], `initgyrscale`/`initaccscale` \[ppm\], `initposstd`/`initvelstd`/
//! `initattstd` \[m, m/s, deg\], optional `initbgstd` \[deg/h\], `initbastd` \[mGal\],
//! `initsgstd`/`initsastd` \[ppm\]; `imunoise.arw` \[deg/√h\], `vrw` \[m/s/√h\], `gbstd`
//! \[deg/h\], `abstd` \[mGal\], `gsstd`/`asstd` \[ppm\], `corrtime` \[h\]; `antlever` \[m,
//! FRD\].
//!
//! Mapping to sdins's filter: KF-GINS models biases and scale factors as first-order
//! Gauss–Markov with one correlation time (q = 2σ²/T). The biases become Gauss–Markov
//! states with σ = `gbstd`/`abstd`, T = `corrtime`; their prior σ is `initbgstd`/`initbastd`
//! (default, as in KF-GINS, `gbstd`/`abstd`); `initgyrbias`/`initaccbias` are the known
//! bias, subtracted. sdins's scale-factor states are random constants
//! (`sdins_core::aiding::layout`): `gsstd`/`asstd` (or `initsgstd`/`initsastd`) become
//! their prior σ and `corrtime` is not applied to them (over a run much shorter than
//! `corrtime`, 4 h in KF-GINS's data set, the two differ little). `initgyrscale`/
//! `initaccscale` must be 0 (the scale-factor states start at 0). `initatt` with
//! `initattstd` is the initial attitude when no `--init`/`--attitude-deg`/`--static-s` is
//! given (position and velocity then from the first fix); `initposstd`/`initvelstd` are
//! the σ of an `--init` state. `initpos`, `initvel`, `starttime`, `endtime`, the data
//! paths and `outputpath` are read and recorded in run.toml but not used: give the files
//! with `--imu`/`--gnss` (sdins reads KF-GINS's IMU and GNSS text formats) and the output
//! folder with `--out` (nothing is written to `outputpath`). The paths resolve relative
//! to the YAML file.

use super::sensor_model::{
    check, InitialSigma, Range, SensorModel, SensorModelError, SensorModelFormat,
};
use crate::fusion::records::RecordModel;
use crate::fusion::simulated::ScaleFactorPrior;
use crate::sensors::imu_error::{DPH, DPSH, MPS_PER_SQRT_H};
use sdins_core::aiding::ekf::NoiseModel;
use sdins_core::math::Vec3;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// 1 mGal in m/s².
pub const MGAL: f64 = 1e-5;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    imupath: Option<String>,
    gnsspath: Option<String>,
    outputpath: Option<String>,
    imudatalen: Option<f64>,
    imudatarate: Option<f64>,
    starttime: Option<f64>,
    endtime: Option<f64>,
    initpos: [f64; 3],
    initvel: [f64; 3],
    initatt: [f64; 3],
    #[serde(default)]
    initgyrbias: [f64; 3],
    #[serde(default)]
    initaccbias: [f64; 3],
    #[serde(default)]
    initgyrscale: [f64; 3],
    #[serde(default)]
    initaccscale: [f64; 3],
    initposstd: [f64; 3],
    initvelstd: [f64; 3],
    initattstd: [f64; 3],
    initbgstd: Option<[f64; 3]>,
    initbastd: Option<[f64; 3]>,
    initsgstd: Option<[f64; 3]>,
    initsastd: Option<[f64; 3]>,
    imunoise: Noise,
    #[serde(default)]
    antlever: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Noise {
    arw: [f64; 3],
    vrw: [f64; 3],
    gbstd: [f64; 3],
    abstd: [f64; 3],
    gsstd: [f64; 3],
    asstd: [f64; 3],
    corrtime: f64,
}

/// What a KF-GINS YAML gives beyond the filter's model (recorded in run.toml, not used).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct KfGinsExtras {
    /// `imupath`, relative to the YAML's folder
    pub imu_path: Option<PathBuf>,
    /// `gnsspath`, relative to the YAML's folder
    pub gnss_path: Option<PathBuf>,
    /// `outputpath`, relative to the YAML's folder (never written)
    pub output_path: Option<PathBuf>,
    /// `starttime` \[s\]
    pub start_time_s: Option<f64>,
    /// `endtime` \[s\] (−1: the end of the IMU file)
    pub end_time_s: Option<f64>,
    /// `initpos` latitude, longitude \[rad\], height \[m\]
    pub pos_lat_rad_lon_rad_h_m: [f64; 3],
    /// `initvel` N, E, D \[m/s\]
    pub vel_ned_mps: [f64; 3],
}

impl KfGinsExtras {
    /// As a run.toml table.
    pub fn to_toml(&self) -> toml::Table {
        let a = |x: &[f64; 3]| toml::Value::Array(x.iter().map(|&e| e.into()).collect());
        let mut t = toml::Table::new();
        for (k, p) in [
            ("imu_path", &self.imu_path),
            ("gnss_path", &self.gnss_path),
            ("output_path", &self.output_path),
        ] {
            if let Some(p) = p {
                t.insert(k.into(), p.display().to_string().into());
            }
        }
        if let Some(s) = self.start_time_s {
            t.insert("start_time_s".into(), s.into());
        }
        if let Some(s) = self.end_time_s {
            t.insert("end_time_s".into(), s.into());
        }
        t.insert(
            "pos_lat_rad_lon_rad_h_m".into(),
            a(&self.pos_lat_rad_lon_rad_h_m),
        );
        t.insert("vel_ned_mps".into(), a(&self.vel_ned_mps));
        t
    }
}

/// 1-based line of the first line whose text starts with `key:` (0 if none).
fn key_line(text: &str, key: &str) -> usize {
    let pat = format!("{key}:");
    text.lines()
        .position(|l| l.trim_start().starts_with(&pat))
        .map_or(0, |i| i + 1)
}

/// Parse a KF-GINS YAML; `file` names the file in errors and anchors its paths.
pub fn parse_kfgins_yaml(file: &Path, text: &str) -> Result<SensorModel, SensorModelError> {
    let r: Raw = serde_norway::from_str(text).map_err(|e| SensorModelError::Syntax {
        file: file.to_path_buf(),
        line: e.location().map_or(0, |l| l.line()),
        message: e.to_string(),
    })?;
    let chk = |key: &str, v: &[f64], range: Range| {
        let leaf = key.rsplit('.').next().unwrap_or(key);
        check(file, key_line(text, leaf), key, v, range)
    };
    use Range::*;
    let n = &r.imunoise;
    chk("imunoise.arw", &n.arw, NonNegative)?;
    chk("imunoise.vrw", &n.vrw, NonNegative)?;
    chk("imunoise.gbstd", &n.gbstd, NonNegative)?;
    chk("imunoise.abstd", &n.abstd, NonNegative)?;
    chk("imunoise.gsstd", &n.gsstd, NonNegative)?;
    chk("imunoise.asstd", &n.asstd, NonNegative)?;
    chk("imunoise.corrtime", &[n.corrtime], Positive)?;
    chk("initpos", &r.initpos, Finite)?;
    chk("initvel", &r.initvel, Finite)?;
    chk("initatt", &r.initatt, Finite)?;
    chk("initgyrbias", &r.initgyrbias, Finite)?;
    chk("initaccbias", &r.initaccbias, Finite)?;
    chk("initposstd", &r.initposstd, Positive)?;
    chk("initvelstd", &r.initvelstd, Positive)?;
    chk("initattstd", &r.initattstd, Positive)?;
    chk("antlever", &r.antlever, Finite)?;
    for (k, v) in [
        ("initbgstd", &r.initbgstd),
        ("initbastd", &r.initbastd),
        ("initsgstd", &r.initsgstd),
        ("initsastd", &r.initsastd),
    ] {
        if let Some(v) = v {
            chk(k, v, NonNegative)?;
        }
    }
    for (k, v) in [
        ("initgyrscale", &r.initgyrscale),
        ("initaccscale", &r.initaccscale),
    ] {
        chk(k, v, Finite)?;
        if v.iter().any(|&x| x != 0.0) {
            return Err(SensorModelError::Invalid {
                file: file.to_path_buf(),
                line: key_line(text, k),
                key: k.into(),
                what: "sdins's scale-factor states start at 0: must be [0, 0, 0]".into(),
            });
        }
    }
    if r.initatt[1].abs() >= 90.0 {
        return Err(SensorModelError::Invalid {
            file: file.to_path_buf(),
            line: key_line(text, "initatt"),
            key: "initatt".into(),
            what: format!("|pitch| must be < 90 deg, got {}", r.initatt[1]),
        });
    }
    let v = |x: [f64; 3], u: f64| Vec3::new(x[0] * u, x[1] * u, x[2] * u);
    let tau_s = n.corrtime * 3600.0;
    let tau = |s: [f64; 3]| Vec3::from_fn(|i, _| if s[i] > 0.0 { tau_s } else { f64::INFINITY });
    let noise = NoiseModel {
        arw_rad_per_sqrt_s: v(n.arw, DPSH),
        vrw_mps_per_sqrt_s: v(n.vrw, MPS_PER_SQRT_H),
        accel_bias_gm_mps2: v(n.abstd, MGAL),
        accel_bias_tau_s: tau(n.abstd),
        gyro_bias_gm_rps: v(n.gbstd, DPH),
        gyro_bias_tau_s: tau(n.gbstd),
        accel_bias_rw: Vec3::zeros(),
        gyro_bias_rw: Vec3::zeros(),
    };
    let model = RecordModel {
        noise,
        accel_bias_sigma_mps2: v(r.initbastd.unwrap_or(n.abstd), MGAL),
        gyro_bias_sigma_rps: v(r.initbgstd.unwrap_or(n.gbstd), DPH),
        accel_bias0_mps2: v(r.initaccbias, MGAL),
        gyro_bias0_rps: v(r.initgyrbias, DPH),
    };
    let scale = ScaleFactorPrior {
        accel_ppm: r.initsastd.unwrap_or(n.asstd),
        gyro_ppm: r.initsgstd.unwrap_or(n.gsstd),
    };
    if scale.validate().is_err() {
        return Err(SensorModelError::Invalid {
            file: file.to_path_buf(),
            line: key_line(text, "gsstd"),
            key: "imunoise.gsstd/asstd".into(),
            what: "scale-factor σ must be in [0, 100000] ppm".into(),
        });
    }
    let any_scale = scale
        .accel_ppm
        .iter()
        .chain(&scale.gyro_ppm)
        .any(|&x| x > 0.0);
    let dir = file.parent().unwrap_or(Path::new(""));
    let rel = |p: &Option<String>| p.as_ref().map(|s| dir.join(s));
    let _ = (r.imudatalen, r.imudatarate);
    Ok(SensorModel {
        file: file.to_path_buf(),
        format: SensorModelFormat::KfGinsYaml,
        model,
        scale_sigma: any_scale.then_some(scale),
        lever_arm_b_m: Some(r.antlever),
        initial_sigma: InitialSigma {
            pos_ned_m: Some(r.initposstd),
            vel_ned_mps: Some(r.initvelstd),
            att_rpy_rad: Some(r.initattstd.map(f64::to_radians)),
        },
        attitude_rpy_rad: Some(r.initatt.map(f64::to_radians)),
        kfgins: Some(KfGinsExtras {
            imu_path: rel(&r.imupath),
            gnss_path: rel(&r.gnsspath),
            output_path: rel(&r.outputpath),
            start_time_s: r.starttime,
            end_time_s: r.endtime,
            pos_lat_rad_lon_rad_h_m: [
                r.initpos[0].to_radians(),
                r.initpos[1].to_radians(),
                r.initpos[2],
            ],
            vel_ned_mps: r.initvel,
        }),
    })
}
