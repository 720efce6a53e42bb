//! IMU error models: the sensor-error terms of docs/theory/imu-errors.md applied to exact
//! body-frame increments, sensor-grade presets (docs/imu-errors.md §"Grades") and a reproducible,
//! stateful corruption of an increment stream.
//!
//! * [`ImuErrorModel`]: every term, per axis, in datasheet units (°/h, °/√h, μg,
//!   μg/√Hz, m/s/√h, ppm, mrad, …). Deserializable from a scenario TOML table
//!   `[imu.errors]` (`deny_unknown_fields`; missing keys are zero = term off).
//! * [`presets`]: the grade presets `ideal`, `marine`, `aviation`, `intermediate`,
//!   `tactical`, `consumer`, and the preset-plus-overrides merge
//!   ([`ImuErrorModel::from_table`]).
//! * [`ImuErrorState`]: corrupts a stream sample by sample; its random numbers are a
//!   pure function of (seed, run index, sensor channel).
//!
//! ## Sensor model (per sample k of period `dt`)
//!
//! The errors act on the **average** rate and specific force over the sample,
//! `ω = Δθ/dt`, `f = Δv/dt`, and the corrupted value is integrated back,
//! `Δθ̃ = ω̃·dt`, `Δṽ = f̃·dt`:
//!
//! ```text
//! ω̃ = sat_ω( D_g(ω) ω + M_g ω + b_g + G f/g0 + n_g )      (then quantized)
//! f̃ = sat_f( D_a(f) f + M_a f + b_a + n_a )
//! D(x) = diag(1 + s_i + a_i·sgn(x_i))     scale factor s (ppm), asymmetry a (ppm)
//! b = b_fixed + b_turn_on + b_GM + b_flicker + b_RW
//! ```
//!
//! with `M` the small-angle misalignment/non-orthogonality matrix (mrad, its
//! diagonal adds to the scale factor), `G` the gyro g-sensitivity (°/h/g, applied to
//! the **true** specific force, `g0` = 9.80665 m/s²), and the discrete noise terms
//! (`w ~ N(0, 1)`, independent per sample and channel):
//!
//! * white noise (ARW `N` in rad/√s, VRW in m/s/√s): rate sample
//!   `n_k = N/√dt · w_k`, i.e. the increment noise has σ = `N·√dt` — its Allan
//!   deviation is `N/√τ`;
//! * rate random walk (`K` in rad/s/√s or m/s²/√s): `b_RW,k+1 = b_RW,k + K√dt·w_k`,
//!   `b_RW,0 = 0` — Allan deviation `K√(τ/3)`;
//! * first-order Gauss–Markov (steady-state σ, correlation time T):
//!   `b_k+1 = e^(−dt/T) b_k + σ√(1 − e^(−2dt/T)) w_k`, `b_0 ~ N(0, σ²)` (exact
//!   discretization; autocorrelation `σ² e^(−|t|/T)`);
//! * flicker (bias instability B, the datasheet "Allan floor" value): a sum of
//!   Gauss–Markov terms with correlation times spaced by a factor 3 over
//!   [`ImuErrorModel::flicker_tau_s`], equal σ, scaled so that the Allan deviation
//!   of the sum averages (in log) `0.664·B` over τ ∈ \[4·T_min, T_max/2\] (IEEE Std
//!   952: flicker floor = B·√(2 ln2/π)); it stays within ±10 % of that there;
//! * turn-on bias: drawn once per run, `b ~ N(0, σ²)`; the fixed bias is added as
//!   given.
//!
//! Quantization works like a real integrating sensor: the exact output increment is
//! added to a carried remainder `r`, the output is `q·floor(r/q)` and the rest stays
//! in `r ∈ [0, q)`, so the cumulative quantized output never differs from the
//! cumulative unquantized output by more than one quantum. Saturation clamps the
//! rate (°/s) and specific force (g) per axis before quantization.

pub mod presets;
mod state;

