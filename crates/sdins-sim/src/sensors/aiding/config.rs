//! The scenario tables of the aiding sensors (`[baro]`, `[odometer]`, `[magnetometer]`,
//! `[dual_antenna]`, `[body_velocity]`): rates, noise, error states, placement, outages
//! and seeds, units in the key names. See `docs/theory/aiding-sensors.md` for the models.

use serde::{Deserialize, Serialize};

/// A bad aiding-sensor setting (names the table and key).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AidingConfigError {
    /// The value of `table.key` is out of range.
    #[error("[{table}] {key}: {what}")]
    Invalid {
        /// table name
        table: &'static str,
        /// key name
        key: &'static str,
        /// what is wrong
        what: String,
    },
}

struct Check {
    table: &'static str,
}

impl Check {
    fn bad(&self, key: &'static str, what: impl Into<String>) -> AidingConfigError {
        AidingConfigError::Invalid {
            table: self.table,
            key,
            what: what.into(),
        }
    }
    /// finite and > 0 (strict) or ≥ 0
    fn pos(&self, key: &'static str, v: f64, strict: bool) -> Result<(), AidingConfigError> {
        if !v.is_finite() || v < 0.0 || (strict && v <= 0.0) {
            let rel = if strict { "> 0" } else { "≥ 0" };
            return Err(self.bad(key, format!("must be finite and {rel}, got {v}")));
        }
        Ok(())
    }
    fn rate(&self, rate_hz: f64) -> Result<(), AidingConfigError> {
        if !(rate_hz.is_finite() && (0.01..=100.0).contains(&rate_hz)) {
            return Err(self.bad("rate_hz", format!("must be in 0.01…100, got {rate_hz}")));
        }
        Ok(())
    }
    fn finite3(&self, key: &'static str, v: &[f64; 3], max: f64) -> Result<(), AidingConfigError> {
        if v.iter().any(|x| !x.is_finite() || x.abs() > max) {
            return Err(self.bad(key, format!("must be finite with |x| ≤ {max}, got {v:?}")));
        }
        Ok(())
    }
    fn outages(&self, o: &[[f64; 2]]) -> Result<(), AidingConfigError> {
        for w in o {
            if !(w[0].is_finite() && w[1].is_finite() && w[0] < w[1]) {
                return Err(self.bad(
                    "outages_s",
                    format!("each outage is [start_s, end_s] with start < end, got {w:?}"),
                ));
            }
        }
        Ok(())
    }
}

fn in_outage(o: &[[f64; 2]], t_s: f64) -> bool {
    o.iter().any(|w| t_s >= w[0] && t_s < w[1])
}

/// `[baro]`: barometric altitude `h_baro = h + b + v`, `b` a first-order Gauss–Markov
/// bias (weather; geoid and QNH offsets are absorbed in it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BaroConfig {
    /// measurement rate \[Hz\]
    pub rate_hz: f64,
    /// white noise σ \[m\]
    pub sigma_m: f64,
    /// bias steady-state σ \[m\] (also the filter's prior)
    pub bias_sigma_m: f64,
    /// bias correlation time \[s\]
    pub bias_tau_s: f64,
    /// outages `[start_s, end_s)`
    pub outages_s: Vec<[f64; 2]>,
    /// random seed
    pub seed: u64,
}

impl Default for BaroConfig {
    fn default() -> Self {
        Self {
            rate_hz: 1.0,
            sigma_m: 0.5,
            bias_sigma_m: 5.0,
            bias_tau_s: 3600.0,
            outages_s: Vec::new(),
            seed: 11,
        }
    }
}