pub use presets::{preset, GRADE_NAMES};
pub use state::ImuErrorState;

use serde::{Deserialize, Serialize};

/// Units: one degree \[rad\].
pub const DEG: f64 = core::f64::consts::PI / 180.0;
/// Units: 1 °/h in rad/s.
pub const DPH: f64 = DEG / 3600.0;
/// Units: 1 °/√h in rad/√s (docs/theory/error-analysis.md §"Constants and units": 2.9089e-4).
pub const DPSH: f64 = DEG / 60.0;
/// Units: 1 °/h/√h in rad/s/√s.
pub const DPHPSH: f64 = DPH / 60.0;
/// Standard gravity for μg and g conversions \[m/s²\] (docs/theory/error-analysis.md
/// §"Constants and units").
pub const G0: f64 = 9.80665;
/// Units: 1 μg in m/s².
pub const UG: f64 = 1e-6 * G0;
/// Units: 1 μg/√Hz in m/s/√s (docs/theory/error-analysis.md §"Constants and units").
pub const UG_PER_SQRT_HZ: f64 = UG;
/// Units: 1 m/s/√h in m/s/√s.
pub const MPS_PER_SQRT_H: f64 = 1.0 / 60.0;
/// Units: 1 μg/√h (accelerometer random walk) in m/s²/√s.
pub const UG_PER_SQRT_H: f64 = UG / 60.0;
/// Units: one arcsecond \[rad\].
pub const ARCSEC: f64 = DEG / 3600.0;
/// Units: 1 ppm.
pub const PPM: f64 = 1e-6;
/// Units: 1 mrad.
pub const MRAD: f64 = 1e-3;

/// Error in an error-model description.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum ImuErrorModelError {
    /// `preset = "…"` names no grade.
    #[error("unknown IMU grade preset `{0}` (known: ideal, marine, aviation, intermediate, tactical, consumer)")]
    UnknownPreset(String),
    /// A term has a value it cannot have (negative σ, zero correlation time, …).
    #[error("IMU error term `{field}`: {what}")]
    Invalid {
        /// the field name
        field: &'static str,
        /// what is wrong
        what: String,
    },
    /// The override table does not deserialize (unknown key, wrong type).
    #[error("IMU error table: {0}")]
    Table(String),
}