/// `[odometer]`: wheel speed at the rear-axle centre along the vehicle's x axis,
/// `z = (1 + s) v_x^v + v` (quantised when `resolution_mps > 0`), `s` a random-constant
/// scale-factor error; optionally the non-holonomic constraint at the same point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OdometerConfig {
    /// measurement rate \[Hz\]
    pub rate_hz: f64,
    /// white speed noise σ \[m/s\]
    pub sigma_mps: f64,
    /// speed quantisation step \[m/s\] (0: none; the filter adds step²/12 to its variance)
    pub resolution_mps: f64,
    /// scale-factor error σ (random constant per run; the filter's prior) \[1\]
    pub scale_sigma: f64,
    /// lever arm IMU → rear-axle centre, body axes \[m\]
    pub lever_arm_b_m: [f64; 3],
    /// the IMU's mounting in the vehicle: roll, pitch, yaw of the body frame relative to
    /// the vehicle frame \[deg\] (`C_b^v`)
    pub mount_deg: [f64; 3],
    /// σ of the non-holonomic rows (lateral and vertical vehicle velocity zero) \[m/s\];
    /// 0: speed only
    pub nhc_sigma_mps: f64,
    /// outages `[start_s, end_s)`
    pub outages_s: Vec<[f64; 2]>,
    /// random seed
    pub seed: u64,
}

impl Default for OdometerConfig {
    fn default() -> Self {
        Self {
            rate_hz: 10.0,
            sigma_mps: 0.05,
            resolution_mps: 0.0,
            scale_sigma: 0.01,
            lever_arm_b_m: [0.0; 3],
            mount_deg: [0.0; 3],
            nhc_sigma_mps: 0.0,
            outages_s: Vec::new(),
            seed: 12,
        }
    }
}

/// `[magnetometer]`: the three-axis field in body axes, `z = C_n^b m^n + b_hi + v`, the
/// reference field from declination, inclination and intensity, `b_hi` a random-constant
/// hard-iron bias.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MagnetometerConfig {
    /// measurement rate \[Hz\]
    pub rate_hz: f64,
    /// white noise σ per axis \[µT\]
    pub sigma_ut: f64,
    /// declination (east of north) \[deg\]
    pub declination_deg: f64,
    /// inclination (down from horizontal) \[deg\]
    pub inclination_deg: f64,
    /// field intensity \[µT\]
    pub intensity_ut: f64,
    /// hard-iron σ per axis (random constant per run; the filter's prior) \[µT\]
    pub hard_iron_sigma_ut: f64,
    /// outages `[start_s, end_s)`
    pub outages_s: Vec<[f64; 2]>,
    /// random seed
    pub seed: u64,
}

impl Default for MagnetometerConfig {
    fn default() -> Self {
        Self {
            rate_hz: 10.0,
            sigma_ut: 0.5,
            declination_deg: 0.0,
            inclination_deg: 60.0,
            intensity_ut: 50.0,
            hard_iron_sigma_ut: 2.0,
            outages_s: Vec::new(),
            seed: 13,
        }
    }
}

/// `[dual_antenna]`: the direction of the baseline between two antennas (azimuth and
/// elevation; azimuth only with `heading_only`), σ_az = σ_rel/(L cos el), σ_el = σ_rel/L.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DualAntennaConfig {
    /// measurement rate \[Hz\]
    pub rate_hz: f64,
    /// baseline, body axes \[m\]
    pub baseline_b_m: [f64; 3],
    /// relative-position σ of the two antennas \[m\]
    pub sigma_rel_m: f64,
    /// azimuth only
    pub heading_only: bool,
    /// outages `[start_s, end_s)`
    pub outages_s: Vec<[f64; 2]>,
    /// random seed
    pub seed: u64,
}

impl Default for DualAntennaConfig {
    fn default() -> Self {
        Self {
            rate_hz: 1.0,
            baseline_b_m: [1.0, 0.0, 0.0],
            sigma_rel_m: 0.005,
            heading_only: false,
            outages_s: Vec::new(),
            seed: 14,
        }
    }
}