/// All IMU error terms, per axis (x, y, z of the FRD body frame), in datasheet units.
///
/// Every term defaults to zero (= off); saturation defaults to none. See the
/// [module documentation](self) for the equations.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImuErrorModel {
    /// Fixed (known-value) gyro bias \[°/h\].
    pub gyro_bias_dph: [f64; 3],
    /// Turn-on (run-to-run) gyro bias σ \[°/h\], drawn once per run.
    pub gyro_bias_turn_on_dph: [f64; 3],
    /// First-order Gauss–Markov gyro bias: steady-state σ \[°/h\].
    pub gyro_bias_gm_dph: [f64; 3],
    /// First-order Gauss–Markov gyro bias: correlation time \[s\] (used where σ > 0).
    pub gyro_bias_gm_tau_s: [f64; 3],
    /// Gyro bias instability B (flicker, Allan floor = 0.664·B) \[°/h\].
    pub gyro_bias_instability_dph: [f64; 3],
    /// Angle random walk \[°/√h\].
    pub gyro_arw_dpsh: [f64; 3],
    /// Rate random walk \[°/h/√h\].
    pub gyro_rrw_dphpsh: [f64; 3],
    /// Gyro scale-factor error \[ppm\].
    pub gyro_scale_ppm: [f64; 3],
    /// Gyro scale-factor asymmetry a \[ppm\]: the scale error is s + a for a positive
    /// rate and s − a for a negative one.
    pub gyro_scale_asym_ppm: [f64; 3],
    /// Gyro misalignment / non-orthogonality, small-angle matrix \[mrad\]:
    /// `ω̃ ∋ M ω` (row i = output axis i).
    pub gyro_misalignment_mrad: [[f64; 3]; 3],
    /// Gyro g-sensitivity matrix \[°/h/g\]: `δω = G f / g0`.
    pub gyro_g_sensitivity_dphpg: [[f64; 3]; 3],
    /// Gyro output quantum (angle per pulse) \[arcsec\]; 0 = none.
    pub gyro_quantum_arcsec: [f64; 3],
    /// Gyro measuring range (saturation) \[°/s\]; `None` = unlimited.
    pub gyro_range_dps: Option<[f64; 3]>,

    /// Fixed (known-value) accelerometer bias \[μg\].
    pub accel_bias_ug: [f64; 3],
    /// Turn-on (run-to-run) accelerometer bias σ \[μg\], drawn once per run.
    pub accel_bias_turn_on_ug: [f64; 3],
    /// First-order Gauss–Markov accelerometer bias: steady-state σ \[μg\].
    pub accel_bias_gm_ug: [f64; 3],
    /// First-order Gauss–Markov accelerometer bias: correlation time \[s\].
    pub accel_bias_gm_tau_s: [f64; 3],
    /// Accelerometer bias instability B (flicker) \[μg\].
    pub accel_bias_instability_ug: [f64; 3],
    /// Velocity random walk \[μg/√Hz\] (1 μg/√Hz = 9.80665e-6 m/s/√s).
    pub accel_vrw_ugpsqrthz: [f64; 3],
    /// Velocity random walk \[m/s/√h\]; added in quadrature to
    /// [`Self::accel_vrw_ugpsqrthz`] (normally only one of the two is set).
    pub accel_vrw_mpsph: [f64; 3],
    /// Acceleration random walk \[μg/√h\].
    pub accel_rrw_ugpsh: [f64; 3],
    /// Accelerometer scale-factor error \[ppm\].
    pub accel_scale_ppm: [f64; 3],
    /// Accelerometer scale-factor asymmetry \[ppm\] (s ± a, as for the gyro).
    pub accel_scale_asym_ppm: [f64; 3],
    /// Accelerometer misalignment / non-orthogonality matrix \[mrad\].
    pub accel_misalignment_mrad: [[f64; 3]; 3],
    /// Accelerometer output quantum (velocity per pulse) \[m/s\]; 0 = none.
    pub accel_quantum_mps: [f64; 3],
    /// Accelerometer measuring range (saturation) \[g\]; `None` = unlimited.
    pub accel_range_g: Option<[f64; 3]>,

    /// Range of the flicker Gauss–Markov correlation times \[s\] (default 0.1…10 000 s).
    pub flicker_tau_s: [f64; 2],
}

impl Default for ImuErrorModel {
    fn default() -> Self {
        let z = [0.0; 3];
        let zm = [[0.0; 3]; 3];
        Self {
            gyro_bias_dph: z,
            gyro_bias_turn_on_dph: z,
            gyro_bias_gm_dph: z,
            gyro_bias_gm_tau_s: z,
            gyro_bias_instability_dph: z,
            gyro_arw_dpsh: z,
            gyro_rrw_dphpsh: z,
            gyro_scale_ppm: z,
            gyro_scale_asym_ppm: z,
            gyro_misalignment_mrad: zm,
            gyro_g_sensitivity_dphpg: zm,
            gyro_quantum_arcsec: z,
            gyro_range_dps: None,
            accel_bias_ug: z,
            accel_bias_turn_on_ug: z,
            accel_bias_gm_ug: z,
            accel_bias_gm_tau_s: z,
            accel_bias_instability_ug: z,
            accel_vrw_ugpsqrthz: z,
            accel_vrw_mpsph: z,
            accel_rrw_ugpsh: z,
            accel_scale_ppm: z,
            accel_scale_asym_ppm: z,
            accel_misalignment_mrad: zm,
            accel_quantum_mps: z,
            accel_range_g: None,
            flicker_tau_s: [0.1, 1.0e4],
        }
    }
}