/// `[body_velocity]`: a Doppler velocity log, the velocity of the sensor point in the
/// vehicle frame, three axes with white noise.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BodyVelocityConfig {
    /// measurement rate \[Hz\]
    pub rate_hz: f64,
    /// white noise σ per vehicle axis \[m/s\]
    pub sigma_mps: [f64; 3],
    /// lever arm IMU → sensor, body axes \[m\]
    pub lever_arm_b_m: [f64; 3],
    /// roll, pitch, yaw of the body frame relative to the vehicle frame \[deg\]
    pub mount_deg: [f64; 3],
    /// outages `[start_s, end_s)`
    pub outages_s: Vec<[f64; 2]>,
    /// random seed
    pub seed: u64,
}

impl Default for BodyVelocityConfig {
    fn default() -> Self {
        Self {
            rate_hz: 5.0,
            sigma_mps: [0.02; 3],
            lever_arm_b_m: [0.0; 3],
            mount_deg: [0.0; 3],
            outages_s: Vec::new(),
            seed: 15,
        }
    }
}

/// Every aiding sensor of a scenario (none by default).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct AidingConfig {
    /// barometer
    pub baro: Option<BaroConfig>,
    /// odometer
    pub odometer: Option<OdometerConfig>,
    /// magnetometer
    pub magnetometer: Option<MagnetometerConfig>,
    /// dual-antenna attitude
    pub dual_antenna: Option<DualAntennaConfig>,
    /// body velocity (DVL)
    pub body_velocity: Option<BodyVelocityConfig>,
}

impl BaroConfig {
    /// Check every value.
    pub fn validate(&self) -> Result<(), AidingConfigError> {
        let c = Check { table: "baro" };
        c.rate(self.rate_hz)?;
        c.pos("sigma_m", self.sigma_m, true)?;
        c.pos("bias_sigma_m", self.bias_sigma_m, true)?;
        c.pos("bias_tau_s", self.bias_tau_s, true)?;
        c.outages(&self.outages_s)
    }
    /// Whether `t_s` lies in an outage.
    pub fn in_outage(&self, t_s: f64) -> bool {
        in_outage(&self.outages_s, t_s)
    }
}

impl OdometerConfig {
    /// Check every value.
    pub fn validate(&self) -> Result<(), AidingConfigError> {
        let c = Check { table: "odometer" };
        c.rate(self.rate_hz)?;
        c.pos("sigma_mps", self.sigma_mps, true)?;
        c.pos("resolution_mps", self.resolution_mps, false)?;
        c.pos("scale_sigma", self.scale_sigma, true)?;
        if self.scale_sigma > 0.5 {
            return Err(c.bad(
                "scale_sigma",
                format!("must be ≤ 0.5, got {}", self.scale_sigma),
            ));
        }
        c.finite3("lever_arm_b_m", &self.lever_arm_b_m, 100.0)?;
        c.finite3("mount_deg", &self.mount_deg, 180.0)?;
        c.pos("nhc_sigma_mps", self.nhc_sigma_mps, false)?;
        c.outages(&self.outages_s)
    }
    /// Whether `t_s` lies in an outage.
    pub fn in_outage(&self, t_s: f64) -> bool {
        in_outage(&self.outages_s, t_s)
    }
    /// The measurement variance of the speed: σ² + step²/12.
    pub fn speed_var(&self) -> f64 {
        self.sigma_mps.powi(2) + self.resolution_mps.powi(2) / 12.0
    }
}

impl MagnetometerConfig {
    /// Check every value.
    pub fn validate(&self) -> Result<(), AidingConfigError> {
        let c = Check {
            table: "magnetometer",
        };
        c.rate(self.rate_hz)?;
        c.pos("sigma_ut", self.sigma_ut, true)?;
        c.pos("intensity_ut", self.intensity_ut, true)?;
        c.pos("hard_iron_sigma_ut", self.hard_iron_sigma_ut, true)?;
        if !(self.declination_deg.is_finite() && self.declination_deg.abs() <= 180.0) {
            return Err(c.bad("declination_deg", "must be in [−180, 180]"));
        }
        if !(self.inclination_deg.is_finite() && self.inclination_deg.abs() < 89.0) {
            return Err(c.bad(
                "inclination_deg",
                "must be in (−89, 89): at the magnetic poles the horizontal field, which gives the heading, vanishes",
            ));
        }
        c.outages(&self.outages_s)
    }
    /// Whether `t_s` lies in an outage.
    pub fn in_outage(&self, t_s: f64) -> bool {
        in_outage(&self.outages_s, t_s)
    }
}

impl DualAntennaConfig {
    /// Check every value.
    pub fn validate(&self) -> Result<(), AidingConfigError> {
        let c = Check {
            table: "dual_antenna",
        };
        c.rate(self.rate_hz)?;
        c.finite3("baseline_b_m", &self.baseline_b_m, 1000.0)?;
        let l = self.baseline_b_m.iter().map(|x| x * x).sum::<f64>().sqrt();
        if l < 0.1 {
            return Err(c.bad(
                "baseline_b_m",
                format!("must be at least 0.1 m long, got {l} m"),
            ));
        }
        c.pos("sigma_rel_m", self.sigma_rel_m, true)?;
        if self.sigma_rel_m > 0.2 * l {
            return Err(c.bad(
                "sigma_rel_m",
                format!("must be ≤ 0.2 × the baseline length ({l} m): the angles are linearised"),
            ));
        }
        c.outages(&self.outages_s)
    }
    /// Whether `t_s` lies in an outage.
    pub fn in_outage(&self, t_s: f64) -> bool {
        in_outage(&self.outages_s, t_s)
    }
}

impl BodyVelocityConfig {
    /// Check every value.
    pub fn validate(&self) -> Result<(), AidingConfigError> {
        let c = Check {
            table: "body_velocity",
        };
        c.rate(self.rate_hz)?;
        for (i, s) in self.sigma_mps.iter().enumerate() {
            if !(s.is_finite() && *s > 0.0) {
                return Err(c.bad(
                    "sigma_mps",
                    format!("entry {} must be finite and > 0, got {s}", i + 1),
                ));
            }
        }
        c.finite3("lever_arm_b_m", &self.lever_arm_b_m, 100.0)?;
        c.finite3("mount_deg", &self.mount_deg, 180.0)?;
        c.outages(&self.outages_s)
    }
    /// Whether `t_s` lies in an outage.
    pub fn in_outage(&self, t_s: f64) -> bool {
        in_outage(&self.outages_s, t_s)
    }
}

impl AidingConfig {
    /// Whether any sensor is configured.
    pub fn any(&self) -> bool {
        self.baro.is_some()
            || self.odometer.is_some()
            || self.magnetometer.is_some()
            || self.dual_antenna.is_some()
            || self.body_velocity.is_some()
    }
    /// Give every configured sensor the seed `seed` (a Monte Carlo's; the sensors' streams
    /// stay distinct by channel).
    pub fn set_seed(&mut self, seed: u64) {
        if let Some(c) = self.baro.as_mut() {
            c.seed = seed;
        }
        if let Some(c) = self.odometer.as_mut() {
            c.seed = seed;
        }
        if let Some(c) = self.magnetometer.as_mut() {
            c.seed = seed;
        }
        if let Some(c) = self.dual_antenna.as_mut() {
            c.seed = seed;
        }
        if let Some(c) = self.body_velocity.as_mut() {
            c.seed = seed;
        }
    }
    /// Check every configured sensor.
    pub fn validate(&self) -> Result<(), AidingConfigError> {
        if let Some(c) = &self.baro {
            c.validate()?;
        }
        if let Some(c) = &self.odometer {
            c.validate()?;
        }
        if let Some(c) = &self.magnetometer {
            c.validate()?;
        }
        if let Some(c) = &self.dual_antenna {
            c.validate()?;
        }
        if let Some(c) = &self.body_velocity {
            c.validate()?;
        }
        Ok(())
    }
}