/// Unit of an `[imu.errors]` key, from its name's unit suffix.
fn unit_of(key: &str) -> &'static str {
    const SUFFIXES: [(&str, &str); 15] = [
        ("_dphpsh", "°/h/√h"),
        ("_dphpg", "°/h/g"),
        ("_dpsh", "°/√h"),
        ("_dph", "°/h"),
        ("_dps", "°/s"),
        ("_ugpsqrthz", "μg/√Hz"),
        ("_ugpsh", "μg/√h"),
        ("_ug", "μg"),
        ("_mpsph", "m/s/√h"),
        ("_mps", "m/s"),
        ("_ppm", "ppm"),
        ("_mrad", "mrad"),
        ("_arcsec", "arcsec"),
        ("_g", "g"),
        ("_s", "s"),
    ];
    SUFFIXES
        .iter()
        .find(|(s, _)| key.ends_with(s))
        .map_or("", |(_, u)| u)
}

/// Every `[imu.errors]` key with its shape and unit, as a Markdown table generated from
/// [`ImuErrorModel`]'s serialization (docs/imu-errors.md holds this text; a test keeps it
/// equal).
pub fn keys_markdown() -> String {
    let full = ImuErrorModel {
        gyro_range_dps: Some([0.0; 3]),
        accel_range_g: Some([0.0; 3]),
        ..ImuErrorModel::default()
    };
    let mut s = String::from("| key | shape | unit | default |\n|---|---|---|---|\n");
    let Ok(toml::Value::Table(t)) = toml::Value::try_from(&full) else {
        return s;
    };
    let fields = toml::Value::try_from(ImuErrorModel::default())
        .ok()
        .and_then(|v| v.as_table().cloned())
        .unwrap_or_default();
    for (k, v) in &t {
        let shape = match v {
            toml::Value::Array(a) if a.first().is_some_and(toml::Value::is_array) => {
                "3×3 matrix (row i = output axis i)".to_string()
            }
            toml::Value::Array(a) if a.len() == 3 => "3-vector (x, y, z)".to_string(),
            toml::Value::Array(a) => format!("{} values", a.len()),
            _ => "scalar".to_string(),
        };
        let default = match fields.get(k) {
            None => "none (unlimited)".to_string(),
            Some(toml::Value::Array(a)) if a.iter().all(|x| x.as_float() == Some(0.0)) => {
                "0 (off)".to_string()
            }
            Some(toml::Value::Array(a))
                if a.iter().all(|x| {
                    x.as_array()
                        .is_some_and(|r| r.iter().all(|y| y.as_float() == Some(0.0)))
                }) =>
            {
                "0 (off)".to_string()
            }
            Some(v) => v.to_string(),
        };
        s += &format!("| `{k}` | {shape} | {} | {default} |\n", unit_of(k));
    }
    s
}

fn check_nonneg(field: &'static str, v: &[f64]) -> Result<(), ImuErrorModelError> {
    for x in v {
        if !(x.is_finite() && *x >= 0.0) {
            return Err(ImuErrorModelError::Invalid {
                field,
                what: format!("must be finite and ≥ 0, got {x}"),
            });
        }
    }
    Ok(())
}

fn check_finite(field: &'static str, v: &[f64]) -> Result<(), ImuErrorModelError> {
    for x in v {
        if !x.is_finite() {
            return Err(ImuErrorModelError::Invalid {
                field,
                what: format!("must be finite, got {x}"),
            });
        }
    }
    Ok(())
}

fn check_positive(field: &'static str, v: &[f64]) -> Result<(), ImuErrorModelError> {
    for x in v {
        if !(x.is_finite() && *x > 0.0) {
            return Err(ImuErrorModelError::Invalid {
                field,
                what: format!("must be finite and > 0, got {x}"),
            });
        }
    }
    Ok(())
}

impl ImuErrorModel {
    /// The error-free model (every term off).
    pub fn ideal() -> Self {
        Self::default()
    }

    /// A grade preset by name (see [`presets`]).
    pub fn preset(name: &str) -> Result<Self, ImuErrorModelError> {
        preset(name)
    }

    /// Check every term: σ's, ranges and quanta ≥ 0, correlation times > 0 where their
    /// σ is set, matrices and signed terms finite, flicker range `0 < lo < hi`.
    pub fn validate(&self) -> Result<(), ImuErrorModelError> {
        check_finite("gyro_bias_dph", &self.gyro_bias_dph)?;
        check_nonneg("gyro_bias_turn_on_dph", &self.gyro_bias_turn_on_dph)?;
        check_nonneg("gyro_bias_gm_dph", &self.gyro_bias_gm_dph)?;
        check_nonneg("gyro_bias_instability_dph", &self.gyro_bias_instability_dph)?;
        check_nonneg("gyro_arw_dpsh", &self.gyro_arw_dpsh)?;
        check_nonneg("gyro_rrw_dphpsh", &self.gyro_rrw_dphpsh)?;
        check_finite("gyro_scale_ppm", &self.gyro_scale_ppm)?;
        check_finite("gyro_scale_asym_ppm", &self.gyro_scale_asym_ppm)?;
        check_finite(
            "gyro_misalignment_mrad",
            self.gyro_misalignment_mrad.as_flattened(),
        )?;
        check_finite(
            "gyro_g_sensitivity_dphpg",
            self.gyro_g_sensitivity_dphpg.as_flattened(),
        )?;
        check_nonneg("gyro_quantum_arcsec", &self.gyro_quantum_arcsec)?;
        if let Some(r) = &self.gyro_range_dps {
            check_positive("gyro_range_dps", r)?;
        }
        check_finite("accel_bias_ug", &self.accel_bias_ug)?;
        check_nonneg("accel_bias_turn_on_ug", &self.accel_bias_turn_on_ug)?;
        check_nonneg("accel_bias_gm_ug", &self.accel_bias_gm_ug)?;
        check_nonneg("accel_bias_instability_ug", &self.accel_bias_instability_ug)?;
        check_nonneg("accel_vrw_ugpsqrthz", &self.accel_vrw_ugpsqrthz)?;
        check_nonneg("accel_vrw_mpsph", &self.accel_vrw_mpsph)?;
        check_nonneg("accel_rrw_ugpsh", &self.accel_rrw_ugpsh)?;
        check_finite("accel_scale_ppm", &self.accel_scale_ppm)?;
        check_finite("accel_scale_asym_ppm", &self.accel_scale_asym_ppm)?;
        check_finite(
            "accel_misalignment_mrad",
            self.accel_misalignment_mrad.as_flattened(),
        )?;
        check_nonneg("accel_quantum_mps", &self.accel_quantum_mps)?;
        if let Some(r) = &self.accel_range_g {
            check_positive("accel_range_g", r)?;
        }
        for i in 0..3 {
            if self.gyro_bias_gm_dph[i] > 0.0 {
                check_positive("gyro_bias_gm_tau_s", &[self.gyro_bias_gm_tau_s[i]])?;
            }
            if self.accel_bias_gm_ug[i] > 0.0 {
                check_positive("accel_bias_gm_tau_s", &[self.accel_bias_gm_tau_s[i]])?;
            }
        }
        check_positive("flicker_tau_s", &self.flicker_tau_s)?;
        if self.flicker_tau_s[0] >= self.flicker_tau_s[1] {
            return Err(ImuErrorModelError::Invalid {
                field: "flicker_tau_s",
                what: format!("needs lo < hi, got {:?}", self.flicker_tau_s),
            });
        }
        Ok(())
    }

    /// Apply an override table on top of `self`: every key present in `table`
    /// replaces that term (whole per-axis array); unknown keys are an error.
    /// `preset` is not allowed here (see [`Self::from_table`]).
    pub fn with_overrides(&self, table: &toml::Table) -> Result<Self, ImuErrorModelError> {
        let base =
            toml::Table::try_from(self).map_err(|e| ImuErrorModelError::Table(e.to_string()))?;
        let mut merged = base;
        for (k, v) in table {
            merged.insert(k.clone(), v.clone());
        }
        let m: Self = merged
            .try_into()
            .map_err(|e: toml::de::Error| ImuErrorModelError::Table(e.to_string()))?;
        m.validate()?;
        Ok(m)
    }

    /// Build from a scenario table such as `[imu.errors]`: an optional
    /// `preset = "tactical"` key selects the starting grade (default `ideal`), every
    /// other key overrides that term.
    ///
    /// ```
    /// let t: toml::Table = toml::from_str("preset = \"tactical\"\ngyro_arw_dpsh = [0.02, 0.02, 0.02]").unwrap();
    /// let m = sdins_sim::sensors::imu_error::ImuErrorModel::from_table(&t).unwrap();
    /// assert_eq!(m.gyro_arw_dpsh, [0.02; 3]);
    /// assert_eq!(m.accel_vrw_ugpsqrthz, [100.0; 3]);
    /// ```
    pub fn from_table(table: &toml::Table) -> Result<Self, ImuErrorModelError> {
        let mut rest = table.clone();
        let base = match rest.remove("preset") {
            None => Self::default(),
            Some(toml::Value::String(name)) => preset(&name)?,
            Some(other) => {
                return Err(ImuErrorModelError::Table(format!(
                    "`preset` must be a string, got {other}"
                )));
            }
        };
        base.with_overrides(&rest)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn units_match_spec_table() {
        // docs/theory/error-analysis.md §"Constants and units": 1 °/√h = 2.9089e-4 rad/√s, 1 °/h =
        // 4.8481368e-6 rad/s,
        // 1 μg/√Hz = 5.88e-4 m/s/√h
        assert!((DPSH - 2.9089e-4).abs() < 1e-8);
        assert!((DPH - 4.8481368e-6).abs() < 1e-13);
        assert!((UG_PER_SQRT_HZ / MPS_PER_SQRT_H - 5.88e-4).abs() < 1e-6);
    }

    #[test]
    fn toml_table_with_preset_and_overrides() {
        let t: toml::Table = toml::from_str(
            "preset = \"aviation\"\naccel_bias_ug = [1.0, 2.0, 3.0]\ngyro_range_dps = [400.0, 400.0, 400.0]",
        )
        .unwrap();
        let m = ImuErrorModel::from_table(&t).unwrap();
        assert_eq!(m.accel_bias_ug, [1.0, 2.0, 3.0]);
        assert_eq!(m.gyro_range_dps, Some([400.0; 3]));
        assert_eq!(m.gyro_arw_dpsh, [0.002; 3]);
        // unknown key → error naming it
        let bad: toml::Table = toml::from_str("gyro_arw = [1.0, 1.0, 1.0]").unwrap();
        let e = ImuErrorModel::from_table(&bad).unwrap_err();
        assert!(e.to_string().contains("gyro_arw"), "{e}");
        // unknown preset
        let bad: toml::Table = toml::from_str("preset = \"military\"").unwrap();
        assert_eq!(
            ImuErrorModel::from_table(&bad),
            Err(ImuErrorModelError::UnknownPreset("military".into()))
        );
        // invalid value
        let bad: toml::Table = toml::from_str("gyro_arw_dpsh = [1.0, -1.0, 1.0]").unwrap();
        assert!(matches!(
            ImuErrorModel::from_table(&bad),
            Err(ImuErrorModelError::Invalid { .. })
        ));
        // direct deserialization of the struct also denies unknown fields
        let r: Result<ImuErrorModel, _> = toml::from_str("accel_vrw = [1.0, 1.0, 1.0]");
        assert!(r.is_err());
    }
}
